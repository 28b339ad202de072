// The row each carpet design has reached, kept across restarts (as a dobby loom server keeps the
// position per pattern): switch to another design and back, and the loom resumes where that design
// was left. Non-RT: read when a session is armed, written after each row's counters.
//
// The file holds the rows woven per design name, which design is active, and the production row count
// at which the book was last written. A power cut between the counters' save and the book's leaves the
// book one row behind; those rows are credited to the design that was active, so the two never
// disagree. A book ahead of the counters (production counts never go back) is refused.
//   {"active":"medallion.csv","at_rows":37,"designs":{"border.png":120,"medallion.csv":12}}
#pragma once

#include <cstdint>
#include <map>
#include <string>

namespace loom::state {

class DesignBook {
 public:
  explicit DesignBook(std::string path) : path_(std::move(path)) {}

  // Loads the book (a missing file is an empty book; anything unreadable or malformed is a ConfigError
  // naming the file, field and value), credits rows woven since it was written to the design active
  // then, makes `design` active at production row `counter_rows` and writes the book. Returns the
  // rows of `design` woven so far.
  std::uint64_t activate(const std::string& design, std::uint32_t counter_rows);
  // After a row's counters were saved: the active design has woven up to `counter_rows`. Throws
  // std::runtime_error when the book cannot be written.
  void record(std::uint32_t counter_rows);

  std::uint64_t rows_done() const;  // of the active design
  const std::string& path() const { return path_; }

  static std::string format(const std::string& active, std::uint32_t at_rows,
                            const std::map<std::string, std::uint64_t>& designs);

 private:
  void load();
  void credit(std::uint32_t counter_rows);

  std::string path_;
  std::string active_;
  std::uint32_t at_rows_ = 0;
  std::map<std::string, std::uint64_t> designs_;
};

}  // namespace loom::state

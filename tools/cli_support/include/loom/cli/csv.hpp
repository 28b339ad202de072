// CSV output of the offline CLIs: a header naming every column with its unit, then rows of numbers in
// the shortest form of 12 significant digits (17 with full precision), '.' as the decimal point
// whatever the locale. Rows are streamed: the writer holds at most `hold_bytes` before writing them
// out, so a ten-million-row sweep runs in constant memory, and an output smaller than that is
// all-or-nothing (an error before finish() leaves stdout empty). A non-finite number is never
// printed: it throws NonFiniteOutput naming the row and column. Offline-tool code (configure-time).
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace loom::cli {

// A computed value is NaN or infinite: the tool exits 2 naming where, never prints it.
class NonFiniteOutput : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CsvWriter {
 public:
  static constexpr std::size_t kDefaultHoldBytes = std::size_t{1} << 20;

  // `header` is the comma-separated column names, without the newline.
  explicit CsvWriter(std::string_view header, bool full_precision = false, std::FILE* out = stdout,
                     std::size_t hold_bytes = kDefaultHoldBytes);
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;
  // Discards whatever was not yet written (an exception is unwinding; finish() was not reached).
  ~CsvWriter() = default;

  CsvWriter& num(double v);
  CsvWriter& text(std::string_view cell);
  // Ends the row; throws std::logic_error when it does not have one cell per column.
  void end_row();
  // Writes the rest and flushes; throws std::runtime_error when stdout cannot be written.
  void finish();

  std::size_t rows() const { return rows_; }
  const std::vector<std::string>& columns() const { return columns_; }

 private:
  void cell_separator();
  void spill();

  std::vector<std::string> columns_;
  bool full_;
  std::FILE* out_;
  std::size_t hold_;
  std::string buf_;
  std::size_t cells_ = 0;  // cells in the current row
  std::size_t rows_ = 0;
};

// A number for labels, titles and messages: 6 significant digits, shortest form.
std::string format_number(double v);

}  // namespace loom::cli

// See design_book.hpp. JSON through nlohmann, checked field by field: a book is never half-trusted.
#include "loom/state/design_book.hpp"

#include <filesystem>
#include <nlohmann/json.hpp>

#include "loom/config/config.hpp"
#include "loom/config/toml_reader.hpp"
#include "loom/state/durable_file.hpp"

namespace loom::state {

using firmware::ConfigError;
using firmware::read_config_file;

std::string DesignBook::format(const std::string& active, std::uint32_t at_rows,
                               const std::map<std::string, std::uint64_t>& designs) {
  nlohmann::json j = {{"active", active}, {"at_rows", at_rows}, {"designs", designs}};
  return j.dump() + "\n";
}

void DesignBook::load() {
  active_.clear();
  at_rows_ = 0;
  designs_.clear();
  std::error_code ec;
  if (std::filesystem::symlink_status(path_, ec).type() == std::filesystem::file_type::not_found) {
    return;  // the only case that starts every design at its first row
  }
  const std::string text = read_config_file(path_, 1L << 20, "design book");
  const auto bad = [&](const std::string& why) {
    return ConfigError(path_ + ": " + why + " (refusing to guess where the designs were left)");
  };
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw bad(std::string("not a design book: ") + e.what());
  }
  if (!j.is_object() || j.size() != 3 || !j.contains("active") || !j.contains("at_rows") ||
      !j.contains("designs")) {
    throw bad("want exactly {\"active\", \"at_rows\", \"designs\"}");
  }
  if (!j["active"].is_string()) throw bad("\"active\" = " + j["active"].dump() + ": not a design name");
  if (!j["at_rows"].is_number_unsigned() || j["at_rows"].get<std::uint64_t>() > UINT32_MAX) {
    throw bad("\"at_rows\" = " + j["at_rows"].dump() + ": not a row count in 0..4294967295");
  }
  if (!j["designs"].is_object())
    throw bad("\"designs\" = " + j["designs"].dump().substr(0, 60) + ": not an object");
  for (const auto& [name, rows] : j["designs"].items()) {
    if (name.empty() || name.size() > 255)
      throw bad("design name '" + name.substr(0, 60) + "': want 1..255 characters");
    // Every row a design has is a row the production counters counted, and those are 32-bit: a larger
    // count was not written by loomctl (and would wrap when credited).
    if (!rows.is_number_unsigned() || rows.get<std::uint64_t>() > UINT32_MAX) {
      throw bad("\"designs\".\"" + name + "\" = " + rows.dump() + ": not a row count in 0..4294967295");
    }
    designs_[name] = rows.get<std::uint64_t>();
  }
  active_ = j["active"].get<std::string>();
  at_rows_ = j["at_rows"].get<std::uint32_t>();
  if (!active_.empty() && !designs_.count(active_)) throw bad("active design '" + active_ + "' has no entry");
}

void DesignBook::credit(std::uint32_t counter_rows) {
  if (counter_rows < at_rows_) {
    throw ConfigError(path_ + ": written at production row " + std::to_string(at_rows_) +
                      " but the counters say " + std::to_string(counter_rows) +
                      " (production counts never go back; refusing to guess)");
  }
  if (!active_.empty()) {
    std::uint64_t& rows = designs_[active_];
    if (rows > UINT32_MAX - static_cast<std::uint64_t>(counter_rows - at_rows_)) {
      throw ConfigError(path_ + ": design '" + active_ + "' at " + std::to_string(rows) + " rows plus " +
                        std::to_string(counter_rows - at_rows_) + " would pass 4294967295 (never wrapped)");
    }
    rows += counter_rows - at_rows_;
  }
  at_rows_ = counter_rows;
}

std::uint64_t DesignBook::activate(const std::string& design, std::uint32_t counter_rows) {
  load();
  credit(counter_rows);
  active_ = design;
  designs_.try_emplace(design, 0);
  write_file_durably(path_, format(active_, at_rows_, designs_));
  return designs_[design];
}

void DesignBook::record(std::uint32_t counter_rows) {
  credit(counter_rows);
  write_file_durably(path_, format(active_, at_rows_, designs_));
}

std::uint64_t DesignBook::rows_done() const {
  const auto it = designs_.find(active_);
  return it == designs_.end() ? 0 : it->second;
}

}  // namespace loom::state

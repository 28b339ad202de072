// Helpers for the synthesis tests: split a printed table into rows of tokens and format a value
// the way the thesis printed it, so "reproduces to every printed digit" is a string comparison.
#pragma once

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

namespace loom::test {

inline std::vector<std::vector<std::string>> table_rows(const char* table) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(table);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream cells(line);
    std::vector<std::string> row;
    std::string cell;
    while (cells >> cell) row.push_back(cell);
    if (!row.empty()) rows.push_back(row);
  }
  return rows;
}

// printf("%.*f") with the decimals the printed token has ("0.25179" → 5, "1" → 0).
inline int decimals_of(const std::string& printed) {
  const auto dot = printed.find('.');
  return dot == std::string::npos ? 0 : static_cast<int>(printed.size() - dot - 1);
}

inline std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// The thesis drops trailing zeros in Table 4.8 ("0.25179" is 0.251790): compare at 6 decimals as
// numbers, i.e. our value rounded to 6 decimals must equal the printed one.
inline bool same_at_decimals(double ours, const std::string& printed, int decimals) {
  return fixed(ours, decimals) == fixed(std::stod(printed), decimals);
}

}  // namespace loom::test

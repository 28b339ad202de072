// CSV output of loom-dynamics: 12 significant digits in the shortest form with '.' as the decimal
// point whatever the locale, header first, SI units in the column names.
#pragma once

#include <cstdio>
#include <string>

namespace loom::dyncli {

inline void put(std::string& line, double v, bool last = false) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  line += buf;
  line += last ? '\n' : ',';
}

inline void put(std::string& line, const std::string& text, bool last = false) {
  line += text;
  line += last ? '\n' : ',';
}

// A number for labels and titles: 6 significant digits, shortest form.
inline std::string format_number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

inline void emit(const std::string& text) { std::fwrite(text.data(), 1, text.size(), stdout); }

}  // namespace loom::dyncli

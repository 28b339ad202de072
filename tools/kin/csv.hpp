// CSV number formatting for loom-kin: 12 significant digits, shortest form, '.' as decimal point
// whatever the locale, so scripts can diff and parse the output.
#pragma once

#include <cstdio>
#include <string>

namespace loom::kin {

inline void put(std::string& line, double v, bool last = false) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  line += buf;
  line += last ? '\n' : ',';
}

}  // namespace loom::kin

// A test's input file, whole, as its bytes are (binary mode). A file that cannot be read gives "", which
// the test's own expectations then show.
#pragma once

#include <fstream>
#include <sstream>
#include <string>

namespace loom::test {

inline std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace loom::test

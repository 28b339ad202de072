// Compares a fresh profile dump with the committed golden copy, file by file and number by number:
// same files, same headers, same rows; numbers equal within 1e-11 relative (1e-12 absolute near
// zero) — far below any change in motion, far above libm's last-bit differences between machines.
// Prints the first difference of each file and exits 1 when anything differs.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  return out;
}

bool number(const std::string& s, double& v) {
  if (s.empty()) return false;
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();
}

bool same_cell(const std::string& a, const std::string& b) {
  double x = 0, y = 0;
  if (number(a, x) && number(b, y)) {
    return std::abs(x - y) <= std::max(1e-12, 1e-11 * std::max(std::abs(x), std::abs(y)));
  }
  return a == b;
}

// True when equal; otherwise prints where they first differ.
bool same_file(const fs::path& golden, const fs::path& fresh) {
  std::ifstream g(golden), f(fresh);
  if (!f) {
    std::printf("%s: missing from the fresh dump\n", fresh.c_str());
    return false;
  }
  std::string lg, lf;
  for (int line = 1;; ++line) {
    const bool more_g = static_cast<bool>(std::getline(g, lg)),
               more_f = static_cast<bool>(std::getline(f, lf));
    if (!more_g && !more_f) return true;
    if (more_g != more_f) {
      std::printf("%s:%d: %s has more rows\n", golden.c_str(), line, more_g ? "golden" : "fresh dump");
      return false;
    }
    const std::vector<std::string> cg = split(lg), cf = split(lf);
    if (cg.size() != cf.size()) {
      std::printf("%s:%d: %zu columns in golden, %zu in the fresh dump\n", golden.c_str(), line, cg.size(),
                  cf.size());
      return false;
    }
    for (std::size_t c = 0; c < cg.size(); ++c) {
      if (!same_cell(cg[c], cf[c])) {
        std::printf("%s:%d: column %zu: golden %s, fresh %s\n", golden.c_str(), line, c + 1, cg[c].c_str(),
                    cf[c].c_str());
        return false;
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: golden_diff GOLDEN_DIR FRESH_DIR\n");
    return 2;
  }
  const fs::path golden = argv[1], fresh = argv[2];
  if (!fs::is_directory(golden) || !fs::is_directory(fresh)) {
    std::fprintf(stderr, "golden_diff: %s or %s is not a directory\n", golden.c_str(), fresh.c_str());
    return 2;
  }
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(golden)) names.insert(e.path().filename().string());
  bool ok = !names.empty();
  for (const auto& e : fs::directory_iterator(fresh)) {
    if (!names.count(e.path().filename().string())) {
      std::printf("%s: new file, not in the golden copy\n", e.path().c_str());
      ok = false;
    }
  }
  for (const std::string& n : names) ok = same_file(golden / n, fresh / n) && ok;
  return ok ? 0 : 1;
}

// libFuzzer harness: the carpet-design parser (design::parse_design_csv and parse_design_png) on
// arbitrary bytes. The first byte picks the format (even: CSV text, odd: PNG bytes), the rest is the
// file. A refusal is a design::DesignError; any other exception escaping, a crash, a hang or a sanitizer
// report is a bug. Every accepted design is read back whole (every row, every palette index in range)
// and its position after a huge row count computed, so a design that parses but breaks its own bounds
// is found here, not on the panel.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "loom/design/design.hpp"

namespace {
void check(const loom::design::Design& d) {
  if (d.width() < 1 || d.width() > loom::design::kMaxWidth || d.height() < 1 ||
      d.height() > loom::design::kMaxHeight || d.palette().empty() ||
      d.palette().size() > static_cast<std::size_t>(loom::design::kMaxColours)) {
    std::abort();
  }
  for (int r = 0; r < d.height(); ++r) {
    const auto row = d.row(r);
    if (row.size() != static_cast<std::size_t>(d.width())) std::abort();
    for (const std::uint16_t k : row) {
      if (k >= d.palette().size()) std::abort();
    }
  }
  const auto pos = loom::design::position_after(d, UINT64_MAX);
  if (pos.row < 0 || pos.row >= d.height() || pos.repeat < 1) std::abort();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool png = (data[0] & 1) != 0;
  const std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    check(png ? loom::design::parse_design_png(bytes, "fuzz_design.png")
              : loom::design::parse_design_csv(bytes, "fuzz_design.csv"));
  } catch (const loom::design::DesignError&) {
    // A refusal naming the file (and line:col for a CSV): expected for most inputs.
  }
  return 0;
}

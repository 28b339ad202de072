// libFuzzer harness: the loom config parser (firmware::parse_loom_config) on arbitrary text. A refusal
// is a firmware::ConfigError and is fine; any other exception escaping, a crash, a hang (-timeout) or a
// sanitizer report is a bug. An accepted config must also carry no NaN/inf in the numbers the loop runs
// on (the "never NaN/inf with exit 0").
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "loom/config/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const loom::firmware::LoomConfig c = loom::firmware::parse_loom_config(text, "fuzz.toml");
    const double checked[] = {c.profile.width_m, c.profile.crank.velocity, c.sequencer.period_s,
                              c.machine.period_s};
    for (const double v : checked) {
      if (!std::isfinite(v)) {
        std::fprintf(stderr, "accepted config carries a non-finite value: %g\n", v);
        std::abort();
      }
    }
  } catch (const loom::firmware::ConfigError&) {
    // A refusal naming file:line: expected for most inputs.
  }
  return 0;
}

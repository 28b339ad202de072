// libFuzzer harness: the simulation scene parser (firmware::parse_scene) on arbitrary text. A refusal is
// a firmware::ConfigError; any other exception escaping, a crash, a hang or a sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "loom/config/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)loom::firmware::parse_scene(text, "fuzz_scene.toml");
  } catch (const loom::firmware::ConfigError&) {
    // A refusal naming file:line: expected for most inputs.
  }
  return 0;
}

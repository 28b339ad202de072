// libFuzzer harness: the EDS/DCF reader (drivers/eds.hpp) on arbitrary text, and everything built on a
// description it accepts: the PDO descriptions, the comparison with a drive's and an I/O module's needs
// (8- and 16-bit input groups),
// the loom's writes, the DCF writer and the concise DCF. A bug is a crash, a hang, a sanitizer report,
// or a broken promise:
//  - strict and non-strict reads give the same diagnostics, strict ones all errors;
//  - every diagnostic's line is within the text;
//  - a DCF written from an accepted description reads back (non-strictly) without errors, and its
//    ParameterValues give back the writes it was written with (and the description's own others);
//  - the concise DCF of those writes decodes to them.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "loom/drivers/eds_dcf.hpp"

namespace {

std::uint32_t key(const loom::drivers::eds::SdoWrite& w) {
  return (std::uint32_t{w.index} << 8) | w.sub;
}

void fail(const char* what) {
  std::fprintf(stderr, "fuzz_eds: %s\n", what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace eds = loom::drivers::eds;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const eds::Description d = eds::read_eds(text, "fuzz.eds");
  const eds::Description strict = eds::read_eds(text, "fuzz.eds", eds::ReadOptions{true});
  if (strict.diagnostics.size() != d.diagnostics.size()) fail("strict and non-strict diagnostics differ");
  const int lines = static_cast<int>(std::count(text.begin(), text.end(), '\n')) + 1;
  for (std::size_t k = 0; k < d.diagnostics.size(); ++k) {
    if (strict.diagnostics[k].severity != eds::Severity::kError) fail("a strict diagnostic is not an error");
    if (strict.diagnostics[k].line != d.diagnostics[k].line) fail("strict and non-strict lines differ");
    if (d.diagnostics[k].line < 0 || d.diagnostics[k].line > lines)
      fail("a diagnostic's line is outside the text");
    (void)eds::format(d.file, d.diagnostics[k]);
  }
  (void)eds::pdos(d);
  (void)eds::profile_of(d);
  (void)eds::input_group_bits_of(d, loom::drivers::IoWiring{});
  // The needs do not depend on the input: built once, not per execution.
  static const std::array<eds::NodeNeeds, 4> needs = [] {
    const loom::drivers::CanAxisPortConfig port;
    loom::drivers::CanAxisPortConfig port2 = port;
    port2.tpdo2 = true;
    loom::drivers::CanAxisConfig homed = port.axes[0];
    homed.homing_method = 34;
    loom::drivers::CanIoConfig words;  // an I/O module read as 16-bit input groups (0x6100)
    words.input_group_bits = 16;
    return std::array<eds::NodeNeeds, 4>{eds::drive_needs(port.axes[1], port), eds::drive_needs(homed, port2),
                                         eds::io_module_needs(loom::drivers::CanIoConfig{}),
                                         eds::io_module_needs(words)};
  }();
  // The DCF round trip (the costly part) for one of the needs per input, chosen by its size.
  const std::size_t round_trip = size % needs.size();
  for (std::size_t k = 0; k < needs.size(); ++k) {
    const eds::NodeNeeds& n = needs[k];
    const eds::NodeCheck c = eds::check_node(d, n);
    for (const eds::Finding& f : c.findings) (void)eds::format(d, n, f);
    if (d.has_errors() || k != round_trip) continue;
    const std::vector<eds::SdoWrite> writes = eds::loom_writes(d, n, c);
    if (eds::decode_concise_dcf(eds::encode_concise_dcf(writes)) != writes) fail("concise DCF round trip");
    const eds::Description back = eds::read_eds(eds::write_dcf(d, n.node_id, 500, writes), "fuzz.dcf");
    if (back.has_errors()) fail("the DCF written from an accepted description has errors");
    // The DCF's values: the description's own ParameterValues, overridden by the writes.
    std::map<std::uint32_t, eds::SdoWrite> expected;
    for (const eds::SdoWrite& w : eds::parameter_writes(d, n.node_id)) expected[key(w)] = w;
    for (const eds::SdoWrite& w : writes) expected[key(w)] = w;
    std::vector<eds::SdoWrite> merged;
    for (const auto& [at, w] : expected) merged.push_back(w);
    if (eds::parameter_writes(back, n.node_id) != merged)
      fail("the DCF's ParameterValues differ from the writes");
  }
  (void)eds::parameter_writes(d, 5);
  return 0;
}

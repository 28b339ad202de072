// The I/O wiring's signals by the names its messages use ("io.inputs.estop_ok",
// "io.outputs.gripper_close.head2"): one list, shared by the wiring's validation (can_io_config.cpp) and
// the CAN I/O node's bring-up messages (can_io_port.cpp), so both name a signal the same way.
#pragma once

#include <string>
#include <vector>

#include "loom/drivers/can_io_config.hpp"

namespace loom::drivers::io_signals {

struct NamedBit {
  std::string name;  // "io.inputs.estop_ok", "io.outputs.gripper_close.head2"
  const IoBit* bit;
  bool required;
  std::string signal;  // the signal alone ("estop_ok", "gripper_close"): its config key is io.<signal>_bit(s)
  int head = 0;        // a knotting head's signal: the head as the operator counts it (1-based); else 0
};

// The knotting heads the wiring uses (IoWiring::heads clamped to 0..hal::kMaxKnottingHeads).
int used_heads(const IoWiring& w);
// The wiring's signals by name, inputs then outputs, for validation and messages. The second channels
// are inputs like any other, so a bit shared between a first and a second channel is refused.
std::vector<NamedBit> inputs_of(const IoWiring& w);
std::vector<NamedBit> outputs_of(const IoWiring& w);
// The wired signal with the highest bit in sub `sub` (1-based) of the groups of `group_bits` (8: 0x6000,
// 16: 0x6100), the one named when the module cannot deliver that sub; nullptr when no signal lives there
// (then the master can do without it).
const NamedBit* signal_in_sub(const std::vector<NamedBit>& bits, int sub, int group_bits = 8);
// The config key an operator edits for a signal ("io.inputs.shuttle_at_right_2" →
// "io.shuttle_at_right_2_bit", "io.inputs.yarn_present.head2" → "io.yarn_present_bits (head 2)") and its
// value: a bring-up refusal points at the TOML line that asks for the input the module cannot deliver.
std::string key_and_value(const NamedBit& b);

}  // namespace loom::drivers::io_signals

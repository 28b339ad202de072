// The CAN I/O modules' configuration as plain data: which bit of which CiA 401 module is which signal,
// each module's node and timing, and the checks and arithmetic made on them before any frame is sent
// (validation, the 8-bit subs and frames a wiring needs). Configure-time only and free of SocketCAN, so
// the loom config library and offline tools use it without the CANopen runtime (can_io_port.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "loom/drivers/bus_load.hpp"
#include "loom/drivers/status.hpp"
#include "loom/hal/types.hpp"

namespace loom::drivers {

struct NodeDescription;  // node_description.hpp

// CiA 401 objects.
namespace od401 {
inline constexpr std::uint16_t kDigitalInputs8 = 0x6000;   // read input 8-bit, sub 1..n
inline constexpr std::uint16_t kDigitalInputs16 = 0x6100;  // read input 16-bit, sub 1..n
inline constexpr std::uint16_t kDigitalOutputs8 = 0x6200;  // write output 8-bit, sub 1..n
inline constexpr std::uint16_t kOutputErrorMode = 0x6206;  // 1 = output goes to 0x6207 on failure
inline constexpr std::uint16_t kOutputErrorValue = 0x6207;
inline constexpr std::uint16_t kAnalogInput16 = 0x6401;  // read analog input 16-bit, sub 1..n
inline constexpr std::uint16_t kConsumerHeartbeat = 0x1016;
inline constexpr std::uint16_t kDeviceProfile401 = 0x0191;  // low word of 0x1000
}  // namespace od401

// The I/O modules one loom can have (module 0 = the [io] table's, the others [io_modules.<name>]).
inline constexpr std::size_t kMaxIoModules = 4;

// One signal on a digital input or output: which module, bit number across that module's terminals
// (bit b lives in 8-bit group b/8 + 1, bit b%8 — or in 16-bit group b/16 + 1, bit b%16: CiA 401 packs
// both the same way, 0x6100:01 = 0x6000:02 << 8 | 0x6000:01), and polarity. bit = −1: not wired.
struct IoBit {
  int bit = -1;
  bool active_low = false;  // the signal is true when the electrical bit is 0
  std::uint8_t module = 0;  // 0..kMaxIoModules-1
};

// How the module's digital inputs are read: 8-bit groups (0x6000, CiA 401's usual form) or 16-bit groups
// (0x6100, modules that offer only that). The input bits mean the same terminals either way.
inline constexpr int kInputGroupBits8 = 8;
inline constexpr int kInputGroupBits16 = 16;
// The object of the input groups of `group_bits` (8: 0x6000, 16: 0x6100).
constexpr std::uint16_t input_object(int group_bits) {
  return group_bits == kInputGroupBits16 ? od401::kDigitalInputs16 : od401::kDigitalInputs8;
}

// Inputs read from 0x6000:01..08 or 0x6100:01..04 (64 bits) and outputs written to 0x6200:01..08 (64 bits),
// each in one PDO of at most 8 bytes; a wiring uses as many 8-bit subs as its highest bit needs (the default
// loom without knotting heads: three input subs, one output sub).
inline constexpr int kIoMaxInputBits = 64;
inline constexpr int kIoMaxOutputBits = 64;

struct IoWiring {
  // Inputs (0x6000). The six sensors and the e-stop chain must be wired; buttons are optional.
  IoBit piston_a_extended{0};
  IoBit piston_a_retracted{1};
  IoBit piston_b_extended{2};
  IoBit piston_b_retracted{3};
  IoBit shuttle_at_left{4};
  IoBit shuttle_at_right{5};
  IoBit estop_ok{6};  // chain closed = 1 (a broken wire reads as e-stop)
  IoBit button_start{8};
  IoBit button_pause{9};
  IoBit button_ack{10};
  IoBit row_knotted{11};
  // Second channels of the six safety sensors (hal::SafetySensor order); −1 = the machine has none for
  // that sensor (then a stuck switch there can only be caught by the sequencer's plausibility checks).
  std::array<IoBit, hal::kSafetySensorCount> second{IoBit{16}, IoBit{17}, IoBit{18},
                                                    IoBit{19}, IoBit{20}, IoBit{21}};
  // Outputs (0x6200). Valves must be wired; the stack light and buzzer are optional.
  IoBit piston_a_extend{0};
  IoBit piston_b_extend{1};
  IoBit lamp_green{4};
  IoBit lamp_amber{5};
  IoBit lamp_red{6};
  IoBit buzzer{7};
  // Knotting heads (the first `heads` entries are used; 0 = the loom has no heads, or they are not on this
  // module): each head's gripper and cutter outputs and its yarn-present (knot tied) input. All three are
  // wired for every head that is used.
  int heads = 0;
  std::array<IoBit, hal::kMaxKnottingHeads> gripper_close{};
  std::array<IoBit, hal::kMaxKnottingHeads> cutter{};
  std::array<IoBit, hal::kMaxKnottingHeads> yarn_present{};
  // Beater load cell on analog input 0x6401:load_cell_channel (0 = no load cell fitted):
  // force_n = gain · counts + offset.
  int load_cell_channel = 1;
  double load_cell_n_per_count = 0.01;
  double load_cell_offset_n = 0.0;
  std::uint8_t load_cell_module = 0;
};

// The first switch of each safety sensor, in hal::SafetySensor order (the second ones are `second`).
inline std::array<const IoBit*, hal::kSafetySensorCount> first_switches(const IoWiring& w) {
  return {&w.piston_a_extended,  &w.piston_a_retracted, &w.piston_b_extended,
          &w.piston_b_retracted, &w.shuttle_at_left,    &w.shuttle_at_right};
}

// Which setting a refusal of the I/O configuration is about. The loom config maps it (with the signal)
// to the TOML key that sets it, so its file:line:col message never has to read the refusal's text.
enum class IoField {
  kNode,
  kModule,
  kHeads,
  kSignalBit,     // a signal's bit: required and unwired, out of range, or used twice on one module
  kSignalModule,  // a signal's module
  kInputGroups,   // 8- or 16-bit input groups
  kLoadCellModule,
  kLoadCellChannel,
  kLoadCellGain,
  kLoadCellOffset,
  kCyclePeriod,
  kHeartbeatProducer,
  kHeartbeatConsumer,
  kSdoTimeout,
  kBootTimeout,
  kOperationalTimeout,
  kMasterNode,
  kMasterConsumer,
};

// A refusal: the field, the signal it is about (kSignalBit, kSignalModule) and the message naming field,
// value and reason.
struct IoConfigFault {
  IoField field = IoField::kNode;
  std::string signal{};   // "estop_ok", "shuttle_at_right_2", "cutter"
  int head = 0;           // a knotting head's signal: the head, 1-based; 0 otherwise
  std::string message{};  // "io.outputs.buzzer.bit = 4 is already used by io.outputs.lamp_green"
  // A bit used twice on module k > 0: the message goes on "(both on I/O module k)" (describe()); the loom
  // config names the module by its [io_modules.<name>] instead.
  std::uint8_t shared_module = 0;
};
// The refusal in one line, as validate() reports it.
std::string describe(const IoConfigFault& fault);

// Configure-time only. The first refusal of the loom's whole wiring (every required signal wired on some
// module, no bit of one module used twice), or none.
std::optional<IoConfigFault> find_fault(const IoWiring& wiring);
// Configure-time only. Error naming the field ("io.inputs.estop_ok.bit = 3 is already used by
// io.inputs.piston_b_retracted") and its value: describe(find_fault()).
Status validate(const IoWiring& wiring);

// Configure-time only. The signals of the loom's wiring that are on module `module`, every other one
// unwired (−1) and the load cell off unless it is there: what that module's node maps, reads and
// writes. With one module it is the wiring itself.
IoWiring module_wiring(const IoWiring& wiring, std::uint8_t module);

struct CanIoConfig {
  std::uint8_t node_id = 4;
  IoWiring wiring;          // the loom's whole wiring; this node serves module_wiring(wiring, module)
  std::uint8_t module = 0;  // which of the loom's modules this node is
  std::string name;         // the module's name in the machine description ("" = the loom's one I/O node)
  double cycle_period_s = 0.002;
  double heartbeat_producer_s = 0.100;  // written to the module's 0x1017
  double heartbeat_consumer_s = 0.250;  // silence longer than this = node lost
  double sdo_timeout_s = 0.100;
  double boot_timeout_s = 2.0;         // boot-up after NMT reset-node
  double operational_timeout_s = 0.5;  // operational heartbeat after NMT start
  // The module watches the master's heartbeat through 0x1016 (when it has one), so its valves go to
  // their safe state (0x6206/0x6207) when the host dies. 0 = do not configure a consumer.
  std::uint8_t master_node_id = 0x7F;
  double master_consumer_s = 0.500;
  // The module's digital inputs as 8-bit groups (0x6000) or 16-bit groups (0x6100): from its EDS when it
  // has one (the loom config derives it), else io.input_group_bits.
  int input_group_bits = kInputGroupBits8;
  // The module's EDS (node_description.hpp), as CanAxisConfig::description. Null: none.
  std::shared_ptr<const NodeDescription> description{};
};

// Configure-time only. The first refusal of the module's config (its node, timing and the whole wiring).
std::optional<IoConfigFault> find_fault(const CanIoConfig& config);
// Configure-time only. describe(find_fault()).
Status validate(const CanIoConfig& config);

// Configure-time only. The input groups of `group_bits` (0x6000's 8-bit subs, or 0x6100's 16-bit ones)
// and the 8-bit subs of 0x6200 (outputs) the wiring uses: 1 up to the one holding its highest wired bit
// (0x6000:01..03, or 0x6100:01..02, for the default wiring's second channels). Of one module's wiring
// (module_wiring()) when the loom has several.
std::uint8_t io_input_subs(const IoWiring& wiring, int group_bits = kInputGroupBits8);
std::uint8_t io_output_subs(const IoWiring& wiring);

// The frames this node adds to every cycle with `wiring` (one RPDO, one or two TPDOs): the inputs' TPDO
// carries one group per sub up to the highest wired input (3 bytes with the default second channels in
// 8-bit groups, 4 in 16-bit groups). `wiring` is the node's own (module_wiring()).
std::vector<FrameGroup> io_frames_per_cycle(const IoWiring& wiring, int group_bits = kInputGroupBits8);

}  // namespace loom::drivers

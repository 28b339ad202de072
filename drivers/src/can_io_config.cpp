// The I/O wiring's configuration checks and arithmetic (can_io_config.hpp) and its signals' names
// (io_signals.hpp): pure functions of the config, shared by the CAN I/O node and the loom config's
// parse-time checks.
#include "loom/drivers/can_io_config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>

#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/io_signals.hpp"

namespace loom::drivers {

namespace io_signals {

namespace {

// Names of the second channels in hal::SafetySensor order.
constexpr std::array<const char*, hal::kSafetySensorCount> kSecondChannelSignals{
    "piston_a_extended_2",  "piston_a_retracted_2", "piston_b_extended_2",
    "piston_b_retracted_2", "shuttle_at_left_2",    "shuttle_at_right_2"};

NamedBit input(const char* signal, const IoBit& bit, bool required) {
  return {std::string("io.inputs.") + signal, &bit, required, signal, 0};
}
NamedBit output(const char* signal, const IoBit& bit, bool required) {
  return {std::string("io.outputs.") + signal, &bit, required, signal, 0};
}
// Head h's (0-based) signal of one kind, named with the head's number as the operator counts it (1-based).
NamedBit head_signal(const char* group, const char* signal, int h, const IoBit& bit) {
  return {std::string(group) + signal + ".head" + std::to_string(h + 1), &bit, true, signal, h + 1};
}

}  // namespace

int used_heads(const IoWiring& w) {
  return std::clamp(w.heads, 0, static_cast<int>(hal::kMaxKnottingHeads));
}

std::vector<NamedBit> inputs_of(const IoWiring& w) {
  std::vector<NamedBit> v{input("piston_a_extended", w.piston_a_extended, true),
                          input("piston_a_retracted", w.piston_a_retracted, true),
                          input("piston_b_extended", w.piston_b_extended, true),
                          input("piston_b_retracted", w.piston_b_retracted, true),
                          input("shuttle_at_left", w.shuttle_at_left, true),
                          input("shuttle_at_right", w.shuttle_at_right, true),
                          input("estop_ok", w.estop_ok, true),
                          input("button_start", w.button_start, false),
                          input("button_pause", w.button_pause, false),
                          input("button_ack", w.button_ack, false),
                          input("row_knotted", w.row_knotted, false)};
  // Optional: a machine may have single-channel sensing (then the sequencer's plausibility checks alone).
  for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i) {
    v.push_back(input(kSecondChannelSignals[i], w.second[i], false));
  }
  for (int h = 0; h < used_heads(w); ++h) {
    v.push_back(head_signal("io.inputs.", "yarn_present", h, w.yarn_present[static_cast<std::size_t>(h)]));
  }
  return v;
}
std::vector<NamedBit> outputs_of(const IoWiring& w) {
  std::vector<NamedBit> v{output("piston_a_extend", w.piston_a_extend, true),
                          output("piston_b_extend", w.piston_b_extend, true),
                          output("lamp_green", w.lamp_green, false),
                          output("lamp_amber", w.lamp_amber, false),
                          output("lamp_red", w.lamp_red, false),
                          output("buzzer", w.buzzer, false)};
  for (int h = 0; h < used_heads(w); ++h) {
    v.push_back(head_signal("io.outputs.", "gripper_close", h, w.gripper_close[static_cast<std::size_t>(h)]));
    v.push_back(head_signal("io.outputs.", "cutter", h, w.cutter[static_cast<std::size_t>(h)]));
  }
  return v;
}

const NamedBit* signal_in_sub(const std::vector<NamedBit>& bits, int sub, int group_bits) {
  const NamedBit* found = nullptr;
  for (const NamedBit& b : bits) {
    const int n = b.bit->bit;
    if (n >= 0 && n / group_bits + 1 == sub && (found == nullptr || n > found->bit->bit)) found = &b;
  }
  return found;
}

std::string key_and_value(const NamedBit& b) {
  const std::string value = " = " + std::to_string(b.bit->bit);
  if (b.head == 0) return "io." + b.signal + "_bit" + value;
  return "io." + b.signal + "_bits (head " + std::to_string(b.head) + ")" + value;
}

}  // namespace io_signals

namespace {

using io_signals::inputs_of;
using io_signals::NamedBit;
using io_signals::outputs_of;

std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g s", s);
  return buf;
}

std::optional<IoConfigFault> fault(IoField field, std::string message) {
  return IoConfigFault{.field = field, .message = std::move(message)};
}
std::optional<IoConfigFault> signal_fault(IoField field, const NamedBit& b, std::string message,
                                          std::uint8_t shared_module = 0) {
  return IoConfigFault{.field = field,
                       .signal = b.signal,
                       .head = b.head,
                       .message = std::move(message),
                       .shared_module = shared_module};
}

// Every required signal wired, every bit in range and used once per module.
std::optional<IoConfigFault> check_bits(const std::vector<NamedBit>& bits, int max_bits) {
  static_assert(kIoMaxInputBits >= kIoMaxOutputBits);
  std::array<std::array<const std::string*, kIoMaxInputBits>, kMaxIoModules> used{};
  for (const NamedBit& b : bits) {
    const int n = b.bit->bit;
    if (n == -1) {
      if (b.required)
        return signal_fault(IoField::kSignalBit, b, b.name + ".bit = -1: this signal must be wired");
      continue;
    }
    if (n < 0 || n >= max_bits) {
      return signal_fault(IoField::kSignalBit, b,
                          b.name + ".bit = " + std::to_string(n) + " is outside 0.." +
                              std::to_string(max_bits - 1) + " (-1 = not wired)");
    }
    if (b.bit->module >= kMaxIoModules) {
      return signal_fault(IoField::kSignalModule, b,
                          b.name + ".module = " + std::to_string(b.bit->module) + " is outside 0.." +
                              std::to_string(kMaxIoModules - 1));
    }
    const std::string*& user = used[b.bit->module][static_cast<std::size_t>(n)];
    if (user != nullptr) {
      return signal_fault(IoField::kSignalBit, b,
                          b.name + ".bit = " + std::to_string(n) + " is already used by " + *user,
                          b.bit->module);
    }
    user = &b.name;
  }
  return std::nullopt;
}

int highest_bit(const std::vector<NamedBit>& bits) {
  int hi = -1;
  for (const NamedBit& b : bits) hi = std::max(hi, b.bit->bit);
  return hi;
}

// The groups of `group_bits` a set of signals needs: up to the one holding the highest wired bit (at
// least one, so the PDO exists even when nothing optional is wired).
std::uint8_t subs_for(const std::vector<NamedBit>& bits, int group_bits) {
  return static_cast<std::uint8_t>(std::max(highest_bit(bits), 0) / group_bits + 1);
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Configuration
// ---------------------------------------------------------------------------------------------------
std::optional<IoConfigFault> find_fault(const IoWiring& w) {
  if (w.heads < 0 || w.heads > static_cast<int>(hal::kMaxKnottingHeads)) {
    return fault(IoField::kHeads, "io: " + std::to_string(w.heads) + " knotting heads wired; at most " +
                                      std::to_string(hal::kMaxKnottingHeads));
  }
  if (auto f = check_bits(inputs_of(w), kIoMaxInputBits)) return f;
  if (auto f = check_bits(outputs_of(w), kIoMaxOutputBits)) return f;
  if (w.load_cell_module >= kMaxIoModules) {
    return fault(IoField::kLoadCellModule, "io.load_cell.module = " + std::to_string(w.load_cell_module) +
                                               " is outside 0.." + std::to_string(kMaxIoModules - 1));
  }
  if (w.load_cell_channel < 0 || w.load_cell_channel > 254) {
    return fault(IoField::kLoadCellChannel,
                 "io.load_cell.channel = " + std::to_string(w.load_cell_channel) +
                     " is outside 0..254 (0 = no load cell, else the sub-index of 0x6401)");
  }
  if (!std::isfinite(w.load_cell_n_per_count) || w.load_cell_n_per_count == 0.0) {
    char buf[128];
    std::snprintf(buf, sizeof(buf), "io.load_cell.n_per_count = %g must be a non-zero number",
                  w.load_cell_n_per_count);
    return fault(IoField::kLoadCellGain, buf);
  }
  if (!std::isfinite(w.load_cell_offset_n)) {
    return fault(IoField::kLoadCellOffset, "io.load_cell.offset_n is not a finite number");
  }
  return std::nullopt;
}

IoWiring module_wiring(const IoWiring& wiring, std::uint8_t module) {
  IoWiring w = wiring;
  const auto keep = [module](IoBit& b) {
    if (b.module != module) b = IoBit{};
  };
  for (IoBit* b : {&w.piston_a_extended, &w.piston_a_retracted, &w.piston_b_extended, &w.piston_b_retracted,
                   &w.shuttle_at_left, &w.shuttle_at_right, &w.estop_ok, &w.button_start, &w.button_pause,
                   &w.button_ack, &w.row_knotted, &w.piston_a_extend, &w.piston_b_extend, &w.lamp_green,
                   &w.lamp_amber, &w.lamp_red, &w.buzzer}) {
    keep(*b);
  }
  for (IoBit& b : w.second) keep(b);
  for (std::size_t h = 0; h < hal::kMaxKnottingHeads; ++h) {
    keep(w.gripper_close[h]);
    keep(w.cutter[h]);
    keep(w.yarn_present[h]);
  }
  if (w.load_cell_module != module) w.load_cell_channel = 0;
  return w;
}

std::optional<IoConfigFault> find_fault(const CanIoConfig& c) {
  if (c.node_id < kMinNodeId || c.node_id > kMaxNodeId) {
    return fault(IoField::kNode, "io.node = " + std::to_string(c.node_id) + " is outside 1..127");
  }
  if (c.module >= kMaxIoModules) {
    return fault(IoField::kModule, "io: module " + std::to_string(c.module) + " is outside 0.." +
                                       std::to_string(kMaxIoModules - 1));
  }
  if (auto f = find_fault(c.wiring)) return f;
  if (c.input_group_bits != kInputGroupBits8 && c.input_group_bits != kInputGroupBits16) {
    return fault(IoField::kInputGroups, "io.input_group_bits = " + std::to_string(c.input_group_bits) +
                                            " is neither 8 (0x6000) nor 16 (0x6100)");
  }
  if (!(c.cycle_period_s > 0.0))
    return fault(IoField::kCyclePeriod, "io: cycle period " + seconds(c.cycle_period_s) + " must be > 0");
  const double producer_ms = c.heartbeat_producer_s * 1e3;
  if (!(producer_ms >= 1.0 && producer_ms <= 65535.0) ||
      std::abs(producer_ms - std::round(producer_ms)) > 1e-6) {
    return fault(IoField::kHeartbeatProducer, "io: heartbeat producer time " +
                                                  seconds(c.heartbeat_producer_s) +
                                                  " must be a whole number of ms in 0.001..65.535 s");
  }
  if (!(c.heartbeat_consumer_s > c.heartbeat_producer_s)) {
    return fault(IoField::kHeartbeatConsumer,
                 "io: heartbeat consumer time " + seconds(c.heartbeat_consumer_s) +
                     " must exceed the producer time " + seconds(c.heartbeat_producer_s));
  }
  if (!(c.sdo_timeout_s > 0.0))
    return fault(IoField::kSdoTimeout, "io: SDO timeout " + seconds(c.sdo_timeout_s) + " must be > 0");
  if (!(c.boot_timeout_s > 0.0)) {
    return fault(IoField::kBootTimeout, "io.boot_timeout_s = " + seconds(c.boot_timeout_s) + " must be > 0");
  }
  if (!(c.operational_timeout_s > 0.0)) {
    return fault(IoField::kOperationalTimeout,
                 "io.operational_timeout_s = " + seconds(c.operational_timeout_s) + " must be > 0");
  }
  if (c.master_node_id > kMaxNodeId) {
    return fault(IoField::kMasterNode,
                 "can.master_node = " + std::to_string(c.master_node_id) + " is outside 0..127");
  }
  if (c.master_node_id != 0) {
    const double ms = c.master_consumer_s * 1e3;
    if (!(ms >= 1.0 && ms <= 65535.0)) {
      return fault(IoField::kMasterConsumer, "io: master heartbeat consumer time " +
                                                 seconds(c.master_consumer_s) +
                                                 " must be in 0.001..65.535 s");
    }
  }
  return std::nullopt;
}

std::string describe(const IoConfigFault& f) {
  return f.message +
         (f.shared_module == 0 ? "" : " (both on I/O module " + std::to_string(f.shared_module) + ")");
}

Status validate(const IoWiring& w) {
  const std::optional<IoConfigFault> f = find_fault(w);
  return f ? Status::error(describe(*f)) : Status::ok();
}

Status validate(const CanIoConfig& c) {
  const std::optional<IoConfigFault> f = find_fault(c);
  return f ? Status::error(describe(*f)) : Status::ok();
}

std::uint8_t io_input_subs(const IoWiring& w, int group_bits) {
  return subs_for(inputs_of(w), group_bits == kInputGroupBits16 ? kInputGroupBits16 : kInputGroupBits8);
}
std::uint8_t io_output_subs(const IoWiring& w) {
  return subs_for(outputs_of(w), 8);
}

std::vector<FrameGroup> io_frames_per_cycle(const IoWiring& w, int group_bits) {
  const int bytes_per_group = group_bits == kInputGroupBits16 ? 2 : 1;
  std::vector<FrameGroup> g;
  g.push_back({io_output_subs(w), 1});  // RPDO: digital outputs
  // TPDO: digital inputs, one group per sub
  g.push_back({static_cast<std::uint8_t>(io_input_subs(w, group_bits) * bytes_per_group), 1});
  if (w.load_cell_channel != 0) g.push_back({2, 1});  // TPDO: load cell
  return g;
}

}  // namespace loom::drivers

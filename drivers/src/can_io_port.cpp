// CiA 401 I/O node (see can_io_port.hpp): configure-time bring-up by NMT and SDO with the CiA 301
// interoperability rules (fixed mappings read back, missing PDOs and optional objects tolerated and
// noted), and the RT exchange decoded through the layout the module really uses.
#include "loom/drivers/can_io_port.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "loom/drivers/can_error_frame.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/io_signals.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/drivers/sdo.hpp"
#include "loom/drivers/sdo_client.hpp"

namespace loom::drivers {

using io_signals::inputs_of;
using io_signals::key_and_value;
using io_signals::NamedBit;
using io_signals::signal_in_sub;
using io_signals::used_heads;

namespace {

std::string hex(std::uint32_t v, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "0x%0*X", digits, v);
  return buf;
}

constexpr std::uint32_t entry(std::uint16_t index, std::uint8_t sub, std::uint8_t bits) {
  return encode_map_entry(PdoMapEntry{index, sub, bits});
}

// "0x6000:03" for a mapping entry.
std::string object_name(std::uint32_t map_entry) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "0x%04X:%02X", map_entry >> 16, (map_entry >> 8) & 0xFF);
  return buf;
}

bool interop_readback_code(std::uint32_t abort) {
  // A module with a fixed mapping says read-only (0x06010002) or unsupported access (0x06010000).
  return abort == sdo_abort::kReadOnly || abort == sdo_abort::kUnsupportedAccess;
}

}  // namespace

hal::DigitalOutputs io_safe_outputs() noexcept {
  hal::DigitalOutputs o;  // grippers open, cutters retracted: every head's outputs false
  o.lamp_red = true;
  return o;
}

CanIoPort::CanIoPort(CanIoConfig config)
    : config_(std::move(config)),
      wiring_(module_wiring(config_.wiring, config_.module)),
      group_bits_(config_.input_group_bits == kInputGroupBits16 ? kInputGroupBits16 : kInputGroupBits8) {}

std::uint32_t CanIoPort::input_entry(std::uint8_t sub) const {
  return entry(input_object(group_bits_), sub, static_cast<std::uint8_t>(group_bits_));
}

std::string CanIoPort::who() const {
  return label() + ": ";
}

CanIoPort::Slot CanIoPort::find(const std::array<PdoLayout, 4>& layouts, std::uint32_t wanted) {
  for (std::size_t k = 0; k < layouts.size(); ++k) {
    std::uint32_t offset_bits = 0;
    for (std::size_t e = 0; e < layouts[k].count; ++e) {
      const std::uint32_t v = layouts[k].entries[e];
      if ((v & 0xFFFFFF00U) == (wanted & 0xFFFFFF00U) && (v & 0xFF) % 8 == 0 && offset_bits % 8 == 0) {
        return Slot{static_cast<int>(k), static_cast<std::uint8_t>(offset_bits / 8),
                    static_cast<std::uint8_t>((v & 0xFF) / 8)};
      }
      offset_bits += v & 0xFF;
    }
  }
  return Slot{};
}

Status CanIoPort::disable_pdo(SdoClient& sdo, bool rx, int pdo) {
  const auto comm = static_cast<std::uint16_t>((rx ? od::kRpdoComm : od::kTpdoComm) + pdo);
  const std::uint8_t id = config_.node_id;
  const std::uint32_t cob = rx ? cob::rpdo(pdo + 1, id) : cob::tpdo(pdo + 1, id);
  if (Status s = sdo.write(id, comm, 1, cob | od::kPdoInvalidBit, 4); !s) {
    // A module with fewer PDOs has nothing to disable (CiA 301 interoperability).
    if (sdo.last_abort() == sdo_abort::kNoObject) return Status::ok();
    return Status::error(who() + s.message());
  }
  return Status::ok();
}

// Write `wanted` into PDO `pdo`; when the module refuses because its mapping is fixed, read back what it
// has. Either way `actual` ends as what the module reports, which the caller checks.
Status CanIoPort::map_pdo(SdoClient& sdo, bool rx, int pdo, const std::vector<std::uint32_t>& wanted,
                          std::uint8_t transmission_type, PdoLayout& actual, std::uint32_t* refused) {
  const std::uint8_t id = config_.node_id;
  const auto comm = static_cast<std::uint16_t>((rx ? od::kRpdoComm : od::kTpdoComm) + pdo);
  const auto map = static_cast<std::uint16_t>((rx ? od::kRpdoMap : od::kTpdoMap) + pdo);
  const std::uint32_t cob = rx ? cob::rpdo(pdo + 1, id) : cob::tpdo(pdo + 1, id);
  const auto fail = [&](const Status& s) { return Status::error(who() + s.message()); };

  // A module configured from its EDS (only what differs is written): a PDO already carrying `wanted` is
  // not re-mapped (no invalidate, no clear).
  bool mapped = false;
  if (sdo.skips_unchanged()) {
    Result<std::uint32_t> n = sdo.read(id, map, 0);
    mapped = n && n.value() == wanted.size();
    for (std::size_t k = 0; mapped && k < wanted.size(); ++k) {
      Result<std::uint32_t> e = sdo.read(id, map, static_cast<std::uint8_t>(k + 1));
      mapped = e && e.value() == wanted[k];
    }
  }
  bool fixed = false;
  if (!mapped) {
    if (Status s = sdo.write(id, comm, 1, cob | od::kPdoInvalidBit, 4); !s) {
      if (!interop_readback_code(sdo.last_abort())) return fail(s);
      fixed = true;  // cannot even invalidate it: use it as it is
    }
  }
  if (!fixed && !mapped) {
    if (Status s = sdo.write(id, map, 0, 0, 1); !s) {
      if (!interop_readback_code(sdo.last_abort())) return fail(s);
      fixed = true;
    }
  }
  if (!fixed && !mapped) {
    for (std::size_t k = 0; k < wanted.size(); ++k) {
      if (Status s = sdo.write(id, map, static_cast<std::uint8_t>(k + 1), wanted[k], 4); !s) {
        if (refused != nullptr) *refused = wanted[k];  // the caller can say what needed it
        return fail(s);
      }
    }
    if (Status s = sdo.write(id, map, 0, static_cast<std::uint32_t>(wanted.size()), 1); !s) return fail(s);
  }
  if (fixed)
    notes_.push_back(who() + hex(map, 4) + " mapping is fixed (write refused): read back and used as found");

  // Synchronous transmission so silence is visible every cycle (TPDO) / outputs apply on SYNC (RPDO: any).
  if (!rx) {
    if (Status s = sdo.write(id, comm, 2, transmission_type, 1); !s) {
      if (!interop_readback_code(sdo.last_abort())) return fail(s);
      Result<std::uint32_t> t = sdo.read(id, comm, 2);
      if (!t) return fail(t.status());
      if (t.value() < 1 || t.value() > 240) {
        return Status::error(who() + hex(comm, 4) + ":02 transmission type is " + std::to_string(t.value()) +
                             " and cannot be changed; the master needs a synchronous TPDO (1..240)");
      }
    }
  }
  if (Status s = sdo.write(id, comm, 1, cob, 4); !s) {
    if (!interop_readback_code(sdo.last_abort())) return fail(s);
    Result<std::uint32_t> c = sdo.read(id, comm, 1);
    if (!c) return fail(c.status());
    if ((c.value() & od::kPdoInvalidBit) != 0 || (c.value() & 0x7FF) != cob) {
      return Status::error(who() + hex(comm, 4) + ":01 COB-ID is " + hex(c.value(), 8) +
                           " and cannot be changed to " + hex(cob, 3));
    }
  }

  // What the module really maps (after our write, or its fixed mapping).
  Result<std::uint32_t> n = sdo.read(id, map, 0);
  if (!n) return fail(n.status());
  if (n.value() > kMaxPdoEntries) {
    return Status::error(who() + hex(map, 4) + ":00 = " + std::to_string(n.value()) + " entries (at most 8)");
  }
  actual.count = static_cast<std::uint8_t>(n.value());
  for (std::uint8_t k = 0; k < actual.count; ++k) {
    Result<std::uint32_t> e = sdo.read(id, map, static_cast<std::uint8_t>(k + 1));
    if (!e) return fail(e.status());
    actual.entries[k] = e.value();
  }
  return Status::ok();
}

Status CanIoPort::configure_mapping(SdoClient& sdo) {
  const IoWiring& w = wiring_;
  const std::uint8_t in_subs = io_input_subs(w, group_bits_);
  const std::uint8_t out_bytes = io_output_subs(w);

  // 0x6000:01..n (or 0x6100:01..n) in TPDO1, in sub order, so the inputs are one sample in one frame.
  std::vector<std::uint32_t> inputs;
  for (std::uint8_t k = 1; k <= in_subs; ++k) inputs.push_back(input_entry(k));
  std::vector<std::uint32_t> outputs;
  for (std::uint8_t k = 1; k <= out_bytes; ++k) outputs.push_back(entry(od401::kDigitalOutputs8, k, 8));
  const bool analog = w.load_cell_channel != 0;
  const std::uint32_t load_cell =
      entry(od401::kAnalogInput16, static_cast<std::uint8_t>(w.load_cell_channel), 16);

  tpdo_ = {};
  rpdo_ = {};
  std::uint32_t refused = 0;
  if (Status s = map_pdo(sdo, false, 0, inputs, 1, tpdo_[0], &refused); !s) {
    if (refused == 0) return s;
    return explain_refused_input(s, refused, in_subs);
  }
  if (analog) {
    if (Status s = map_pdo(sdo, false, 1, {load_cell}, 1, tpdo_[1]); !s) return s;
  } else if (Status s = disable_pdo(sdo, false, 1); !s) {
    return s;
  }
  for (int k = 2; k < 4; ++k) {
    if (Status s = disable_pdo(sdo, false, k); !s) return s;
  }
  if (Status s = map_pdo(sdo, true, 0, outputs, 255, rpdo_[0]); !s) return s;
  for (int k = 1; k < 4; ++k) {
    if (Status s = disable_pdo(sdo, true, k); !s) return s;
  }

  // Every object the wiring needs must be in what the module reports; else refuse, naming it.
  output_slot_ = {};
  analog_slot_ = {};
  if (Status s = locate_inputs(in_subs); !s) return s;
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    if (Status s = locate(rpdo_, outputs[k], "digital outputs", output_slot_[k]); !s) return s;
  }
  if (analog) {
    if (Status s = locate(tpdo_, load_cell, "load cell", analog_slot_); !s) return s;
  }
  output_pdo_ = output_slot_[0].pdo;
  for (std::size_t k = 1; k < outputs.size(); ++k) {
    if (output_slot_[k].pdo != output_pdo_) {
      return Status::error(who() + "0x6200:01 and " + object_name(outputs[k]) +
                           " are in different RPDOs; the master needs every digital output in one");
    }
  }
  std::uint32_t bits = 0;
  const PdoLayout& out = rpdo_[static_cast<std::size_t>(output_pdo_)];
  for (std::size_t e = 0; e < out.count; ++e) bits += out.entries[e] & 0xFF;
  output_pdo_bytes_ = static_cast<std::uint8_t>((bits + 7) / 8);
  if (output_pdo_bytes_ > 8) return Status::error(who() + "the output RPDO maps more than 64 bits");
  return Status::ok();
}

// Where `wanted` sits in `layouts`; refused, naming the object and what needs it, when the module's
// mapping lacks it or maps it with another length.
Status CanIoPort::locate(const std::array<PdoLayout, 4>& layouts, std::uint32_t wanted,
                         const std::string& what, Slot& slot) const {
  slot = find(layouts, wanted);
  if (slot.pdo < 0) {
    return Status::error(who() + "no PDO carries " + object_name(wanted) + " (" + what +
                         "); the module's mapping (fixed or refused) lacks it");
  }
  if (slot.bytes != (wanted & 0xFF) / 8) {
    return Status::error(who() + object_name(wanted) + " is mapped with " + std::to_string(slot.bytes * 8) +
                         " bits, the master needs " + std::to_string(wanted & 0xFF) + " (" + what + ")");
  }
  return Status::ok();
}

// The module refused to map `entry` into the inputs' TPDO: most likely it has fewer inputs than the
// wiring uses, so say which signal makes the master read that far (the highest one, in the last sub).
Status CanIoPort::explain_refused_input(const Status& s, std::uint32_t entry, std::uint8_t subs) const {
  const std::vector<NamedBit> bits = inputs_of(wiring_);
  const NamedBit* highest = signal_in_sub(bits, subs, group_bits_);
  if (highest == nullptr) return s;
  char range[24];
  std::snprintf(range, sizeof range, "0x%04X:01..%02X", input_object(group_bits_), subs);
  return Status::error(s.message() + "; " + object_name(entry) + " is mapped because the wiring reads " +
                       range + " up to " + key_and_value(*highest) +
                       " (a module with fewer digital inputs needs that signal moved or unwired, -1)");
}

// 0x6000:01..`subs` (0x6100's with 16-bit groups). Every sub a wired input lives in must be carried, and all
// of them by ONE TPDO: the inputs are one sample with one `refreshed` tick, so a sensor and its second
// channel (or a shed's end switches) are compared as seen at the same instant, never one frame against
// another. A sub no signal lives in is read when it comes in that TPDO and otherwise not needed.
Status CanIoPort::locate_inputs(std::uint8_t subs) {
  const std::vector<NamedBit> bits = inputs_of(wiring_);
  input_slot_ = {};
  input_pdo_ = -1;
  std::uint32_t first = 0;  // the needed sub that fixed input_pdo_, for the message
  for (std::uint8_t k = 1; k <= subs; ++k) {
    const std::uint32_t e = input_entry(k);
    Slot& slot = input_slot_[static_cast<std::size_t>(k - 1)];
    const NamedBit* user = signal_in_sub(bits, k, group_bits_);
    if (user == nullptr) {
      slot = find(tpdo_, e);
      continue;
    }
    const std::string needed_by = "digital inputs, needed by " + key_and_value(*user);
    if (Status s = locate(tpdo_, e, needed_by, slot); !s) return s;
    if (input_pdo_ < 0) {
      input_pdo_ = slot.pdo;
      first = e;
    } else if (slot.pdo != input_pdo_) {
      return Status::error(who() + object_name(e) + " (" + needed_by + ") is in TPDO" +
                           std::to_string(slot.pdo + 1) + ", " + object_name(first) + " in TPDO" +
                           std::to_string(input_pdo_ + 1) +
                           "; the master needs every digital input in one TPDO (one sample per cycle)");
    }
  }
  for (Slot& slot : input_slot_) {
    if (slot.pdo != input_pdo_ || slot.bytes != group_bits_ / 8) slot = {};
  }
  return Status::ok();
}

std::string CanIoPort::label() const {
  return "node " + std::to_string(config_.node_id) +
         (config_.name.empty() ? " (I/O node)" : " (I/O module " + config_.name + ")");
}

NodeTiming CanIoPort::timing() const {
  return NodeTiming{config_.boot_timeout_s, config_.operational_timeout_s, config_.heartbeat_consumer_s};
}

CanMasterConfig CanIoPort::master_config() const {
  // The module's cycle and timeouts; no master heartbeat (node 0, period 0): nothing but the module.
  return CanMasterConfig{config_.cycle_period_s,
                         config_.sdo_timeout_s,
                         config_.boot_timeout_s,
                         config_.operational_timeout_s,
                         0,
                         0.0};
}

void CanIoPort::bring_up_started() {
  configured_ = false;
  bus_ = nullptr;
  notes_.clear();
  inputs_refreshed_ = analog_refreshed_ = hal::kNeverTick;
  inputs_ = {};  // a re-arm must not show the sensors of the last configuration before the first TPDO
}

void CanIoPort::brought_up(CanBus& bus) {
  bus_ = &bus;
  configured_ = true;
}

Status CanIoPort::configure_profile(SdoClient& sdo) {
  if (Status s = validate(config_); !s) return Status::error("CAN I/O configuration: " + s.message());
  const std::uint8_t id = config_.node_id;
  const auto fail = [&](const Status& s) { return Status::error(who() + s.message()); };

  Result<std::uint32_t> type = sdo.read(id, od::kDeviceType, 0);
  if (!type) return fail(type.status());
  if ((type.value() & 0xFFFF) != od401::kDeviceProfile401) {
    return Status::error(who() + "0x1000 device type = " + hex(type.value(), 8) +
                         ": not a CiA 401 generic I/O module (low word 0x0191)");
  }
  const auto producer_ms = static_cast<std::uint32_t>(std::lround(config_.heartbeat_producer_s * 1e3));
  if (Status s = sdo.write(id, od::kHeartbeatProducer, 0, producer_ms, 2); !s) return fail(s);

  // The module's own reaction to a failure: valves off (see io_safe_outputs()).
  {
    const IoWiring& w = wiring_;
    const hal::DigitalOutputs safe = io_safe_outputs();
    std::array<std::uint8_t, kMaxOutputSubs> mode{}, value{};
    const auto put = [&](const IoBit& b, bool on) {
      if (b.bit < 0) return;
      const auto byte = static_cast<std::size_t>(b.bit / 8);
      const auto mask = static_cast<std::uint8_t>(1U << (b.bit % 8));
      mode[byte] |= mask;
      if (on != b.active_low) value[byte] |= mask;
    };
    put(w.piston_a_extend, safe.piston_a_extend);
    put(w.piston_b_extend, safe.piston_b_extend);
    put(w.lamp_green, safe.lamp_green);
    put(w.lamp_amber, safe.lamp_amber);
    put(w.lamp_red, safe.lamp_red);
    put(w.buzzer, safe.buzzer);
    for (int h = 0; h < used_heads(w); ++h) {
      const auto hh = static_cast<std::size_t>(h);
      put(w.gripper_close[hh], safe.gripper_close[hh]);
      put(w.cutter[hh], safe.cutter[hh]);
    }
    const std::uint8_t bytes = io_output_subs(w);
    bool absent = false;
    for (std::uint8_t k = 0; k < bytes && !absent; ++k) {
      if (Status s = sdo.write(id, od401::kOutputErrorMode, static_cast<std::uint8_t>(k + 1), mode[k], 1);
          !s) {
        if (sdo.last_abort() != sdo_abort::kNoObject) return fail(s);
        absent = true;
        break;
      }
      if (Status s = sdo.write(id, od401::kOutputErrorValue, static_cast<std::uint8_t>(k + 1), value[k], 1);
          !s) {
        if (sdo.last_abort() != sdo_abort::kNoObject) return fail(s);
        absent = true;
      }
    }
    if (absent) {
      notes_.push_back(who() +
                       "0x6206/0x6207 (output error mode/value) absent: the outputs keep their last "
                       "state if the master dies; wire the valves' supply through the e-stop chain");
    }
  }

  if (config_.master_node_id != 0) {
    const std::uint32_t v = (static_cast<std::uint32_t>(config_.master_node_id) << 16) |
                            static_cast<std::uint32_t>(std::lround(config_.master_consumer_s * 1e3));
    if (Status s = sdo.write(id, od401::kConsumerHeartbeat, 1, v, 4); !s) {
      if (sdo.last_abort() != sdo_abort::kNoObject && sdo.last_abort() != sdo_abort::kNoSubIndex)
        return fail(s);
      notes_.push_back(who() +
                       "0x1016 (consumer heartbeat time) absent: the module cannot notice that the "
                       "master died; only its own failure mode protects the outputs");
    }
  }

  return configure_mapping(sdo);
}

// ---------------------------------------------------------------------------------------------------
// Per tick (RT-safe)
// ---------------------------------------------------------------------------------------------------
void CanIoPort::on_profile_frame(hal::Tick now, const CanFrame& f) noexcept {
  const CobDecoded d = decode_cob_id(f.id);
  const auto read_le = [&](const Slot& s, std::uint32_t& v) {
    if (s.offset + s.bytes > f.dlc) return false;
    v = 0;
    for (std::size_t b = 0; b < s.bytes; ++b)
      v |= static_cast<std::uint32_t>(f.data[s.offset + b]) << (8 * b);
    return true;
  };
  int tpdo = -1;
  switch (d.function) {
    case CobFunction::kTpdo1:
      tpdo = 0;
      break;
    case CobFunction::kTpdo2:
      tpdo = 1;
      break;
    case CobFunction::kTpdo3:
      tpdo = 2;
      break;
    case CobFunction::kTpdo4:
      tpdo = 3;
      break;
    default:
      return;
  }
  if (f.is_rtr()) {  // a remote request for this TPDO (another master, a bus tool) carries no data
    ++rx_errors_;
    return;
  }
  bool used = false;
  std::uint32_t v = 0;
  if (input_pdo_ == tpdo) {
    // Every sub first, then all at once: a short frame changes nothing, so the inputs stay one sample.
    // A 16-bit group k holds the terminals of 8-bit groups 2k and 2k+1 (low byte first, as CiA 401 says).
    std::array<std::uint8_t, kMaxInputBytes> sample = inputs_;
    const auto group_bytes = static_cast<std::size_t>(group_bits_ / 8);
    for (std::size_t k = 0; k < input_slot_.size(); ++k) {
      if (input_slot_[k].pdo != tpdo) continue;
      if (!read_le(input_slot_[k], v)) {
        ++rx_errors_;
        return;
      }
      for (std::size_t b = 0; b < group_bytes && k * group_bytes + b < sample.size(); ++b)
        sample[k * group_bytes + b] = static_cast<std::uint8_t>(v >> (8 * b));
    }
    inputs_ = sample;
    inputs_refreshed_ = now;
    used = true;
  }
  if (analog_slot_.pdo == tpdo) {
    if (!read_le(analog_slot_, v)) {
      ++rx_errors_;
      return;
    }
    analog_counts_ = static_cast<std::int16_t>(static_cast<std::uint16_t>(v));
    analog_refreshed_ = now;
    used = true;
  }
  if (!used) ++rx_errors_;  // a TPDO we disabled: the module ignores its configuration
}

bool CanIoPort::input(const IoBit& b) const noexcept {
  // Never seen reads false whatever the polarity: the cleared inputs_ of an active-low signal would
  // otherwise read true (a break-contact sensor confirmed, a button pressed) before the first TPDO.
  if (b.bit < 0 || inputs_refreshed_ == hal::kNeverTick) return false;
  const bool level = ((inputs_[static_cast<std::size_t>(b.bit / 8)] >> (b.bit % 8)) & 1U) != 0;
  return level != b.active_low;
}

void CanIoPort::read_wired(hal::DigitalInputs& io) const noexcept {
  const IoWiring& w = wiring_;
  const auto take = [this](const IoBit& b, bool& to) {
    if (b.bit >= 0) to = input(b);
  };
  take(w.piston_a_extended, io.piston_a_extended);
  take(w.piston_a_retracted, io.piston_a_retracted);
  take(w.piston_b_extended, io.piston_b_extended);
  take(w.piston_b_retracted, io.piston_b_retracted);
  take(w.shuttle_at_left, io.shuttle_at_left);
  take(w.shuttle_at_right, io.shuttle_at_right);
  // Before the first TPDO there is no news, not an opened chain: the sample's `refreshed` stays kNeverTick,
  // which the sequencer counts as old from arming (stale → fault), and every input reads false (active-low
  // ones too, see input()), so nothing can be confirmed (no shed, no pick) on inputs never seen.
  if (w.estop_ok.bit >= 0) io.estop_ok = inputs_refreshed_ == hal::kNeverTick || input(w.estop_ok);
  take(w.button_start, io.button_start);
  take(w.button_pause, io.button_pause);
  take(w.button_ack, io.button_ack);
  take(w.row_knotted, io.row_knotted);
  // Each second channel from its own terminal, never derived from the first: false where not wired.
  for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i) take(w.second[i], io.second_channel[i]);
  for (std::size_t h = 0; h < static_cast<std::size_t>(w.heads); ++h)
    take(w.yarn_present[h], io.yarn_present[h]);
}

void CanIoPort::read_io(hal::Tick /*now*/, const hal::AxisFeedbacks& /*axes*/,
                        hal::DigitalInputs& io) noexcept {
  io = hal::DigitalInputs{};  // what this module does not carry reads false
  read_wired(io);
  io.refreshed = inputs_refreshed_;
}

void CanIoPort::read_analog(hal::Tick /*now*/, hal::AnalogInputs& analog) noexcept {
  const IoWiring& w = wiring_;
  analog.beat_force_valid = w.load_cell_channel != 0 && analog_refreshed_ != hal::kNeverTick;
  analog.beat_force_n =
      analog.beat_force_valid
          ? w.load_cell_n_per_count * static_cast<double>(analog_counts_) + w.load_cell_offset_n
          : 0.0;
  analog.refreshed = analog_refreshed_;
}

void CanIoPort::write_io(hal::Tick /*now*/, const hal::DigitalOutputs& requested) noexcept {
  if (!configured_) return;
  // A node we cannot supervise gets its safe outputs (it may still hear us).
  const hal::DigitalOutputs& o = supervisor_.link_fault() != 0 ? io_safe_outputs() : requested;
  const IoWiring& w = wiring_;
  std::array<std::uint8_t, kMaxOutputSubs> bytes{};
  const auto put = [&](const IoBit& b, bool on) {
    if (b.bit < 0) return;
    if (on != b.active_low)
      bytes[static_cast<std::size_t>(b.bit / 8)] |= static_cast<std::uint8_t>(1U << (b.bit % 8));
  };
  put(w.piston_a_extend, o.piston_a_extend);
  put(w.piston_b_extend, o.piston_b_extend);
  put(w.lamp_green, o.lamp_green);
  put(w.lamp_amber, o.lamp_amber);
  put(w.lamp_red, o.lamp_red);
  put(w.buzzer, o.buzzer);
  for (std::size_t h = 0; h < static_cast<std::size_t>(w.heads); ++h) {
    put(w.gripper_close[h], o.gripper_close[h]);
    put(w.cutter[h], o.cutter[h]);
  }
  CanFrame f;
  f.id = cob::rpdo(output_pdo_ + 1, config_.node_id);
  f.dlc = output_pdo_bytes_;
  for (std::size_t k = 0; k < output_slot_.size(); ++k) {
    if (output_slot_[k].pdo == output_pdo_ && output_slot_[k].bytes == 1)
      f.data[output_slot_[k].offset] = bytes[k];
  }
  if (bus_->send(f) != SendResult::kOk) ++tx_dropped_;
}

}  // namespace loom::drivers

// Required objects per node kind, named with the master's own od:: constants.
#include "loom/drivers/required_objects.hpp"

#include <algorithm>
#include <cstdio>
#include <initializer_list>
#include <utility>

#include "loom/drivers/can_io_config.hpp"
#include "loom/drivers/pdo.hpp"

namespace loom::drivers {

std::vector<RequiredObject> drive_objects() {
  return {
      {od::kDeviceType, "device type", false, "identifies a CiA 402 drive"},
      {od::kErrorRegister, "error register", false, "EMCY context"},
      {od::kHeartbeatProducer, "producer heartbeat time", false, "the drive is supervised by its heartbeat"},
      {od401::kConsumerHeartbeat, "consumer heartbeat time", true,
       "the drive stops by itself when the controller dies"},
      {od::kRpdoComm, "RPDO1 communication", false, "controlword + target position every SYNC"},
      {od::kRpdoMap, "RPDO1 mapping (writable, or fixed to 0x6040 + 0x607A)", false,
       "read back when read-only"},
      {od::kTpdoComm, "TPDO1 communication", false, "statusword + position actual every SYNC"},
      {od::kTpdoMap, "TPDO1 mapping (writable, or fixed to 0x6041 + 0x6064)", false,
       "read back when read-only"},
      {static_cast<std::uint16_t>(od::kTpdoComm + 1), "TPDO2 communication", true,
       "velocity + torque actual"},
      {od::kErrorCode, "error code", false, "fault text for the technician"},
      {od::kControlword, "controlword", false, "CiA 402 power state machine"},
      {od::kStatusword, "statusword", false, "CiA 402 state, following error bit"},
      {od::kModesOfOperation, "modes of operation", false, "set to 8 (cyclic synchronous position)"},
      {od::kModesOfOperationDisplay, "modes of operation display", false, "confirms mode 8"},
      {od::kPositionActual, "position actual value", false, "feedback; seeds the first target"},
      {od::kVelocityActual, "velocity actual value", true, "in TPDO2 when present"},
      {od::kTorqueActual, "torque actual value", true, "in TPDO2 when present"},
      {od::kTargetPosition, "target position", false, "the profile, every SYNC"},
      {od::kInterpolationPeriod, "interpolation time period", false, "set to the control period"},
      {od::kSupportedDriveModes, "supported drive modes", false, "must offer CSP (bit 7)"},
  };
}

std::vector<RequiredObject> homing_drive_objects() {
  return {
      {od::kModesOfOperation, "modes of operation", false,
       "set to 6 (homing) for the referencing run, then 8"},
      {od::kHomeOffset, "home offset", false, "the axis' reading at the home point"},
      {od::kHomingMethod, "homing method", false, "the configured method (switch, index pulse or here)"},
      {od::kHomingSpeeds, "homing speeds", false, ":01 search for the switch, :02 search for zero"},
      {od::kHomingAcceleration, "homing acceleration", false, "the referencing run's acceleration"},
      {od::kStatusword, "statusword", false, "bits 12/13 homing attained / homing error in mode 6"},
  };
}

std::vector<RequiredObject> io_module_objects() {
  return {
      {od::kDeviceType, "device type", false, "must be CiA 401"},
      {od::kHeartbeatProducer, "producer heartbeat time", false, "the module is supervised by its heartbeat"},
      {od401::kConsumerHeartbeat, "consumer heartbeat time", true, "valves drop when the controller dies"},
      {od::kRpdoComm, "RPDO1 communication/mapping", false, "digital outputs every SYNC"},
      {od::kTpdoComm, "TPDO1 communication/mapping", false, "digital inputs every SYNC"},
      {static_cast<std::uint16_t>(od::kTpdoComm + 1), "TPDO2 communication/mapping", true,
       "load cell (when wired)"},
      {od401::kDigitalInputs8, "read digital inputs, 8-bit", false,
       "sensors and their second channels, e-stop chain, buttons"},
      {od401::kDigitalOutputs8, "write digital outputs, 8-bit", false, "valves, stack light, buzzer"},
      {od401::kOutputErrorMode, "output error mode", true, "the module adopts the safe outputs by itself"},
      {od401::kOutputErrorValue, "output error value", true, "both valves de-energised on failure"},
      {od401::kAnalogInput16, "read analog input, 16-bit", true, "the beater's load cell (when wired)"},
  };
}

namespace {

// "a, b, c" of the parts that are present.
std::string joined(std::initializer_list<std::pair<bool, const char*>> parts) {
  std::string out;
  for (const auto& [present, text] : parts) {
    if (present) out += (out.empty() ? "" : ", ") + std::string(text);
  }
  return out;
}

bool wired(const IoBit& b) {
  return b.bit >= 0;
}

}  // namespace

std::vector<RequiredObject> io_module_objects(const IoWiring& w, int input_group_bits) {
  // The group counts come from the same function configure() maps with, so a module checked against
  // this list is one the master accepts (a module with fewer groups cannot map what the wiring asks for).
  const auto heads =
      static_cast<std::size_t>(std::clamp(w.heads, 0, static_cast<int>(hal::kMaxKnottingHeads)));
  const auto any = [&](const auto& signals) {
    return std::any_of(signals.begin(), signals.begin() + static_cast<std::ptrdiff_t>(heads), wired);
  };
  const auto firsts = first_switches(w);
  const bool sensors = std::any_of(firsts.begin(), firsts.end(), [](const IoBit* b) { return wired(*b); });
  const bool seconds = std::any_of(w.second.begin(), w.second.end(), wired);
  const bool buttons =
      wired(w.button_start) || wired(w.button_pause) || wired(w.button_ack) || wired(w.row_knotted);
  const bool valves = wired(w.piston_a_extend) || wired(w.piston_b_extend);
  const bool lamps = wired(w.lamp_green) || wired(w.lamp_amber) || wired(w.lamp_red);
  const bool grippers = any(w.gripper_close) || any(w.cutter);
  std::vector<RequiredObject> v;
  for (RequiredObject& o : io_module_objects()) {
    const bool load_cell_object = o.index == od401::kAnalogInput16 || o.index == od::kTpdoComm + 1;
    if (load_cell_object && w.load_cell_channel == 0) continue;  // not on this module
    if (o.index == od401::kDigitalInputs8) {
      if (input_group_bits == kInputGroupBits16) {
        o.index = od401::kDigitalInputs16;
        o.name = "read digital inputs, 16-bit";
      }
      o.subs = io_input_subs(w, input_group_bits);
      o.why = joined({{sensors, seconds ? "sensors and their second channels" : "sensors"},
                      {!sensors && seconds, "the sensors' second channels"},
                      {wired(w.estop_ok), "e-stop chain"},
                      {buttons, "buttons"},
                      {any(w.yarn_present), "the heads' yarn-present switches"}});
      if (o.why.empty()) o.why = "none wired: read for the module's supervision";
    } else if (o.index == od401::kDigitalOutputs8) {
      o.subs = io_output_subs(w);
      o.why = joined({{valves, "valves"},
                      {lamps, "stack light"},
                      {wired(w.buzzer), "buzzer"},
                      {grippers, "the heads' grippers and cutters"}});
      if (o.why.empty()) o.why = "none wired";
    } else if (o.index == od401::kOutputErrorValue) {
      o.why = joined({{valves, "both valves de-energised"}, {grippers, "grippers open, cutters retracted"}});
      o.why = o.why.empty() ? "the safe outputs on failure" : o.why + " on failure";
    } else if (o.index == od401::kConsumerHeartbeat && !valves) {
      o.why = "its outputs go safe when the controller dies";
    }
    v.push_back(std::move(o));
  }
  return v;
}

std::string describe(const RequiredObject& o) {
  char object[24];
  if (o.subs > 1) {
    std::snprintf(object, sizeof object, "0x%04X:01..%02X", o.index, o.subs);
  } else if (o.subs == 1) {
    std::snprintf(object, sizeof object, "0x%04X:01", o.index);
  } else {
    std::snprintf(object, sizeof object, "0x%04X", o.index);
  }
  char buf[200];
  std::snprintf(buf, sizeof buf, "%s %s%s: %s", object, o.name, o.optional ? " (optional)" : "",
                o.why.c_str());
  return buf;
}

}  // namespace loom::drivers

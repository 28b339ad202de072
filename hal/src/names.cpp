// Human-readable names for HAL enums (used by telemetry, logs and error messages).
#include <cstring>

#include "loom/hal/types.hpp"

namespace loom::hal {

const char* axis_name(CoreAxis a) {
  switch (a) {
    case CoreAxis::kBeatCrank:
      return "beat_crank";
    case CoreAxis::kCarriage:
      return "carriage";
    case CoreAxis::kHelix:
      return "helix";
  }
  return "?";
}

const char* axis_role_name(AxisRole r) {
  switch (r) {
    case AxisRole::kBeatCrank:
      return "beat_crank";
    case AxisRole::kCarriage:
      return "carriage";
    case AxisRole::kHelix:
      return "helix";
    case AxisRole::kKnotter:
      return "knotter";
    case AxisRole::kSelector:
      return "selector";
    case AxisRole::kAuxiliary:
      return "auxiliary";
  }
  return "?";
}

bool parse_axis_role(const char* text, AxisRole& role) {
  for (std::size_t i = 0; i < kAxisRoleCount; ++i) {
    const auto r = static_cast<AxisRole>(i);
    if (std::strcmp(text, axis_role_name(r)) == 0) {
      role = r;
      return true;
    }
  }
  return false;
}

bool is_rotary(AxisRole r) {
  return r != AxisRole::kCarriage;
}
const char* axis_unit(AxisRole r) {
  return is_rotary(r) ? "rad" : "m";
}

AxisLayout AxisLayout::core() {
  AxisLayout l;
  l.add("beat_crank", AxisRole::kBeatCrank);
  l.add("carriage", AxisRole::kCarriage);
  l.add("helix", AxisRole::kHelix);
  return l;
}

const AxisLayout& core_axis_layout() {
  static const AxisLayout core = AxisLayout::core();
  return core;
}

bool AxisLayout::add(const char* name, AxisRole role) {
  const std::size_t n = std::strlen(name);
  if (count >= kMaxAxes || n == 0 || n > kNameMax) return false;
  Entry& e = axis[count++];
  std::memcpy(e.name.data(), name, n + 1);
  e.role = role;
  return true;
}

int AxisLayout::find(const char* name) const {
  for (std::size_t i = 0; i < count; ++i) {
    if (std::strcmp(axis[i].name.data(), name) == 0) return static_cast<int>(i);
  }
  return -1;
}

const char* drive_state_name(DriveState s) {
  switch (s) {
    case DriveState::kUnknown:
      return "unknown";
    case DriveState::kNotReadyToSwitchOn:
      return "not_ready_to_switch_on";
    case DriveState::kSwitchOnDisabled:
      return "switch_on_disabled";
    case DriveState::kReadyToSwitchOn:
      return "ready_to_switch_on";
    case DriveState::kSwitchedOn:
      return "switched_on";
    case DriveState::kOperationEnabled:
      return "operation_enabled";
    case DriveState::kQuickStopActive:
      return "quick_stop_active";
    case DriveState::kFaultReactionActive:
      return "fault_reaction_active";
    case DriveState::kFault:
      return "fault";
  }
  return "?";
}

const char* safety_sensor_name(SafetySensor s) {
  switch (s) {
    case SafetySensor::kPistonAExtended:
      return "piston_a_extended";
    case SafetySensor::kPistonARetracted:
      return "piston_a_retracted";
    case SafetySensor::kPistonBExtended:
      return "piston_b_extended";
    case SafetySensor::kPistonBRetracted:
      return "piston_b_retracted";
    case SafetySensor::kShuttleAtLeft:
      return "shuttle_at_left";
    case SafetySensor::kShuttleAtRight:
      return "shuttle_at_right";
  }
  return "?";
}

const char* fault_kind_name(FaultKind k) {
  switch (k) {
    case FaultKind::kNone:
      return "none";
    case FaultKind::kDrive:
      return "drive";
    case FaultKind::kEmcy:
      return "emcy";
    case FaultKind::kNodeLost:
      return "node_lost";
    case FaultKind::kBusOff:
      return "bus_off";
    case FaultKind::kCommunication:
      return "communication";
  }
  return "?";
}

const char* link_recovery_name(LinkRecovery r) {
  switch (r) {
    case LinkRecovery::kHealthy:
      return "healthy";
    case LinkRecovery::kBusOff:
      return "bus_off";
    case LinkRecovery::kNodeSilent:
      return "node_silent";
    case LinkRecovery::kReady:
      return "ready";
  }
  return "?";
}

}  // namespace loom::hal

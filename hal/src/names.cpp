// Human-readable names for HAL enums (used by telemetry, logs and error messages).
#include "loom/hal/types.hpp"

namespace loom::hal {

const char* axis_name(Axis a) {
  switch (a) {
    case Axis::kBeatCrank: return "beat_crank";
    case Axis::kCarriage: return "carriage";
    case Axis::kHelix: return "helix";
  }
  return "?";
}

const char* drive_state_name(DriveState s) {
  switch (s) {
    case DriveState::kUnknown: return "unknown";
    case DriveState::kNotReadyToSwitchOn: return "not_ready_to_switch_on";
    case DriveState::kSwitchOnDisabled: return "switch_on_disabled";
    case DriveState::kReadyToSwitchOn: return "ready_to_switch_on";
    case DriveState::kSwitchedOn: return "switched_on";
    case DriveState::kOperationEnabled: return "operation_enabled";
    case DriveState::kQuickStopActive: return "quick_stop_active";
    case DriveState::kFaultReactionActive: return "fault_reaction_active";
    case DriveState::kFault: return "fault";
  }
  return "?";
}

const char* safety_sensor_name(SafetySensor s) {
  switch (s) {
    case SafetySensor::kPistonAExtended: return "piston_a_extended";
    case SafetySensor::kPistonARetracted: return "piston_a_retracted";
    case SafetySensor::kPistonBExtended: return "piston_b_extended";
    case SafetySensor::kPistonBRetracted: return "piston_b_retracted";
    case SafetySensor::kShuttleAtLeft: return "shuttle_at_left";
    case SafetySensor::kShuttleAtRight: return "shuttle_at_right";
  }
  return "?";
}

const char* link_recovery_name(LinkRecovery r) {
  switch (r) {
    case LinkRecovery::kHealthy: return "healthy";
    case LinkRecovery::kBusOff: return "bus_off";
    case LinkRecovery::kNodeSilent: return "node_silent";
    case LinkRecovery::kReady: return "ready";
  }
  return "?";
}

}  // namespace loom::hal

// The scene file's names (effects, injected faults, sensors, load-cell modes): what a scene may say,
// shared by the simulator and the scene parser, which links this without the simulator itself.
#include <string>
#include <vector>

#include "loom/sim_hal/scene.hpp"

namespace loom::sim_hal {

const std::vector<std::string>& known_effects() {
  static const std::vector<std::string> names{
      kEffectIdeal,       kEffectServoLag, kEffectPneumatics,    kEffectShuttleSlip, kEffectSensorNoise,
      kEffectBeatContact, kEffectInertia,  kEffectJointFriction, kEffectKnotter,     kEffectWarpTension};
  return names;
}

const char* sensor_name(Sensor s) {
  switch (s) {
    case Sensor::kPistonAExtended:
      return "piston_a_extended";
    case Sensor::kPistonARetracted:
      return "piston_a_retracted";
    case Sensor::kPistonBExtended:
      return "piston_b_extended";
    case Sensor::kPistonBRetracted:
      return "piston_b_retracted";
    case Sensor::kShuttleLeft:
      return "shuttle_at_left";
    case Sensor::kShuttleRight:
      return "shuttle_at_right";
    case Sensor::kPistonAExtended2:
      return "piston_a_extended_2";
    case Sensor::kPistonARetracted2:
      return "piston_a_retracted_2";
    case Sensor::kPistonBExtended2:
      return "piston_b_extended_2";
    case Sensor::kPistonBRetracted2:
      return "piston_b_retracted_2";
    case Sensor::kShuttleLeft2:
      return "shuttle_at_left_2";
    case Sensor::kShuttleRight2:
      return "shuttle_at_right_2";
  }
  return "?";
}

const char* injected_fault_name(InjectedFault f) {
  switch (f) {
    case InjectedFault::kDriveFault:
      return "drive_fault";
    case InjectedFault::kEStop:
      return "estop";
    case InjectedFault::kStuckPiston:
      return "stuck_piston";
    case InjectedFault::kStuckSensor:
      return "stuck_sensor";
    case InjectedFault::kIntermittentSensor:
      return "intermittent_sensor";
    case InjectedFault::kCanFrameLoss:
      return "can_frame_loss";
    case InjectedFault::kCanLatency:
      return "can_latency";
    case InjectedFault::kBusOff:
      return "bus_off";
    case InjectedFault::kHeartbeatLoss:
      return "heartbeat_loss";
    case InjectedFault::kEmcy:
      return "emcy";
    case InjectedFault::kEncoderGlitch:
      return "encoder_glitch";
    case InjectedFault::kLoadCellFailure:
      return "load_cell_failure";
    case InjectedFault::kAirLoss:
      return "air_loss";
    case InjectedFault::kLoopStall:
      return "loop_stall";
    case InjectedFault::kPowerCut:
      return "power_cut";
    case InjectedFault::kSelectorJam:
      return "selector_jam";
    case InjectedFault::kYarnOut:
      return "yarn_out";
    case InjectedFault::kAxisJam:
      return "axis_jam";
  }
  return "?";
}

const char* load_cell_mode_name(LoadCellMode m) {
  return m == LoadCellMode::kNan ? "nan" : "lost";
}

}  // namespace loom::sim_hal

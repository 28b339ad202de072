// The one table of faults: code, name, operator text. Code, telemetry, logs and docs all come from it.
// Every fault has the same reaction in this machine: quick stop every axis, valves hold, latch the
// first fault, keep the production counters. (ODrive-style single error schema.)
#pragma once

#include <cstdint>

namespace loom::sequencer {

#define LOOM_FAULT_TABLE(X)                                                                                 \
  X(kNone, 0x0000, "none", "no fault")                                                                      \
  X(kEStop, 0x1001, "estop", "e-stop chain opened")                                                         \
  X(kDriveFault, 0x1002, "drive_fault", "a servo drive reported a fault")                                   \
  X(kHeartbeatLost, 0x1003, "heartbeat_lost", "a CAN node stopped sending heartbeats")                      \
  X(kLinkFault, 0x1004, "link_fault", "CAN link fault (bus-off or socket error)")                           \
  X(kStaleFeedback, 0x1005, "stale_feedback", "axis or I/O feedback not refreshed in time")                 \
  X(kEnableTimeout, 0x1006, "enable_timeout", "drives did not reach Operation Enabled in time")             \
  X(kShedTimeout, 0x1007, "shed_timeout", "piston end sensors did not confirm the shed in time")            \
  X(kShuttleNotArrived, 0x1008, "shuttle_not_arrived", "shuttle-arrival sensor did not see the shuttle")    \
  X(kShuttleLost, 0x1009, "shuttle_lost", "shuttle is at neither selvedge before a pick")                   \
  X(kCarriageInWarp, 0x100A, "interlock_carriage_in_warp",                                                  \
    "carriage commanded while the beater is in the warp")                                                   \
  X(kPickWithoutShed, 0x100B, "interlock_pick_without_shed",                                                \
    "pick commanded while the shed is not confirmed open")                                                  \
  X(kShedWithShuttle, 0x100C, "interlock_shed_with_shuttle",                                                \
    "shed change commanded while the shuttle is in the shed")                                               \
  X(kShedSensorEarly, 0x100E, "shed_sensor_early",                                                          \
    "piston end sensors confirmed faster than a frame can move")                                            \
  X(kShedNotReleased, 0x100F, "shed_not_released",                                                          \
    "a heald frame never left its end position (valve, air, jam)")                                          \
  X(kAirLost, 0x1010, "air_lost", "neither heald frame left its end position: no air at the valves")        \
  X(kShedSensorConflict, 0x1011, "shed_sensor_conflict",                                                    \
    "a piston reads extended and retracted at once (stuck sensor or wiring)")                               \
  X(kShuttleSensorConflict, 0x1012, "shuttle_sensor_conflict",                                              \
    "the shuttle reads at both selvedges at once (stuck sensor or wiring)")                                 \
  X(kShuttleSensorEarly, 0x1013, "shuttle_sensor_early",                                                    \
    "the arrival sensor saw the shuttle before its carrier could bring it")                                 \
  X(kShuttleSideMismatch, 0x1014, "shuttle_side_mismatch",                                                  \
    "the shuttle is at the selvedge the production counters say it left")                                   \
  X(kCountersInconsistent, 0x1015, "counters_inconsistent",                                                 \
    "the resumed production counters are impossible for this recipe")                                       \
  X(kNonFiniteFeedback, 0x1016, "nonfinite_feedback",                                                       \
    "an axis reported a NaN or infinite position, velocity or effort")                                      \
  X(kEncoderJump, 0x1017, "encoder_jump",                                                                   \
    "an axis position jumped faster than the axis can move (encoder or wiring)")                            \
  X(kDriveEmcy, 0x1018, "drive_emcy", "a drive sent an error code (EMCY) while still enabled")              \
  X(kLoadCellFault, 0x1019, "load_cell_fault", "the beater's load cell failed (lost, NaN or out of range)") \
  X(kLoopStall, 0x101A, "loop_stall",                                                                       \
    "feedback from every device stopped at once (the loop or the bus stalled)")                             \
  X(kStopRequested, 0x101B, "stop_requested", "stopped at once on the operator's request (counters kept)")  \
  X(kShuttleSlipped, 0x101C, "shuttle_slipped",                                                             \
    "the shuttle did not leave or arrive with its carrier (slipped off the magnet)")                        \
  X(kShedSensorLate, 0x101D, "shed_sensor_late",                                                            \
    "a heald frame took far longer than its learned stroke (stuck on its way)")                             \
  X(kLoopOverrun, 0x101E, "loop_overrun", "the control loop missed its deadline too many ticks in a row")   \
  X(kCountersNotSaved, 0x101F, "counters_not_saved",                                                        \
    "the production counters could not be saved in time (a finished row, or a knot cycle's start written "  \
    "ahead)")                                                                                               \
  X(kSensorDiscrepancy, 0x1020, "sensor_discrepancy",                                                       \
    "the two channels of a safety sensor disagree (a stuck switch or a wiring fault)")                      \
  X(kHomingFailed, 0x1021, "homing_failed",                                                                 \
    "an axis' homing run failed or did not find its reference in time")                                     \
  X(kAxisUnreferenced, 0x1022, "axis_unreferenced",                                                         \
    "an axis lost its reference (drive power cycle) or cannot be homed")                                    \
  X(kKnotServoLag, 0x1023, "knot_servo_lag",                                                                \
    "a knotting servo did not follow its knot cycle (jammed linkage or drive limit)")                       \
  X(kSelectorJam, 0x1024, "selector_jam",                                                                   \
    "a colour selector did not reach its magazine slot (jammed magazine or drive limit)")                   \
  X(kYarnSensorStuck, 0x1025, "yarn_sensor_stuck",                                                          \
    "a head's yarn-present switch saw a knot before the head tied one (stuck switch, or a knot already "    \
    "there)")                                                                                               \
  X(kGripperInWarp, 0x1026, "interlock_gripper_in_warp",                                                    \
    "carriage, beater or shed commanded while a knotting gripper is in the warp")                           \
  X(kKnotNotClear, 0x1027, "interlock_knot_not_clear",                                                      \
    "knot cycle commanded while the beater is in the warp or the shed is not still")                        \
  X(kSelectorWithYarn, 0x1028, "interlock_selector_with_yarn",                                              \
    "colour selector commanded while its gripper holds yarn")                                               \
  X(kShedLost, 0x1029, "shed_lost",                                                                         \
    "a heald frame left its end position while the shed was held for knotting (air, valve or end sensor)")  \
  X(kCarriageNotAtKnot, 0x102A, "carriage_not_at_knot",                                                     \
    "the carriage was not measured at the knot within its placement tolerance in time (jam, drive limit "   \
    "or late feedback)")

enum class Fault : std::uint8_t {
#define LOOM_FAULT_ENUM(id, code, name, text) id,
  LOOM_FAULT_TABLE(LOOM_FAULT_ENUM)
#undef LOOM_FAULT_ENUM
};

std::uint16_t fault_code(Fault f);
const char* fault_name(Fault f);
const char* fault_text(Fault f);

}  // namespace loom::sequencer

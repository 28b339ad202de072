// Plain per-tick data exchanged between the sequencer and whatever drives the machine (CAN drives or
// the simulator). Everything is SI (m, rad, s, N, N·m); drive counts exist only inside drivers/.
// Every feedback value carries the tick it was refreshed, so staleness is visible in the data.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace loom::hal {

// The loop's time base: an integer tick counter. Seconds = tick * period; never a float clock.
using Tick = std::int64_t;
inline constexpr Tick kNeverTick = -1;

// ---------------------------------------------------------------------------------------------------
// Axes: a configured set (the machine description's [axes.<name>] tables), bounded by kMaxAxes.
// Every loom has the three core axes, always at slots 0..2 in this order; the axes a machine adds
// (knotting servos, colour selectors, auxiliaries) follow from slot 3 on. Arrays are sized for the
// capacity and only the first `AxisLayout::count` entries are used.
// ---------------------------------------------------------------------------------------------------
inline constexpr std::size_t kMaxAxes = 32;  // 12 knotting heads x 2 servos + 3 core axes, with room
// Knotting heads on the carriage (the machine description's [knotting] section): each has a knotting
// servo and a colour-selector servo (axes with roles knotter / selector) and the digital I/O below.
inline constexpr std::size_t kMaxKnottingHeads = 12;
enum class CoreAxis : std::uint8_t {
  kBeatCrank = 0,  // crank of the beat-up crank-rocker, position in rad (unwrapped)
  kCarriage = 1,   // carriage slider across the width, position in m
  kHelix = 2,      // helix shaft carrying the shuttle's magnetic carrier, position in rad (unwrapped)
};
inline constexpr std::size_t kCoreAxisCount = 3;
inline constexpr std::size_t index(CoreAxis a) {
  return static_cast<std::size_t>(a);
}
const char* axis_name(CoreAxis a);  // the core axes' default names: "beat_crank", "carriage", "helix"

// What an axis is for. The core roles are held by exactly one axis each (slots 0..2).
enum class AxisRole : std::uint8_t { kBeatCrank, kCarriage, kHelix, kKnotter, kSelector, kAuxiliary };
inline constexpr std::size_t kAxisRoleCount = 6;
const char* axis_role_name(AxisRole r);                  // "beat_crank", ..., "auxiliary"
bool parse_axis_role(const char* text, AxisRole& role);  // false for an unknown name
bool is_rotary(AxisRole r);                              // rad (true) or m (the carriage)
// The SI unit of an axis' position: "rad" for a rotary axis, "m" for a linear one (is_rotary). The one
// place it is decided: the config's checks, commissioning and telemetry (AXES, for the panel and monitor)
// all take it from here.
const char* axis_unit(AxisRole r);

// The machine's axes: names and roles, in slot order. Plain fixed-size data, built at configure time
// and shared by the sequencer, the simulator, the drivers and telemetry.
struct AxisLayout {
  static constexpr std::size_t kNameMax = 31;
  struct Entry {
    std::array<char, kNameMax + 1> name{};  // NUL-terminated
    AxisRole role = AxisRole::kAuxiliary;
  };
  std::array<Entry, kMaxAxes> axis{};
  std::size_t count = 0;

  // The three core axes, named after their roles: today's loom, and every test's default.
  static AxisLayout core();
  // Configure-time. Appends an axis; false when full or the name is empty or too long.
  bool add(const char* name, AxisRole role);
  const char* name(std::size_t i) const { return i < count ? axis[i].name.data() : "?"; }
  AxisRole role(std::size_t i) const { return axis[i].role; }
  // The slot of the axis called `name`, or -1.
  int find(const char* name) const;
};
// The core layout as a shared constant (for defaults).
const AxisLayout& core_axis_layout();

// CiA 402 power-state machine states, as decoded from the statusword (0x6041).
enum class DriveState : std::uint8_t {
  kUnknown = 0,  // no statusword seen yet
  kNotReadyToSwitchOn,
  kSwitchOnDisabled,
  kReadyToSwitchOn,
  kSwitchedOn,
  kOperationEnabled,
  kQuickStopActive,
  kFaultReactionActive,
  kFault,
};
const char* drive_state_name(DriveState s);

// What the sequencer wants an axis' power stage to do. The HAL implementation walks the drive's state
// machine toward it (CiA 402 transitions on CAN, immediate in the simulator).
enum class AxisRequest : std::uint8_t {
  kDisable = 0,     // voltage off / switch-on disabled
  kEnable = 1,      // reach Operation Enabled and follow target_position
  kQuickStop = 2,   // decelerate on the drive's quick-stop ramp, hold
  kFaultReset = 3,  // rising edge of fault reset, then back to Switch On Disabled
  kHome = 4,        // enabled, run the axis' referencing (CiA 402 homing) until referenced or failed
};

// What kind of fault a HAL found on a device or the link. The sequencer decides by kind; the raw code
// (a CiA 301 EMCY code on CAN) travels beside it for display and logs only.
enum class FaultKind : std::uint8_t {
  kNone = 0,
  kDrive,          // the drive reports Fault / fault reaction, or the master's own supervision of it tripped
  kEmcy,           // the device sent an emergency message but may still be enabled
  kNodeLost,       // heartbeat lost, unexpected boot-up, or not operational: the node cannot be supervised
  kBusOff,         // the controller left the bus
  kCommunication,  // the link itself failed (socket error, not configured)
};
const char* fault_kind_name(FaultKind k);

struct AxisFeedback {
  DriveState state = DriveState::kUnknown;
  double position = 0.0;         // SI: rad (crank, helix) or m (carriage)
  double velocity = 0.0;         // SI per second
  double effort = 0.0;           // N·m (rotary) or N (linear); 0 when the drive does not report it
  std::uint16_t fault_code = 0;  // raw device code for display (a CiA 301 EMCY code on CAN; 0 = none)
  FaultKind fault_kind = FaultKind::kNone;  // what the fault is; kNone while healthy
  bool fault = false;                       // drive reports Fault / Fault reaction, or the HAL lost the node
  bool following_error = false;             // statusword bit 13 in CSP
  // The axis' position is referenced to the machine: always for an absolute axis; for a homed axis only
  // after a homing run since its drive powered up (kHome). An unreferenced axis never moves in production.
  bool referenced = true;
  bool homing_error = false;  // the last homing run failed (the drive's homing error, or its time-out)
  // Event of this read: the fault report begins, or its code changes (fault_events.hpp). The loop reports
  // it once; the port sets it on exactly one read. (Beside the other flags: in their padding, so the
  // struct every tick copies does not grow.)
  bool fault_raised = false;
  Tick refreshed = kNeverTick;  // tick this feedback was last received
};

struct AxisCommand {
  AxisRequest request = AxisRequest::kDisable;
  double target_position = 0.0;  // SI; in CSP the drive interpolates to it within one cycle
  // SI; the end of the planned move target_position is on, NaN when it is not on one (holding, jogging).
  // A profile-position drive is sent this once, as its set-point, and runs its own profile to it.
  double move_end = std::numeric_limits<double>::quiet_NaN();
};

// Indexed by slot; entries at and beyond the layout's count are unused.
using AxisFeedbacks = std::array<AxisFeedback, kMaxAxes>;
using AxisCommands = std::array<AxisCommand, kMaxAxes>;

// ---------------------------------------------------------------------------------------------------
// Digital I/O (the I/O node): two piston valves for the heald frames, their end sensors, the shuttle
// arrival sensors at both selvedges, and the e-stop chain.
// ---------------------------------------------------------------------------------------------------
struct DigitalOutputs {
  // Valve coil energised = that piston extends. Safe state (both false) leaves both frames retracted
  // and vented; the shed closes, which never traps the shuttle because it cannot be picked then.
  bool piston_a_extend = false;
  bool piston_b_extend = false;
  // Stack light and buzzer (operator signalling only; nothing safety-relevant depends on them).
  bool lamp_green = false;  // weaving
  bool lamp_amber = false;  // waiting for the operator (armed, paused, waiting for the knotter)
  bool lamp_red = false;    // fault latched, waiting for acknowledgement
  bool buzzer = false;
  // Knotting heads (the first `heads` entries): gripper closed on the yarn, cutter blade firing. Safe state
  // (false) opens the grippers and retracts the cutters.
  std::array<bool, kMaxKnottingHeads> gripper_close{};
  std::array<bool, kMaxKnottingHeads> cutter{};
};

// The six safety sensors — the ones whose word lets a frame move or a pick start — in a fixed order
// (debouncing, second channels, diagnostics).
enum class SafetySensor : std::uint8_t {
  kPistonAExtended,
  kPistonARetracted,
  kPistonBExtended,
  kPistonBRetracted,
  kShuttleAtLeft,
  kShuttleAtRight
};
inline constexpr std::size_t kSafetySensorCount = 6;
const char* safety_sensor_name(SafetySensor s);  // "shuttle_at_right", as in the config's io keys

struct DigitalInputs {
  bool piston_a_extended = false;  // end sensors (reed switches) of piston A
  bool piston_a_retracted = false;
  bool piston_b_extended = false;
  bool piston_b_retracted = false;
  bool shuttle_at_left = false;  // shuttle-arrival sensors at each selvedge
  bool shuttle_at_right = false;
  bool estop_ok = false;  // e-stop chain closed (true = healthy; broken wire reads as e-stop)
  // Operator inputs (push buttons / foot pedal on the I/O node): true while pressed. They request;
  // the sequencer decides when a request is acted on. Not safety inputs (the e-stop chain is).
  bool button_start = false;
  bool button_pause = false;
  bool button_ack = false;   // reset / acknowledge a latched fault
  bool row_knotted = false;  // the weaver's "row knotted" pedal (knotting mode)
  // Second channels of the safety sensors, in SafetySensor order: an independent switch at the same
  // place on its own input, where the machine has one (io.<sensor>_2_bit). One stuck switch then cannot
  // confirm a shed or an arrival that did not happen: the two must agree. False where not wired.
  std::array<bool, kSafetySensorCount> second_channel{};
  // Knotting heads: the yarn-present switch behind each gripper's knot position, true when a knot was
  // tied and pulled down to the fell (sampled in the knot cycle's window). False where no head is fitted.
  std::array<bool, kMaxKnottingHeads> yarn_present{};
  Tick refreshed = kNeverTick;
};

// The primary channels of the safety sensors, in SafetySensor order, and back.
inline std::array<bool, kSafetySensorCount> safety_sensors(const DigitalInputs& io) {
  return {io.piston_a_extended,  io.piston_a_retracted, io.piston_b_extended,
          io.piston_b_retracted, io.shuttle_at_left,    io.shuttle_at_right};
}
inline void set_safety_sensors(DigitalInputs& io, const std::array<bool, kSafetySensorCount>& v) {
  io.piston_a_extended = v[0];
  io.piston_a_retracted = v[1];
  io.piston_b_extended = v[2];
  io.piston_b_retracted = v[3];
  io.shuttle_at_left = v[4];
  io.shuttle_at_right = v[5];
}

// ---------------------------------------------------------------------------------------------------
// Analog inputs: the beater's load cell (force the comb exerts on the cloth fell), when fitted.
// ---------------------------------------------------------------------------------------------------
struct AnalogInputs {
  double beat_force_n = 0.0;      // ≥ 0; meaningful only when beat_force_valid
  bool beat_force_valid = false;  // false when no load cell is fitted / simulated
  Tick refreshed = kNeverTick;
};

// ---------------------------------------------------------------------------------------------------
// Bus / link health reported by the HAL implementation (zeros for the simulator unless a scene injects).
// ---------------------------------------------------------------------------------------------------
// How far a link fault has recovered: the HAL works it out every tick from what the bus says, and the
// loop honours the operator's acknowledgement (which re-arms and reconfigures the link from the non-RT
// side) only once nothing is still missing.
enum class LinkRecovery : std::uint8_t {
  kHealthy,     // no link fault
  kBusOff,      // the CAN controller left the bus and has not restarted (restart-ms, or ip link ... restart)
  kNodeSilent,  // a lost node has not been heard again (no heartbeat within the consumer time, no boot-up)
  kReady,       // every node is on the bus again: an acknowledgement re-arms and reconfigures the link
};
const char* link_recovery_name(LinkRecovery r);

struct LinkStatus {
  bool link_fault = false;  // bus-off, heartbeat lost, socket error: motion must stop
  FaultKind link_fault_kind = FaultKind::kNone;
  std::uint16_t link_fault_code = 0;  // raw code for display
  LinkRecovery recovery = LinkRecovery::kHealthy;
  std::uint8_t silent_node = 0;  // kNodeSilent: the first node still missing
  bool fault_raised = false;     // event of this read: link_fault begins (fault_events.hpp)
  std::uint32_t tx_dropped = 0;  // frames not sent (ENOBUFS/EAGAIN), cumulative
  std::uint32_t rx_errors = 0;   // error frames / malformed frames, cumulative
};

struct HalInputs {
  AxisFeedbacks axes{};
  DigitalInputs io{};
  AnalogInputs analog{};
  LinkStatus link{};
};

struct HalOutputs {
  AxisCommands axes{};
  DigitalOutputs io{};
};

}  // namespace loom::hal

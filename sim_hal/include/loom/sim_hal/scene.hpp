// What a simulation scene asks for, as plain data (the firmware parses scene files into this). Effects
// not named here are never constructed, so they cost nothing per tick.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loom/hal/types.hpp"
#include "loom/motion/beatup.hpp"
#include "loom/sim_hal/knotter.hpp"

namespace loom::sim_hal {

// Names of every effect this simulator knows; a scene naming anything else is rejected.
inline constexpr const char* kEffectIdeal = "ideal";               // axes track their targets exactly
inline constexpr const char* kEffectServoLag = "servo_lag";        // first-order lag of each servo axis
inline constexpr const char* kEffectPneumatics = "pneumatics";     // valve fill time and piston breakaway
inline constexpr const char* kEffectShuttleSlip = "shuttle_slip";  // shuttle lost above the carrier force
inline constexpr const char* kEffectSensorNoise = "sensor_noise";  // end/arrival sensors bounce
inline constexpr const char* kEffectBeatContact = "beat_contact";  // beater load cell at the cloth fell
inline constexpr const char* kEffectInertia = "inertia";  // rigid-body beat-up behind a torque-limited servo
inline constexpr const char* kEffectJointFriction =
    "joint_friction";                                     // crank bearing friction (needs inertia)
inline constexpr const char* kEffectKnotter = "knotter";  // the knotting heads, their yarn and the weaver
inline constexpr const char* kEffectWarpTension =
    "warp_tension";  // uneven, drifting warp tension (needs beat_contact)
const std::vector<std::string>& known_effects();

struct ServoLag {
  double tau_s = 0.005;  // time constant of the position loop
};

// Valve and cylinder: chamber pressure rises as 1 - exp(-t/fill_tau_s) after the valve switches; the
// piston starts once it exceeds `breakaway` (fraction of supply), then moves at a speed proportional to
// the pressure margin, covering the stroke in piston_travel_s at full pressure.
struct Pneumatics {
  double fill_tau_s = 0.04;
  double breakaway = 0.3;
};

// The magnetic carrier drags the shuttle while carrier acceleration × shuttle mass stays below the
// coupling force; above it the shuttle decouples and slides to rest on the race (it never arrives).
struct ShuttleSlip {
  double carrier_force_n = 20.0;
  double shuttle_mass_kg = 0.40;
  double race_friction_m_s2 = 4.0;  // deceleration of a decoupled shuttle
};

// Every binary sensor flips for one tick with this probability per tick (contact bounce, EMI).
struct SensorNoise {
  double flip_probability = 1e-3;
};

// The comb's teeth press the weft into the fell while the tip is within `contact_depth_m` of the fell
// extreme; the force on the cloth is the beater's inertial force m·|a_tangential| (the thesis' model:
// the linkage decelerates the beater and its inertia does the beating).
struct BeatContact {
  double beater_mass_kg = 2.5;
  double contact_depth_m = 0.005;
};

// The warp's tension where the comb beats, relative to the uniform warp the loom was set up for; it scales
// the beat contact's force on the load cell (warp_tension.hpp). Across the width: the parabola through 1 at
// both selvedges and `centre_ratio` in the middle, or, when `points` is given, the relative tensions at
// equally spaced points from the left selvedge to the right, linear between. Over the rows: × (1 +
// drift_per_row × rows woven) — a warp beam held by a constant brake pulls harder as it empties. Per beat:
// × (1 + noise × a standard normal draw), seeded by the scene. The defaults take the open-loop beat out of
// the 80–100 N band: a slack middle (0.84: 75 N) and, after 200 rows, taut selvedges (1.24: 111 N).
struct WarpTension {
  double centre_ratio = 0.84;
  std::vector<double> points;  // empty: the parabola
  double drift_per_row = 0.0012;
  double noise = 0.01;
};

// The beat-up crank stops being a kinematic follower: the linkage's rigid-body dynamics (thesis cast-iron
// links and beater, gravity) driven by the motor's torque, which a position loop of `bandwidth_hz`
// computes from the target and limits to `motor_torque_limit_nm`. Integrated by RK4 in substeps.
struct Inertia {
  double motor_torque_limit_nm = 30.0;
  double drive_inertia_kg_m2 = 0.01;  // motor and gearbox reflected to the crank
  double bandwidth_hz = 25.0;
  int substeps = 8;  // RK4 steps per tick (the free linkage needs ≤ 0.25 ms steps)
  double beater_mass_kg = 2.5;
};

// Crank bearing friction: viscous plus Coulomb (smoothed over 1e-3 rad/s so RK4 sees a continuous law).
struct JointFriction {
  double viscous_nm_s = 0.02;
  double coulomb_nm = 0.3;
};

// Faults a scene can inject, each at a time (at_s) from the start of the run. The first four keep their
// numbers (older tools cast them).
enum class InjectedFault : std::uint8_t {
  kDriveFault,          // the drive of `axis` goes to Fault with EMCY `code`
  kEStop,               // the e-stop chain opens
  kStuckPiston,         // `piston` seizes where it is (a dry seal)
  kStuckSensor,         // `sensor` reads `value` for ever
  kIntermittentSensor,  // `sensor` reads `value` for `duration_s`, then recovers
  kCanFrameLoss,        // a fraction `probability` of the axes' feedback frames is lost for `duration_s`
  kCanLatency,       // axis feedback arrives `latency_s` late (stamped with its sample tick) for `duration_s`
  kBusOff,           // the CAN controller goes bus-off: link fault, no more feedback
  kHeartbeatLoss,    // the node of `axis` falls silent; after the heartbeat time it is reported lost
  kEmcy,             // the drive of `axis` sends EMCY `code` but stays enabled
  kEncoderGlitch,    // the position of `axis` reads `jump` (m or rad) off for `ticks` ticks
  kLoadCellFailure,  // the beater's load cell reads NaN (`mode` "nan") or disappears ("lost")
  kAirLoss,          // the air supply fails: neither piston moves any more
  kLoopStall,        // the loop stalls for `ticks` ticks: no input refreshed, `ticks` overruns counted
  kPowerCut,         // the power fails at tick `at_tick`: the run ends as if the process were killed
  kSelectorJam,      // the colour selector of `head` jams where it stands (needs the knotter effect)
  kYarnOut,          // slot `slot` of `head`'s magazine runs out of yarn early (needs the knotter effect)
  kAxisJam,          // the drive of `axis` stops following its target: it stays where it stands (a jammed
                     // rail or a seized gearbox; the simulated drive reports no following error)
};
inline constexpr int kInjectedFaultCount = 18;
const char* injected_fault_name(InjectedFault f);  // the scene file's `kind`

// Every switch a scene can fail: the six safety sensors' first channels, then their second channels
// ("<sensor>_2", in the same order: second channel of sensor i is 6 + i).
enum class Sensor : std::uint8_t {
  kPistonAExtended,
  kPistonARetracted,
  kPistonBExtended,
  kPistonBRetracted,
  kShuttleLeft,
  kShuttleRight,
  kPistonAExtended2,
  kPistonARetracted2,
  kPistonBExtended2,
  kPistonBRetracted2,
  kShuttleLeft2,
  kShuttleRight2
};
inline constexpr int kSensorCount = 12;
const char* sensor_name(Sensor s);

enum class LoadCellMode : std::uint8_t { kNan, kLost };
const char* load_cell_mode_name(LoadCellMode m);

// The heartbeat consumer time of the simulated nodes: a silent node is reported lost this long after it
// fell silent (its feedback is stale well before).
inline constexpr double kSimHeartbeatTimeoutS = 0.15;
inline constexpr std::uint16_t kEmcyHeartbeat = 0x8130;  // CiA 301 life guard / heartbeat error
inline constexpr std::uint16_t kEmcyBusOff = 0x8140;     // CiA 301 recovered from bus-off (bus-off)

struct FaultInjection {
  double at_s = 0.0;  // virtual time from start
  InjectedFault kind = InjectedFault::kDriveFault;
  // Drive faults, heartbeat loss, EMCY, encoder glitch: the axis by its machine name, and its slot
  // (the core axes' at parse time; others once the scene is checked against the loom's axes).
  std::string axis_name = "beat_crank";
  std::size_t axis = 0;
  std::uint16_t code = 0x8611;            // EMCY code reported (default: following error)
  int piston = 0;                         // stuck piston: 0 = A, 1 = B
  Sensor sensor = Sensor::kShuttleRight;  // stuck / intermittent sensor
  bool stuck_value = false;
  double duration_s = 0.0;   // intermittent sensor, frame loss, latency (0: for ever)
  double probability = 1.0;  // frame loss
  double latency_s = 0.0;    // CAN latency
  double jump = 0.0;         // encoder glitch, SI (m or rad)
  int ticks = 1;             // encoder glitch, loop stall
  LoadCellMode load_cell = LoadCellMode::kNan;
  hal::Tick at_tick = -1;  // power cut: the tick it strikes (at_s is ignored)
  int head = 0;            // selector jam, yarn out: 0-based head
  int slot = 0;            // yarn out: magazine slot
};

// Physical facts of the simulated machine that are not effects (they come from the loom config).
// How a simulated axis' reading is referenced to the machine. An absolute encoder reads the machine's
// position from power-up. A homed axis (incremental encoder) powers up at a random count and is
// referenced by a homing run (hal::AxisRequest::kHome), by CiA 402 method: 19 / 21 the edge of a home
// switch whose active region lies on the positive / negative side, 33 / 34 the next index pulse in the
// negative / positive direction (one per motor revolution), 37 where it stands. The home switch and the
// index pulses sit where the machine's own coordinate reads `home_offset` (+ whole pitches), so a
// correctly homed axis reads the machine position again.
struct SimReferencing {
  int method = 0;            // 0 = absolute encoder
  double home_offset = 0.0;  // reading at the home point once homed (SI)
  double speed = 0.0;        // homing speed (SI/s)
  double index_pitch = 0.0;  // axis travel per index pulse (2 pi rad, or a linear axis' lead)
};

struct SimMachine {
  double period_s = 0.002;
  std::size_t axis_count = hal::kCoreAxisCount;             // the machine's axes (hal::AxisLayout::count)
  std::array<SimReferencing, hal::kMaxAxes> referencing{};  // per axis; default absolute
  double width_m = 1.2;
  double beater_width_m = 0.10;  // the comb (warp_tension: where across the width it beats)
  double carriage_home_m = 0.0;  // carriage axis reading at the left selvedge
  double helix_lead_m = 0.10;
  double piston_travel_s = 0.25;  // heald frame stroke time with the nominal air supply
  double selvedge_sensor_window_m = 0.005;
  motion::BeatUpGeometry beatup = motion::default_beatup_geometry();
  double crank_park_position_rad = 0.0;  // crank axis reading at the park pose
  // Which safety sensors have a second switch (hal::SafetySensor order): each sees the same truth as the
  // first and fails on its own (its own stuck faults, its own noise).
  std::array<bool, hal::kSafetySensorCount> second_channel{};
  SimKnotting knotting;  // the knotting heads (heads = 0: none)
};

struct SceneSpec {
  std::string name = "default";
  std::uint64_t seed = 1;
  std::vector<std::string> effects{kEffectIdeal};  // in the order named
  std::optional<ServoLag> servo_lag;               // each present iff its effect is named
  std::optional<Pneumatics> pneumatics;
  std::optional<ShuttleSlip> shuttle_slip;
  std::optional<SensorNoise> sensor_noise;
  std::optional<BeatContact> beat_contact;
  std::optional<Inertia> inertia;
  std::optional<JointFriction> joint_friction;
  std::optional<Knotter> knotter;
  std::optional<WarpTension> warp_tension;
  std::vector<FaultInjection> faults;
};

}  // namespace loom::sim_hal

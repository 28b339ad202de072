// The loom's configuration: one machine description, parsed and checked before anything starts.
//
// The file has three kinds of facts, each stated once:
//   - the physical MACHINE ([loom], [beatup], [carriage], [helix], [shedding], [can]): geometry,
//     width, limits, drive scaling, node ids, calibration; changes only with a restart;
//   - the RECIPE ([recipe], [profiles]): speeds or force target, crank law, picks per row, beats per
//     position, overlap, table settings; may be swapped between rows (SIGHUP);
//   - RUN settings ([timing], [telemetry]): period, timeouts, debouncing, telemetry.
// One derivation (derive_module_configs) turns them into every module's own config (the profile
// spec, the sequencer's, the simulator's, the CAN master's); each module's own validation runs at
// parse time, so every refusal is one ConfigError naming file:line:col, key and value.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "loom/config/scene_config.hpp"  // the scene file (kept here so callers of config.hpp see it)
#include "loom/design/design.hpp"
#include "loom/drivers/can_axis_config.hpp"
#include "loom/drivers/can_io_config.hpp"
#include "loom/motion/knot_cycle.hpp"
#include "loom/motion/profile_set.hpp"
#include "loom/sequencer/knot_plan.hpp"
#include "loom/sequencer/knot_program.hpp"
#include "loom/sequencer/sequencer.hpp"
#include "loom/sim_hal/scene.hpp"

namespace loom::firmware {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// ---- machine (restart only) ------------------------------------------------------------------------
struct CanSettings {
  std::uint32_t bitrate = 1'000'000;
  double bus_load_budget = 0.7;
  std::uint16_t heartbeat_ms = 100;
  std::uint16_t heartbeat_timeout_ms = 250;
  std::uint16_t sdo_timeout_ms = 500;
  // The master's own heartbeat (0x700 + master_node) and the consumer time written to every node's
  // 0x1016 (drives and I/O module, where present). master_node = 0: neither.
  std::uint8_t master_node = 0x7F;
  std::uint16_t master_heartbeat_ms = 100;
  std::uint16_t master_consumer_ms = 500;
};

// One servo axis of the machine, a table [axes.<name>]: what it is for, which drive moves it and how
// that drive's counts map to SI. Every loom has the three core axes (roles beat_crank, carriage,
// helix); a machine adds its own (knotting servos, colour selectors, auxiliaries) up to hal::kMaxAxes.
struct AxisSpec {
  std::string name;
  hal::AxisRole role = hal::AxisRole::kAuxiliary;
  std::uint8_t node = 0;  // CANopen node id of its drive
  std::uint8_t bus = 0;   // which CAN bus its drive is on: 0 = the first --iface, 1 = the second, ...
  double counts_per_rev = 1048576.0;  // encoder counts per motor revolution
  double lead_m = 0.0;                // linear axes: travel per motor revolution (m); rotary axes: 0
  // Added axes' top speed (rad/s or m/s; bounds the plausible feedback step). The core axes' limits are
  // facts of their mechanisms ([beatup] via the recipe, [carriage], [helix]) and are not repeated here.
  // With a drive, the drive's no-load speed at the output unless the file caps it lower (max_speed_set).
  double max_speed = 0.0;
  bool max_speed_set = false;
  // The drive model that moves it (a [drives.<model>] table), "" = none described.
  std::string drive{};
  // Following-error supervision (LinuxCNC rule): fault when |commanded − actual| >
  // max(ferror_min, ferror_k_s · |commanded velocity|); rad or m, and s. ferror_min = 0 turns it off.
  double ferror_min = 0.0;
  double ferror_k_s = 0.05;
  // Bring-up windows of its drive; 0 = 2000 ms to boot, can.heartbeat_timeout_ms to go operational.
  std::uint32_t boot_ms = 0;
  std::uint32_t operational_ms = 0;
  // Referencing: "absolute" (the encoder reads the machine position from power-up; commissioning
  // captures the references once) or "homing" (an incremental encoder: a CiA 402 homing run after every
  // power-up of the drive, before the axis may move in production).
  bool homing = false;
  int homing_method = 0;      // 19 / 21 home switch (positive / negative side), 33 / 34 index pulse, 37 here
  double home_offset = 0.0;   // the reading at the home point (0x607C), SI
  double homing_speed = 0.0;  // SI/s (0x6099)
  double homing_accel = 0.0;  // SI/s^2 (0x609A)
  double homing_timeout_s = 0.0;  // a run not referenced by then is the fault homing_failed
  // The drive's electronic data sheet (CiA 306 EDS or DCF), axes.<name>.eds: its path (a relative one in
  // the file is relative to the file); "" = none (the loom assumes a drive with every object it needs).
  std::string eds{};
  // axes.<name>.store_config: after a bring-up that wrote anything, the master makes the drive store it
  // (0x1010:01 = "save"); needs an EDS with a writable 0x1010:01.
  bool store_config = false;
  // axes.<name>.drive_mode: "cyclic" (CiA 402 cyclic synchronous position: a set-point every SYNC) or
  // "profile" (profile position: one set-point per move, event-driven PDOs; the colour selectors only).
  bool profile_position = false;

  // Drive counts per SI unit (per rad, or per m on a linear axis).
  double counts_per_unit() const;
};

// The default loom's three axes, as firmware/config/default_loom.toml states them (a test holds the two
// equal): 20-bit encoders, the carriage on a toothed belt, 20 mm of travel per motor turn.
inline std::vector<AxisSpec> default_axes() {
  return {
      {.name = "beat_crank",
       .role = hal::AxisRole::kBeatCrank,
       .node = 1,
       .drive = "servo_400w_10to1",
       .ferror_min = 0.2},
      {.name = "carriage",
       .role = hal::AxisRole::kCarriage,
       .node = 2,
       .lead_m = 0.020,
       .drive = "servo_400w_belt",
       .ferror_min = 0.002},
      {.name = "helix",
       .role = hal::AxisRole::kHelix,
       .node = 3,
       .drive = "servo_200w_5to1",
       .ferror_min = 0.5},
  };
}

// A servo drive as it is sold, a table [drives.<model>]: the motor and its gearbox (see
// motion::ServoDrive for what it gives at the output). Axes name it by `drive`.
struct DriveModel {
  std::string name;
  motion::ServoDrive drive{};
};

// The default loom's drives, by name, as firmware/config/default_loom.toml states them (a test holds the
// two equal; the comments above its tables say where the figures come from): the knotting heads' servo and
// the core axes' (the beat crank's, the carriage's on its belt, the helix').
inline std::vector<DriveModel> default_drives() {
  constexpr double kRpm = 2.0 * 3.14159265358979323846 / 60.0;
  return {
      {"servo_100w_10to1", motion::shipped_knotter_drive()},
      {"servo_200w_5to1", {6000 * kRpm, 0.64, 1.91, 0.14e-4, 5.0, 0.07e-4, 0.95}},
      {"servo_400w_10to1", {6000 * kRpm, 1.27, 3.8, 0.27e-4, 10.0, 0.07e-4, 0.95}},
      {"servo_400w_belt", {6000 * kRpm, 1.27, 3.8, 0.27e-4, 5.0, 0.073e-4, 0.93}},
  };
}

// Where the valves, sensors, e-stop chain, buttons and load cell come from on the CAN HAL.
enum class IoKind { kCan, kSimulated };

// A further CiA 401 module, a table [io_modules.<name>]: its node on its bus, and the signals moved onto
// it from the [io] table's module (their bits and polarities stay io.<signal>_bit / _active_low).
struct IoModuleSpec {
  std::string name;
  std::uint8_t node = 0;
  std::uint8_t bus = 0;
  std::uint32_t boot_timeout_ms = 2000;
  std::uint32_t operational_timeout_ms = 500;
  std::vector<std::string> signals;  // io signal names as the file lists them ("lamp_green", "cutter", ...)
  std::string eds{};                 // io_modules.<name>.eds: the module's EDS path ("" = none)
  bool store_config = false;         // io_modules.<name>.store_config: as IoSettings::store_config
  int input_group_bits = 0;          // io_modules.<name>.input_group_bits: as IoSettings's
};

struct IoSettings {
  IoKind kind = IoKind::kCan;  // simulated I/O beside real drives needs --io simulated as well
  // The [io] table's module (module 0, always on bus 0). Every signal is on it unless a further module
  // in `modules` lists it (module k + 1 is modules[k]; the signal's IoBit::module says which).
  std::uint8_t node = 4;
  std::string eds{};  // io.eds: the [io] module's EDS path ("" = none)
  // io.store_config: the module stores its configuration (0x1010:01 = "save") after a bring-up that wrote
  // anything; needs an EDS with a writable 0x1010:01.
  bool store_config = false;
  // io.input_group_bits: the digital inputs as 8-bit (0x6000) or 16-bit (0x6100) groups; 0 = from the
  // module's EDS (8-bit groups when it has them all, else 16-bit), 8 without an EDS.
  int input_group_bits = 0;
  std::uint32_t boot_timeout_ms = 2000;
  std::uint32_t operational_timeout_ms = 500;
  drivers::IoWiring wiring;  // bit per signal, polarity, load-cell channel and scaling
  // The knotting heads' signals on the same module, head 1 first (used when knotting.mode = "heads": one
  // bit per head, knotting.heads of them; the wiring above gets them then, see can_io_config()).
  struct HeadSignals {
    std::vector<int> bits;
    bool active_low = false;
    std::uint8_t module = 0;  // every head's signal of this kind is on one module
  };
  HeadSignals gripper_close{{8, 9, 10, 11, 12, 13}};
  HeadSignals cutter{{20, 21, 22, 23, 24, 25}};
  HeadSignals yarn_present{{24, 25, 26, 27, 28, 29}};
  std::vector<IoModuleSpec> modules;  // [io_modules.<name>], by name; at most drivers::kMaxIoModules - 1
};

// Axis readings at the mechanical references, found when commissioning.
struct Calibration {
  double crank_park_position_rad = 0.0;  // crank axis reading at the park pose
  double carriage_home_m = 0.0;          // carriage axis reading at the left selvedge
  double helix_left_position_rad = 0.0;  // helix axis reading with the carrier at the left selvedge
};

struct MachineSpec {
  double width_m = 1.2;
  motion::BeatUpGeometry beatup = motion::default_beatup_geometry();
  double beater_mass_kg = 2.5;
  double beater_width_m = 0.10;
  double carriage_max_speed_m_s = 1.0, carriage_max_accel_m_s2 = 20.0, carriage_max_jerk_m_s3 = 2000.0;
  double carriage_reposition_jerk_m_s3 = 100.0;  // re-arm moves
  double carriage_mass_kg = 20.0;  // what the carriage's drive moves besides itself: the heads it carries
  double helix_lead_m = 0.10;
  motion::JerkLimits helix{.velocity = 60.0, .acceleration = 3000.0, .jerk = 2.0e5};
  double carrier_force_n = 20.0;
  double shuttle_mass_kg = 0.40;
  motion::ShedSpec shed{};  // piston stroke time and the end sensors' confirmation windows
  Calibration calibration;
};

// ---- recipe (adopted at a row boundary) -----------------------------------------------------------
struct Recipe {
  double beat_force_target_n = 90.0;  // > 0: the crank speed follows from the linkage's dynamics
  double crank_speed_rad_s = 0.0;     // > 0: fixed crank speed instead of a force target
  double crank_accel_rad_s2 = 400.0, crank_jerk_rad_s3 = 2.0e4;
  motion::CrankLawSpec crank_law{};
  std::uint32_t picks_per_row = 1;
  // The carpet's knot map, shown to the weaver row by row: the file as written (relative to the config
  // file's folder) and what was loaded from it (null when the recipe names none).
  std::string design_file;
  std::shared_ptr<const design::Design> design;
  // Knotting heads and no design here: a carpet job brings one (loomctl job add). Without a job too, arming
  // is refused with this, at knotting.mode's line ("" when the recipe has a design or the loom no heads).
  std::string design_missing;
  int beats_per_position = 1;
  double overlap_m = 0.02;
  double cam_margin_rad = 20.0 * 3.141592653589793 / 180.0;   // cam_margin_deg = 20
  double beat_force_min_n = 80.0, beat_force_max_n = 100.0;   // the band every beat must hit
  std::size_t table_size = motion::ProfileSpec{}.table_size;  // one default, motion's
  motion::Interp table_interp = motion::Interp::kCubic;
  motion::Precision table_precision = motion::Precision::kDouble;
  double max_table_error_rad = 1e-7;
};

// ---- run settings (restart only) ------------------------------------------------------------------
struct RunSettings {
  double period_s = 0.002;
  double enable_timeout_s = 2.0;
  double pick_timeout_margin_s = 0.5;
  double stale_timeout_s = 0.05;
  double row_save_timeout_s = 5.0;  // a finished row's counters not confirmed on disk by then: a fault
  int debounce_ticks = 3;
  double sensor_discrepancy_s = 0.02;     // the two channels of a safety sensor may disagree this long
  std::uint32_t overrun_stop_after = 10;  // on hardware: this many overruns in a row → safe stop (0 = never)
};

struct TelemetrySettings {
  std::string lcm_url;
  std::uint32_t status_every = 50, axes_every = 10, rt_every = 500;
};

// The loop's timing, derived once from timing.period_ms (and the CAN heartbeat) for everything that
// runs at it: the control loop's and the session's clocks take the period in nanoseconds from here.
struct LoopTiming {
  double period_s = 0.002;
  std::int64_t period_ns = 2'000'000;  // period_s rounded to the nanosecond
  // On CAN, how long the sequencer waits after stale PDOs for the heartbeat loss that names the root
  // cause: the heartbeat time-out and ten periods.
  double can_diagnosis_window_s = 0.27;
};

struct LoomConfig {
  std::string source = "<embedded default>";  // where it came from, for messages
  // What the file says, each fact once.
  std::string loom_id = "loom1";
  MachineSpec machine_spec;
  // The axes in slot order (hal::AxisLayout): beat crank, carriage, helix, then the others by name.
  std::vector<AxisSpec> axes = default_axes();
  // The servo drives the axes name, by model (toml++ order: by name): default_drives().
  std::vector<DriveModel> drives = default_drives();
  // The pile: none (a flat weave), knotted by the weaver while the loom waits, or by the heads.
  sequencer::KnottingSpec knotting;
  // The knotting servo's cycle through seed 001's linkage: its precision points, dimensions, masses and the
  // dwells ([knotting.linkage], [knotting]); its servo fields derived from the knotter axes' drives.
  motion::KnotCycleSpec knot_cycle = motion::seed001_knot_cycle_spec();
  CanSettings can;
  IoSettings io;
  Recipe recipe;
  RunSettings run;
  TelemetrySettings telemetry;

  // Derived by derive_module_configs() from the facts above; never edited by hand.
  double beat_force_target_n = 0.0;  // > 0 when the crank speed was derived from a beat-force target
  LoopTiming timing;
  motion::ProfileSpec profile;
  sequencer::SequencerConfig sequencer;
  sim_hal::SimMachine machine;
};

// Configure-time only. Fill every module's config from the machine, recipe and run settings (throws
// ConfigError naming `source` when the recipe's force target cannot be met). Call again after
// changing a fact (e.g. a --period-ms override).
void derive_module_configs(LoomConfig& c);
// Configure-time only. After a command-line override of a fact (`origin` names it, e.g.
// "--period-ms = 4"): derive again and run every module's validation, as parsing does.
void rederive_and_check(LoomConfig& c, const std::string& origin);
// The machine's axes as the runtime sees them (names and roles in slot order).
hal::AxisLayout axis_layout(const LoomConfig& c);
// Configure-time only. The recipe's design as the knotting heads tie it (`c.recipe.design` must be set):
// `design_rows_done` of its rows woven by production row `counter_rows`. Throws std::invalid_argument naming
// the design row, colour and knot when the loom's magazines or width cannot tie it.
sequencer::KnotProgram knot_program(const LoomConfig& c, std::uint64_t design_rows_done,
                                    std::uint32_t counter_rows);
// Configure-time only. The CAN master's config for the machine's servo axes, from the same facts.
drivers::CanAxisPortConfig can_axis_config(const LoomConfig& c);
// Configure-time only. The CAN I/O modules' configs, from the same facts: the [io] table's module first,
// then [io_modules.<name>] in file order of names; each with the loom's whole wiring and its module index.
std::vector<drivers::CanIoConfig> can_io_configs(const LoomConfig& c);
// Configure-time only. The bus of each I/O module, in can_io_configs() order.
std::vector<std::size_t> can_io_buses(const LoomConfig& c);
// Configure-time only. The worst-case load of CAN bus `bus` (its drives and I/O modules; the master
// heartbeat) — the figure that bus' CAN master checks when it configures. The machine uses
// drivers::bus_count(can_axis_config(c)) buses.
drivers::BusLoad can_bus_load(const LoomConfig& c, std::size_t bus = 0);

// Configure-time only. Parse a loom config from TOML text; `source` names it in errors. The file must
// be complete, or start with `extends = "default"` to take what it does not say from the embedded
// default loom.
LoomConfig parse_loom_config(const std::string& text, const std::string& source);
// Configure-time only. Read and parse a file (ConfigError if it cannot be read or is not a regular
// file of reasonable size).
LoomConfig load_loom_config(const std::string& path);
LoomConfig default_loom_config();

// Configure-time only. The keys a recipe reload changed that only a restart may change ("" if none):
// `next` may differ from `running` in its [recipe] and [profiles] sections only.
std::string restart_only_changes(const LoomConfig& running, const LoomConfig& next);

// Every config key with its class (machine / recipe / run), unit range and meaning, in file order;
// for `loomctl check` and the README.
struct KeyInfo {
  const char* path;
  const char* klass;  // "machine", "recipe" or "run"
  std::string range;
};
std::vector<KeyInfo> config_keys();

// The embedded default loom (generated at build time from firmware/config/default_loom.toml).
extern const char* const kDefaultLoomToml;

}  // namespace loom::firmware

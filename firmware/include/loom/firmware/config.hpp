// The loom's configuration file and the simulation scene file, parsed and checked before anything
// starts. Any bad value is one ConfigError whose message names file, line, column, field and value.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "loom/drivers/can_io_port.hpp"
#include "loom/motion/profile_set.hpp"
#include "loom/sequencer/sequencer.hpp"
#include "loom/sim_hal/scene.hpp"

namespace loom::firmware {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CanSettings {
  std::uint32_t bitrate = 1'000'000;
  double bus_load_budget = 0.7;
  std::uint8_t node_beat_crank = 1, node_carriage = 2, node_helix = 3;
  double counts_per_rev = 1048576.0;
  double carriage_counts_per_m = 1.0e6;
  std::uint16_t heartbeat_ms = 100;
  std::uint16_t heartbeat_timeout_ms = 250;
  std::uint16_t sdo_timeout_ms = 500;
  // The master's own heartbeat (0x700 + master_node) and the consumer time written to every node's
  // 0x1016 (drives and I/O module, where present). master_node = 0: neither.
  std::uint8_t master_node = 0x7F;
  std::uint16_t master_heartbeat_ms = 100;
  std::uint16_t master_consumer_ms = 500;
  // Per-drive bring-up windows, indexed beat_crank, carriage, helix; 0 = boot 2000 ms / operational
  // = heartbeat_timeout_ms. Commercial drives may need hundreds of ms for either.
  std::array<std::uint32_t, 3> boot_timeout_ms{0, 0, 0};
  std::array<std::uint32_t, 3> operational_timeout_ms{0, 0, 0};
  // Following-error supervision per axis (LinuxCNC rule): fault when |commanded − actual| >
  // max(ferror_min, ferror_k_s · |commanded velocity|). Units: rad (crank, helix) or m (carriage); s.
  // ferror_min = 0 disables it for that axis.
  // Defaults allow 0.1 s of lag at any speed (a CSP drive lags 1–2 cycles; a loaded VM many more).
  std::array<double, 3> ferror_min{0.3, 0.005, 1.0};
  std::array<double, 3> ferror_k_s{0.1, 0.1, 0.1};
};

// Where the valves, sensors, e-stop chain, buttons and load cell come from on the CAN HAL.
enum class IoKind { kCan, kSimulated };

struct IoSettings {
  IoKind kind = IoKind::kCan;  // simulated I/O beside real drives needs --io simulated as well
  std::uint8_t node = 4;
  std::uint32_t boot_timeout_ms = 2000;
  std::uint32_t operational_timeout_ms = 500;
  drivers::IoWiring wiring;  // bit per signal, polarity, load-cell channel and scaling
};

struct TelemetrySettings {
  std::string lcm_url;
  std::uint32_t status_every = 50, axes_every = 10, rt_every = 500;
};

struct LoomConfig {
  std::string source = "<embedded default>";  // where it came from, for messages
  std::string loom_id = "loom1";
  double beat_force_target_n = 0.0;  // > 0 when the crank speed was derived from a beat-force target
  motion::ProfileSpec profile;
  sequencer::SequencerConfig sequencer;
  sim_hal::SimMachine machine;
  CanSettings can;
  IoSettings io;
  TelemetrySettings telemetry;
};

struct Scene {
  std::string source = "<embedded default scene>";
  sim_hal::SceneSpec spec;
  std::string config_path;  // loom config named by the scene ("" = embedded default)
};

// Configure-time only. Parse a loom config from TOML text; `source` names it in errors.
LoomConfig parse_loom_config(const std::string& text, const std::string& source);
// Configure-time only. Read and parse a file (ConfigError if it cannot be read).
LoomConfig load_loom_config(const std::string& path);
LoomConfig default_loom_config();

Scene parse_scene(const std::string& text, const std::string& source);
Scene load_scene(const std::string& path);
Scene default_scene();

// The embedded defaults (generated at build time from firmware/config and sim_hal/scenes).
extern const char* const kDefaultLoomToml;
extern const char* const kDefaultSceneToml;

}  // namespace loom::firmware

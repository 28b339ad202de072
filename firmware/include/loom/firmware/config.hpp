// The loom's configuration file and the simulation scene file, parsed and checked before anything
// starts. Any bad value is one ConfigError whose message names file, line, column, field and value.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include "loom/motion/profile_set.hpp"
#include "loom/sequencer/sequencer.hpp"
#include "loom/firmware/scene_config.hpp"  // the scene file (kept here so callers of config.hpp see it)
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
  TelemetrySettings telemetry;
};

// Configure-time only. Parse a loom config from TOML text; `source` names it in errors.
LoomConfig parse_loom_config(const std::string& text, const std::string& source);
// Configure-time only. Read and parse a file (ConfigError if it cannot be read).
LoomConfig load_loom_config(const std::string& path);
LoomConfig default_loom_config();

// The embedded defaults (generated at build time from firmware/config and sim_hal/scenes).
extern const char* const kDefaultLoomToml;

}  // namespace loom::firmware

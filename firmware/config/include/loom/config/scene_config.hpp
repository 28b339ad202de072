// The simulation scene file: which effects to simulate, their parameters, the faults to inject and the
// seed. Read as strictly as the loom config: every bad value is one ConfigError naming file:line:col,
// key and value (loomctl exits 2) — non-finite or negative times, a fault kind without the fields it
// needs or with fields it does not use, duplicated effects or faults, parameters of an effect the
// scene does not name. Configure-time only.
#pragma once

#include <string>
#include <vector>

#include "loom/sim_hal/scene.hpp"

namespace loom::firmware {

struct Scene {
  std::string source = "<embedded default scene>";
  sim_hal::SceneSpec spec;
  std::string config_path;               // loom config named by the scene ("" = embedded default)
  std::vector<std::string> fault_where;  // "file:line:col" of each [[fault]] (spec.faults order)
};

struct LoomConfig;
// Configure-time. A scene is written for a machine: the scene as it runs on `cfg`'s loom, each fault's
// axis resolved to its slot by name. Faults on axes the loom does not have, or injected into switches it
// does not have (a second channel its wiring leaves at -1), are refused, naming the fault's
// file:line:col. Throws ConfigError.
// `simulated_io`: the loom's I/O is the simulator's (a loom with knotting heads then needs the scene's
// "knotter"); false when a real I/O module carries the heads' signals.
Scene check_scene_fits(Scene scene, const LoomConfig& cfg, bool simulated_io = true);

// Parse a scene from TOML text; `source` names it in errors. Throws ConfigError.
Scene parse_scene(const std::string& text, const std::string& source);
// Read and parse a scene file (ConfigError if it cannot be read).
Scene load_scene(const std::string& path);
Scene default_scene();

// The scene as a scene file that parse_scene reads back to the same SceneSpec (loom-safety writes
// each violating run this way, so `loomctl weave --scene FILE` replays it). `config` is written as the
// scene's loom config when not empty.
std::string scene_to_toml(const sim_hal::SceneSpec& spec, const std::string& config = "");

// The embedded default scene (generated at build time from sim_hal/scenes/default.toml).
extern const char* const kDefaultSceneToml;

}  // namespace loom::firmware

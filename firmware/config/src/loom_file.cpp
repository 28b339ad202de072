// Reading a loom file: the key table in file order, the axes and I/O modules, the cross-field checks,
// the one derivation and each module's own validation; a recipe's restart-only changes; the key list.
#include <algorithm>
#include <string>
#include <vector>

#include "axes.hpp"
#include "checks.hpp"
#include "derive.hpp"
#include "drives.hpp"
#include "eds_keys.hpp"
#include "io_modules_config.hpp"
#include "keys.hpp"
#include "loom/config/config.hpp"
#include "loom/config/toml_reader.hpp"

namespace loom::firmware {

using namespace detail;

namespace {

// "a|b|c" -> {a, b, c}; never empty.
std::vector<std::string> split_bars(const std::string& s) {
  std::vector<std::string> parts;
  for (std::size_t from = 0;;) {
    const std::size_t bar = s.find('|', from);
    parts.push_back(s.substr(from, bar == std::string::npos ? bar : bar - from));
    if (bar == std::string::npos) return parts;
    from = bar + 1;
  }
}

LoomConfig parse_complete(const std::string& text, const std::string& source, const LoomConfig* base) {
  TomlReader r(text, source);
  r.consume("extends");
  LoomConfig c = base ? *base : LoomConfig{};
  c.source = source;
  const auto present = [&](const std::string& path) { return r.root().at_path(path).node() != nullptr; };
  for (const Key& k : keys()) {
    if (present(k.path)) {
      k.read(r, c);
    } else {
      r.consume(k.path);
      if (!base && k.required) {
        r.fail_missing(k.path,
                       "missing: a config file must be complete, or begin with extends = \"default\" to take "
                       "what it does not say from the embedded default loom");
      }
    }
  }
  // The crank speed is given, or follows from a beat-force target: exactly one of the two.
  const bool speed = present("recipe.crank_speed_rad_s"), force = present("recipe.beat_force_target_n");
  if (speed && force) {
    r.fail("recipe.crank_speed_rad_s", fmt_num(c.recipe.crank_speed_rad_s),
           "give either beat_force_target_n or crank_speed_rad_s, not both");
  }
  if (speed) c.recipe.beat_force_target_n = 0.0;
  if (force) c.recipe.crank_speed_rad_s = 0.0;
  if (!speed && !force && !base) {
    r.fail_missing("recipe.beat_force_target_n",
                   "missing: give beat_force_target_n (N) or crank_speed_rad_s (rad/s)");
  }
  refuse_moved_keys(r);
  read_drives(r, c);
  read_axes(r, c, base != nullptr);
  check_axis_drives(r, c);
  read_io_modules(r, c);
  r.reject_unknown(known_sections());
  check_relations(r, c);
  if (c.knotting.mode == sequencer::KnottingMode::kHeads && !c.recipe.design) {
    // Not refused here: a carpet job brings the design (the queue is read when the loom arms). Said at the
    // mode's line when the loom arms with neither (issue 30: said without a line, it was no help).
    c.recipe.design_missing = r.message(
        "knotting.mode", "heads",
        "the heads tie a design's knots: set recipe.design to its knot map (loomctl design fit makes "
        "one from a picture), or give the loom a carpet job (loomctl job add DESIGN, then weave or "
        "serve with that --state-dir)");
  }
  check_eds_keys(r, c);
  // `key` may name several facts that clash ("axes.helix.node|can.master_node", values likewise; a value
  // list shorter than the keys repeats its last): the first the file says is the line to point at.
  const Fail fail = [&](const std::string& key, const std::string& value, const std::string& why) {
    const std::vector<std::string> keys = split_bars(key), values = split_bars(value);
    for (std::size_t i = 0; i < keys.size(); ++i) {
      if (present(keys[i])) r.fail(keys[i], values[std::min(i, values.size() - 1)], why);
    }
    throw ConfigError(source + ": " + keys[0] + " = " + values[0] + " (from the embedded default): " + why);
  };
  derive(c, fail);
  check_can(c, fail);
  check_motion(c, fail);
  check_beat_resolution(c, fail);
  return c;
}

}  // namespace

void rederive_and_check(LoomConfig& c, const std::string& origin) {
  const Fail fail = [&](const std::string& key, const std::string& value, const std::string& why) {
    throw ConfigError(origin + ": with it, " + key + " = " + value + ": " + why);
  };
  if (c.run.stale_timeout_s < 2.0 * c.run.period_s) {
    fail("timing.stale_timeout_ms", fmt_num(c.run.stale_timeout_s * 1e3), "must be at least two periods");
  }
  derive(c, fail);
  check_can(c, fail);
  check_motion(c, fail);
  check_beat_resolution(c, fail);
}

LoomConfig parse_loom_config(const std::string& text, const std::string& source) {
  // `extends` is read before anything else: it decides whether missing keys are errors.
  const TomlReader probe(text, source);
  if (const toml::node* ext = probe.root().get("extends")) {
    const auto name = ext->value<std::string>();
    if (!name || *name != "default") {
      probe.fail("extends", name ? '"' + *name + '"' : "?",
                 "only \"default\" (the embedded default loom) can be extended");
    }
    static const LoomConfig base = parse_complete(kDefaultLoomToml, "<embedded default_loom.toml>", nullptr);
    return parse_complete(text, source, &base);
  }
  return parse_complete(text, source, nullptr);
}

LoomConfig load_loom_config(const std::string& path) {
  return parse_loom_config(read_config_file(path), path);
}

LoomConfig default_loom_config() {
  return parse_loom_config(kDefaultLoomToml, "<embedded default_loom.toml>");
}

std::string restart_only_changes(const LoomConfig& running, const LoomConfig& next) {
  std::string out;
  for (const Key& k : keys()) {
    if (k.klass == Klass::kRecipe) continue;
    const std::string a = k.value(running), b = k.value(next);
    if (a != b) out += (out.empty() ? "" : ", ") + k.path + " " + a + " -> " + b;
  }
  if (const std::string a = axes_text(running), b = axes_text(next); a != b) {
    out += (out.empty() ? "" : ", ") + std::string("axes ") + a + " -> " + b;
  }
  if (const std::string a = drives_text(running), b = drives_text(next); a != b) {
    out += (out.empty() ? "" : ", ") + std::string("drives ") + a + " -> " + b;
  }
  if (const std::string a = io_modules_text(running), b = io_modules_text(next); a != b) {
    out += (out.empty() ? "" : ", ") + std::string("io_modules ") + a + " -> " + b;
  }
  return out;
}

std::vector<KeyInfo> config_keys() {
  std::vector<KeyInfo> out;
  for (const Key& k : keys()) {
    out.push_back({k.path.c_str(), klass_name(k.klass), k.range});
    if (k.path == "can.master_consumer_ms") {
      for (const AxisKeyInfo& a : axis_keys()) out.push_back({a.path, "machine", a.range});
      for (const DriveKeyInfo& d : drive_keys()) out.push_back({d.path, "machine", d.range});
    }
    if (k.path == "io.yarn_present_active_low") {
      for (const IoModuleKeyInfo& m : io_module_keys()) out.push_back({m.path, "machine", m.range});
    }
  }
  return out;
}

}  // namespace loom::firmware

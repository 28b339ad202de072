// Scene file parsing and writing. Each [[fault]] is read against the fields its kind needs: a missing
// field is an error at the fault, a field the kind does not use is an error at that field (it would
// silently do nothing), and times must be finite — `at_s = nan` would otherwise never strike and hide
// every later fault.
#include "loom/config/scene_config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "loom/config/config.hpp"
#include "loom/config/toml_reader.hpp"

namespace loom::firmware {
namespace {

constexpr double kMaxSceneTimeS = 1e7;  // about four months of machine time

std::string read_text(const std::string& path) {
  return read_config_file(path);
}

std::string shown(const toml::node& n) {
  std::ostringstream os;
  if (const auto s = n.value<std::string>()) {
    os << '"' << *s << '"';
  } else if (n.is_table()) {
    os << "{...}";
  } else if (n.is_array()) {
    os << "[...]";
  } else {
    n.visit([&](auto&& v) {
      if constexpr (toml::is_value<decltype(v)>) os << v.get();
    });
  }
  return os.str();
}

using sim_hal::InjectedFault;

// The fields each fault kind needs (beyond `kind` and its time) and may take.
struct KindFields {
  std::set<std::string> required, optional;
};
const std::map<InjectedFault, KindFields>& kind_fields() {
  static const std::map<InjectedFault, KindFields> m{
      {InjectedFault::kDriveFault, {{"axis"}, {"code"}}},
      {InjectedFault::kEStop, {{}, {}}},
      {InjectedFault::kStuckPiston, {{"piston"}, {}}},
      {InjectedFault::kStuckSensor, {{"sensor", "value"}, {}}},
      {InjectedFault::kIntermittentSensor, {{"sensor", "value", "duration_s"}, {}}},
      {InjectedFault::kCanFrameLoss, {{"probability", "duration_s"}, {}}},
      {InjectedFault::kCanLatency, {{"latency_s"}, {"duration_s"}}},
      {InjectedFault::kBusOff, {{}, {}}},
      {InjectedFault::kHeartbeatLoss, {{"axis"}, {}}},
      {InjectedFault::kEmcy, {{"axis", "code"}, {}}},
      {InjectedFault::kEncoderGlitch, {{"axis", "jump"}, {"ticks"}}},
      {InjectedFault::kLoadCellFailure, {{"mode"}, {}}},
      {InjectedFault::kAirLoss, {{}, {}}},
      {InjectedFault::kLoopStall, {{"ticks"}, {}}},
      {InjectedFault::kPowerCut, {{}, {}}},
      {InjectedFault::kSelectorJam, {{"head"}, {}}},
      {InjectedFault::kYarnOut, {{"head", "slot"}, {}}},
      {InjectedFault::kAxisJam, {{"axis"}, {}}},
  };
  return m;
}

std::string kinds_list() {
  std::string list;
  for (int i = 0; i < sim_hal::kInjectedFaultCount; ++i) {
    list +=
        (list.empty() ? "" : ", ") + std::string(sim_hal::injected_fault_name(static_cast<InjectedFault>(i)));
  }
  return list;
}

void read_fault(const TomlReader& r, const toml::table& t, std::size_t n, bool load_cell_fitted,
                sim_hal::FaultInjection& f) {
  const std::string prefix = "fault[" + std::to_string(n) + "].";
  const toml::node* kind_node = t.get("kind");
  if (kind_node == nullptr) {
    r.fail_at(t, prefix + "kind", "(missing)", "every [[fault]] needs a kind (" + kinds_list() + ")");
  }
  const auto kind = kind_node->value<std::string>();
  bool found = false;
  for (int i = 0; i < sim_hal::kInjectedFaultCount && kind; ++i) {
    if (*kind == sim_hal::injected_fault_name(static_cast<InjectedFault>(i))) {
      f.kind = static_cast<InjectedFault>(i);
      found = true;
    }
  }
  if (!found) r.fail_at(*kind_node, prefix + "kind", shown(*kind_node), "must be one of: " + kinds_list());
  const KindFields& fields = kind_fields().at(f.kind);
  const bool power_cut = f.kind == InjectedFault::kPowerCut;
  const std::string when = power_cut ? "at_tick" : "at_s";
  if (t.get(when) == nullptr) {
    r.fail_at(t, prefix + when, "(missing)",
              power_cut ? "a power cut strikes at a tick: give at_tick"
                        : "every fault needs at_s (seconds from start)");
  }
  for (const std::string& k : fields.required) {
    if (t.get(k) == nullptr) r.fail_at(t, prefix + k, "(missing)", "a " + *kind + " fault needs " + k);
  }
  for (const auto& [key, node] : t) {
    // A named reference, not the structured binding: clang before 16 cannot capture bindings in lambdas.
    const toml::node& v = node;
    const std::string k(key.str());
    const std::string field = prefix + k;
    if (k == "kind") continue;
    if (k != when && !fields.required.count(k) && !fields.optional.count(k)) {
      r.fail_at(v, field, shown(v), "not used by a " + *kind + " fault");
    }
    const auto number = [&](double lo, double hi) {
      const auto x = v.value<double>();
      if (!x || !std::isfinite(*x) || *x < lo || *x > hi) {
        std::ostringstream os;
        os << "must be a finite number in [" << lo << ", " << hi << "]";
        r.fail_at(v, field, shown(v), os.str());
      }
      return *x;
    };
    const auto integer = [&](std::int64_t lo, std::int64_t hi) {
      const auto x = v.value_exact<std::int64_t>();
      if (!x || *x < lo || *x > hi) {
        r.fail_at(v, field, shown(v),
                  "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
      }
      return *x;
    };
    const auto text = [&]() {
      const auto x = v.value<std::string>();
      return x ? *x : std::string("\x01");
    };
    if (k == "at_s") {
      f.at_s = number(0.0, kMaxSceneTimeS);
    } else if (k == "at_tick") {
      f.at_tick = integer(0, INT64_C(1) << 40);
    } else if (k == "piston") {
      const std::string x = text();
      if (x != "a" && x != "b") r.fail_at(v, field, shown(v), "must be \"a\" or \"b\"");
      f.piston = x == "a" ? 0 : 1;
    } else if (k == "sensor") {
      const std::string x = text();
      bool known = false;
      for (int i = 0; i < sim_hal::kSensorCount; ++i) {
        if (x == sim_hal::sensor_name(static_cast<sim_hal::Sensor>(i))) {
          f.sensor = static_cast<sim_hal::Sensor>(i);
          known = true;
        }
      }
      if (!known) {
        std::string names;
        for (int i = 0; i < sim_hal::kSensorCount; ++i) {
          names += std::string(i == 0 ? "" : ", ") + sim_hal::sensor_name(static_cast<sim_hal::Sensor>(i));
        }
        r.fail_at(v, field, shown(v), "must be a sensor: " + names);
      }
    } else if (k == "value") {
      const auto x = v.value<bool>();
      if (!x || !v.is_boolean()) r.fail_at(v, field, shown(v), "must be true or false");
      f.stuck_value = *x;
    } else if (k == "axis") {
      // Any axis of the machine by its name ([axes.<name>]); the core axes' slots are known now, the
      // others' once the scene meets its loom (check_scene_fits).
      const std::string x = text();
      const int core = hal::core_axis_layout().find(x.c_str());
      if (x.empty() || x.size() > hal::AxisLayout::kNameMax)
        r.fail_at(v, field, shown(v), "must name an axis of the loom");
      f.axis_name = x;
      f.axis = core >= 0 ? static_cast<std::size_t>(core) : hal::kMaxAxes;
    } else if (k == "code") {
      f.code = static_cast<std::uint16_t>(integer(f.kind == InjectedFault::kEmcy ? 1 : 0, 0xFFFF));
    } else if (k == "duration_s") {
      f.duration_s = number(1e-6, kMaxSceneTimeS);
    } else if (k == "probability") {
      f.probability = number(1e-6, 1.0);
    } else if (k == "latency_s") {
      f.latency_s = number(1e-6, 1.0);
    } else if (k == "jump") {
      f.jump = number(-1e3, 1e3);
      if (f.jump == 0.0) r.fail_at(v, field, shown(v), "an encoder glitch must jump (non-zero)");
    } else if (k == "head") {
      f.head = static_cast<int>(integer(1, static_cast<std::int64_t>(hal::kMaxKnottingHeads))) -
               1;  // 1-based in the file
    } else if (k == "slot") {
      f.slot = static_cast<int>(integer(0, 15));
    } else if (k == "ticks") {
      f.ticks = static_cast<int>(integer(1, 1'000'000));
    } else if (k == "mode") {
      const std::string x = text();
      if (x == "nan") {
        f.load_cell = sim_hal::LoadCellMode::kNan;
      } else if (x == "lost") {
        f.load_cell = sim_hal::LoadCellMode::kLost;
      } else {
        r.fail_at(v, field, shown(v), "must be \"nan\" or \"lost\"");
      }
    }
  }
  if (f.kind == InjectedFault::kLoadCellFailure && !load_cell_fitted) {
    r.fail_at(*kind_node, prefix + "kind", shown(*kind_node),
              "a load cell can only fail when one is fitted: name the effect \"beat_contact\"");
  }
}

bool same_fault(const sim_hal::FaultInjection& a, const sim_hal::FaultInjection& b) {
  return a.kind == b.kind && a.at_s == b.at_s && a.at_tick == b.at_tick && a.axis_name == b.axis_name &&
         a.piston == b.piston && a.sensor == b.sensor && a.head == b.head && a.slot == b.slot;
}

}  // namespace

Scene parse_scene(const std::string& text, const std::string& source) {
  TomlReader r(text, source);
  Scene s;
  s.source = source;
  r.string("name", s.spec.name);
  std::int64_t seed = static_cast<std::int64_t>(s.spec.seed);
  r.integer("seed", seed, 0, INT64_MAX);
  s.spec.seed = static_cast<std::uint64_t>(seed);
  r.string("config", s.config_path);
  r.string_list("effects", s.spec.effects);
  if (s.spec.effects.empty())
    r.fail("effects", "[]", "name at least one effect (\"ideal\": nothing simulated)");
  for (std::size_t i = 0; i < s.spec.effects.size(); ++i) {
    const std::string& e = s.spec.effects[i];
    const auto& known = sim_hal::known_effects();
    if (std::find(known.begin(), known.end(), e) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      r.fail("effects", '"' + e + '"', "unknown effect (known: " + list + ")");
    }
    if (std::find(s.spec.effects.begin(), s.spec.effects.begin() + static_cast<std::ptrdiff_t>(i), e) !=
        s.spec.effects.begin() + static_cast<std::ptrdiff_t>(i)) {
      r.fail("effects", '"' + e + '"', "named twice (an effect is simulated once)");
    }
  }
  // Parameter tables belong to named effects only: parameters for an effect that is not simulated
  // would silently do nothing, which is exactly the mistake a scene file must not hide.
  const auto named = [&](const char* effect) {
    return std::find(s.spec.effects.begin(), s.spec.effects.end(), effect) != s.spec.effects.end();
  };
  for (const char* effect :
       {sim_hal::kEffectServoLag, sim_hal::kEffectPneumatics, sim_hal::kEffectShuttleSlip,
        sim_hal::kEffectSensorNoise, sim_hal::kEffectBeatContact, sim_hal::kEffectInertia,
        sim_hal::kEffectJointFriction, sim_hal::kEffectKnotter, sim_hal::kEffectWarpTension}) {
    if (r.root().contains(effect) && !named(effect)) {
      r.fail(effect, "{...}", "parameters given for an effect the scene does not name");
    }
  }
  if (named(sim_hal::kEffectServoLag)) {
    sim_hal::ServoLag lag;
    r.number("servo_lag.tau_s", lag.tau_s, [](double v) { return in_range(v, 1e-5, 1.0); });
    s.spec.servo_lag = lag;
  }
  if (named(sim_hal::kEffectPneumatics)) {
    sim_hal::Pneumatics p;
    r.number("pneumatics.fill_tau_s", p.fill_tau_s, [](double v) { return in_range(v, 1e-4, 5.0); });
    r.number("pneumatics.breakaway", p.breakaway, [](double v) { return in_range(v, 0.0, 0.95); });
    s.spec.pneumatics = p;
  }
  if (named(sim_hal::kEffectShuttleSlip)) {
    sim_hal::ShuttleSlip p;
    r.number("shuttle_slip.carrier_force_n", p.carrier_force_n,
             [](double v) { return in_range(v, 1e-3, 1e4); });
    r.number("shuttle_slip.shuttle_mass_kg", p.shuttle_mass_kg,
             [](double v) { return in_range(v, 1e-3, 100.0); });
    r.number("shuttle_slip.race_friction_m_s2", p.race_friction_m_s2,
             [](double v) { return in_range(v, 1e-3, 1e3); });
    s.spec.shuttle_slip = p;
  }
  if (named(sim_hal::kEffectSensorNoise)) {
    sim_hal::SensorNoise p;
    r.number("sensor_noise.flip_probability", p.flip_probability,
             [](double v) { return in_range(v, 0.0, 0.2); });
    s.spec.sensor_noise = p;
  }
  if (named(sim_hal::kEffectJointFriction) && !named(sim_hal::kEffectInertia)) {
    r.fail("effects", "\"joint_friction\"", "acts on the crank's dynamics: name \"inertia\" too");
  }
  if (named(sim_hal::kEffectInertia)) {
    sim_hal::Inertia p;
    r.number("inertia.motor_torque_limit_nm", p.motor_torque_limit_nm,
             [](double v) { return in_range(v, 1e-3, 1e5); });
    r.number("inertia.drive_inertia_kg_m2", p.drive_inertia_kg_m2,
             [](double v) { return in_range(v, 0.0, 100.0); });
    r.number("inertia.bandwidth_hz", p.bandwidth_hz, [](double v) { return in_range(v, 1.0, 500.0); });
    std::int64_t sub = p.substeps;
    r.integer("inertia.substeps", sub, 1, 1000);
    p.substeps = static_cast<int>(sub);
    r.number("inertia.beater_mass_kg", p.beater_mass_kg, [](double v) { return in_range(v, 1e-3, 1e3); });
    s.spec.inertia = p;
  }
  if (named(sim_hal::kEffectJointFriction)) {
    sim_hal::JointFriction p;
    r.number("joint_friction.viscous_nm_s", p.viscous_nm_s, [](double v) { return in_range(v, 0.0, 1e6); });
    r.number("joint_friction.coulomb_nm", p.coulomb_nm, [](double v) { return in_range(v, 0.0, 1e6); });
    s.spec.joint_friction = p;
  }
  if (named(sim_hal::kEffectKnotter)) {
    sim_hal::Knotter p;
    r.number("knotter.miss_probability", p.miss_probability, [](double v) { return in_range(v, 0.0, 1.0); });
    r.number("knotter.weaver_s", p.weaver_s, [](double v) { return in_range(v, 1e-3, 3600.0); });
    std::int64_t rows = p.carpet_rows;
    // 0: the record is as long as the run's carpet; N: an override (a deliberately short record).
    r.integer("knotter.carpet_rows", rows, 0, 1'000'000);
    p.carpet_rows = static_cast<int>(rows);
    s.spec.knotter = p;
  }
  if (named(sim_hal::kEffectBeatContact)) {
    sim_hal::BeatContact p;
    r.number("beat_contact.beater_mass_kg", p.beater_mass_kg,
             [](double v) { return in_range(v, 1e-3, 1e3); });
    r.number("beat_contact.contact_depth_m", p.contact_depth_m,
             [](double v) { return in_range(v, 1e-6, 1.0); });
    s.spec.beat_contact = p;
  }
  if (named(sim_hal::kEffectWarpTension)) {
    if (!named(sim_hal::kEffectBeatContact)) {
      r.fail("effects", "\"warp_tension\"",
             "scales the beat's force on the load cell: name \"beat_contact\" too");
    }
    sim_hal::WarpTension p;
    r.number("warp_tension.centre_ratio", p.centre_ratio, [](double v) { return in_range(v, 0.05, 5.0); });
    r.number("warp_tension.drift_per_row", p.drift_per_row,
             [](double v) { return in_range(v, -0.01, 0.01); });
    r.number("warp_tension.noise", p.noise, [](double v) { return in_range(v, 0.0, 0.2); });
    r.consume("warp_tension.points");
    const toml::table* wt = r.root().get_as<toml::table>(sim_hal::kEffectWarpTension);
    if (const toml::node* pts = wt ? wt->get("points") : nullptr) {
      const toml::array* arr = pts->as_array();
      if (arr == nullptr || arr->size() < 2 || arr->size() > 64) {
        r.fail_at(*pts, "warp_tension.points", shown(*pts),
                  "expected 2..64 relative tensions, equally spaced from the left selvedge to the right");
      }
      if (wt->get("centre_ratio") != nullptr) {
        r.fail_at(*pts, "warp_tension.points", shown(*pts), "give either points or centre_ratio, not both");
      }
      for (const toml::node& e : *arr) {
        const auto v = e.value<double>();
        if (!v || !std::isfinite(*v) || *v < 0.05 || *v > 5.0) {
          r.fail_at(e, "warp_tension.points", shown(e),
                    "each relative tension must be a number in [0.05, 5]");
        }
        p.points.push_back(*v);
      }
    }
    s.spec.warp_tension = p;
  }
  r.consume("fault");
  if (const toml::node* faults = r.root().get("fault")) {
    const toml::array* arr = faults->as_array();
    if (!arr || !arr->is_array_of_tables())
      r.fail_at(*faults, "fault", shown(*faults), "expected [[fault]] tables");
    std::size_t n = 0;
    for (const toml::node& fn : *arr) {
      sim_hal::FaultInjection f;
      read_fault(r, *fn.as_table(), n, named(sim_hal::kEffectBeatContact), f);
      for (const auto& g : s.spec.faults) {
        if (same_fault(f, g))
          r.fail_at(fn, "fault[" + std::to_string(n) + "]", "{...}", "the same fault is injected twice");
      }
      if (f.kind == InjectedFault::kPowerCut) {
        for (const auto& g : s.spec.faults) {
          if (g.kind == InjectedFault::kPowerCut) {
            r.fail_at(fn, "fault[" + std::to_string(n) + "]", "{...}", "the power can only be cut once");
          }
        }
      }
      s.spec.faults.push_back(f);
      s.fault_where.push_back(source + ":" + std::to_string(fn.source().begin.line) + ":" +
                              std::to_string(fn.source().begin.column));
      ++n;
    }
  }
  r.reject_unknown();
  return s;
}

Scene check_scene_fits(Scene scene, const LoomConfig& cfg, bool simulated_io) {
  const bool heads = cfg.knotting.mode == sequencer::KnottingMode::kHeads;
  if (scene.spec.knotter && !heads) {
    throw ConfigError(scene.source + ": effects: \"knotter\" simulates knotting heads; the loom (" +
                      cfg.source + ") has none (knotting.mode = \"" +
                      sequencer::knotting_mode_name(cfg.knotting.mode) + "\")");
  }
  if (heads && simulated_io && !scene.spec.knotter) {
    throw ConfigError(
        scene.source + ": effects: the loom (" + cfg.source +
        ") ties its knots with heads (knotting.mode = \"heads\"): the scene must name the effect \"knotter\" "
        "(the heads' yarn, knots and the weaver are simulated only when named)");
  }
  for (std::size_t n = 0; n < scene.spec.faults.size(); ++n) {
    sim_hal::FaultInjection& f = scene.spec.faults[n];
    const std::string at = n < scene.fault_where.size() ? scene.fault_where[n] : scene.source;
    const bool names_axis = f.kind == InjectedFault::kDriveFault || f.kind == InjectedFault::kHeartbeatLoss ||
                            f.kind == InjectedFault::kEmcy || f.kind == InjectedFault::kEncoderGlitch ||
                            f.kind == InjectedFault::kAxisJam;
    if (names_axis) {
      const int slot = cfg.sequencer.axes.find(f.axis_name.c_str());
      if (slot < 0) {
        std::string names;
        for (std::size_t i = 0; i < cfg.sequencer.axes.count; ++i)
          names += std::string(i ? ", " : "") + cfg.sequencer.axes.name(i);
        throw ConfigError(at + ": fault[" + std::to_string(n) + "].axis = \"" + f.axis_name +
                          "\": the loom (" + cfg.source + ") has no such axis (its axes: " + names + ")");
      }
      f.axis = static_cast<std::size_t>(slot);
    }
    if (f.kind == InjectedFault::kSelectorJam || f.kind == InjectedFault::kYarnOut) {
      if (!scene.spec.knotter) {
        throw ConfigError(at + ": fault[" + std::to_string(n) + "].kind = \"" +
                          sim_hal::injected_fault_name(f.kind) +
                          "\": a knotting head's fault needs the effect \"knotter\"");
      }
      if (f.head >= cfg.knotting.heads) {
        throw ConfigError(at + ": fault[" + std::to_string(n) + "].head = " + std::to_string(f.head + 1) +
                          ": the loom (" + cfg.source + ") has " + std::to_string(cfg.knotting.heads) +
                          " knotting heads");
      }
      if (f.kind == InjectedFault::kYarnOut && f.slot >= static_cast<int>(cfg.knotting.slot_colours.size())) {
        throw ConfigError(at + ": fault[" + std::to_string(n) + "].slot = " + std::to_string(f.slot) +
                          ": the heads' magazines have " + std::to_string(cfg.knotting.slot_colours.size()) +
                          " slots (0.." + std::to_string(cfg.knotting.slot_colours.size() - 1) + ")");
      }
    }
    if (f.kind != InjectedFault::kStuckSensor && f.kind != InjectedFault::kIntermittentSensor) continue;
    const auto i = static_cast<std::size_t>(f.sensor);
    if (i < hal::kSafetySensorCount || cfg.sequencer.second_channel[i - hal::kSafetySensorCount]) continue;
    throw ConfigError(at + ": fault[" + std::to_string(n) + "].sensor = \"" + sim_hal::sensor_name(f.sensor) +
                      "\": the loom (" + cfg.source + ") has no second switch there (io." +
                      sim_hal::sensor_name(f.sensor) + "_bit = -1)");
  }
  return scene;
}

Scene load_scene(const std::string& path) {
  return parse_scene(read_text(path), path);
}
Scene default_scene() {
  return parse_scene(kDefaultSceneToml, "<embedded default.toml scene>");
}

std::string scene_to_toml(const sim_hal::SceneSpec& s, const std::string& config) {
  std::ostringstream os;
  os.precision(17);
  const auto quoted = [](const std::string& x) {
    std::string q = "\"";
    for (char c : x) {
      if (c == '"' || c == '\\') q += '\\';
      q += c;
    }
    return q + "\"";
  };
  os << "name = " << quoted(s.name) << "\nseed = " << static_cast<std::int64_t>(s.seed & INT64_MAX) << "\n";
  if (!config.empty()) os << "config = " << quoted(config) << "\n";
  os << "effects = [";
  for (std::size_t i = 0; i < s.effects.size(); ++i) os << (i ? ", " : "") << quoted(s.effects[i]);
  os << "]\n";
  if (s.servo_lag) os << "\n[servo_lag]\ntau_s = " << s.servo_lag->tau_s << "\n";
  if (s.pneumatics) {
    os << "\n[pneumatics]\nfill_tau_s = " << s.pneumatics->fill_tau_s
       << "\nbreakaway = " << s.pneumatics->breakaway << "\n";
  }
  if (s.shuttle_slip) {
    os << "\n[shuttle_slip]\ncarrier_force_n = " << s.shuttle_slip->carrier_force_n
       << "\nshuttle_mass_kg = " << s.shuttle_slip->shuttle_mass_kg
       << "\nrace_friction_m_s2 = " << s.shuttle_slip->race_friction_m_s2 << "\n";
  }
  if (s.sensor_noise)
    os << "\n[sensor_noise]\nflip_probability = " << s.sensor_noise->flip_probability << "\n";
  if (s.beat_contact) {
    os << "\n[beat_contact]\nbeater_mass_kg = " << s.beat_contact->beater_mass_kg
       << "\ncontact_depth_m = " << s.beat_contact->contact_depth_m << "\n";
  }
  if (s.warp_tension) {
    os << "\n[warp_tension]\n";
    if (s.warp_tension->points.empty()) {
      os << "centre_ratio = " << s.warp_tension->centre_ratio << "\n";
    } else {
      os << "points = [";
      for (std::size_t i = 0; i < s.warp_tension->points.size(); ++i)
        os << (i ? ", " : "") << s.warp_tension->points[i];
      os << "]\n";
    }
    os << "drift_per_row = " << s.warp_tension->drift_per_row << "\nnoise = " << s.warp_tension->noise
       << "\n";
  }
  if (s.inertia) {
    os << "\n[inertia]\nmotor_torque_limit_nm = " << s.inertia->motor_torque_limit_nm
       << "\ndrive_inertia_kg_m2 = " << s.inertia->drive_inertia_kg_m2
       << "\nbandwidth_hz = " << s.inertia->bandwidth_hz << "\nsubsteps = " << s.inertia->substeps
       << "\nbeater_mass_kg = " << s.inertia->beater_mass_kg << "\n";
  }
  if (s.knotter) {
    os << "\n[knotter]\nmiss_probability = " << s.knotter->miss_probability
       << "\nweaver_s = " << s.knotter->weaver_s << "\ncarpet_rows = " << s.knotter->carpet_rows << "\n";
  }
  if (s.joint_friction) {
    os << "\n[joint_friction]\nviscous_nm_s = " << s.joint_friction->viscous_nm_s
       << "\ncoulomb_nm = " << s.joint_friction->coulomb_nm << "\n";
  }
  for (const sim_hal::FaultInjection& f : s.faults) {
    os << "\n[[fault]]\nkind = " << quoted(sim_hal::injected_fault_name(f.kind)) << "\n";
    if (f.kind == InjectedFault::kPowerCut) {
      os << "at_tick = " << f.at_tick << "\n";
    } else {
      os << "at_s = " << f.at_s << "\n";
    }
    const KindFields& fields = kind_fields().at(f.kind);
    const auto has = [&](const char* k) { return fields.required.count(k) || fields.optional.count(k); };
    if (has("axis")) os << "axis = " << quoted(f.axis_name) << "\n";
    if (has("code")) os << "code = " << f.code << "\n";
    if (has("piston")) os << "piston = " << (f.piston == 0 ? "\"a\"" : "\"b\"") << "\n";
    if (has("sensor")) os << "sensor = " << quoted(sim_hal::sensor_name(f.sensor)) << "\n";
    if (has("value")) os << "value = " << (f.stuck_value ? "true" : "false") << "\n";
    if (has("duration_s") && f.duration_s > 0.0) os << "duration_s = " << f.duration_s << "\n";
    if (has("probability")) os << "probability = " << f.probability << "\n";
    if (has("latency_s")) os << "latency_s = " << f.latency_s << "\n";
    if (has("jump")) os << "jump = " << f.jump << "\n";
    if (has("ticks")) os << "ticks = " << f.ticks << "\n";
    if (has("mode")) os << "mode = " << quoted(sim_hal::load_cell_mode_name(f.load_cell)) << "\n";
    if (has("head")) os << "head = " << f.head + 1 << "\n";
    if (has("slot")) os << "slot = " << f.slot << "\n";
  }
  return os.str();
}

}  // namespace loom::firmware

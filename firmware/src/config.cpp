// Loom config parsing: one table of keys (section, class, plausible range, where the value goes), read
// in file order; then the cross-field checks, each pointing at the line that is wrong; then the one
// derivation of every module's config; then each module's own validation (motion builds the profiles,
// the CAN master checks its timing and bus load). A config that parses but cannot be woven is refused
// here, never at the first row.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <sstream>

#include "loom/drivers/bus_load.hpp"
#include "loom/firmware/config.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/dynamics.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/fourbar.hpp"
#include "loom/motion/mass_properties.hpp"
#include "loom/motion/profile_crank.hpp"
#include "toml_reader.hpp"

namespace loom::firmware {
namespace {

std::string read_file(const std::string& path) { return read_config_file(path); }

// The recipe's design file, read relative to the config file's folder (the working directory for the
// embedded default). A design that cannot be used is reported at the recipe.design line, with the
// design file's own line:col inside the message.
std::shared_ptr<const design::Design> load_design_for(const TomlReader& r, const std::string& file) {
  if (file.empty()) return nullptr;
  std::string path = file;
  const std::string& src = r.source();
  if (file[0] != '/' && !src.empty() && src[0] != '<' && src.find('/') != std::string::npos) {
    path = src.substr(0, src.rfind('/') + 1) + file;
  }
  constexpr long kMaxDesignBytes = 16L << 20;
  try {
    return std::make_shared<const design::Design>(design::parse_design(read_config_file(path, kMaxDesignBytes, "design"), path));
  } catch (const ConfigError& e) {
    r.fail("recipe.design", '"' + file + '"', e.what());
  } catch (const design::DesignError& e) {
    r.fail("recipe.design", '"' + file + '"', e.what());
  }
}


std::string fmt_num(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

// Longest plausible row: a recipe whose row takes longer than this is a typo, not a carpet.
constexpr double kMaxRowSeconds = 3600.0;

// ---------------------------------------------------------------------------------------------------
// The key table
// ---------------------------------------------------------------------------------------------------
enum class Klass { kMachine, kRecipe, kRun };
const char* klass_name(Klass k) {
  switch (k) {
    case Klass::kMachine: return "machine";
    case Klass::kRecipe: return "recipe";
    case Klass::kRun: return "run";
  }
  return "?";
}

struct Key {
  std::string path;
  Klass klass;
  std::string range;  // for messages and `loomctl check --keys`
  bool required;      // must be in a complete file (false: has a documented default or an alternative)
  std::function<void(TomlReader&, LoomConfig&)> read;
  std::function<std::string(const LoomConfig&)> value;  // canonical text, to compare two configs
};

using Num = std::function<double&(LoomConfig&)>;

Key number(std::string path, Klass k, double lo, double hi, Num field, bool required = true) {
  std::ostringstream range;
  range << "[" << lo << ", " << hi << "]";
  Key key{path, k, range.str(), required, nullptr, nullptr};
  key.read = [=](TomlReader& r, LoomConfig& c) {
    r.number(path, field(c), [=](double v) { return in_range(v, lo, hi); });
  };
  key.value = [=](const LoomConfig& c) { return fmt_num(field(const_cast<LoomConfig&>(c))); };
  return key;
}

// Angles are written in degrees (…_deg) and kept in radians.
Key degrees(std::string path, Klass k, double lo, double hi, Num field_rad) {
  Key key = number(path, k, lo, hi, field_rad);
  key.read = [=](TomlReader& r, LoomConfig& c) {
    double deg = motion::deg(field_rad(c));
    r.number(path, deg, [=](double v) { return in_range(v, lo, hi); });
    field_rad(c) = motion::rad(deg);
  };
  return key;
}

// Milliseconds in the file, seconds inside.
Key millis(std::string path, Klass k, double lo, double hi, Num field_s) {
  Key key = number(path, k, lo, hi, field_s);
  key.read = [=](TomlReader& r, LoomConfig& c) {
    double ms = field_s(c) * 1e3;
    r.number(path, ms, [=](double v) { return in_range(v, lo, hi); });
    field_s(c) = ms * 1e-3;
  };
  return key;
}

template <typename T>
Key integer(std::string path, Klass k, std::int64_t lo, std::int64_t hi, std::function<T&(LoomConfig&)> field) {
  Key key{path, k, "[" + std::to_string(lo) + ", " + std::to_string(hi) + "] (integer)", true, nullptr, nullptr};
  key.read = [=](TomlReader& r, LoomConfig& c) {
    std::int64_t v = static_cast<std::int64_t>(field(c));
    r.integer(path, v, lo, hi);
    field(c) = static_cast<T>(v);
  };
  key.value = [=](const LoomConfig& c) { return std::to_string(field(const_cast<LoomConfig&>(c))); };
  return key;
}

// A string from a closed set, stored through name/parse functions.
template <typename E>
Key choice(std::string path, Klass k, std::set<std::string> allowed, std::function<E&(LoomConfig&)> field,
           const char* (*name)(E), bool (*parse)(const char*, E&)) {
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : " | ") + a;
  Key key{path, k, list, true, nullptr, nullptr};
  key.read = [=](TomlReader& r, LoomConfig& c) {
    std::string s = name(field(c));
    r.string(path, s, allowed);
    parse(s.c_str(), field(c));
  };
  key.value = [=](const LoomConfig& c) { return std::string(name(field(const_cast<LoomConfig&>(c)))); };
  return key;
}

Key boolean(std::string path, Klass k, std::function<bool&(LoomConfig&)> field) {
  Key key{path, k, "true | false", true, nullptr, nullptr};
  key.read = [=](TomlReader& r, LoomConfig& c) { r.boolean(path, field(c)); };
  key.value = [=](const LoomConfig& c) { return std::string(field(const_cast<LoomConfig&>(c)) ? "true" : "false"); };
  return key;
}

const char* io_kind_name(IoKind k) { return k == IoKind::kCan ? "can" : "simulated"; }
bool parse_io_kind(const char* s, IoKind& k) {
  k = std::string(s) == "can" ? IoKind::kCan : IoKind::kSimulated;
  return true;
}

// One wired signal of the I/O module: `io.<name>_bit` (-1 = not wired, else 0..max_bits-1) and
// `io.<name>_active_low`; `get` finds the signal in a config.
template <class Get>
void io_signal(std::vector<Key>& v, const std::string& name, int max_bits, Get get) {
  v.push_back(integer<int>("io." + name + "_bit", Klass::kMachine, -1, max_bits - 1,
                           [get](LoomConfig& c) -> int& { return get(c).bit; }));
  v.push_back(boolean("io." + name + "_active_low", Klass::kMachine,
                      [get](LoomConfig& c) -> bool& { return get(c).active_low; }));
}
void io_input(std::vector<Key>& v, const std::string& name, drivers::IoBit drivers::IoWiring::*member) {
  io_signal(v, name, drivers::kIoMaxInputBits, [member](LoomConfig& c) -> drivers::IoBit& { return c.io.wiring.*member; });
}
void io_output(std::vector<Key>& v, const std::string& name, drivers::IoBit drivers::IoWiring::*member) {
  io_signal(v, name, drivers::kIoMaxOutputBits, [member](LoomConfig& c) -> drivers::IoBit& { return c.io.wiring.*member; });
}
// The second channel of safety sensor `i`: `io.<sensor>_2_bit`, `io.<sensor>_2_active_low`.
void io_second_channel(std::vector<Key>& v, std::size_t i) {
  io_signal(v, std::string(hal::safety_sensor_name(static_cast<hal::SafetySensor>(i))) + "_2", drivers::kIoMaxInputBits,
            [i](LoomConfig& c) -> drivers::IoBit& { return c.io.wiring.second[i]; });
}

const char* branch_name(motion::Branch b) { return b == motion::Branch::kPositive ? "positive" : "negative"; }
bool parse_branch(const char* s, motion::Branch& b) {
  b = std::string(s) == "positive" ? motion::Branch::kPositive : motion::Branch::kNegative;
  return true;
}
const char* fell_name(motion::FellSide f) { return f == motion::FellSide::kExtended ? "extended" : "folded"; }
bool parse_fell(const char* s, motion::FellSide& f) {
  f = std::string(s) == "extended" ? motion::FellSide::kExtended : motion::FellSide::kFolded;
  return true;
}

// Node ids, counts and rates are integers on the wire; ranges are the protocol's or a plausible
// machine's. Every number has a range a real loom fits in with room to spare, so a unit slip (mm for
// m, a missing exponent) or an absurd value (1e-320, 1e308, nan) is refused with the line.
const std::vector<Key>& keys() {
  using M = Klass;
  static const std::vector<Key> k = [] {
    std::vector<Key> v;
    // [loom]
    {
      Key id{"loom.id", M::kMachine, "string without spaces, dots, slashes or '*'", true, nullptr, nullptr};
      id.read = [](TomlReader& r, LoomConfig& c) {
        r.string("loom.id", c.loom_id);
        if (c.loom_id.empty() || c.loom_id.size() > 64 || c.loom_id.find_first_of(" ./*\t\"\\") != std::string::npos) {
          r.fail("loom.id", '"' + c.loom_id + '"', "must be 1..64 characters without spaces, dots, slashes or '*'");
        }
      };
      id.value = [](const LoomConfig& c) { return c.loom_id; };
      v.push_back(id);
    }
    v.push_back(number("loom.width_m", M::kMachine, 0.2, 10.0, [](LoomConfig& c) -> double& { return c.machine_spec.width_m; }));
    // [beatup] — the linkage and the beater (machine)
    v.push_back(number("beatup.crank_m", M::kMachine, 0.005, 2.0, [](LoomConfig& c) -> double& { return c.machine_spec.beatup.bar.crank; }));
    v.push_back(number("beatup.coupler_m", M::kMachine, 0.005, 5.0, [](LoomConfig& c) -> double& { return c.machine_spec.beatup.bar.coupler; }));
    v.push_back(number("beatup.rocker_m", M::kMachine, 0.005, 5.0, [](LoomConfig& c) -> double& { return c.machine_spec.beatup.bar.rocker; }));
    v.push_back(number("beatup.ground_m", M::kMachine, 0.005, 5.0, [](LoomConfig& c) -> double& { return c.machine_spec.beatup.bar.ground; }));
    v.push_back(number("beatup.beater_arm_m", M::kMachine, 0.01, 5.0, [](LoomConfig& c) -> double& { return c.machine_spec.beatup.beater_arm_m; }));
    v.push_back(choice<motion::Branch>("beatup.branch", M::kMachine, {"positive", "negative"},
                                       [](LoomConfig& c) -> motion::Branch& { return c.machine_spec.beatup.branch; },
                                       branch_name, parse_branch));
    v.push_back(choice<motion::FellSide>("beatup.fell_at", M::kMachine, {"extended", "folded"},
                                         [](LoomConfig& c) -> motion::FellSide& { return c.machine_spec.beatup.fell_at; },
                                         fell_name, parse_fell));
    v.push_back(number("beatup.warp_depth_m", M::kMachine, 0.001, 0.5, [](LoomConfig& c) -> double& { return c.machine_spec.beatup.warp_depth_m; }));
    v.push_back(number("beatup.beater_mass_kg", M::kMachine, 0.1, 50.0, [](LoomConfig& c) -> double& { return c.machine_spec.beater_mass_kg; }));
    v.push_back(number("beatup.beater_width_m", M::kMachine, 0.01, 1.0, [](LoomConfig& c) -> double& { return c.machine_spec.beater_width_m; }));
    v.push_back(number("beatup.crank_park_position_rad", M::kMachine, -1.0e5, 1.0e5,
                       [](LoomConfig& c) -> double& { return c.machine_spec.calibration.crank_park_position_rad; }));
    // [carriage]
    v.push_back(number("carriage.max_speed_m_s", M::kMachine, 0.01, 10.0, [](LoomConfig& c) -> double& { return c.machine_spec.carriage_max_speed_m_s; }));
    v.push_back(number("carriage.max_accel_m_s2", M::kMachine, 0.1, 1000.0, [](LoomConfig& c) -> double& { return c.machine_spec.carriage_max_accel_m_s2; }));
    v.push_back(number("carriage.max_jerk_m_s3", M::kMachine, 1.0, 1.0e6, [](LoomConfig& c) -> double& { return c.machine_spec.carriage_max_jerk_m_s3; }));
    v.push_back(number("carriage.jerk_m_s3", M::kMachine, 1.0, 1.0e6, [](LoomConfig& c) -> double& { return c.machine_spec.carriage_reposition_jerk_m_s3; }));
    v.push_back(number("carriage.home_position_m", M::kMachine, -10.0, 10.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.calibration.carriage_home_m; }));
    // [helix]
    v.push_back(number("helix.lead_m", M::kMachine, 0.005, 1.0, [](LoomConfig& c) -> double& { return c.machine_spec.helix_lead_m; }));
    v.push_back(number("helix.left_position_rad", M::kMachine, -1.0e5, 1.0e5,
                       [](LoomConfig& c) -> double& { return c.machine_spec.calibration.helix_left_position_rad; }));
    v.push_back(number("helix.max_speed_rad_s", M::kMachine, 1.0, 1000.0, [](LoomConfig& c) -> double& { return c.machine_spec.helix.velocity; }));
    v.push_back(number("helix.max_accel_rad_s2", M::kMachine, 1.0, 1.0e6, [](LoomConfig& c) -> double& { return c.machine_spec.helix.acceleration; }));
    v.push_back(number("helix.jerk_rad_s3", M::kMachine, 10.0, 1.0e8, [](LoomConfig& c) -> double& { return c.machine_spec.helix.jerk; }));
    v.push_back(number("helix.carrier_force_n", M::kMachine, 0.1, 1000.0, [](LoomConfig& c) -> double& { return c.machine_spec.carrier_force_n; }));
    v.push_back(number("helix.shuttle_mass_kg", M::kMachine, 0.01, 10.0, [](LoomConfig& c) -> double& { return c.machine_spec.shuttle_mass_kg; }));
    // [shedding]
    v.push_back(number("shedding.piston_travel_s", M::kMachine, 0.01, 10.0, [](LoomConfig& c) -> double& { return c.machine_spec.shed.piston_travel_s; }));
    v.push_back(number("shedding.timeout_s", M::kMachine, 0.05, 60.0, [](LoomConfig& c) -> double& { return c.machine_spec.shed.timeout_s; }));
    v.push_back(number("shedding.earliest_fraction", M::kMachine, 0.0, 0.99, [](LoomConfig& c) -> double& { return c.machine_spec.shed.earliest_fraction; }));
    v.push_back(number("shedding.release_timeout_s", M::kMachine, 0.005, 10.0, [](LoomConfig& c) -> double& { return c.machine_spec.shed.release_timeout_s; }));
    v.push_back(millis("shedding.settle_ms", M::kMachine, 0.0, 1000.0, [](LoomConfig& c) -> double& { return c.machine_spec.shed.settle_s; }));
    // [can]
    {
      Key bitrate{"can.bitrate", M::kMachine, "10000 | 20000 | 50000 | 125000 | 250000 | 500000 | 800000 | 1000000", true, nullptr, nullptr};
      bitrate.read = [](TomlReader& r, LoomConfig& c) {
        std::int64_t b = c.can.bitrate;
        r.integer("can.bitrate", b, 10'000, 1'000'000);
        static const std::set<std::int64_t> cia{10'000, 20'000, 50'000, 125'000, 250'000, 500'000, 800'000, 1'000'000};
        if (!cia.count(b)) r.fail("can.bitrate", std::to_string(b), "must be a CiA 301 bit rate: 10000, 20000, 50000, 125000, 250000, 500000, 800000 or 1000000");
        c.can.bitrate = static_cast<std::uint32_t>(b);
      };
      bitrate.value = [](const LoomConfig& c) { return std::to_string(c.can.bitrate); };
      v.push_back(bitrate);
    }
    v.push_back(number("can.bus_load_budget", M::kMachine, 0.05, 1.0, [](LoomConfig& c) -> double& { return c.can.bus_load_budget; }));
    v.push_back(integer<std::uint8_t>("can.node_beat_crank", M::kMachine, 1, 127, [](LoomConfig& c) -> std::uint8_t& { return c.can.node_beat_crank; }));
    v.push_back(integer<std::uint8_t>("can.node_carriage", M::kMachine, 1, 127, [](LoomConfig& c) -> std::uint8_t& { return c.can.node_carriage; }));
    v.push_back(integer<std::uint8_t>("can.node_helix", M::kMachine, 1, 127, [](LoomConfig& c) -> std::uint8_t& { return c.can.node_helix; }));
    v.push_back(number("can.counts_per_rev", M::kMachine, 16.0, 2147483648.0, [](LoomConfig& c) -> double& { return c.can.counts_per_rev; }));
    v.push_back(number("can.carriage_counts_per_m", M::kMachine, 100.0, 1.0e9, [](LoomConfig& c) -> double& { return c.can.carriage_counts_per_m; }));
    v.push_back(integer<std::uint16_t>("can.heartbeat_ms", M::kMachine, 10, 10000, [](LoomConfig& c) -> std::uint16_t& { return c.can.heartbeat_ms; }));
    v.push_back(integer<std::uint16_t>("can.heartbeat_timeout_ms", M::kMachine, 10, 30000, [](LoomConfig& c) -> std::uint16_t& { return c.can.heartbeat_timeout_ms; }));
    v.push_back(integer<std::uint16_t>("can.sdo_timeout_ms", M::kMachine, 10, 10000, [](LoomConfig& c) -> std::uint16_t& { return c.can.sdo_timeout_ms; }));
    v.push_back(integer<std::uint8_t>("can.master_node", M::kMachine, 0, 127, [](LoomConfig& c) -> std::uint8_t& { return c.can.master_node; }));
    v.push_back(integer<std::uint16_t>("can.master_heartbeat_ms", M::kMachine, 10, 10000, [](LoomConfig& c) -> std::uint16_t& { return c.can.master_heartbeat_ms; }));
    v.push_back(integer<std::uint16_t>("can.master_consumer_ms", M::kMachine, 20, 30000, [](LoomConfig& c) -> std::uint16_t& { return c.can.master_consumer_ms; }));
    {
      static const char* const axes[] = {"beat_crank", "carriage", "helix"};
      static const char* const units[] = {"rad", "m", "rad"};
      for (std::size_t i = 0; i < 3; ++i) {
        const std::string a = axes[i];
        v.push_back(integer<std::uint32_t>("can." + a + "_boot_ms", M::kMachine, 0, 60000,
                                           [i](LoomConfig& c) -> std::uint32_t& { return c.can.boot_timeout_ms[i]; }));
        v.push_back(integer<std::uint32_t>("can." + a + "_operational_ms", M::kMachine, 0, 60000,
                                           [i](LoomConfig& c) -> std::uint32_t& { return c.can.operational_timeout_ms[i]; }));
        v.push_back(number("can." + a + "_ferror_min_" + units[i], M::kMachine, 0.0, i == 1 ? 1.0 : 100.0,
                           [i](LoomConfig& c) -> double& { return c.can.ferror_min[i]; }));
        v.push_back(number("can." + a + "_ferror_k_s", M::kMachine, 0.0, 10.0,
                           [i](LoomConfig& c) -> double& { return c.can.ferror_k_s[i]; }));
      }
    }
    // [io] — the CiA 401 module: where each signal is wired
    v.push_back(choice<IoKind>("io.kind", M::kMachine, {"can", "simulated"}, [](LoomConfig& c) -> IoKind& { return c.io.kind; },
                               io_kind_name, parse_io_kind));
    v.push_back(integer<std::uint8_t>("io.node", M::kMachine, 1, 127, [](LoomConfig& c) -> std::uint8_t& { return c.io.node; }));
    v.push_back(integer<std::uint32_t>("io.boot_timeout_ms", M::kMachine, 10, 60000, [](LoomConfig& c) -> std::uint32_t& { return c.io.boot_timeout_ms; }));
    v.push_back(integer<std::uint32_t>("io.operational_timeout_ms", M::kMachine, 10, 60000, [](LoomConfig& c) -> std::uint32_t& { return c.io.operational_timeout_ms; }));
    using W = drivers::IoWiring;
    io_input(v, "piston_a_extended", &W::piston_a_extended);
    io_input(v, "piston_a_retracted", &W::piston_a_retracted);
    io_input(v, "piston_b_extended", &W::piston_b_extended);
    io_input(v, "piston_b_retracted", &W::piston_b_retracted);
    io_input(v, "shuttle_at_left", &W::shuttle_at_left);
    io_input(v, "shuttle_at_right", &W::shuttle_at_right);
    io_input(v, "estop_ok", &W::estop_ok);
    io_input(v, "button_start", &W::button_start);
    io_input(v, "button_pause", &W::button_pause);
    io_input(v, "button_ack", &W::button_ack);
    io_input(v, "row_knotted", &W::row_knotted);
    for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i) io_second_channel(v, i);
    io_output(v, "piston_a_extend", &W::piston_a_extend);
    io_output(v, "piston_b_extend", &W::piston_b_extend);
    io_output(v, "lamp_green", &W::lamp_green);
    io_output(v, "lamp_amber", &W::lamp_amber);
    io_output(v, "lamp_red", &W::lamp_red);
    io_output(v, "buzzer", &W::buzzer);
    v.push_back(integer<int>("io.load_cell_channel", M::kMachine, 0, 254, [](LoomConfig& c) -> int& { return c.io.wiring.load_cell_channel; }));
    v.push_back(number("io.load_cell_n_per_count", M::kMachine, -1.0e3, 1.0e3, [](LoomConfig& c) -> double& { return c.io.wiring.load_cell_n_per_count; }));
    v.push_back(number("io.load_cell_offset_n", M::kMachine, -1.0e4, 1.0e4, [](LoomConfig& c) -> double& { return c.io.wiring.load_cell_offset_n; }));
    // [recipe]
    v.push_back(integer<std::uint32_t>("recipe.picks_per_row", M::kRecipe, 1, 16, [](LoomConfig& c) -> std::uint32_t& { return c.recipe.picks_per_row; }));
    v.push_back(boolean("recipe.knotting", M::kRecipe, [](LoomConfig& c) -> bool& { return c.recipe.knotting; }));
    {
      Key design{"recipe.design", M::kRecipe, "file: .csv grid of colour codes or .png, one pixel per knot; \"\" = none",
                 false, nullptr, nullptr};
      design.read = [](TomlReader& r, LoomConfig& c) {
        r.string("recipe.design", c.recipe.design_file);
        c.recipe.design = load_design_for(r, c.recipe.design_file);
      };
      design.value = [](const LoomConfig& c) { return c.recipe.design_file; };
      v.push_back(design);
    }
    v.push_back(integer<int>("recipe.beats_per_position", M::kRecipe, 1, 16, [](LoomConfig& c) -> int& { return c.recipe.beats_per_position; }));
    {
      Key force = number("recipe.beat_force_target_n", M::kRecipe, 1.0, 1000.0, [](LoomConfig& c) -> double& { return c.recipe.beat_force_target_n; }, false);
      Key speed = number("recipe.crank_speed_rad_s", M::kRecipe, 0.1, 100.0, [](LoomConfig& c) -> double& { return c.recipe.crank_speed_rad_s; }, false);
      v.push_back(force);
      v.push_back(speed);
    }
    v.push_back(number("recipe.beat_force_min_n", M::kRecipe, 1.0, 1000.0, [](LoomConfig& c) -> double& { return c.recipe.beat_force_min_n; }));
    v.push_back(number("recipe.beat_force_max_n", M::kRecipe, 1.0, 1000.0, [](LoomConfig& c) -> double& { return c.recipe.beat_force_max_n; }));
    v.push_back(number("recipe.crank_accel_rad_s2", M::kRecipe, 1.0, 1.0e5, [](LoomConfig& c) -> double& { return c.recipe.crank_accel_rad_s2; }));
    v.push_back(number("recipe.crank_jerk_rad_s3", M::kRecipe, 10.0, 1.0e7, [](LoomConfig& c) -> double& { return c.recipe.crank_jerk_rad_s3; }));
    v.push_back(choice<motion::CrankLawKind>("recipe.crank_law", M::kRecipe, {"constant", "elliptic"},
                                             [](LoomConfig& c) -> motion::CrankLawKind& { return c.recipe.crank_law.kind; },
                                             motion::crank_law_name, motion::parse_crank_law));
    v.push_back(number("recipe.ellipse_e", M::kRecipe, 0.0, 0.9, [](LoomConfig& c) -> double& { return c.recipe.crank_law.ellipse_e; }));
    v.push_back(integer<int>("recipe.ellipse_lobes", M::kRecipe, 1, 16, [](LoomConfig& c) -> int& { return c.recipe.crank_law.ellipse_lobes; }));
    v.push_back(degrees("recipe.ellipse_phi02_deg", M::kRecipe, -360.0, 360.0, [](LoomConfig& c) -> double& { return c.recipe.crank_law.ellipse_phi02_rad; }));
    v.push_back(number("recipe.overlap_m", M::kRecipe, 0.0, 1.0, [](LoomConfig& c) -> double& { return c.recipe.overlap_m; }));
    v.push_back(degrees("recipe.cam_margin_deg", M::kRecipe, 0.0, 90.0, [](LoomConfig& c) -> double& { return c.recipe.cam_margin_rad; }));
    // [profiles] — how the recipe's motion is tabulated (a recipe property: rebuilt with it)
    {
      Key size = integer<std::size_t>("profiles.table_size", M::kRecipe, 64, 1 << 20, [](LoomConfig& c) -> std::size_t& { return c.recipe.table_size; });
      v.push_back(size);
    }
    v.push_back(choice<motion::Interp>("profiles.interp", M::kRecipe, {"linear", "cubic", "quintic"},
                                       [](LoomConfig& c) -> motion::Interp& { return c.recipe.table_interp; },
                                       motion::interp_name, motion::parse_interp));
    v.push_back(choice<motion::Precision>("profiles.table_precision", M::kRecipe, {"double", "float32"},
                                          [](LoomConfig& c) -> motion::Precision& { return c.recipe.table_precision; },
                                          motion::precision_name, motion::parse_precision));
    v.push_back(number("profiles.max_table_error_rad", M::kRecipe, 1e-12, 1e-2, [](LoomConfig& c) -> double& { return c.recipe.max_table_error_rad; }));
    // [timing] (run)
    v.push_back(millis("timing.period_ms", M::kRun, 0.25, 20.0, [](LoomConfig& c) -> double& { return c.run.period_s; }));
    v.push_back(number("timing.enable_timeout_s", M::kRun, 0.05, 60.0, [](LoomConfig& c) -> double& { return c.run.enable_timeout_s; }));
    v.push_back(number("timing.pick_timeout_margin_s", M::kRun, 0.01, 60.0, [](LoomConfig& c) -> double& { return c.run.pick_timeout_margin_s; }));
    v.push_back(number("timing.row_save_timeout_s", M::kRun, 0.1, 600.0, [](LoomConfig& c) -> double& { return c.run.row_save_timeout_s; }));
    v.push_back(millis("timing.stale_timeout_ms", M::kRun, 0.5, 10000.0, [](LoomConfig& c) -> double& { return c.run.stale_timeout_s; }));
    v.push_back(integer<int>("timing.debounce_ticks", M::kRun, 1, 100, [](LoomConfig& c) -> int& { return c.run.debounce_ticks; }));
    v.push_back(millis("timing.sensor_discrepancy_ms", M::kRun, 1.0, 1000.0, [](LoomConfig& c) -> double& { return c.run.sensor_discrepancy_s; }));
    v.push_back(integer<std::uint32_t>("timing.overrun_stop_after", M::kRun, 0, 1'000'000,
                                       [](LoomConfig& c) -> std::uint32_t& { return c.run.overrun_stop_after; }));
    // [telemetry] (run)
    {
      Key url{"telemetry.lcm_url", M::kRun, "LCM provider URL, \"\" = LCM's default", false, nullptr, nullptr};
      url.read = [](TomlReader& r, LoomConfig& c) { r.string("telemetry.lcm_url", c.telemetry.lcm_url); };
      url.value = [](const LoomConfig& c) { return c.telemetry.lcm_url; };
      v.push_back(url);
    }
    v.push_back(integer<std::uint32_t>("telemetry.status_every", M::kRun, 1, 1'000'000, [](LoomConfig& c) -> std::uint32_t& { return c.telemetry.status_every; }));
    v.push_back(integer<std::uint32_t>("telemetry.axes_every", M::kRun, 1, 1'000'000, [](LoomConfig& c) -> std::uint32_t& { return c.telemetry.axes_every; }));
    v.push_back(integer<std::uint32_t>("telemetry.rt_every", M::kRun, 1, 1'000'000, [](LoomConfig& c) -> std::uint32_t& { return c.telemetry.rt_every; }));
    return v;
  }();
  return k;
}

const std::set<std::string>& known_sections() {
  static const std::set<std::string> s = [] {
    std::set<std::string> out;
    for (const Key& k : keys()) out.insert(k.path.substr(0, k.path.find('.')));
    return out;
  }();
  return s;
}

// Where a derived problem is reported: the key in the file that the user can change to fix it.
using Fail = std::function<void(const std::string& key, const std::string& value, const std::string& why)>;

// ---------------------------------------------------------------------------------------------------
// Cross-field checks (each at the line that is wrong)
// ---------------------------------------------------------------------------------------------------
void check_relations(const TomlReader& r, const LoomConfig& c) {
  const auto present = [&](const std::string& path) { return r.root().at_path(path).node() != nullptr; };
  // A duplicated node id is reported at its second use (in file order, whichever key repeats it).
  {
    struct Use { const char* key; std::uint8_t id; };
    std::vector<Use> uses{{"can.node_beat_crank", c.can.node_beat_crank}, {"can.node_carriage", c.can.node_carriage},
                          {"can.node_helix", c.can.node_helix}};
    std::stable_sort(uses.begin(), uses.end(), [&](const Use& a, const Use& b) {
      const toml::node* na = r.root().at_path(a.key).node();
      const toml::node* nb = r.root().at_path(b.key).node();
      const auto line = [](const toml::node* n) { return n ? n->source().begin.line : 0u; };
      return line(na) < line(nb);
    });
    for (std::size_t i = 1; i < uses.size(); ++i) {
      for (std::size_t j = 0; j < i; ++j) {
        if (uses[i].id == uses[j].id) {
          const char* at = present(uses[i].key) ? uses[i].key : uses[j].key;
          r.fail(at, std::to_string(uses[i].id),
                 std::string("node id already used by ") + (at == uses[i].key ? uses[j].key : uses[i].key));
        }
      }
    }
  }
  const auto& m = c.machine_spec;
  // The beat-up must be a Grashof crank-rocker: the crank turns fully, the rocker swings the beater.
  if (motion::classify(m.beatup.bar) != motion::GrashofClass::kCrankRocker) {
    const auto& b = m.beatup.bar;
    std::ostringstream os;
    os << "the linkage (crank " << b.crank << ", coupler " << b.coupler << ", rocker " << b.rocker << ", ground "
       << b.ground << " m) is a " << motion::grashof_class_name(motion::classify(b))
       << ", not a crank-rocker: the crank must be the shortest link and shortest + longest <= the other two";
    r.fail("beatup.crank_m", fmt_num(b.crank), os.str());
  }
  if (m.beater_width_m >= m.width_m) {
    r.fail("beatup.beater_width_m", fmt_num(m.beater_width_m), "must be narrower than loom.width_m = " + fmt_num(m.width_m));
  }
  if (c.recipe.overlap_m >= m.beater_width_m) {
    r.fail("recipe.overlap_m", fmt_num(c.recipe.overlap_m),
           "must be less than beatup.beater_width_m = " + fmt_num(m.beater_width_m) + " (the carriage must step forward)");
  }
  if (c.recipe.beat_force_min_n >= c.recipe.beat_force_max_n) {
    r.fail("recipe.beat_force_max_n", fmt_num(c.recipe.beat_force_max_n),
           "must exceed recipe.beat_force_min_n = " + fmt_num(c.recipe.beat_force_min_n));
  }
  if (c.recipe.beat_force_target_n > 0.0 &&
      (c.recipe.beat_force_target_n < c.recipe.beat_force_min_n || c.recipe.beat_force_target_n > c.recipe.beat_force_max_n)) {
    r.fail("recipe.beat_force_target_n", fmt_num(c.recipe.beat_force_target_n),
           "must lie in the band [beat_force_min_n, beat_force_max_n] = [" + fmt_num(c.recipe.beat_force_min_n) + ", " +
               fmt_num(c.recipe.beat_force_max_n) + "]");
  }
  if (c.run.stale_timeout_s < 2.0 * c.run.period_s) {
    r.fail("timing.stale_timeout_ms", fmt_num(c.run.stale_timeout_s * 1e3),
           "must be at least two periods (timing.period_ms = " + fmt_num(c.run.period_s * 1e3) + ")");
  }
  if (m.shed.release_timeout_s >= m.shed.timeout_s) {
    r.fail("shedding.release_timeout_s", fmt_num(m.shed.release_timeout_s),
           "must be shorter than shedding.timeout_s = " + fmt_num(m.shed.timeout_s));
  }
}

// The CAN master's own validation (drives and I/O module), with its complaint pinned to the key that
// sets the field; the worst-case bus load counts every node's frames.
void check_can(const LoomConfig& c, const Fail& fail) {
  const drivers::CanAxisPortConfig cc = can_axis_config(c);
  if (const drivers::Status s = drivers::validate(cc); !s) {
    const std::string& msg = s.message();
    std::string key = "can.heartbeat_timeout_ms", value = std::to_string(c.can.heartbeat_timeout_ms);
    if (msg.find("heartbeat_producer") == 0) key = "can.heartbeat_ms", value = std::to_string(c.can.heartbeat_ms);
    if (msg.find("master_heartbeat") == 0) key = "can.master_heartbeat_ms", value = std::to_string(c.can.master_heartbeat_ms);
    if (msg.find("master_consumer") == 0) key = "can.master_consumer_ms", value = std::to_string(c.can.master_consumer_ms);
    if (msg.find("sdo") == 0) key = "can.sdo_timeout_ms", value = std::to_string(c.can.sdo_timeout_ms);
    if (msg.find("counts_per_unit") != std::string::npos) key = "can.counts_per_rev", value = fmt_num(c.can.counts_per_rev);
    if (msg.find("bus") != std::string::npos || msg.find("bit") != std::string::npos) {
      key = "can.bus_load_budget", value = fmt_num(c.can.bus_load_budget);
    }
    fail(key, value, "the CAN master refuses it: " + msg);
  }
  if (c.io.kind == IoKind::kCan) {
    for (std::size_t i = 0; i < hal::kAxisCount; ++i) {
      if (cc.axes[i].node_id == c.io.node) {
        fail("io.node", std::to_string(c.io.node),
             std::string("node id already used by the ") + hal::axis_name(static_cast<hal::Axis>(i)) + " drive");
      }
    }
    if (const drivers::Status s = drivers::validate(can_io_config(c)); !s) {
      // The driver names the signal ("io.inputs.estop_ok.bit = 3 ..."): point at that signal's key.
      std::string key = "io.node", value = std::to_string(c.io.node);
      const std::string& msg = s.message();
      for (const Key& k : keys()) {
        if (k.path.rfind("io.", 0) != 0 || k.path.size() < 4) continue;
        const std::string name = k.path.substr(3, k.path.rfind('_') - 3);
        if (k.path.size() > 4 && k.path.substr(k.path.size() - 4) == "_bit" && msg.find("." + name + ".") != std::string::npos) {
          key = k.path, value = k.value(c);
          break;
        }
      }
      fail(key, value, "the I/O module refuses it: " + msg);
    }
  }
  if (const drivers::Status s = drivers::check_bus_load(can_bus_load(c), c.can.bus_load_budget); !s) {
    fail("can.bus_load_budget", fmt_num(c.can.bus_load_budget), s.message());
  }
}

// Crank speed at the fell / master speed: 1 at constant speed, the crank law's ratio where the crank
// reaches the fell otherwise.
double beat_speed_ratio(const LoomConfig& c) {
  const Recipe& rc = c.recipe;
  if (rc.crank_law.kind == motion::CrankLawKind::kConstant) return 1.0;
  const motion::BeatUp head(c.machine_spec.beatup);
  const double fell_phase = head.warp().fell;
  const motion::CrankLaw speed_law(rc.crank_law, fell_phase,
                                   {.size = rc.table_size, .interp = rc.table_interp, .precision = rc.table_precision, .rise = 0.0});
  double x = fell_phase;  // Newton on Φc(x) = x + offset(x) = fell; dΦc/dx ≥ min ratio > 0
  for (int i = 0; i < 50; ++i) {
    const motion::CrankLawExact e = speed_law.exact(x);
    const double step = (x + e.offset - fell_phase) / e.d1;
    x -= step;
    if (std::abs(step) < 1e-14) break;
  }
  return speed_law.exact(x).d1;
}

// Crank (master) speed for the recipe: given, or from the beat-force target through the linkage's
// inverse dynamics (the beater force is inertial, so it scales with ω²) and the crank law.
double master_crank_speed(const LoomConfig& c, const Fail& fail) {
  const Recipe& rc = c.recipe;
  if (rc.beat_force_target_n <= 0.0) return rc.crank_speed_rad_s;
  const auto& m = c.machine_spec;
  double crank_speed_at_beat = 0.0;
  try {
    const motion::BeatUpDynamics dyn(m.beatup, motion::beatup_masses(m.beatup, m.beater_mass_kg));
    crank_speed_at_beat = dyn.crank_speed_for_beat_force(rc.beat_force_target_n);
  } catch (const motion::MotionError& e) {
    fail("recipe.beat_force_target_n", fmt_num(rc.beat_force_target_n), e.what());
  }
  // With a speed law the crank is faster (or slower) than the master at the beat: the master runs at
  // the crank speed divided by the law's ratio where the crank reaches the fell.
  const double master = crank_speed_at_beat / beat_speed_ratio(c);
  if (!std::isfinite(master) || master < 0.1 || master > 100.0) {
    fail("recipe.beat_force_target_n", fmt_num(rc.beat_force_target_n),
         "needs a crank speed of " + fmt_num(master) + " rad/s, outside the crank's [0.1, 100] rad/s");
  }
  return master;
}

void derive(LoomConfig& c, const Fail& fail) {
  const MachineSpec& m = c.machine_spec;
  const Recipe& rc = c.recipe;
  c.beat_force_target_n = rc.beat_force_target_n > 0.0 ? rc.beat_force_target_n : 0.0;

  motion::ProfileSpec& p = c.profile;
  p = motion::ProfileSpec{};
  p.beatup = m.beatup;
  p.width_m = m.width_m;
  p.beater_width_m = m.beater_width_m;
  p.overlap_m = rc.overlap_m;
  p.beats_per_position = rc.beats_per_position;
  p.crank = {.velocity = 0.0, .acceleration = rc.crank_accel_rad_s2, .jerk = rc.crank_jerk_rad_s3};
  p.crank_law = rc.crank_law;
  p.cam_margin_rad = rc.cam_margin_rad;
  p.carriage_max_speed_m_s = m.carriage_max_speed_m_s;
  p.carriage_max_accel_m_s2 = m.carriage_max_accel_m_s2;
  p.carriage_max_jerk_m_s3 = m.carriage_max_jerk_m_s3;
  p.helix_lead_m = m.helix_lead_m;
  p.helix = m.helix;
  p.carrier_force_n = m.carrier_force_n;
  p.shuttle_mass_kg = m.shuttle_mass_kg;
  p.shed = m.shed;
  p.table_size = rc.table_size;
  p.table_interp = rc.table_interp;
  p.table_precision = rc.table_precision;
  p.max_table_error_rad = rc.max_table_error_rad;
  p.crank.velocity = master_crank_speed(c, fail);

  sequencer::SequencerConfig& s = c.sequencer;
  s = sequencer::SequencerConfig{};
  s.period_s = c.run.period_s;
  s.picks_per_row = rc.picks_per_row;
  s.knotting = rc.knotting;
  s.debounce_ticks = c.run.debounce_ticks;
  s.sensor_discrepancy_s = c.run.sensor_discrepancy_s;
  for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i) s.second_channel[i] = c.io.wiring.second[i].bit >= 0;
  s.enable_timeout_s = c.run.enable_timeout_s;
  s.pick_timeout_margin_s = c.run.pick_timeout_margin_s;
  s.row_save_timeout_s = c.run.row_save_timeout_s;
  s.stale_timeout_s = c.run.stale_timeout_s;
  s.crank_park_position_rad = m.calibration.crank_park_position_rad;
  s.carriage_home_m = m.calibration.carriage_home_m;
  s.helix_left_position_rad = m.calibration.helix_left_position_rad;
  s.beat_force_min_n = rc.beat_force_min_n;
  s.beat_force_max_n = rc.beat_force_max_n;
  s.carriage = {.velocity = m.carriage_max_speed_m_s, .acceleration = m.carriage_max_accel_m_s2,
                .jerk = m.carriage_reposition_jerk_m_s3};

  sim_hal::SimMachine& sm = c.machine;
  sm = sim_hal::SimMachine{};
  sm.period_s = c.run.period_s;
  sm.width_m = m.width_m;
  sm.helix_lead_m = m.helix_lead_m;
  sm.piston_travel_s = m.shed.piston_travel_s;
  sm.beatup = m.beatup;
  sm.crank_park_position_rad = m.calibration.crank_park_position_rad;
  sm.second_channel = s.second_channel;
}

// The derived motion must be buildable, fit the sequencer's fixed capacities and end in finite time.
void check_motion(const LoomConfig& c, const Fail& fail) {
  const bool from_force = c.recipe.beat_force_target_n > 0.0;
  const std::string speed_key = from_force ? "recipe.beat_force_target_n" : "recipe.crank_speed_rad_s";
  const std::string speed_value = fmt_num(from_force ? c.recipe.beat_force_target_n : c.recipe.crank_speed_rad_s);
  std::optional<motion::ProfileSet> set;
  try {
    set.emplace(c.profile);
  } catch (const motion::MotionError& e) {
    std::string why = std::string("motion profiles cannot be built: ") + e.what();
    if (from_force) why += " (the force target asks for a crank speed of " + fmt_num(c.profile.crank.velocity) + " rad/s)";
    fail(speed_key, speed_value, why);
  }
  if (set->beats_per_row() > sequencer::kMaxBeatsPerRow) {
    fail("recipe.beats_per_position", std::to_string(c.recipe.beats_per_position),
         "gives " + std::to_string(set->beats_per_row()) + " beats per row on a " + fmt_num(c.machine_spec.width_m) +
             " m loom; the sequencer holds at most " + std::to_string(sequencer::kMaxBeatsPerRow));
  }
  const double pick_s = set->pick().duration(), sweep_s = set->crank_sweep().duration();
  if (!std::isfinite(pick_s) || pick_s <= 0.0 || pick_s > 600.0) {
    fail("helix.max_accel_rad_s2", fmt_num(c.machine_spec.helix.acceleration),
         "a pick would take " + fmt_num(pick_s) + " s (must end within 600 s)");
  }
  const double row_s = c.recipe.picks_per_row * (c.machine_spec.shed.timeout_s + pick_s) + sweep_s;
  if (!std::isfinite(sweep_s) || !std::isfinite(row_s) || row_s > kMaxRowSeconds) {
    fail(speed_key, speed_value,
         "a row would take up to " + fmt_num(row_s) + " s (beat sweep " + fmt_num(sweep_s) + " s); at most " +
             fmt_num(kMaxRowSeconds) + " s");
  }
}

// The loop period must resolve the beat. A beat presses the comb into the fell for only a short arc of
// crank (the simulated load cell: the last 5 mm of the tip's travel, about 33 deg of crank); its force
// rises through the contact and peaks as the beater leaves the cloth. The load cell is read once per
// tick, so the peak the sequencer records (and checks against the band) can come up to one tick of crank
// travel early. Measured with the default scene and recipe (90 N target, 80..100 N band, 16.06 rad/s):
//   period ms    2     4     5     8     10    12    15    16    18    19    20
//   deg/tick     1.8   3.7   4.6   7.4   9.2   11.0  13.8  14.7  16.6  17.5  18.4
//   min peak N   89.3  88.7  88.3  86.9  85.6  84.2  82.6  81.6  79.8  78.4  78.8
// about 0.45..0.6 N lost per degree of crank per tick, so 20 ms beats fall out of the band. The sampling
// may use at most half of the band's 10 N headroom below the target (the other half is for servo lag,
// load-cell noise and speed ripple): at most 10 deg of crank per tick at the beat, which loses ~4.6 N.
constexpr double kMaxBeatCrankDegPerTick = 10.0;

void check_beat_resolution(const LoomConfig& c, const Fail& fail) {
  const double omega = c.profile.crank.velocity * beat_speed_ratio(c);  // crank speed at the fell (rad/s)
  const double deg_per_tick = motion::deg(omega * c.run.period_s);
  if (!(deg_per_tick > kMaxBeatCrankDegPerTick)) return;
  // The largest period this recipe allows, rounded down to 0.01 ms so that it is itself accepted.
  const double max_period_ms = std::floor(motion::rad(kMaxBeatCrankDegPerTick) / omega * 1e5) / 100.0;
  char why[512];
  std::snprintf(why, sizeof why,
                "the crank turns %.1f deg per tick at the beat (%.2f rad/s); at most %.0f deg per tick, i.e. "
                "period_ms <= %.2f for this recipe: a beat's contact with the fell lasts only a few ticks and the "
                "load cell, read once per tick, can miss its peak by up to a tick of crank travel (simulated at "
                "20 ms with the default recipe: beats down to 78.8 N against the 80 N minimum)",
                deg_per_tick, omega, kMaxBeatCrankDegPerTick, max_period_ms);
  fail("timing.period_ms", fmt_num(c.run.period_s * 1e3), why);
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
        r.fail_missing(k.path, "missing: a config file must be complete, or begin with extends = \"default\" to take "
                               "what it does not say from the embedded default loom");
      }
    }
  }
  // The crank speed is given, or follows from a beat-force target: exactly one of the two.
  const bool speed = present("recipe.crank_speed_rad_s"), force = present("recipe.beat_force_target_n");
  if (speed && force) {
    r.fail("recipe.crank_speed_rad_s", fmt_num(c.recipe.crank_speed_rad_s), "give either beat_force_target_n or crank_speed_rad_s, not both");
  }
  if (speed) c.recipe.beat_force_target_n = 0.0;
  if (force) c.recipe.crank_speed_rad_s = 0.0;
  if (!speed && !force && !base) {
    r.fail_missing("recipe.beat_force_target_n", "missing: give beat_force_target_n (N) or crank_speed_rad_s (rad/s)");
  }
  r.reject_unknown(known_sections());
  check_relations(r, c);
  const Fail fail = [&](const std::string& key, const std::string& value, const std::string& why) {
    if (present(key)) r.fail(key, value, why);
    throw ConfigError(source + ": " + key + " = " + value + " (from the embedded default): " + why);
  };
  derive(c, fail);
  check_can(c, fail);
  check_motion(c, fail);
  check_beat_resolution(c, fail);
  return c;
}

}  // namespace

void derive_module_configs(LoomConfig& c) {
  derive(c, [&](const std::string& key, const std::string& value, const std::string& why) {
    throw ConfigError(c.source + ": " + key + " = " + value + ": " + why);
  });
}

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

drivers::CanAxisPortConfig can_axis_config(const LoomConfig& c) {
  drivers::CanAxisPortConfig cc;
  const double counts_per_rad = c.can.counts_per_rev / (2.0 * M_PI);
  const std::array<std::uint8_t, 3> nodes{c.can.node_beat_crank, c.can.node_carriage, c.can.node_helix};
  const std::array<double, 3> counts{counts_per_rad, c.can.carriage_counts_per_m, counts_per_rad};
  for (std::size_t i = 0; i < hal::kAxisCount; ++i) {
    drivers::CanAxisConfig& a = cc.axes[i];
    a.node_id = nodes[i];
    a.counts_per_unit = counts[i];
    a.rated_effort = 0.0;
    a.ferror_min = c.can.ferror_min[i];
    a.ferror_k_s = c.can.ferror_k_s[i];
    a.boot_timeout_s = c.can.boot_timeout_ms[i] * 1e-3;
    a.operational_timeout_s = c.can.operational_timeout_ms[i] * 1e-3;
  }
  cc.cycle_period_s = c.run.period_s;
  cc.heartbeat_producer_s = c.can.heartbeat_ms * 1e-3;
  cc.heartbeat_consumer_s = c.can.heartbeat_timeout_ms * 1e-3;
  cc.sdo_timeout_s = c.can.sdo_timeout_ms * 1e-3;
  cc.bitrate_bps = c.can.bitrate;
  cc.bus_load_budget = c.can.bus_load_budget;
  cc.master_node_id = c.can.master_node;
  cc.master_heartbeat_s = c.can.master_heartbeat_ms * 1e-3;
  cc.master_consumer_s = c.can.master_consumer_ms * 1e-3;
  if (c.io.kind == IoKind::kCan) cc.other_frames_per_cycle = drivers::io_frames_per_cycle(c.io.wiring);
  return cc;
}

drivers::CanIoConfig can_io_config(const LoomConfig& c) {
  drivers::CanIoConfig ic;
  ic.node_id = c.io.node;
  ic.wiring = c.io.wiring;
  ic.cycle_period_s = c.run.period_s;
  ic.heartbeat_producer_s = c.can.heartbeat_ms * 1e-3;
  ic.heartbeat_consumer_s = c.can.heartbeat_timeout_ms * 1e-3;
  ic.sdo_timeout_s = c.can.sdo_timeout_ms * 1e-3;
  ic.boot_timeout_s = c.io.boot_timeout_ms * 1e-3;
  ic.operational_timeout_s = c.io.operational_timeout_ms * 1e-3;
  ic.master_node_id = c.can.master_node;
  ic.master_consumer_s = c.can.master_consumer_ms * 1e-3;
  return ic;
}

drivers::BusLoad can_bus_load(const LoomConfig& c) {
  const drivers::CanAxisPortConfig cc = can_axis_config(c);
  return drivers::planned_bus_load(cc);
}

LoomConfig parse_loom_config(const std::string& text, const std::string& source) {
  // `extends` is read before anything else: it decides whether missing keys are errors.
  const TomlReader probe(text, source);
  if (const toml::node* ext = probe.root().get("extends")) {
    const auto name = ext->value<std::string>();
    if (!name || *name != "default") {
      probe.fail("extends", name ? '"' + *name + '"' : "?", "only \"default\" (the embedded default loom) can be extended");
    }
    static const LoomConfig base = parse_complete(kDefaultLoomToml, "<embedded default_loom.toml>", nullptr);
    return parse_complete(text, source, &base);
  }
  return parse_complete(text, source, nullptr);
}

LoomConfig load_loom_config(const std::string& path) { return parse_loom_config(read_file(path), path); }
LoomConfig default_loom_config() { return parse_loom_config(kDefaultLoomToml, "<embedded default_loom.toml>"); }

std::string restart_only_changes(const LoomConfig& running, const LoomConfig& next) {
  std::string out;
  for (const Key& k : keys()) {
    if (k.klass == Klass::kRecipe) continue;
    const std::string a = k.value(running), b = k.value(next);
    if (a != b) out += (out.empty() ? "" : ", ") + k.path + " " + a + " -> " + b;
  }
  return out;
}

std::vector<KeyInfo> config_keys() {
  std::vector<KeyInfo> out;
  for (const Key& k : keys()) out.push_back({k.path.c_str(), klass_name(k.klass), k.range});
  return out;
}

}  // namespace loom::firmware

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
#include <utility>
#include <sstream>

#include "loom/drivers/bus_load.hpp"
#include "loom/firmware/config.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/dynamics.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/fourbar.hpp"
#include "loom/motion/mass_properties.hpp"
#include "loom/motion/profile_crank.hpp"
#include "io_modules_config.hpp"
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

// A knotting-head signal of one kind: `io.<name>_bits` (one bit per head, head 1 first) and
// `io.<name>_active_low` (the same part on every head, so one polarity).
void io_head_signals(std::vector<Key>& v, const std::string& name, IoSettings::HeadSignals IoSettings::*member,
                     int max_bits) {
  const std::string path = "io." + name + "_bits";
  Key bits{path, Klass::kMachine,
           "one bit per knotting head, each in [0, " + std::to_string(max_bits - 1) + "] (integer)", true, nullptr,
           nullptr};
  bits.read = [=](TomlReader& r, LoomConfig& c) {
    r.integer_list(path, (c.io.*member).bits, 0, max_bits - 1, hal::kMaxKnottingHeads);
  };
  bits.value = [=](const LoomConfig& c) {
    std::string out;
    for (int b : (c.io.*member).bits) out += (out.empty() ? "" : ",") + std::to_string(b);
    return out;
  };
  v.push_back(bits);
  v.push_back(boolean("io." + name + "_active_low", Klass::kMachine,
                      [member](LoomConfig& c) -> bool& { return (c.io.*member).active_low; }));
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
    v.push_back(integer<std::uint16_t>("can.heartbeat_ms", M::kMachine, 10, 10000, [](LoomConfig& c) -> std::uint16_t& { return c.can.heartbeat_ms; }));
    v.push_back(integer<std::uint16_t>("can.heartbeat_timeout_ms", M::kMachine, 10, 30000, [](LoomConfig& c) -> std::uint16_t& { return c.can.heartbeat_timeout_ms; }));
    v.push_back(integer<std::uint16_t>("can.sdo_timeout_ms", M::kMachine, 10, 10000, [](LoomConfig& c) -> std::uint16_t& { return c.can.sdo_timeout_ms; }));
    v.push_back(integer<std::uint8_t>("can.master_node", M::kMachine, 0, 127, [](LoomConfig& c) -> std::uint8_t& { return c.can.master_node; }));
    v.push_back(integer<std::uint16_t>("can.master_heartbeat_ms", M::kMachine, 10, 10000, [](LoomConfig& c) -> std::uint16_t& { return c.can.master_heartbeat_ms; }));
    v.push_back(integer<std::uint16_t>("can.master_consumer_ms", M::kMachine, 20, 30000, [](LoomConfig& c) -> std::uint16_t& { return c.can.master_consumer_ms; }));
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
    io_head_signals(v, "gripper_close", &IoSettings::gripper_close, drivers::kIoMaxOutputBits);
    io_head_signals(v, "cutter", &IoSettings::cutter, drivers::kIoMaxOutputBits);
    io_head_signals(v, "yarn_present", &IoSettings::yarn_present, drivers::kIoMaxInputBits);
    // [knotting] — the pile (machine: the heads are hardware)
    v.push_back(choice<sequencer::KnottingMode>("knotting.mode", M::kMachine, {"none", "weaver", "heads"},
                                                [](LoomConfig& c) -> sequencer::KnottingMode& { return c.knotting.mode; },
                                                sequencer::knotting_mode_name, sequencer::parse_knotting_mode));
    v.push_back(choice<sequencer::KnotType>("knotting.knot", M::kMachine, {"turkish", "persian_left", "persian_right"},
                                            [](LoomConfig& c) -> sequencer::KnotType& { return c.knotting.knot; },
                                            sequencer::knot_type_name, sequencer::parse_knot_type));
    v.push_back(number("knotting.knots_per_dm", M::kMachine, 5.0, 200.0, [](LoomConfig& c) -> double& { return c.knotting.knots_per_dm; }));
    v.push_back(number("knotting.rows_per_dm", M::kMachine, 5.0, 200.0, [](LoomConfig& c) -> double& { return c.knotting.rows_per_dm; }));
    v.push_back(integer<int>("knotting.heads", M::kMachine, 1, sequencer::kMaxKnottingHeads,
                             [](LoomConfig& c) -> int& { return c.knotting.heads; }));
    v.push_back(number("knotting.head_spacing_m", M::kMachine, 0.005, 10.0, [](LoomConfig& c) -> double& { return c.knotting.head_spacing_m; }));
    {
      Key slots{"knotting.slot_colours", M::kMachine, "design palette codes, one per magazine slot (at most 16)", true,
                nullptr, nullptr};
      slots.read = [](TomlReader& r, LoomConfig& c) { r.string_list("knotting.slot_colours", c.knotting.slot_colours); };
      slots.value = [](const LoomConfig& c) {
        std::string out;
        for (const auto& code : c.knotting.slot_colours) out += (out.empty() ? "" : ",") + code;
        return out;
      };
      v.push_back(slots);
    }
    v.push_back(integer<int>("knotting.knots_per_slot", M::kMachine, 1, 1'000'000,
                             [](LoomConfig& c) -> int& { return c.knotting.knots_per_slot; }));
    v.push_back(number("knotting.take_position_rad", M::kMachine, -1e6, 1e6, [](LoomConfig& c) -> double& { return c.knotting.take_position_rad; }));
    v.push_back(number("knotting.selector_zero_rad", M::kMachine, -1e6, 1e6, [](LoomConfig& c) -> double& { return c.knotting.selector_zero_rad; }));
    v.push_back(number("knotting.selector_accel_rad_s2", M::kMachine, 1.0, 1e6, [](LoomConfig& c) -> double& { return c.knotting.selector_accel_rad_s2; }));
    v.push_back(number("knotting.selector_jerk_rad_s3", M::kMachine, 10.0, 1e9, [](LoomConfig& c) -> double& { return c.knotting.selector_jerk_rad_s3; }));
    // The knotting servo (its top speed is the knotter axes' max_speed) and the gripper's dwells.
    using KC = motion::KnotCycleSpec;
    const auto kc = [](double KC::*f) { return [f](LoomConfig& c) -> double& { return c.knot_cycle.*f; }; };
    v.push_back(number("knotting.servo_accel_rad_s2", M::kMachine, 1.0, 1e6, kc(&KC::max_accel_rad_s2)));
    v.push_back(number("knotting.servo_jerk_rad_s3", M::kMachine, 10.0, 1e9, kc(&KC::jerk_rad_s3)));
    v.push_back(number("knotting.servo_torque_nm", M::kMachine, 1e-5, 100.0, kc(&KC::max_torque_nm)));
    v.push_back(number("knotting.servo_rotor_inertia_kg_m2", M::kMachine, 0.0, 1.0, kc(&KC::rotor_inertia_kg_m2)));
    v.push_back(millis("knotting.grip_ms", M::kMachine, 1.0, 5000.0, kc(&KC::grip_s)));
    v.push_back(millis("knotting.cut_ms", M::kMachine, 1.0, 5000.0, kc(&KC::cut_s)));
    v.push_back(millis("knotting.release_ms", M::kMachine, 1.0, 5000.0, kc(&KC::release_s)));
    v.push_back(degrees("knotting.min_transmission_deg", M::kMachine, 1.0, 89.0, kc(&KC::min_transmission_rad)));
    // [knotting.linkage] — seed 001's four-bar as `loom-synth knotter` prints it (checked when the cycle is built).
    const char* point_names[] = {"take", "wrap", "pull"};
    for (std::size_t i = 0; i < 3; ++i) {
      const std::string p = std::string("knotting.linkage.") + point_names[i];
      v.push_back(number(p + "_x_m", M::kMachine, -1.0, 1.0, [i](LoomConfig& c) -> double& { return c.knot_cycle.points[i].x_m; }));
      v.push_back(number(p + "_y_m", M::kMachine, -1.0, 1.0, [i](LoomConfig& c) -> double& { return c.knot_cycle.points[i].y_m; }));
      v.push_back(degrees(p + "_gripper_deg", M::kMachine, -360.0, 360.0,
                          [i](LoomConfig& c) -> double& { return c.knot_cycle.points[i].gripper_rad; }));
    }
    v.push_back(degrees("knotting.linkage.theta0_deg", M::kMachine, -360.0, 360.0, kc(&KC::theta0_rad)));
    v.push_back(number("knotting.linkage.crank_pivot_x_m", M::kMachine, -1.0, 1.0, kc(&KC::crank_pivot_x_m)));
    v.push_back(number("knotting.linkage.crank_pivot_y_m", M::kMachine, -1.0, 1.0, kc(&KC::crank_pivot_y_m)));
    v.push_back(number("knotting.linkage.rocker_pivot_x_m", M::kMachine, -1.0, 1.0, kc(&KC::rocker_pivot_x_m)));
    v.push_back(number("knotting.linkage.rocker_pivot_y_m", M::kMachine, -1.0, 1.0, kc(&KC::rocker_pivot_y_m)));
    const auto link = [](motion::KnotLinkSpec KC::*l, double motion::KnotLinkSpec::*f) {
      return [l, f](LoomConfig& c) -> double& { return (c.knot_cycle.*l).*f; };
    };
    const struct {
      const char* name;
      motion::KnotLinkSpec KC::*link;
    } links[] = {{"crank", &KC::crank}, {"coupler", &KC::coupler}, {"rocker", &KC::rocker}};
    for (const auto& l : links) {
      const std::string p = std::string("knotting.linkage.") + l.name;
      v.push_back(number(p + "_m", M::kMachine, 1e-4, 1.0, link(l.link, &motion::KnotLinkSpec::length_m)));
    }
    v.push_back(number("knotting.linkage.gripper_along_m", M::kMachine, -1.0, 1.0, kc(&KC::gripper_along_m)));
    v.push_back(number("knotting.linkage.gripper_normal_m", M::kMachine, -1.0, 1.0, kc(&KC::gripper_normal_m)));
    v.push_back(choice<motion::Branch>("knotting.linkage.branch", M::kMachine, {"positive", "negative"},
                                       [](LoomConfig& c) -> motion::Branch& { return c.knot_cycle.branch; },
                                       branch_name, parse_branch));
    for (const auto& l : links) {
      const std::string p = std::string("knotting.linkage.") + l.name;
      v.push_back(number(p + "_mass_kg", M::kMachine, 0.0, 10.0, link(l.link, &motion::KnotLinkSpec::mass_kg)));
      v.push_back(number(p + "_cg_m", M::kMachine, -1.0, 1.0, link(l.link, &motion::KnotLinkSpec::cg_m)));
      v.push_back(number(p + "_inertia_kg_m2", M::kMachine, 0.0, 1.0, link(l.link, &motion::KnotLinkSpec::inertia_kg_m2)));
    }
    v.push_back(number("knotting.linkage.warp_entry_x_m", M::kMachine, -1.0, 1.0, kc(&KC::warp_entry_x_m)));
    // [recipe]
    v.push_back(integer<std::uint32_t>("recipe.picks_per_row", M::kRecipe, 1, 16, [](LoomConfig& c) -> std::uint32_t& { return c.recipe.picks_per_row; }));
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
    out.insert("axes");        // [axes.<name>] tables, read by read_axes()
    out.insert("io_modules");  // [io_modules.<name>] tables, read by read_io_modules()
    return out;
  }();
  return s;
}

// Where a derived problem is reported: the key in the file that the user can change to fix it.
using Fail = std::function<void(const std::string& key, const std::string& value, const std::string& why)>;

// ---------------------------------------------------------------------------------------------------
// The axes: [axes.<name>] tables, one per servo axis
// ---------------------------------------------------------------------------------------------------
constexpr std::int64_t kMaxBuses = 4;  // CAN interfaces one controller drives

struct AxisKeyInfo {
  const char* path;
  const char* range;
};
const std::vector<AxisKeyInfo>& axis_keys() {
  static const std::vector<AxisKeyInfo> k{
      {"axes.<name>.role", "beat_crank | carriage | helix | knotter | selector | auxiliary"},
      {"axes.<name>.node", "[1, 127] (integer)"},
      {"axes.<name>.bus", "[0, 3] (integer): 0 = the first CAN interface; default 0"},
      {"axes.<name>.counts_per_rev", "[16, 2147483648]"},
      {"axes.<name>.lead_m", "[0.0001, 1] (linear axes only)"},
      {"axes.<name>.max_speed", "[0.001, 1000] rad/s or m/s (added axes only)"},
      {"axes.<name>.ferror_min", "[0, 100] rad, [0, 1] m; 0 = off"},
      {"axes.<name>.ferror_k_s", "[0, 10]"},
      {"axes.<name>.boot_ms", "[0, 60000] (integer); 0 = 2000 ms"},
      {"axes.<name>.operational_ms", "[0, 60000] (integer); 0 = can.heartbeat_timeout_ms"},
      {"axes.<name>.referencing", "absolute | homing"},
      {"axes.<name>.homing_method", "19 | 21 (home switch) | 33 | 34 (index pulse) | 37 (where it stands)"},
      {"axes.<name>.home_offset", "[-1e5, 1e5] rad or m: the reading at the home point"},
      {"axes.<name>.homing_speed", "[1e-4, 100] rad/s or m/s"},
      {"axes.<name>.homing_accel", "[1e-3, 1e5] rad/s^2 or m/s^2"},
      {"axes.<name>.homing_timeout_s", "[0.1, 600]"},
  };
  return k;
}

// The canonical text of the axes, to tell a restart-only change.
std::string axes_text(const LoomConfig& c) {
  std::ostringstream os;
  for (const AxisSpec& a : c.axes) {
    os << "[" << a.name << " " << hal::axis_role_name(a.role) << " node " << int{a.node} << " " << fmt_num(a.counts_per_rev)
       << "/rev bus " << int{a.bus} << " lead " << fmt_num(a.lead_m) << " vmax " << fmt_num(a.max_speed) << " ferror " << fmt_num(a.ferror_min) << "+"
       << fmt_num(a.ferror_k_s) << "s boot " << a.boot_ms << " op " << a.operational_ms;
    if (a.homing) {
      os << " homing " << a.homing_method << " at " << fmt_num(a.home_offset) << " " << fmt_num(a.homing_speed) << "/s "
         << fmt_num(a.homing_accel) << "/s2 " << fmt_num(a.homing_timeout_s) << "s";
    }
    os << "]";
  }
  return os.str();
}

// Keys of the three-axis layout that became [axes.<name>] tables: a file that still says them is refused
// with the line and where the fact lives now (a typo-proof migration: nothing is silently ignored).
void refuse_moved_keys(TomlReader& r) {
  static const struct {
    const char* old_key;
    const char* now;
  } moved[] = {
      {"can.node_beat_crank", "axes.beat_crank.node"},           {"can.node_carriage", "axes.carriage.node"},
      {"can.node_helix", "axes.helix.node"},                     {"can.counts_per_rev", "axes.<name>.counts_per_rev of each rotary axis"},
      {"can.carriage_counts_per_m", "axes.carriage.counts_per_rev and axes.carriage.lead_m (counts per m = counts_per_rev / lead_m)"},
      {"can.beat_crank_boot_ms", "axes.beat_crank.boot_ms"},     {"can.beat_crank_operational_ms", "axes.beat_crank.operational_ms"},
      {"can.beat_crank_ferror_min_rad", "axes.beat_crank.ferror_min"}, {"can.beat_crank_ferror_k_s", "axes.beat_crank.ferror_k_s"},
      {"can.carriage_boot_ms", "axes.carriage.boot_ms"},         {"can.carriage_operational_ms", "axes.carriage.operational_ms"},
      {"can.carriage_ferror_min_m", "axes.carriage.ferror_min"}, {"can.carriage_ferror_k_s", "axes.carriage.ferror_k_s"},
      {"can.helix_boot_ms", "axes.helix.boot_ms"},               {"can.helix_operational_ms", "axes.helix.operational_ms"},
      {"can.helix_ferror_min_rad", "axes.helix.ferror_min"},     {"can.helix_ferror_k_s", "axes.helix.ferror_k_s"},
      {"recipe.knotting", "knotting.mode (\"none\", \"weaver\" or \"heads\")"},
  };
  for (const auto& m : moved) {
    if (const toml::node* n = r.root().at_path(m.old_key).node()) {
      const auto i = n->value<std::int64_t>();
      const auto d = n->value<double>();
      const std::string shown = n->is_boolean() ? (n->value<bool>().value_or(false) ? "true" : "false")
                                : i             ? std::to_string(*i)
                                : d             ? fmt_num(*d)
                                                : "...";
      r.fail_at(*n, m.old_key, shown, std::string("moved: this fact is ") + m.now +
                                       " (loomctl check --keys lists every key)");
    }
  }
}

bool valid_axis_name(const std::string& n) {
  if (n.empty() || n.size() > hal::AxisLayout::kNameMax) return false;
  return std::all_of(n.begin(), n.end(), [](char ch) { return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_'; });
}

// An axis' referencing: "absolute", or "homing" with its CiA 402 method and parameters (all required
// then, and refused on an absolute axis so a half-changed table never passes).
void read_referencing(TomlReader& r, const toml::node& table, const std::string& p, AxisSpec& a, bool is_new) {
  const auto has = [&](const char* k) { return table.as_table()->get(k) != nullptr; };
  std::string kind = a.homing ? "homing" : "absolute";
  if (is_new && !has("referencing")) r.fail_at(table, p + "referencing", "(missing)", "missing: absolute | homing");
  r.string(p + "referencing", kind, {"absolute", "homing"});
  a.homing = kind == "homing";
  static const char* const keys[] = {"homing_method", "home_offset", "homing_speed", "homing_accel", "homing_timeout_s"};
  if (!a.homing) {
    for (const char* k : keys) {
      if (has(k)) r.fail(p + k, "", "only an axis with referencing = \"homing\" has homing parameters");
    }
    a.homing_method = 0;
    return;
  }
  // Switching an absolute axis to homing must say every parameter (there are no defaults to inherit).
  const bool was_absolute = a.homing_method == 0;
  for (const char* k : keys) {
    if (was_absolute && !has(k)) r.fail_at(table, p + k, "(missing)", "missing: referencing = \"homing\" needs it");
  }
  std::int64_t method = a.homing_method;
  r.integer(p + "homing_method", method, 1, 37);
  if (method != 19 && method != 21 && method != 33 && method != 34 && method != 37) {
    r.fail(p + "homing_method", std::to_string(method),
           "supported CiA 402 methods: 19, 21 (home switch), 33, 34 (index pulse), 37 (current position)");
  }
  a.homing_method = static_cast<int>(method);
  r.number(p + "home_offset", a.home_offset, [](double v) { return in_range(v, -1e5, 1e5); });
  r.number(p + "homing_speed", a.homing_speed, [](double v) { return in_range(v, 1e-4, 100.0); });
  r.number(p + "homing_accel", a.homing_accel, [](double v) { return in_range(v, 1e-3, 1e5); });
  r.number(p + "homing_timeout_s", a.homing_timeout_s, [](double v) { return in_range(v, 0.1, 600.0); });
  if (a.role == hal::AxisRole::kHelix) {
    r.fail(p + "referencing", "\"homing\"",
           "the helix cannot home: a homing run would drag the shuttle's carrier through a shed that may be closed; "
           "give the helix an absolute (multi-turn) encoder");
  }
}

// Reads every [axes.<name>] table over what `c` already holds (the embedded default's axes when the
// file extends it), then puts the axes in slot order and checks the set: each core role exactly once,
// at most hal::kMaxAxes axes.
void read_axes(TomlReader& r, LoomConfig& c, bool extending) {
  r.consume("axes");
  const toml::node* root = r.root().get("axes");
  if (root == nullptr) {
    if (!extending) r.fail_missing("axes", "missing: every loom has [axes.beat_crank], [axes.carriage] and [axes.helix] tables");
    return;
  }
  const toml::table* tables = root->as_table();
  if (tables == nullptr) r.fail_at(*root, "axes", "", "must be tables [axes.<name>]");
  std::vector<std::string> added;
  for (auto&& entry : *tables) {
    // Named references, not a structured binding: lambdas below capture them (clang 14 cannot capture
    // structured bindings).
    const toml::node& node = entry.second;
    const std::string name(entry.first.str());
    const std::string p = "axes." + name + ".";
    if (!valid_axis_name(name)) {
      r.fail_at(node, "axes." + name, "", "an axis name is 1.." + std::to_string(hal::AxisLayout::kNameMax) +
                                            " characters of a-z, 0-9 and _");
    }
    if (!node.is_table()) r.fail_at(node, "axes." + name, "", "must be a table [axes." + name + "]");
    r.consume("axes." + name);
    auto it = std::find_if(c.axes.begin(), c.axes.end(), [&](const AxisSpec& a) { return a.name == name; });
    const bool is_new = it == c.axes.end();
    if (is_new) {
      c.axes.push_back(AxisSpec{});
      c.axes.back().name = name;
      it = c.axes.end() - 1;
      added.push_back(name);
    }
    AxisSpec& a = *it;
    const auto has = [&](const char* k) { return node.as_table()->get(k) != nullptr; };
    const auto need = [&](const char* k, const std::string& why) {
      if (is_new && !has(k)) r.fail_at(node, p + k, "(missing)", why);
    };
    need("role", "missing: what the axis is for (" + std::string(axis_keys()[0].range) + ")");
    if (has("role")) {
      std::string role = hal::axis_role_name(a.role);
      r.string(p + "role", role, {"beat_crank", "carriage", "helix", "knotter", "selector", "auxiliary"});
      hal::parse_axis_role(role.c_str(), a.role);
    }
    const bool core = a.role == hal::AxisRole::kBeatCrank || a.role == hal::AxisRole::kCarriage || a.role == hal::AxisRole::kHelix;
    const bool linear = !hal::is_rotary(a.role);
    need("node", "missing: the CANopen node id of its drive");
    std::int64_t node_id = a.node;
    r.integer(p + "node", node_id, 1, 127);
    a.node = static_cast<std::uint8_t>(node_id);
    std::int64_t bus = a.bus;
    r.integer(p + "bus", bus, 0, kMaxBuses - 1);
    a.bus = static_cast<std::uint8_t>(bus);
        need("counts_per_rev", "missing: encoder counts per motor revolution");
    r.number(p + "counts_per_rev", a.counts_per_rev, [](double v) { return in_range(v, 16.0, 2147483648.0); });
    if (linear) {
      need("lead_m", "missing: a linear axis' travel per motor revolution (m)");
      r.number(p + "lead_m", a.lead_m, [](double v) { return in_range(v, 1e-4, 1.0); });
    } else if (has("lead_m")) {
      r.fail(p + "lead_m", "", "only a linear axis (role carriage) has a lead; a rotary axis is scaled per revolution");
    } else {
      a.lead_m = 0.0;
    }
    if (core && has("max_speed")) {
      r.fail(p + "max_speed", "", "the core axes' speed limits are facts of their mechanisms: [carriage] max_speed_m_s, "
                                  "[helix] max_speed_rad_s, the recipe's crank speed");
    }
    if (!core) {
      need("max_speed", std::string("missing: the axis' top speed (") + (linear ? "m/s" : "rad/s") + ")");
      r.number(p + "max_speed", a.max_speed, [](double v) { return in_range(v, 1e-3, 1e3); });
    } else {
      a.max_speed = 0.0;
    }
    need("ferror_min", std::string("missing: the following-error limit (") + (linear ? "m" : "rad") + "; 0 = off)");
    r.number(p + "ferror_min", a.ferror_min, [linear](double v) { return in_range(v, 0.0, linear ? 1.0 : 100.0); });
    r.number(p + "ferror_k_s", a.ferror_k_s, [](double v) { return in_range(v, 0.0, 10.0); });
    std::int64_t boot = a.boot_ms, op = a.operational_ms;
    r.integer(p + "boot_ms", boot, 0, 60000);
    r.integer(p + "operational_ms", op, 0, 60000);
    a.boot_ms = static_cast<std::uint32_t>(boot);
    a.operational_ms = static_cast<std::uint32_t>(op);
    read_referencing(r, node, p, a, is_new);
  }
  // Slot order: the core roles first (slots 0..2), then the others by name (toml++ keeps keys sorted).
  std::stable_sort(c.axes.begin(), c.axes.end(), [](const AxisSpec& x, const AxisSpec& y) {
    const auto rank = [](const AxisSpec& a) { return std::min(static_cast<int>(a.role), 3); };
    return rank(x) != rank(y) ? rank(x) < rank(y) : (rank(x) == 3 && x.name < y.name);
  });
  for (std::size_t role = 0; role < hal::kCoreAxisCount; ++role) {
    const auto r_ = static_cast<hal::AxisRole>(role);
    const auto n = std::count_if(c.axes.begin(), c.axes.end(), [&](const AxisSpec& a) { return a.role == r_; });
    if (n == 0) r.fail_at(*root, "axes", "", std::string("no axis has role = \"") + hal::axis_role_name(r_) + "\": every loom has one");
    if (n > 1) {
      const AxisSpec& second = c.axes[role + 1];
      r.fail("axes." + second.name + ".role", std::string("\"") + hal::axis_role_name(r_) + "\"",
             "the loom has one " + std::string(hal::axis_role_name(r_)) + " axis (axes." + c.axes[role].name + ")");
    }
  }
  if (c.axes.size() > hal::kMaxAxes) {
    r.fail("axes." + (added.empty() ? c.axes.back().name : added.back()), "",
           std::to_string(c.axes.size()) + " axes; the controller holds at most " + std::to_string(hal::kMaxAxes));
  }
}

// ---------------------------------------------------------------------------------------------------
// Cross-field checks (each at the line that is wrong)
// ---------------------------------------------------------------------------------------------------
// With knotting heads, every row of the recipe's design must be tied by them: its width is the loom's
// knots per row and every colour sits in a magazine slot (refused naming the colour and the first knot).
void check_design_fits_heads(const TomlReader& r, const LoomConfig& c) {
  if (c.knotting.mode != sequencer::KnottingMode::kHeads || !c.recipe.design) return;
  try {
    (void)knot_program(c, 0, 0);
  } catch (const std::invalid_argument& e) {
    r.fail("recipe.design", '"' + c.recipe.design_file + '"', e.what());
  }
}

void check_relations(const TomlReader& r, const LoomConfig& c) {
  const auto present = [&](const std::string& path) { return r.root().at_path(path).node() != nullptr; };
  // A drive's node id is used once on the bus (the I/O module's is checked with it in check_can).
  for (std::size_t i = 1; i < c.axes.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (c.axes[i].node != c.axes[j].node || c.axes[i].bus != c.axes[j].bus) continue;
      const std::string ki = "axes." + c.axes[i].name + ".node", kj = "axes." + c.axes[j].name + ".node";
      const bool i_here = present(ki), j_here = present(kj);
      const toml::node* ni = r.root().at_path(ki).node();
      const toml::node* nj = r.root().at_path(kj).node();
      // At the later of the two lines the file writes (the one the file repeats).
      const bool at_i = i_here && (!j_here || ni->source().begin.line >= nj->source().begin.line);
      r.fail(at_i ? ki : kj, std::to_string(c.axes[i].node), "node id already used by " + (at_i ? kj : ki));
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
  if (const std::string why = sequencer::validate(c.knotting, m.width_m); !why.empty()) {
    const std::string named = why.substr(0, why.find_first_of(" :["));
    const std::string key = present(named) ? named : "knotting.mode";
    std::string value;
    for (const Key& k : keys()) {
      if (k.path == key) value = k.value(c);
    }
    r.fail(key, value, why);
  }
  check_design_fits_heads(r, c);
  if (c.knotting.mode == sequencer::KnottingMode::kHeads) {
    // The knotting linkage must reach its three precision points on one branch, in order, with a usable
    // transmission angle and no dead centre in the stroke, and the servo must move it (the knot cycle's checks).
    try {
      (void)motion::KnotCycle::build(c.knot_cycle);
    } catch (const motion::MotionError& e) {
      r.fail("knotting.linkage.crank_m", fmt_num(c.knot_cycle.crank.length_m), std::string("the knotting linkage: ") + e.what());
    }
  }
  if (c.knotting.mode == sequencer::KnottingMode::kHeads) {
    // One knotting servo and one colour selector per head, in the axes table.
    for (const hal::AxisRole role : {hal::AxisRole::kKnotter, hal::AxisRole::kSelector}) {
      const auto n = std::count_if(c.axes.begin(), c.axes.end(), [&](const AxisSpec& a) { return a.role == role; });
      if (n != c.knotting.heads) {
        r.fail("knotting.heads", std::to_string(c.knotting.heads),
               "the loom has " + std::to_string(n) + " axes with role = \"" + hal::axis_role_name(role) +
                   "\": every head needs its knotting servo and its colour selector ([axes.<name>] role = \"knotter\" "
                   "and role = \"selector\", one of each per head)");
      }
    }
  }
  if (m.shed.release_timeout_s >= m.shed.timeout_s) {
    r.fail("shedding.release_timeout_s", fmt_num(m.shed.release_timeout_s),
           "must be shorter than shedding.timeout_s = " + fmt_num(m.shed.timeout_s));
  }
}

// The key (and its value) a refusal of the CAN master's configuration is pinned to: the key that sets the
// field. Fields no single key sets, or whose own key's range already refuses every bad value, keep the
// keys their refusals have always named (the tests pin the messages): can.heartbeat_timeout_ms, or
// can.bus_load_budget for the bus, bit-rate and axis-count limits.
std::pair<std::string, std::string> can_master_key(const LoomConfig& c, const drivers::CanAxisConfigFault& f) {
  using F = drivers::CanAxisField;
  const AxisSpec* axis = f.axis < c.axes.size() ? &c.axes[f.axis] : nullptr;
  const std::string on_axis = axis != nullptr ? "axes." + axis->name + "." : "";
  switch (f.field) {
    case F::kHeartbeatProducer: return {"can.heartbeat_ms", std::to_string(c.can.heartbeat_ms)};
    case F::kMasterHeartbeat: return {"can.master_heartbeat_ms", std::to_string(c.can.master_heartbeat_ms)};
    case F::kSdoTimeout: return {"can.sdo_timeout_ms", std::to_string(c.can.sdo_timeout_ms)};
    case F::kCountsPerUnit:
      if (axis != nullptr) return {on_axis + "counts_per_rev", fmt_num(axis->counts_per_rev)};
      break;
    case F::kFerrorMin:
    case F::kFerrorK:
      if (axis != nullptr) return {on_axis + "ferror_min", fmt_num(axis->ferror_min)};
      break;
    case F::kHomingMethod:
    case F::kHomingSpeed:
    case F::kHomeOffset:
      if (axis != nullptr) return {on_axis + "homing_method", std::to_string(axis->homing_method)};
      break;
    case F::kNodeId:
    case F::kNodeIdTaken:
      if (axis != nullptr) return {on_axis + "node", std::to_string(axis->node)};
      break;
    case F::kNodeIdIsMaster:  // the drive's node id or the master's, whichever the file says
      if (axis != nullptr) {
        return {on_axis + "node|can.master_node", std::to_string(axis->node) + "|" + std::to_string(c.can.master_node)};
      }
      return {"can.master_node", std::to_string(c.can.master_node)};
    case F::kBus:
      if (axis != nullptr) return {on_axis + "bus", std::to_string(axis->bus)};
      break;
    case F::kMasterNode: return {"can.master_node", std::to_string(c.can.master_node)};
    case F::kAxisCount:
    case F::kBitrate:
    case F::kBusLoadBudget: return {"can.bus_load_budget", fmt_num(c.can.bus_load_budget)};
    case F::kRatedEffort:
    case F::kBringUpTimeouts:
    case F::kCyclePeriod:
    case F::kHeartbeatConsumer:
    case F::kBootTimeout:
    case F::kStateTimeout:
    case F::kTpdo2EveryN:
    case F::kOperationalTimeout:
    case F::kOtherFrames: break;
  }
  return {"can.heartbeat_timeout_ms", std::to_string(c.can.heartbeat_timeout_ms)};
}

// The key (and its value) a refusal of the I/O module's configuration is pinned to: a signal's bit is set
// by io.<signal>_bit (a knotting head's by io.<signal>_bits), as the key table has it; the rest by io.node.
std::pair<std::string, std::string> io_module_key(const LoomConfig& c, const drivers::IoConfigFault& f) {
  if (f.field == drivers::IoField::kSignalBit) {
    const std::string path = "io." + f.signal + (f.head == 0 ? "_bit" : "_bits");
    for (const Key& k : keys()) {
      if (k.path == path) return {k.path, k.value(c)};
    }
  }
  return {"io.node", std::to_string(c.io.node)};
}

// The CAN master's own validation (drives and I/O module), with its complaint pinned to the key that
// sets the field; the worst-case bus load counts every node's frames.
void check_can(const LoomConfig& c, const Fail& fail) {
  const drivers::CanAxisPortConfig cc = can_axis_config(c);
  if (const std::optional<drivers::CanAxisConfigFault> f = drivers::find_fault(cc)) {
    const auto [key, value] = can_master_key(c, *f);
    fail(key, value, "the CAN master refuses it: " + f->message);
  }
  if (c.io.kind == IoKind::kCan) {
    // Node ids are unique per bus: each module against the axes and the modules before it on its bus.
    const std::vector<std::size_t> buses = can_io_buses(c);
    const auto node_key = [&](std::size_t k) { return k == 0 ? std::string("io.node") : "io_modules." + c.io.modules[k - 1].name + ".node"; };
    const auto node_of = [&](std::size_t k) { return k == 0 ? c.io.node : c.io.modules[k - 1].node; };
    for (std::size_t k = 0; k < buses.size(); ++k) {
      for (const AxisSpec& a : c.axes) {
        if (a.bus == buses[k] && a.node == node_of(k)) {
          fail(node_key(k), std::to_string(node_of(k)), "node id already used by axes." + a.name + ".node");
        }
      }
      for (std::size_t j = 0; j < k; ++j) {
        if (buses[j] == buses[k] && node_of(j) == node_of(k)) {
          fail(node_key(k), std::to_string(node_of(k)), "node id already used by " + node_key(j) + " on bus " + std::to_string(buses[k]));
        }
      }
    }
    if (c.knotting.mode == sequencer::KnottingMode::kHeads) {
      // One bit per head: a list of another length is a wiring that does not match the heads fitted.
      for (const auto& [name, signals] : {std::pair{"io.gripper_close_bits", &c.io.gripper_close},
                                          std::pair{"io.cutter_bits", &c.io.cutter},
                                          std::pair{"io.yarn_present_bits", &c.io.yarn_present}}) {
        if (signals->bits.size() != static_cast<std::size_t>(c.knotting.heads)) {
          std::string list;
          for (int b : signals->bits) list += (list.empty() ? "" : ", ") + std::to_string(b);
          fail(name, "[" + list + "]",
               std::to_string(signals->bits.size()) + " bits for knotting.heads = " + std::to_string(c.knotting.heads) +
                   ": one per head, head 1 first");
        }
      }
    }
    if (const std::optional<drivers::IoConfigFault> f = drivers::find_fault(can_io_configs(c).front())) {
      const auto [key, value] = io_module_key(c, *f);
      std::string msg = f->message;
      if (f->shared_module != 0) {  // the driver numbers modules; the file names them
        const std::size_t k = f->shared_module;
        msg += " (both on " +
               (k <= c.io.modules.size() ? "io_modules." + c.io.modules[k - 1].name : "I/O module " + std::to_string(k)) +
               ")";
      }
      fail(key, value, "the I/O module refuses it: " + msg);
    }
  }
  // Each bus has its own master, SYNC and budget: a bus is judged by its own nodes' frames.
  const std::size_t buses = drivers::bus_count(cc);
  for (std::size_t b = 0; b < buses; ++b) {
    if (const drivers::Status s = drivers::check_bus_load(can_bus_load(c, b), c.can.bus_load_budget); !s) {
      fail("can.bus_load_budget", fmt_num(c.can.bus_load_budget),
           buses == 1 ? s.message() : "bus " + std::to_string(b) + ": " + s.message());
    }
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
  s.axes = axis_layout(c);
  for (std::size_t i = hal::kCoreAxisCount; i < c.axes.size(); ++i) s.axis_max_speed[i] = c.axes[i].max_speed;
  for (std::size_t i = 0; i < c.axes.size(); ++i) s.homing_timeout_s[i] = c.axes[i].homing ? c.axes[i].homing_timeout_s : 0.0;
  s.picks_per_row = rc.picks_per_row;
  s.knotting = c.knotting.mode == sequencer::KnottingMode::kWeaver;
  if (c.knotting.mode == sequencer::KnottingMode::kHeads) {
    // Head h drives with the h-th knotter and the h-th selector axis in slot order (names sort: knotter_1,
    // knotter_2, ...). The design program and the knot cycle are built with the machine (they need the
    // design's progress); the selectors' top speed is their axes' max_speed.
    sequencer::KnottingConfig& k = s.heads;
    int knotters = 0, selectors = 0;
    double selector_speed = 1e300;
    for (std::size_t i = hal::kCoreAxisCount; i < c.axes.size(); ++i) {
      if (c.axes[i].role == hal::AxisRole::kKnotter && knotters < sequencer::kMaxKnottingHeads) {
        k.knotter_axis[static_cast<std::size_t>(knotters++)] = static_cast<int>(i);
      } else if (c.axes[i].role == hal::AxisRole::kSelector && selectors < sequencer::kMaxKnottingHeads) {
        k.selector_axis[static_cast<std::size_t>(selectors++)] = static_cast<int>(i);
        selector_speed = std::min(selector_speed, c.axes[i].max_speed);
      }
    }
    double knotter_speed = 1e300;
    for (int h = 0; h < knotters; ++h) knotter_speed = std::min(knotter_speed, c.axes[static_cast<std::size_t>(k.knotter_axis[static_cast<std::size_t>(h)])].max_speed);
    if (knotters > 0) c.knot_cycle.max_speed_rad_s = knotter_speed;
    k.take_position_rad = c.knotting.take_position_rad;
    k.selector_zero_rad = c.knotting.selector_zero_rad;
    if (selectors > 0) {
      k.selector = {.velocity = selector_speed, .acceleration = c.knotting.selector_accel_rad_s2,
                    .jerk = c.knotting.selector_jerk_rad_s3};
    }
  }
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
  sm.axis_count = c.axes.size();
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    const AxisSpec& a = c.axes[i];
    if (!a.homing) continue;
    sm.referencing[i] = {.method = a.homing_method, .home_offset = a.home_offset, .speed = a.homing_speed,
                         .index_pitch = hal::is_rotary(a.role) ? 2.0 * M_PI : a.lead_m};
  }
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
  // A homed crank comes to rest at its home point before anything else moves: the beater must be clear
  // of the warp there, or the carriage could never home or move after it.
  const AxisSpec& crank = c.axes[hal::index(hal::CoreAxis::kBeatCrank)];
  if (crank.homing) {
    const motion::WarpWindow& w = set->beatup().warp();
    const double phase = motion::wrap_two_pi(crank.home_offset - c.machine_spec.calibration.crank_park_position_rad);
    if (phase > w.enter && phase < w.exit) {
      fail("axes." + crank.name + ".home_offset", fmt_num(crank.home_offset),
           "the beater is inside the warp at the crank's home point (" + fmt_num(motion::deg(phase)) +
               " deg from park; the warp spans " + fmt_num(motion::deg(w.enter)) + ".." + fmt_num(motion::deg(w.exit)) +
               " deg): put the home switch where the beater is clear");
    }
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
  refuse_moved_keys(r);
  read_axes(r, c, base != nullptr);
  read_io_modules(r, c);
  r.reject_unknown(known_sections());
  check_relations(r, c);
  // `key` may name two facts that clash ("axes.helix.node|can.master_node", values likewise): the one the
  // file says is the line to point at (the first when it says both).
  const Fail fail = [&](const std::string& key, const std::string& value, const std::string& why) {
    const std::size_t bar = key.find('|'), vbar = value.find('|');
    if (bar != std::string::npos) {
      const std::string k1 = key.substr(0, bar), v1 = value.substr(0, vbar);
      const std::string k2 = key.substr(bar + 1), v2 = vbar == std::string::npos ? value : value.substr(vbar + 1);
      if (present(k1)) r.fail(k1, v1, why);
      if (present(k2)) r.fail(k2, v2, why);
      throw ConfigError(source + ": " + k1 + " = " + v1 + " (from the embedded default): " + why);
    }
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
  cc.axes.clear();
  for (const AxisSpec& a : c.axes) {
    drivers::CanAxisConfig& d = cc.axes.emplace_back();
    d.name = a.name;
    d.bus = a.bus;
    d.node_id = a.node;
    d.counts_per_unit = a.counts_per_unit();
    d.rated_effort = 0.0;
    d.ferror_min = a.ferror_min;
    d.ferror_k_s = a.ferror_k_s;
    d.boot_timeout_s = a.boot_ms * 1e-3;
    d.operational_timeout_s = a.operational_ms * 1e-3;
    if (a.homing) {  // CiA 402 homing run over CAN (0x6098, 0x607C, 0x6099, 0x609A)
      d.homing_method = static_cast<std::int8_t>(a.homing_method);
      d.home_offset = a.home_offset;
      d.homing_speed = a.homing_speed;
      d.homing_accel = a.homing_accel;
    }
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
  if (c.io.kind == IoKind::kCan) {
    const std::vector<drivers::CanIoConfig> modules = can_io_configs(c);
    const std::vector<std::size_t> buses = can_io_buses(c);
    for (std::size_t k = 0; k < modules.size(); ++k) {
      const auto frames = drivers::io_frames_per_cycle(drivers::module_wiring(modules[k].wiring, modules[k].module));
      std::vector<drivers::FrameGroup>& on_bus = cc.other_frames_per_cycle[std::min(buses[k], drivers::kMaxBuses - 1)];
      on_bus.insert(on_bus.end(), frames.begin(), frames.end());
    }
  }
  return cc;
}

std::vector<std::size_t> can_io_buses(const LoomConfig& c) {
  std::vector<std::size_t> buses{0};  // the [io] module is on bus 0
  for (const IoModuleSpec& m : c.io.modules) buses.push_back(m.bus);
  return buses;
}

std::vector<drivers::CanIoConfig> can_io_configs(const LoomConfig& c) {
  drivers::CanIoConfig ic;
  ic.node_id = c.io.node;
  ic.wiring = c.io.wiring;
  // The heads' signals are on the module only when the heads are fitted (a loom without them keeps its
  // frames as they were).
  if (c.knotting.mode == sequencer::KnottingMode::kHeads) {
    drivers::IoWiring& w = ic.wiring;
    w.heads = std::clamp(c.knotting.heads, 0, static_cast<int>(hal::kMaxKnottingHeads));
    const auto fill = [&](const IoSettings::HeadSignals& from, std::array<drivers::IoBit, hal::kMaxKnottingHeads>& to) {
      for (std::size_t h = 0; h < to.size(); ++h) {
        to[h] = drivers::IoBit{h < from.bits.size() ? from.bits[h] : -1, from.active_low, from.module};
      }
    };
    fill(c.io.gripper_close, w.gripper_close);
    fill(c.io.cutter, w.cutter);
    fill(c.io.yarn_present, w.yarn_present);
  }
  ic.cycle_period_s = c.run.period_s;
  ic.heartbeat_producer_s = c.can.heartbeat_ms * 1e-3;
  ic.heartbeat_consumer_s = c.can.heartbeat_timeout_ms * 1e-3;
  ic.sdo_timeout_s = c.can.sdo_timeout_ms * 1e-3;
  ic.boot_timeout_s = c.io.boot_timeout_ms * 1e-3;
  ic.operational_timeout_s = c.io.operational_timeout_ms * 1e-3;
  ic.master_node_id = c.can.master_node;
  ic.master_consumer_s = c.can.master_consumer_ms * 1e-3;
  std::vector<drivers::CanIoConfig> out{ic};
  for (std::size_t k = 0; k < c.io.modules.size(); ++k) {
    const IoModuleSpec& m = c.io.modules[k];
    drivers::CanIoConfig mc = ic;  // the same wiring, bus timing and master; its own node and windows
    mc.module = static_cast<std::uint8_t>(k + 1);
    mc.name = m.name;
    mc.node_id = m.node;
    mc.boot_timeout_s = m.boot_timeout_ms * 1e-3;
    mc.operational_timeout_s = m.operational_timeout_ms * 1e-3;
    out.push_back(std::move(mc));
  }
  return out;
}

drivers::BusLoad can_bus_load(const LoomConfig& c, std::size_t bus) {
  const drivers::CanAxisPortConfig cc = can_axis_config(c);
  return drivers::planned_bus_load(cc, bus);
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
sequencer::KnotProgram knot_program(const LoomConfig& c, std::uint64_t design_rows_done, std::uint32_t counter_rows) {
  const design::Design& d = *c.recipe.design;
  std::vector<std::string> codes;
  for (const auto& colour : d.palette()) codes.push_back(colour.code);
  std::vector<std::uint16_t> knots;
  knots.reserve(static_cast<std::size_t>(d.width()) * static_cast<std::size_t>(d.height()));
  for (int r = 0; r < d.height(); ++r) {
    const auto row = d.row(r);
    knots.insert(knots.end(), row.begin(), row.end());
  }
  return sequencer::KnotProgram::build(c.knotting, c.machine_spec.width_m, d.width(), d.height(), knots, codes,
                                       design_rows_done, counter_rows);
}

LoomConfig default_loom_config() { return parse_loom_config(kDefaultLoomToml, "<embedded default_loom.toml>"); }

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
    }
    if (k.path == "io.yarn_present_active_low") {
      for (const IoModuleKeyInfo& m : io_module_keys()) out.push_back({m.path, "machine", m.range});
    }
  }
  return out;
}

double AxisSpec::counts_per_unit() const {
  return lead_m > 0.0 ? counts_per_rev / lead_m : counts_per_rev / (2.0 * M_PI);
}

hal::AxisLayout axis_layout(const LoomConfig& c) {
  hal::AxisLayout l;
  for (const AxisSpec& a : c.axes) l.add(a.name.c_str(), a.role);
  return l;
}

}  // namespace loom::firmware

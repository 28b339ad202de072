// The key table: every key of a loom file with its class, range, reader (in file order) and canonical
// value. A reader checks its value's range and type at the key's line; relations between keys are
// checks.cpp's.
#include "keys.hpp"

#include <cstdint>
#include <memory>
#include <sstream>

#include "eds_keys.hpp"
#include "loom/motion/angles.hpp"

namespace loom::firmware::detail {
namespace {

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
    return std::make_shared<const design::Design>(
        design::parse_design(read_config_file(path, kMaxDesignBytes, "design"), path));
  } catch (const ConfigError& e) {
    r.fail("recipe.design", '"' + file + '"', e.what());
  } catch (const design::DesignError& e) {
    r.fail("recipe.design", '"' + file + '"', e.what());
  }
}

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
Key integer(std::string path, Klass k, std::int64_t lo, std::int64_t hi,
            std::function<T&(LoomConfig&)> field) {
  Key key{path, k,       "[" + std::to_string(lo) + ", " + std::to_string(hi) + "] (integer)",
          true, nullptr, nullptr};
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
  key.value = [=](const LoomConfig& c) {
    return std::string(field(const_cast<LoomConfig&>(c)) ? "true" : "false");
  };
  return key;
}

const char* io_kind_name(IoKind k) {
  return k == IoKind::kCan ? "can" : "simulated";
}
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
  io_signal(v, name, drivers::kIoMaxInputBits,
            [member](LoomConfig& c) -> drivers::IoBit& { return c.io.wiring.*member; });
}
void io_output(std::vector<Key>& v, const std::string& name, drivers::IoBit drivers::IoWiring::*member) {
  io_signal(v, name, drivers::kIoMaxOutputBits,
            [member](LoomConfig& c) -> drivers::IoBit& { return c.io.wiring.*member; });
}
// The second channel of safety sensor `i`: `io.<sensor>_2_bit`, `io.<sensor>_2_active_low`.
void io_second_channel(std::vector<Key>& v, std::size_t i) {
  io_signal(v, std::string(hal::safety_sensor_name(static_cast<hal::SafetySensor>(i))) + "_2",
            drivers::kIoMaxInputBits,
            [i](LoomConfig& c) -> drivers::IoBit& { return c.io.wiring.second[i]; });
}

// A knotting-head signal of one kind: `io.<name>_bits` (one bit per head, head 1 first) and
// `io.<name>_active_low` (the same part on every head, so one polarity).
void io_head_signals(std::vector<Key>& v, const std::string& name,
                     IoSettings::HeadSignals IoSettings::*member, int max_bits) {
  const std::string path = "io." + name + "_bits";
  Key bits{path,
           Klass::kMachine,
           "one bit per knotting head, each in [0, " + std::to_string(max_bits - 1) + "] (integer)",
           true,
           nullptr,
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

const char* branch_name(motion::Branch b) {
  return b == motion::Branch::kPositive ? "positive" : "negative";
}
bool parse_branch(const char* s, motion::Branch& b) {
  b = std::string(s) == "positive" ? motion::Branch::kPositive : motion::Branch::kNegative;
  return true;
}
const char* fell_name(motion::FellSide f) {
  return f == motion::FellSide::kExtended ? "extended" : "folded";
}
bool parse_fell(const char* s, motion::FellSide& f) {
  f = std::string(s) == "extended" ? motion::FellSide::kExtended : motion::FellSide::kFolded;
  return true;
}

}  // namespace

std::string fmt_num(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

const char* klass_name(Klass k) {
  switch (k) {
    case Klass::kMachine:
      return "machine";
    case Klass::kRecipe:
      return "recipe";
    case Klass::kRun:
      return "run";
  }
  return "?";
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
        if (c.loom_id.empty() || c.loom_id.size() > 64 ||
            c.loom_id.find_first_of(" ./*\t\"\\") != std::string::npos) {
          r.fail("loom.id", '"' + c.loom_id + '"',
                 "must be 1..64 characters without spaces, dots, slashes or '*'");
        }
      };
      id.value = [](const LoomConfig& c) { return c.loom_id; };
      v.push_back(id);
    }
    v.push_back(number("loom.width_m", M::kMachine, 0.2, 10.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.width_m; }));
    // [beatup] — the linkage and the beater (machine)
    v.push_back(number("beatup.crank_m", M::kMachine, 0.005, 2.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.beatup.bar.crank; }));
    v.push_back(number("beatup.coupler_m", M::kMachine, 0.005, 5.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.beatup.bar.coupler; }));
    v.push_back(number("beatup.rocker_m", M::kMachine, 0.005, 5.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.beatup.bar.rocker; }));
    v.push_back(number("beatup.ground_m", M::kMachine, 0.005, 5.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.beatup.bar.ground; }));
    v.push_back(number("beatup.beater_arm_m", M::kMachine, 0.01, 5.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.beatup.beater_arm_m; }));
    v.push_back(choice<motion::Branch>(
        "beatup.branch", M::kMachine, {"positive", "negative"},
        [](LoomConfig& c) -> motion::Branch& { return c.machine_spec.beatup.branch; }, branch_name,
        parse_branch));
    v.push_back(choice<motion::FellSide>(
        "beatup.fell_at", M::kMachine, {"extended", "folded"},
        [](LoomConfig& c) -> motion::FellSide& { return c.machine_spec.beatup.fell_at; }, fell_name,
        parse_fell));
    v.push_back(number("beatup.warp_depth_m", M::kMachine, 0.001, 0.5,
                       [](LoomConfig& c) -> double& { return c.machine_spec.beatup.warp_depth_m; }));
    v.push_back(number("beatup.beater_mass_kg", M::kMachine, 0.1, 50.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.beater_mass_kg; }));
    v.push_back(number("beatup.beater_width_m", M::kMachine, 0.01, 1.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.beater_width_m; }));
    v.push_back(
        number("beatup.crank_park_position_rad", M::kMachine, -1.0e5, 1.0e5,
               [](LoomConfig& c) -> double& { return c.machine_spec.calibration.crank_park_position_rad; }));
    // [carriage]
    v.push_back(number("carriage.max_speed_m_s", M::kMachine, 0.01, 10.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.carriage_max_speed_m_s; }));
    v.push_back(number("carriage.max_accel_m_s2", M::kMachine, 0.1, 1000.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.carriage_max_accel_m_s2; }));
    v.push_back(number("carriage.max_jerk_m_s3", M::kMachine, 1.0, 1.0e6,
                       [](LoomConfig& c) -> double& { return c.machine_spec.carriage_max_jerk_m_s3; }));
    v.push_back(number("carriage.jerk_m_s3", M::kMachine, 1.0, 1.0e6, [](LoomConfig& c) -> double& {
      return c.machine_spec.carriage_reposition_jerk_m_s3;
    }));
    v.push_back(number("carriage.mass_kg", M::kMachine, 0.0, 1000.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.carriage_mass_kg; }));
    v.push_back(number("carriage.home_position_m", M::kMachine, -10.0, 10.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.calibration.carriage_home_m; }));
    // [helix]
    v.push_back(number("helix.lead_m", M::kMachine, 0.005, 1.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.helix_lead_m; }));
    v.push_back(number("helix.left_position_rad", M::kMachine, -1.0e5, 1.0e5, [](LoomConfig& c) -> double& {
      return c.machine_spec.calibration.helix_left_position_rad;
    }));
    v.push_back(number("helix.max_speed_rad_s", M::kMachine, 1.0, 1000.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.helix.velocity; }));
    v.push_back(number("helix.max_accel_rad_s2", M::kMachine, 1.0, 1.0e6,
                       [](LoomConfig& c) -> double& { return c.machine_spec.helix.acceleration; }));
    v.push_back(number("helix.jerk_rad_s3", M::kMachine, 10.0, 1.0e8,
                       [](LoomConfig& c) -> double& { return c.machine_spec.helix.jerk; }));
    v.push_back(number("helix.carrier_force_n", M::kMachine, 0.1, 1000.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.carrier_force_n; }));
    v.push_back(number("helix.shuttle_mass_kg", M::kMachine, 0.01, 10.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.shuttle_mass_kg; }));
    // [shedding]
    v.push_back(number("shedding.piston_travel_s", M::kMachine, 0.01, 10.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.shed.piston_travel_s; }));
    v.push_back(number("shedding.timeout_s", M::kMachine, 0.05, 60.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.shed.timeout_s; }));
    v.push_back(number("shedding.earliest_fraction", M::kMachine, 0.0, 0.99,
                       [](LoomConfig& c) -> double& { return c.machine_spec.shed.earliest_fraction; }));
    v.push_back(number("shedding.release_timeout_s", M::kMachine, 0.005, 10.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.shed.release_timeout_s; }));
    v.push_back(millis("shedding.settle_ms", M::kMachine, 0.0, 1000.0,
                       [](LoomConfig& c) -> double& { return c.machine_spec.shed.settle_s; }));
    // [can]
    {
      Key bitrate{
          "can.bitrate", M::kMachine, "10000 | 20000 | 50000 | 125000 | 250000 | 500000 | 800000 | 1000000",
          true,          nullptr,     nullptr};
      bitrate.read = [](TomlReader& r, LoomConfig& c) {
        std::int64_t b = c.can.bitrate;
        r.integer("can.bitrate", b, 10'000, 1'000'000);
        static const std::set<std::int64_t> cia{10'000,  20'000,  50'000,  125'000,
                                                250'000, 500'000, 800'000, 1'000'000};
        if (!cia.count(b))
          r.fail(
              "can.bitrate", std::to_string(b),
              "must be a CiA 301 bit rate: 10000, 20000, 50000, 125000, 250000, 500000, 800000 or 1000000");
        c.can.bitrate = static_cast<std::uint32_t>(b);
      };
      bitrate.value = [](const LoomConfig& c) { return std::to_string(c.can.bitrate); };
      v.push_back(bitrate);
    }
    v.push_back(number("can.bus_load_budget", M::kMachine, 0.05, 1.0,
                       [](LoomConfig& c) -> double& { return c.can.bus_load_budget; }));
    v.push_back(integer<std::uint16_t>("can.heartbeat_ms", M::kMachine, 10, 10000,
                                       [](LoomConfig& c) -> std::uint16_t& { return c.can.heartbeat_ms; }));
    v.push_back(
        integer<std::uint16_t>("can.heartbeat_timeout_ms", M::kMachine, 10, 30000,
                               [](LoomConfig& c) -> std::uint16_t& { return c.can.heartbeat_timeout_ms; }));
    v.push_back(integer<std::uint16_t>("can.sdo_timeout_ms", M::kMachine, 10, 10000,
                                       [](LoomConfig& c) -> std::uint16_t& { return c.can.sdo_timeout_ms; }));
    v.push_back(integer<std::uint8_t>("can.master_node", M::kMachine, 0, 127,
                                      [](LoomConfig& c) -> std::uint8_t& { return c.can.master_node; }));
    v.push_back(
        integer<std::uint16_t>("can.master_heartbeat_ms", M::kMachine, 10, 10000,
                               [](LoomConfig& c) -> std::uint16_t& { return c.can.master_heartbeat_ms; }));
    v.push_back(
        integer<std::uint16_t>("can.master_consumer_ms", M::kMachine, 20, 30000,
                               [](LoomConfig& c) -> std::uint16_t& { return c.can.master_consumer_ms; }));
    // [io] — the CiA 401 module: where each signal is wired
    v.push_back(choice<IoKind>(
        "io.kind", M::kMachine, {"can", "simulated"}, [](LoomConfig& c) -> IoKind& { return c.io.kind; },
        io_kind_name, parse_io_kind));
    v.push_back(integer<std::uint8_t>("io.node", M::kMachine, 1, 127,
                                      [](LoomConfig& c) -> std::uint8_t& { return c.io.node; }));
    {
      Key eds{"io.eds", M::kMachine, "path of the I/O module's EDS (CiA 306), relative to this file",
              false,    nullptr,     nullptr};
      eds.read = [](TomlReader& r, LoomConfig& c) { read_eds_key(r, "io.eds", c.io.eds); };
      eds.value = [](const LoomConfig& c) { return c.io.eds; };
      v.push_back(eds);
      Key store =
          boolean("io.store_config", M::kMachine, [](LoomConfig& c) -> bool& { return c.io.store_config; });
      store.required = false;
      store.range =
          "true | false; default false: after a bring-up that wrote anything, 0x1010:01 = \"save\" "
          "(needs io.eds with a writable 0x1010:01)";
      v.push_back(store);
      Key groups{"io.input_group_bits",
                 M::kMachine,
                 "8 (0x6000) | 16 (0x6100); default: from io.eds (8-bit groups when it has them all), else 8",
                 false,
                 nullptr,
                 nullptr};
      groups.read = [](TomlReader& r, LoomConfig& c) {
        read_input_group_bits(r, "io.input_group_bits", c.io.input_group_bits);
      };
      groups.value = [](const LoomConfig& c) { return std::to_string(c.io.input_group_bits); };
      v.push_back(groups);
    }
    v.push_back(integer<std::uint32_t>("io.boot_timeout_ms", M::kMachine, 10, 60000,
                                       [](LoomConfig& c) -> std::uint32_t& { return c.io.boot_timeout_ms; }));
    v.push_back(
        integer<std::uint32_t>("io.operational_timeout_ms", M::kMachine, 10, 60000,
                               [](LoomConfig& c) -> std::uint32_t& { return c.io.operational_timeout_ms; }));
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
    v.push_back(integer<int>("io.load_cell_channel", M::kMachine, 0, 254,
                             [](LoomConfig& c) -> int& { return c.io.wiring.load_cell_channel; }));
    v.push_back(number("io.load_cell_n_per_count", M::kMachine, -1.0e3, 1.0e3,
                       [](LoomConfig& c) -> double& { return c.io.wiring.load_cell_n_per_count; }));
    v.push_back(number("io.load_cell_offset_n", M::kMachine, -1.0e4, 1.0e4,
                       [](LoomConfig& c) -> double& { return c.io.wiring.load_cell_offset_n; }));
    io_head_signals(v, "gripper_close", &IoSettings::gripper_close, drivers::kIoMaxOutputBits);
    io_head_signals(v, "cutter", &IoSettings::cutter, drivers::kIoMaxOutputBits);
    io_head_signals(v, "yarn_present", &IoSettings::yarn_present, drivers::kIoMaxInputBits);
    // [knotting] — the pile (machine: the heads are hardware)
    v.push_back(choice<sequencer::KnottingMode>(
        "knotting.mode", M::kMachine, {"none", "weaver", "heads"},
        [](LoomConfig& c) -> sequencer::KnottingMode& { return c.knotting.mode; },
        sequencer::knotting_mode_name, sequencer::parse_knotting_mode));
    v.push_back(choice<sequencer::KnotType>(
        "knotting.knot", M::kMachine, {"turkish", "persian_left", "persian_right"},
        [](LoomConfig& c) -> sequencer::KnotType& { return c.knotting.knot; }, sequencer::knot_type_name,
        sequencer::parse_knot_type));
    v.push_back(number("knotting.knots_per_dm", M::kMachine, 5.0, 200.0,
                       [](LoomConfig& c) -> double& { return c.knotting.knots_per_dm; }));
    v.push_back(number("knotting.rows_per_dm", M::kMachine, 5.0, 200.0,
                       [](LoomConfig& c) -> double& { return c.knotting.rows_per_dm; }));
    v.push_back(integer<int>("knotting.heads", M::kMachine, 1, sequencer::kMaxKnottingHeads,
                             [](LoomConfig& c) -> int& { return c.knotting.heads; }));
    v.push_back(number("knotting.head_spacing_m", M::kMachine, 0.005, 10.0,
                       [](LoomConfig& c) -> double& { return c.knotting.head_spacing_m; }));
    {
      Key slots{"knotting.slot_colours",
                M::kMachine,
                "design palette codes, one per magazine slot (at most 16)",
                true,
                nullptr,
                nullptr};
      slots.read = [](TomlReader& r, LoomConfig& c) {
        r.string_list("knotting.slot_colours", c.knotting.slot_colours);
      };
      slots.value = [](const LoomConfig& c) {
        std::string out;
        for (const auto& code : c.knotting.slot_colours) out += (out.empty() ? "" : ",") + code;
        return out;
      };
      v.push_back(slots);
    }
    v.push_back(integer<int>("knotting.knots_per_slot", M::kMachine, 1, 1'000'000,
                             [](LoomConfig& c) -> int& { return c.knotting.knots_per_slot; }));
    v.push_back(number("knotting.take_position_rad", M::kMachine, -1e6, 1e6,
                       [](LoomConfig& c) -> double& { return c.knotting.take_position_rad; }));
    v.push_back(number("knotting.selector_zero_rad", M::kMachine, -1e6, 1e6,
                       [](LoomConfig& c) -> double& { return c.knotting.selector_zero_rad; }));
    v.push_back(number("knotting.selector_accel_rad_s2", M::kMachine, 1.0, 1e6,
                       [](LoomConfig& c) -> double& { return c.knotting.selector_accel_rad_s2; }));
    v.push_back(number("knotting.selector_jerk_rad_s3", M::kMachine, 10.0, 1e9,
                       [](LoomConfig& c) -> double& { return c.knotting.selector_jerk_rad_s3; }));
    {
      // Not given: a quarter of the knot pitch (derived from knots_per_dm); below half a pitch is
      // checks.cpp's (sequencer::find_fault), where the pitch is known.
      Key tol{"knotting.placement_tolerance_m",
              M::kMachine,
              "(0, half the knot pitch); default a quarter of the knot pitch",
              false,
              nullptr,
              nullptr};
      tol.read = [](TomlReader& r, LoomConfig& c) {
        r.number("knotting.placement_tolerance_m", c.knotting.placement_tolerance_m, positive);
      };
      tol.value = [](const LoomConfig& c) { return fmt_num(sequencer::placement_tolerance_m(c.knotting)); };
      v.push_back(tol);
    }
    // The gripper's dwells (the knotting servo itself is its axes' drive, [drives.<model>]).
    using KC = motion::KnotCycleSpec;
    const auto kc = [](double KC::*f) { return [f](LoomConfig& c) -> double& { return c.knot_cycle.*f; }; };
    v.push_back(millis("knotting.grip_ms", M::kMachine, 1.0, 5000.0, kc(&KC::grip_s)));
    v.push_back(millis("knotting.cut_ms", M::kMachine, 1.0, 5000.0, kc(&KC::cut_s)));
    v.push_back(millis("knotting.release_ms", M::kMachine, 1.0, 5000.0, kc(&KC::release_s)));
    v.push_back(
        degrees("knotting.min_transmission_deg", M::kMachine, 1.0, 89.0, kc(&KC::min_transmission_rad)));
    // [knotting.linkage] — seed 001's four-bar as `loom-synth knotter` prints it (checked when the cycle is
    // built).
    const char* point_names[] = {"take", "wrap", "pull"};
    for (std::size_t i = 0; i < 3; ++i) {
      const std::string p = std::string("knotting.linkage.") + point_names[i];
      v.push_back(number(p + "_x_m", M::kMachine, -1.0, 1.0,
                         [i](LoomConfig& c) -> double& { return c.knot_cycle.points[i].x_m; }));
      v.push_back(number(p + "_y_m", M::kMachine, -1.0, 1.0,
                         [i](LoomConfig& c) -> double& { return c.knot_cycle.points[i].y_m; }));
      v.push_back(degrees(p + "_gripper_deg", M::kMachine, -360.0, 360.0,
                          [i](LoomConfig& c) -> double& { return c.knot_cycle.points[i].gripper_rad; }));
    }
    v.push_back(degrees("knotting.linkage.theta0_deg", M::kMachine, -360.0, 360.0, kc(&KC::theta0_rad)));
    v.push_back(number("knotting.linkage.crank_pivot_x_m", M::kMachine, -1.0, 1.0, kc(&KC::crank_pivot_x_m)));
    v.push_back(number("knotting.linkage.crank_pivot_y_m", M::kMachine, -1.0, 1.0, kc(&KC::crank_pivot_y_m)));
    v.push_back(
        number("knotting.linkage.rocker_pivot_x_m", M::kMachine, -1.0, 1.0, kc(&KC::rocker_pivot_x_m)));
    v.push_back(
        number("knotting.linkage.rocker_pivot_y_m", M::kMachine, -1.0, 1.0, kc(&KC::rocker_pivot_y_m)));
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
    v.push_back(
        number("knotting.linkage.gripper_normal_m", M::kMachine, -1.0, 1.0, kc(&KC::gripper_normal_m)));
    v.push_back(choice<motion::Branch>(
        "knotting.linkage.branch", M::kMachine, {"positive", "negative"},
        [](LoomConfig& c) -> motion::Branch& { return c.knot_cycle.branch; }, branch_name, parse_branch));
    for (const auto& l : links) {
      const std::string p = std::string("knotting.linkage.") + l.name;
      v.push_back(
          number(p + "_mass_kg", M::kMachine, 0.0, 10.0, link(l.link, &motion::KnotLinkSpec::mass_kg)));
      v.push_back(number(p + "_cg_m", M::kMachine, -1.0, 1.0, link(l.link, &motion::KnotLinkSpec::cg_m)));
      v.push_back(number(p + "_inertia_kg_m2", M::kMachine, 0.0, 1.0,
                         link(l.link, &motion::KnotLinkSpec::inertia_kg_m2)));
    }
    v.push_back(number("knotting.linkage.warp_entry_x_m", M::kMachine, -1.0, 1.0, kc(&KC::warp_entry_x_m)));
    // [recipe]
    v.push_back(
        integer<std::uint32_t>("recipe.picks_per_row", M::kRecipe, 1, 16,
                               [](LoomConfig& c) -> std::uint32_t& { return c.recipe.picks_per_row; }));
    {
      Key design{
          "recipe.design",
          M::kRecipe,
          "file: .csv grid of colour codes or .png, one pixel per knot; \"\" = none (knotting heads: "
          "each carpet job brings its design; with neither, weaving is refused at knotting.mode's line)",
          false,
          nullptr,
          nullptr};
      design.read = [](TomlReader& r, LoomConfig& c) {
        r.string("recipe.design", c.recipe.design_file);
        c.recipe.design = load_design_for(r, c.recipe.design_file);
      };
      design.value = [](const LoomConfig& c) { return c.recipe.design_file; };
      v.push_back(design);
    }
    v.push_back(integer<int>("recipe.beats_per_position", M::kRecipe, 1, 16,
                             [](LoomConfig& c) -> int& { return c.recipe.beats_per_position; }));
    {
      Key force = number(
          "recipe.beat_force_target_n", M::kRecipe, 1.0, 1000.0,
          [](LoomConfig& c) -> double& { return c.recipe.beat_force_target_n; }, false);
      Key speed = number(
          "recipe.crank_speed_rad_s", M::kRecipe, 0.1, 100.0,
          [](LoomConfig& c) -> double& { return c.recipe.crank_speed_rad_s; }, false);
      v.push_back(force);
      v.push_back(speed);
    }
    v.push_back(number("recipe.beat_force_min_n", M::kRecipe, 1.0, 1000.0,
                       [](LoomConfig& c) -> double& { return c.recipe.beat_force_min_n; }));
    v.push_back(number("recipe.beat_force_max_n", M::kRecipe, 1.0, 1000.0,
                       [](LoomConfig& c) -> double& { return c.recipe.beat_force_max_n; }));
    v.push_back(number("recipe.crank_accel_rad_s2", M::kRecipe, 1.0, 1.0e5,
                       [](LoomConfig& c) -> double& { return c.recipe.crank_accel_rad_s2; }));
    v.push_back(number("recipe.crank_jerk_rad_s3", M::kRecipe, 10.0, 1.0e7,
                       [](LoomConfig& c) -> double& { return c.recipe.crank_jerk_rad_s3; }));
    v.push_back(choice<motion::CrankLawKind>(
        "recipe.crank_law", M::kRecipe, {"constant", "elliptic"},
        [](LoomConfig& c) -> motion::CrankLawKind& { return c.recipe.crank_law.kind; },
        motion::crank_law_name, motion::parse_crank_law));
    v.push_back(number("recipe.ellipse_e", M::kRecipe, 0.0, 0.9,
                       [](LoomConfig& c) -> double& { return c.recipe.crank_law.ellipse_e; }));
    v.push_back(integer<int>("recipe.ellipse_lobes", M::kRecipe, 1, 16,
                             [](LoomConfig& c) -> int& { return c.recipe.crank_law.ellipse_lobes; }));
    v.push_back(degrees("recipe.ellipse_phi02_deg", M::kRecipe, -360.0, 360.0,
                        [](LoomConfig& c) -> double& { return c.recipe.crank_law.ellipse_phi02_rad; }));
    v.push_back(number("recipe.overlap_m", M::kRecipe, 0.0, 1.0,
                       [](LoomConfig& c) -> double& { return c.recipe.overlap_m; }));
    v.push_back(degrees("recipe.cam_margin_deg", M::kRecipe, 0.0, 90.0,
                        [](LoomConfig& c) -> double& { return c.recipe.cam_margin_rad; }));
    // [profiles] — how the recipe's motion is tabulated (a recipe property: rebuilt with it)
    {
      Key size = integer<std::size_t>("profiles.table_size", M::kRecipe, 64, 1 << 20,
                                      [](LoomConfig& c) -> std::size_t& { return c.recipe.table_size; });
      v.push_back(size);
    }
    v.push_back(choice<motion::Interp>(
        "profiles.interp", M::kRecipe, {"linear", "cubic", "quintic"},
        [](LoomConfig& c) -> motion::Interp& { return c.recipe.table_interp; }, motion::interp_name,
        motion::parse_interp));
    v.push_back(choice<motion::Precision>(
        "profiles.table_precision", M::kRecipe, {"double", "float32"},
        [](LoomConfig& c) -> motion::Precision& { return c.recipe.table_precision; }, motion::precision_name,
        motion::parse_precision));
    v.push_back(number("profiles.max_table_error_rad", M::kRecipe, 1e-12, 1e-2,
                       [](LoomConfig& c) -> double& { return c.recipe.max_table_error_rad; }));
    // [timing] (run)
    v.push_back(millis("timing.period_ms", M::kRun, 0.25, 20.0,
                       [](LoomConfig& c) -> double& { return c.run.period_s; }));
    v.push_back(number("timing.enable_timeout_s", M::kRun, 0.05, 60.0,
                       [](LoomConfig& c) -> double& { return c.run.enable_timeout_s; }));
    v.push_back(number("timing.pick_timeout_margin_s", M::kRun, 0.01, 60.0,
                       [](LoomConfig& c) -> double& { return c.run.pick_timeout_margin_s; }));
    v.push_back(number("timing.row_save_timeout_s", M::kRun, 0.1, 600.0,
                       [](LoomConfig& c) -> double& { return c.run.row_save_timeout_s; }));
    v.push_back(millis("timing.stale_timeout_ms", M::kRun, 0.5, 10000.0,
                       [](LoomConfig& c) -> double& { return c.run.stale_timeout_s; }));
    v.push_back(integer<int>("timing.debounce_ticks", M::kRun, 1, 100,
                             [](LoomConfig& c) -> int& { return c.run.debounce_ticks; }));
    v.push_back(millis("timing.sensor_discrepancy_ms", M::kRun, 1.0, 1000.0,
                       [](LoomConfig& c) -> double& { return c.run.sensor_discrepancy_s; }));
    v.push_back(
        integer<std::uint32_t>("timing.overrun_stop_after", M::kRun, 0, 1'000'000,
                               [](LoomConfig& c) -> std::uint32_t& { return c.run.overrun_stop_after; }));
    // [telemetry] (run)
    {
      Key url{
          "telemetry.lcm_url", M::kRun, "LCM provider URL, \"\" = LCM's default", false, nullptr, nullptr};
      url.read = [](TomlReader& r, LoomConfig& c) { r.string("telemetry.lcm_url", c.telemetry.lcm_url); };
      url.value = [](const LoomConfig& c) { return c.telemetry.lcm_url; };
      v.push_back(url);
    }
    v.push_back(
        integer<std::uint32_t>("telemetry.status_every", M::kRun, 1, 1'000'000,
                               [](LoomConfig& c) -> std::uint32_t& { return c.telemetry.status_every; }));
    v.push_back(
        integer<std::uint32_t>("telemetry.axes_every", M::kRun, 1, 1'000'000,
                               [](LoomConfig& c) -> std::uint32_t& { return c.telemetry.axes_every; }));
    v.push_back(integer<std::uint32_t>("telemetry.rt_every", M::kRun, 1, 1'000'000,
                                       [](LoomConfig& c) -> std::uint32_t& { return c.telemetry.rt_every; }));
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
    out.insert("drives");      // [drives.<model>] tables, read by read_drives()
    return out;
  }();
  return s;
}

const Key* find_key(const std::string& path) {
  for (const Key& k : keys()) {
    if (k.path == path) return &k;
  }
  return nullptr;
}

std::string value_of(const LoomConfig& c, const std::string& path) {
  const Key* k = find_key(path);
  return k != nullptr ? k->value(c) : std::string();
}

void refuse_moved_keys(TomlReader& r) {
  static const struct {
    const char* old_key;
    const char* now;
  } moved[] = {
      {"can.node_beat_crank", "axes.beat_crank.node"},
      {"can.node_carriage", "axes.carriage.node"},
      {"can.node_helix", "axes.helix.node"},
      {"can.counts_per_rev", "axes.<name>.counts_per_rev of each rotary axis"},
      {"can.carriage_counts_per_m",
       "axes.carriage.counts_per_rev and axes.carriage.lead_m (counts per m = counts_per_rev / lead_m)"},
      {"can.beat_crank_boot_ms", "axes.beat_crank.boot_ms"},
      {"can.beat_crank_operational_ms", "axes.beat_crank.operational_ms"},
      {"can.beat_crank_ferror_min_rad", "axes.beat_crank.ferror_min"},
      {"can.beat_crank_ferror_k_s", "axes.beat_crank.ferror_k_s"},
      {"can.carriage_boot_ms", "axes.carriage.boot_ms"},
      {"can.carriage_operational_ms", "axes.carriage.operational_ms"},
      {"can.carriage_ferror_min_m", "axes.carriage.ferror_min"},
      {"can.carriage_ferror_k_s", "axes.carriage.ferror_k_s"},
      {"can.helix_boot_ms", "axes.helix.boot_ms"},
      {"can.helix_operational_ms", "axes.helix.operational_ms"},
      {"can.helix_ferror_min_rad", "axes.helix.ferror_min"},
      {"can.helix_ferror_k_s", "axes.helix.ferror_k_s"},
      {"recipe.knotting", "knotting.mode (\"none\", \"weaver\" or \"heads\")"},
      {"knotting.servo_accel_rad_s2",
       "the knotting servo's drive: axes.<knotter>.drive and its [drives.<model>] table (the knot cycle "
       "is the time-optimal move under the drive's torque-speed line, not a speed/acceleration box)"},
      {"knotting.servo_jerk_rad_s3",
       "the drive's envelope: the knot cycle is the time-optimal move under its torque-speed line"},
      {"knotting.servo_torque_nm",
       "drives.<model>.rated_torque_nm and peak_torque_nm (the motor's, through gear_ratio)"},
      {"knotting.servo_rotor_inertia_kg_m2",
       "drives.<model>.rotor_inertia_kg_m2 and gear_inertia_kg_m2 (at the motor, through gear_ratio)"},
  };
  for (const auto& m : moved) {
    if (const toml::node* n = r.root().at_path(m.old_key).node()) {
      const auto i = n->value<std::int64_t>();
      const auto d = n->value<double>();
      const std::string shown = n->is_boolean() ? (n->value<bool>().value_or(false) ? "true" : "false")
                                : i             ? std::to_string(*i)
                                : d             ? fmt_num(*d)
                                                : "...";
      r.fail_at(*n, m.old_key, shown,
                std::string("moved: this fact is ") + m.now + " (loomctl check --keys lists every key)");
    }
  }
}

}  // namespace loom::firmware::detail

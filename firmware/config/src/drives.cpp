// [drives.<model>] tables and the axes' drive references (see drives.hpp).
#include "drives.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "keys.hpp"

namespace loom::firmware::detail {

namespace {

bool valid_model_name(const std::string& n) {
  if (n.empty() || n.size() > 32) return false;
  return std::all_of(n.begin(), n.end(), [](char ch) {
    return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_';
  });
}

constexpr double kRpm = 2.0 * M_PI / 60.0;  // rad/s per rpm

bool is_core(hal::AxisRole r) {
  return r == hal::AxisRole::kBeatCrank || r == hal::AxisRole::kCarriage || r == hal::AxisRole::kHelix;
}

// A drive's derived figure as a person reads it (3 significant digits).
std::string figure(double v) {
  std::ostringstream os;
  os.precision(3);
  os << v;
  return os.str();
}

}  // namespace

const std::vector<DriveKeyInfo>& drive_keys() {
  static const std::vector<DriveKeyInfo> k{
      {"drives.<model>.motor_speed_rpm",
       "[1, 100000]: no-load (maximum) motor speed, where the torque-speed "
       "line reaches 0"},
      {"drives.<model>.rated_torque_nm", "[1e-6, 1e4]: continuous motor torque"},
      {"drives.<model>.peak_torque_nm", "[1e-6, 1e4]: short-time motor torque, >= rated"},
      {"drives.<model>.rotor_inertia_kg_m2", "[0, 10]: the motor's rotor"},
      {"drives.<model>.gear_ratio", "[0.01, 10000]: motor turns per output turn; default 1 (direct)"},
      {"drives.<model>.gear_inertia_kg_m2", "[0, 10]: the gearbox at its input shaft; default 0"},
      {"drives.<model>.gear_efficiency", "(0, 1]; default 1"},
  };
  return k;
}

void read_drives(TomlReader& r, LoomConfig& c) {
  r.consume("drives");
  const toml::node* root = r.root().get("drives");
  if (root == nullptr) return;
  const toml::table* tables = root->as_table();
  if (tables == nullptr) r.fail_at(*root, "drives", "", "must be tables [drives.<model>]");
  for (auto&& entry : *tables) {
    const toml::node& node = entry.second;
    const std::string name(entry.first.str());
    const std::string p = "drives." + name + ".";
    if (!valid_model_name(name))
      r.fail_at(node, "drives." + name, "", "a drive model's name is 1..32 characters of a-z, 0-9 and _");
    if (!node.is_table()) r.fail_at(node, "drives." + name, "", "must be a table [drives." + name + "]");
    r.consume("drives." + name);
    auto it =
        std::find_if(c.drives.begin(), c.drives.end(), [&](const DriveModel& d) { return d.name == name; });
    const bool is_new = it == c.drives.end();
    if (is_new) {
      c.drives.push_back(DriveModel{});
      c.drives.back().name = name;
      it = c.drives.end() - 1;
    }
    motion::ServoDrive& d = it->drive;
    const auto has = [&](const char* k) { return node.as_table()->get(k) != nullptr; };
    for (const char* k : {"motor_speed_rpm", "rated_torque_nm", "peak_torque_nm", "rotor_inertia_kg_m2"}) {
      if (is_new && !has(k)) r.fail_at(node, p + k, "(missing)", "missing: a fact of the drive's data sheet");
    }
    double rpm = d.motor_speed_rad_s / kRpm;
    r.number(p + "motor_speed_rpm", rpm, [](double v) { return in_range(v, 1.0, 1e5); });
    d.motor_speed_rad_s = rpm * kRpm;
    r.number(p + "rated_torque_nm", d.motor_rated_torque_nm, [](double v) { return in_range(v, 1e-6, 1e4); });
    r.number(p + "peak_torque_nm", d.motor_peak_torque_nm, [](double v) { return in_range(v, 1e-6, 1e4); });
    r.number(p + "rotor_inertia_kg_m2", d.rotor_inertia_kg_m2,
             [](double v) { return in_range(v, 0.0, 10.0); });
    r.number(p + "gear_ratio", d.gear_ratio, [](double v) { return in_range(v, 0.01, 1e4); });
    r.number(p + "gear_inertia_kg_m2", d.gear_inertia_kg_m2, [](double v) { return in_range(v, 0.0, 10.0); });
    r.number(p + "gear_efficiency", d.gear_efficiency,
             [](double v) { return v > 0.0 && v <= 1.0 ? std::string() : std::string("must be in (0, 1]"); });
    if (d.motor_rated_torque_nm > d.motor_peak_torque_nm) {
      r.fail(has("rated_torque_nm") ? p + "rated_torque_nm" : p + "peak_torque_nm",
             fmt_num(has("rated_torque_nm") ? d.motor_rated_torque_nm : d.motor_peak_torque_nm),
             "the rated (continuous) torque " + fmt_num(d.motor_rated_torque_nm) +
                 " N m exceeds the peak torque " + fmt_num(d.motor_peak_torque_nm) + " N m");
    }
  }
}

const DriveModel* find_drive(const LoomConfig& c, const std::string& name) {
  const auto it =
      std::find_if(c.drives.begin(), c.drives.end(), [&](const DriveModel& d) { return d.name == name; });
  return it == c.drives.end() ? nullptr : &*it;
}

void check_axis_drives(TomlReader& r, LoomConfig& c) {
  for (AxisSpec& a : c.axes) {
    const std::string p = "axes." + a.name + ".";
    if (a.drive.empty()) {
      if (a.role == hal::AxisRole::kKnotter && c.knotting.mode == sequencer::KnottingMode::kHeads) {
        r.fail(p + "role", "\"knotter\"",
               "a knotting servo names its drive (axes." + a.name +
                   ".drive = \"<model>\" and a [drives.<model>] table): the knot cycle is planned under "
                   "its torque-speed line");
      }
      continue;
    }
    const DriveModel* m = find_drive(c, a.drive);
    if (m == nullptr) {
      std::string known;
      for (const DriveModel& d : c.drives) known += (known.empty() ? "" : ", ") + d.name;
      r.fail(
          p + "drive", "\"" + a.drive + "\"",
          "no [drives." + a.drive + "] table" + (known.empty() ? "" : " (the file describes " + known + ")"));
    }
    if (is_core(a.role)) continue;  // its limits are its mechanism's keys: check_core_drives
    const double top = m->drive.output_speed_rad_s();
    if (a.role == hal::AxisRole::kSelector) {
      const double need = m->drive.output_inertia_kg_m2() * c.knotting.selector_accel_rad_s2;
      if (!(need < m->drive.output_peak_torque_nm())) {
        r.fail("knotting.selector_accel_rad_s2", fmt_num(c.knotting.selector_accel_rad_s2),
               "needs " + fmt_num(need) + " N m for the rotor and gears of axes." + a.name +
                   "'s drive alone; " + "drives." + m->name + " gives " +
                   fmt_num(m->drive.output_peak_torque_nm()) + " N m at the output");
      }
    }
    if (!a.max_speed_set) {
      a.max_speed = top;
    } else if (a.max_speed > top * (1.0 + 1e-12)) {
      r.fail(p + "max_speed", fmt_num(a.max_speed) + " rad/s",
             "exceeds the drive's " + figure(top) + " rad/s at the output (drives." + m->name + ": " +
                 fmt_num(m->drive.motor_speed_rad_s / kRpm) + " rpm / gear_ratio " +
                 fmt_num(m->drive.gear_ratio) + ")");
    }
  }
  set_knot_cycle_servo(c);
}

void set_knot_cycle_servo(LoomConfig& c) {
  // One knot cycle for every head: planned for the weakest of their drives, fact by fact (the slowest line,
  // the least torque, the most inertia), and the lowest speed cap a knotter axis sets below its drive's
  // (0 = none: the line alone bounds the speed).
  motion::KnotCycleSpec& kc = c.knot_cycle;
  bool first = true, capped = false;
  double cap = 0.0;
  for (const AxisSpec& a : c.axes) {
    if (a.role != hal::AxisRole::kKnotter) continue;
    const DriveModel* m = a.drive.empty() ? nullptr : find_drive(c, a.drive);
    if (m == nullptr) continue;
    const motion::ServoDrive& d = m->drive;
    if (first) {
      motion::set_servo(kc, d);
    } else {
      kc.no_load_speed_rad_s = std::min(kc.no_load_speed_rad_s, d.output_speed_rad_s());
      kc.peak_torque_nm = std::min(kc.peak_torque_nm, d.output_peak_torque_nm());
      kc.continuous_torque_nm = std::min(kc.continuous_torque_nm, d.output_rated_torque_nm());
      kc.rotor_inertia_kg_m2 = std::max(kc.rotor_inertia_kg_m2, d.output_inertia_kg_m2());
    }
    if (a.max_speed_set && a.max_speed < d.output_speed_rad_s()) {
      cap = capped ? std::min(cap, a.max_speed) : a.max_speed;
      capped = true;
    }
    first = false;
  }
  kc.max_speed_rad_s = capped ? cap : 0.0;
}

std::string drives_text(const LoomConfig& c) {
  std::ostringstream os;
  for (const DriveModel& m : c.drives) {
    const motion::ServoDrive& d = m.drive;
    os << "[" << m.name << " " << fmt_num(d.motor_speed_rad_s / kRpm) << " rpm "
       << fmt_num(d.motor_rated_torque_nm) << "/" << fmt_num(d.motor_peak_torque_nm) << " N m rotor "
       << fmt_num(d.rotor_inertia_kg_m2) << " gear " << fmt_num(d.gear_ratio) << " "
       << fmt_num(d.gear_inertia_kg_m2) << " " << fmt_num(d.gear_efficiency) << "]";
  }
  return os.str();
}

}  // namespace loom::firmware::detail

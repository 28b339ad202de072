// The axes of a loom file: [axes.<name>] tables, one per servo axis (role, drive, scaling, supervision,
// referencing), read over the base file's axes and put in slot order; the axis layout and the drive's
// scaling derived from them.
#include "axes.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "eds_keys.hpp"
#include "keys.hpp"

namespace loom::firmware {
namespace detail {
namespace {

bool valid_axis_name(const std::string& n) {
  if (n.empty() || n.size() > hal::AxisLayout::kNameMax) return false;
  return std::all_of(n.begin(), n.end(), [](char ch) {
    return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_';
  });
}

// An axis' referencing: "absolute", or "homing" with its CiA 402 method and parameters (all required
// then, and refused on an absolute axis so a half-changed table never passes).
void read_referencing(TomlReader& r, const toml::node& table, const std::string& p, AxisSpec& a,
                      bool is_new) {
  const auto has = [&](const char* k) { return table.as_table()->get(k) != nullptr; };
  std::string kind = a.homing ? "homing" : "absolute";
  if (is_new && !has("referencing"))
    r.fail_at(table, p + "referencing", "(missing)", "missing: absolute | homing");
  r.string(p + "referencing", kind, {"absolute", "homing"});
  a.homing = kind == "homing";
  static const char* const keys[] = {"homing_method", "home_offset", "homing_speed", "homing_accel",
                                     "homing_timeout_s"};
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
    if (was_absolute && !has(k))
      r.fail_at(table, p + k, "(missing)", "missing: referencing = \"homing\" needs it");
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
           "the helix cannot home: a homing run would drag the shuttle's carrier through a shed that may be "
           "closed; "
           "give the helix an absolute (multi-turn) encoder");
  }
}

}  // namespace

const std::vector<AxisKeyInfo>& axis_keys() {
  static const std::vector<AxisKeyInfo> k{
      {"axes.<name>.role", "beat_crank | carriage | helix | knotter | selector | auxiliary"},
      {"axes.<name>.node", "[1, 127] (integer)"},
      {"axes.<name>.bus", "[0, 3] (integer): 0 = the first CAN interface; default 0"},
      {"axes.<name>.counts_per_rev", "[16, 2147483648]"},
      {"axes.<name>.lead_m", "[0.0001, 1] (linear axes only)"},
      {"axes.<name>.drive",
       "a [drives.<model>] name (knotters with heads must name one; a core axis' limits are checked "
       "against its drive's)"},
      {"axes.<name>.max_speed",
       "[0.001, 1000] rad/s or m/s (added axes only; with a drive: at most its output speed, default it)"},
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
      {"axes.<name>.eds",
       "path of the drive's EDS (CiA 306), relative to this file; checked, and used at bring-up"},
      {"axes.<name>.store_config",
       "true | false; default false: after a bring-up that wrote anything, 0x1010:01 = \"save\" (needs "
       "its eds with a writable 0x1010:01)"},
      {"axes.<name>.drive_mode",
       "cyclic | profile; default cyclic (a set-point every SYNC); profile = CiA 402 profile position, "
       "one set-point per move and event-driven PDOs (role selector only)"},
  };
  return k;
}

std::string axes_text(const LoomConfig& c) {
  std::ostringstream os;
  for (const AxisSpec& a : c.axes) {
    os << "[" << a.name << " " << hal::axis_role_name(a.role) << " node " << int{a.node} << " "
       << fmt_num(a.counts_per_rev) << "/rev bus " << int{a.bus} << " lead " << fmt_num(a.lead_m) << " vmax "
       << fmt_num(a.max_speed) << (a.drive.empty() ? "" : " drive " + a.drive) << " ferror "
       << fmt_num(a.ferror_min) << "+" << fmt_num(a.ferror_k_s) << "s boot " << a.boot_ms << " op "
       << a.operational_ms;
    if (a.homing) {
      os << " homing " << a.homing_method << " at " << fmt_num(a.home_offset) << " "
         << fmt_num(a.homing_speed) << "/s " << fmt_num(a.homing_accel) << "/s2 "
         << fmt_num(a.homing_timeout_s) << "s";
    }
    if (!a.eds.empty()) os << " eds " << a.eds;
    if (a.store_config) os << " store";
    if (a.profile_position) os << " profile";
    os << "]";
  }
  return os.str();
}

void read_axes(TomlReader& r, LoomConfig& c, bool extending) {
  r.consume("axes");
  const toml::node* root = r.root().get("axes");
  if (root == nullptr) {
    if (!extending)
      r.fail_missing("axes",
                     "missing: every loom has [axes.beat_crank], [axes.carriage] and [axes.helix] tables");
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
      r.fail_at(node, "axes." + name, "",
                "an axis name is 1.." + std::to_string(hal::AxisLayout::kNameMax) +
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
    const bool core = a.role == hal::AxisRole::kBeatCrank || a.role == hal::AxisRole::kCarriage ||
                      a.role == hal::AxisRole::kHelix;
    const bool linear = !hal::is_rotary(a.role);
    need("node", "missing: the CANopen node id of its drive");
    std::int64_t node_id = a.node;
    r.integer(p + "node", node_id, 1, 127);
    a.node = static_cast<std::uint8_t>(node_id);
    std::int64_t bus = a.bus;
    r.integer(p + "bus", bus, 0, kMaxBuses - 1);
    a.bus = static_cast<std::uint8_t>(bus);
    need("counts_per_rev", "missing: encoder counts per motor revolution");
    r.number(p + "counts_per_rev", a.counts_per_rev,
             [](double v) { return in_range(v, 16.0, 2147483648.0); });
    if (linear) {
      need("lead_m", "missing: a linear axis' travel per motor revolution (m)");
      r.number(p + "lead_m", a.lead_m, [](double v) { return in_range(v, 1e-4, 1.0); });
    } else if (has("lead_m")) {
      r.fail(p + "lead_m", "",
             "only a linear axis (role carriage) has a lead; a rotary axis is scaled per revolution");
    } else {
      a.lead_m = 0.0;
    }
    if (core && has("max_speed")) {
      r.fail(p + "max_speed", "",
             "the core axes' speed limits are facts of their mechanisms: [carriage] max_speed_m_s, "
             "[helix] max_speed_rad_s, the recipe's crank speed");
    }
    // A core axis may name its drive too: its limits stay the mechanism's keys ([carriage], [helix], the
    // recipe's crank speed), and each is checked against what the drive gives (check_core_drives).
    r.string(p + "drive", a.drive);
    if (!core) {
      if (a.drive.empty())
        need("max_speed", std::string("missing: the axis' top speed (") + (linear ? "m/s" : "rad/s") +
                              "), or its drive (axes." + name + ".drive)");
      r.number(p + "max_speed", a.max_speed, [](double v) { return in_range(v, 1e-3, 1e3); });
      if (has("max_speed")) a.max_speed_set = true;
    } else {
      a.max_speed = 0.0;
    }
    need("ferror_min",
         std::string("missing: the following-error limit (") + (linear ? "m" : "rad") + "; 0 = off)");
    r.number(p + "ferror_min", a.ferror_min,
             [linear](double v) { return in_range(v, 0.0, linear ? 1.0 : 100.0); });
    r.number(p + "ferror_k_s", a.ferror_k_s, [](double v) { return in_range(v, 0.0, 10.0); });
    std::int64_t boot = a.boot_ms, op = a.operational_ms;
    r.integer(p + "boot_ms", boot, 0, 60000);
    r.integer(p + "operational_ms", op, 0, 60000);
    a.boot_ms = static_cast<std::uint32_t>(boot);
    a.operational_ms = static_cast<std::uint32_t>(op);
    read_referencing(r, node, p, a, is_new);
    read_eds_key(r, p + "eds", a.eds);
    r.boolean(p + "store_config", a.store_config);
    std::string mode = a.profile_position ? "profile" : "cyclic";
    r.string(p + "drive_mode", mode, {"cyclic", "profile"});
    if (mode == "profile" && a.role != hal::AxisRole::kSelector) {
      r.fail(p + "drive_mode", "\"profile\"",
             "profile position is for axes that move point to point between knots: the colour selectors "
             "(role = \"selector\"); this axis has role = \"" +
                 std::string(hal::axis_role_name(a.role)) + "\"");
    }
    a.profile_position = mode == "profile";
  }
  // Slot order: the core roles first (slots 0..2), then the others by name (toml++ keeps keys sorted).
  std::stable_sort(c.axes.begin(), c.axes.end(), [](const AxisSpec& x, const AxisSpec& y) {
    const auto rank = [](const AxisSpec& a) { return std::min(static_cast<int>(a.role), 3); };
    return rank(x) != rank(y) ? rank(x) < rank(y) : (rank(x) == 3 && x.name < y.name);
  });
  for (std::size_t role = 0; role < hal::kCoreAxisCount; ++role) {
    const auto r_ = static_cast<hal::AxisRole>(role);
    const auto n =
        std::count_if(c.axes.begin(), c.axes.end(), [&](const AxisSpec& a) { return a.role == r_; });
    if (n == 0)
      r.fail_at(*root, "axes", "",
                std::string("no axis has role = \"") + hal::axis_role_name(r_) + "\": every loom has one");
    if (n > 1) {
      const AxisSpec& second = c.axes[role + 1];
      r.fail("axes." + second.name + ".role", std::string("\"") + hal::axis_role_name(r_) + "\"",
             "the loom has one " + std::string(hal::axis_role_name(r_)) + " axis (axes." + c.axes[role].name +
                 ")");
    }
  }
  if (c.axes.size() > hal::kMaxAxes) {
    r.fail("axes." + (added.empty() ? c.axes.back().name : added.back()), "",
           std::to_string(c.axes.size()) + " axes; the controller holds at most " +
               std::to_string(hal::kMaxAxes));
  }
}

}  // namespace detail

double AxisSpec::counts_per_unit() const {
  return lead_m > 0.0 ? counts_per_rev / lead_m : counts_per_rev / (2.0 * M_PI);
}

hal::AxisLayout axis_layout(const LoomConfig& c) {
  hal::AxisLayout l;
  for (const AxisSpec& a : c.axes) l.add(a.name.c_str(), a.role);
  return l;
}
}  // namespace loom::firmware

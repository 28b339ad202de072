// [io_modules.<name>] tables (see io_modules_config.hpp).
#include "io_modules_config.hpp"

#include <algorithm>
#include <sstream>

#include "eds_keys.hpp"
#include "loom/drivers/can_axis_config.hpp"

namespace loom::firmware {

namespace {

// Every place a signal's module is kept, by the name a module table lists it under.
struct SignalSlot {
  std::string name;
  std::uint8_t& (*module)(LoomConfig&);
};

template <drivers::IoBit drivers::IoWiring::*member>
std::uint8_t& wiring_module(LoomConfig& c) {
  return (c.io.wiring.*member).module;
}
template <std::size_t i>
std::uint8_t& second_module(LoomConfig& c) {
  return c.io.wiring.second[i].module;
}
template <IoSettings::HeadSignals IoSettings::*member>
std::uint8_t& heads_module(LoomConfig& c) {
  return (c.io.*member).module;
}
std::uint8_t& load_cell_module(LoomConfig& c) {
  return c.io.wiring.load_cell_module;
}

const std::vector<SignalSlot>& signal_slots() {
  using W = drivers::IoWiring;
  static const std::vector<SignalSlot> slots{
      {"piston_a_extended", wiring_module<&W::piston_a_extended>},
      {"piston_a_retracted", wiring_module<&W::piston_a_retracted>},
      {"piston_b_extended", wiring_module<&W::piston_b_extended>},
      {"piston_b_retracted", wiring_module<&W::piston_b_retracted>},
      {"shuttle_at_left", wiring_module<&W::shuttle_at_left>},
      {"shuttle_at_right", wiring_module<&W::shuttle_at_right>},
      {"estop_ok", wiring_module<&W::estop_ok>},
      {"button_start", wiring_module<&W::button_start>},
      {"button_pause", wiring_module<&W::button_pause>},
      {"button_ack", wiring_module<&W::button_ack>},
      {"row_knotted", wiring_module<&W::row_knotted>},
      {"piston_a_extended_2", second_module<0>},
      {"piston_a_retracted_2", second_module<1>},
      {"piston_b_extended_2", second_module<2>},
      {"piston_b_retracted_2", second_module<3>},
      {"shuttle_at_left_2", second_module<4>},
      {"shuttle_at_right_2", second_module<5>},
      {"piston_a_extend", wiring_module<&W::piston_a_extend>},
      {"piston_b_extend", wiring_module<&W::piston_b_extend>},
      {"lamp_green", wiring_module<&W::lamp_green>},
      {"lamp_amber", wiring_module<&W::lamp_amber>},
      {"lamp_red", wiring_module<&W::lamp_red>},
      {"buzzer", wiring_module<&W::buzzer>},
      {"load_cell", load_cell_module},
      {"gripper_close", heads_module<&IoSettings::gripper_close>},
      {"cutter", heads_module<&IoSettings::cutter>},
      {"yarn_present", heads_module<&IoSettings::yarn_present>},
  };
  static_assert(hal::kSafetySensorCount == 6, "one _2 entry per safety sensor above");
  return slots;
}

bool valid_module_name(const std::string& n) {
  if (n.empty() || n.size() > 24) return false;
  return std::all_of(n.begin(), n.end(), [](char ch) {
    return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_';
  });
}

std::string quoted_list(const std::vector<std::string>& v) {
  std::string out;
  for (const std::string& s : v) out += (out.empty() ? "" : ", ") + s;
  return out;
}

}  // namespace

const std::vector<std::string>& io_signal_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const SignalSlot& s : signal_slots()) v.push_back(s.name);
    return v;
  }();
  return names;
}

const std::vector<IoModuleKeyInfo>& io_module_keys() {
  static const std::vector<IoModuleKeyInfo> k{
      {"io_modules.<name>.node", "[1, 127] (integer)"},
      {"io_modules.<name>.bus", "[0, 3] (integer): 0 = the first CAN interface; default 0"},
      {"io_modules.<name>.boot_timeout_ms", "[10, 60000] (integer); default 2000"},
      {"io_modules.<name>.operational_timeout_ms", "[10, 60000] (integer); default 500"},
      {"io_modules.<name>.signals",
       "io signal names (piston_a_extended … buzzer, load_cell, gripper_close, cutter, yarn_present)"},
      {"io_modules.<name>.eds", "path of the module's EDS (CiA 306), relative to this file"},
      {"io_modules.<name>.store_config",
       "true | false; default false: after a bring-up that wrote anything, 0x1010:01 = \"save\" (needs "
       "its eds with a writable 0x1010:01)"},
      {"io_modules.<name>.input_group_bits",
       "8 (0x6000) | 16 (0x6100); default: from its eds (8-bit groups when it has them all), else 8"},
  };
  return k;
}

void read_io_modules(TomlReader& r, LoomConfig& c) {
  r.consume("io_modules");
  if (const toml::node* root = r.root().get("io_modules")) {
    const toml::table* tables = root->as_table();
    if (tables == nullptr) r.fail_at(*root, "io_modules", "", "must be tables [io_modules.<name>]");
    for (auto&& entry : *tables) {
      const toml::node& node = entry.second;
      const std::string name(entry.first.str());
      const std::string p = "io_modules." + name + ".";
      if (!valid_module_name(name)) {
        r.fail_at(node, "io_modules." + name, "", "a module name is 1..24 characters of a-z, 0-9 and _");
      }
      if (!node.is_table())
        r.fail_at(node, "io_modules." + name, "", "must be a table [io_modules." + name + "]");
      r.consume("io_modules." + name);
      auto it = std::find_if(c.io.modules.begin(), c.io.modules.end(),
                             [&](const IoModuleSpec& m) { return m.name == name; });
      const bool is_new = it == c.io.modules.end();
      if (is_new) {
        if (c.io.modules.size() + 1 >= drivers::kMaxIoModules) {
          r.fail_at(node, "io_modules." + name, "",
                    "the controller holds at most " + std::to_string(drivers::kMaxIoModules) +
                        " I/O modules (the [io] one and " + std::to_string(drivers::kMaxIoModules - 1) +
                        " more)");
        }
        c.io.modules.push_back(IoModuleSpec{});
        c.io.modules.back().name = name;
        it = c.io.modules.end() - 1;
      }
      IoModuleSpec& m = *it;
      const auto has = [&](const char* k) { return node.as_table()->get(k) != nullptr; };
      if (is_new && !has("node"))
        r.fail_at(node, p + "node", "(missing)", "missing: the module's CANopen node id");
      if (is_new && !has("signals")) {
        r.fail_at(node, p + "signals", "(missing)",
                  "missing: the signals wired to this module (" + quoted_list(io_signal_names()) + ")");
      }
      std::int64_t v = m.node;
      r.integer(p + "node", v, 1, 127);
      m.node = static_cast<std::uint8_t>(v);
      v = m.bus;
      r.integer(p + "bus", v, 0, static_cast<std::int64_t>(drivers::kMaxBuses) - 1);
      m.bus = static_cast<std::uint8_t>(v);
      v = m.boot_timeout_ms;
      r.integer(p + "boot_timeout_ms", v, 10, 60000);
      m.boot_timeout_ms = static_cast<std::uint32_t>(v);
      v = m.operational_timeout_ms;
      r.integer(p + "operational_timeout_ms", v, 10, 60000);
      m.operational_timeout_ms = static_cast<std::uint32_t>(v);
      detail::read_eds_key(r, p + "eds", m.eds);
      r.boolean(p + "store_config", m.store_config);
      detail::read_input_group_bits(r, p + "input_group_bits", m.input_group_bits);
      r.string_list(p + "signals", m.signals);
      const std::string shown = "[" + quoted_list(m.signals) + "]";
      if (m.signals.empty()) r.fail(p + "signals", shown, "a module carries at least one signal");
      for (const std::string& s : m.signals) {
        const auto& names = io_signal_names();
        if (std::find(names.begin(), names.end(), s) == names.end()) {
          r.fail(p + "signals", shown,
                 "\"" + s + "\" is not an I/O signal; the signals are " + quoted_list(names));
        }
        if (std::count(m.signals.begin(), m.signals.end(), s) > 1) {
          r.fail(p + "signals", shown, "\"" + s + "\" is listed twice");
        }
      }
    }
  }
  // Module numbers follow the names (not the file's order, nor whether a module came from an extended
  // base): every signal on the [io] module, then each module's onto it.
  std::sort(c.io.modules.begin(), c.io.modules.end(),
            [](const IoModuleSpec& a, const IoModuleSpec& b) { return a.name < b.name; });
  for (const SignalSlot& s : signal_slots()) s.module(c) = 0;
  for (std::size_t k = 0; k < c.io.modules.size(); ++k) {
    const IoModuleSpec& m = c.io.modules[k];
    for (const std::string& name : m.signals) {
      const auto slot = std::find_if(signal_slots().begin(), signal_slots().end(),
                                     [&](const SignalSlot& s) { return s.name == name; });
      std::uint8_t& module = slot->module(c);
      if (module != 0) {
        r.fail("io_modules." + m.name + ".signals", "[" + quoted_list(m.signals) + "]",
               "\"" + name + "\" is already on io_modules." + c.io.modules[module - 1].name +
                   ": a signal is wired to one module");
      }
      module = static_cast<std::uint8_t>(k + 1);
    }
  }
}

std::string io_modules_text(const LoomConfig& c) {
  std::ostringstream os;
  for (const IoModuleSpec& m : c.io.modules) {
    os << "[" << m.name << " node " << int{m.node} << " bus " << int{m.bus} << " boot " << m.boot_timeout_ms
       << " op " << m.operational_timeout_ms << " signals " << quoted_list(m.signals);
    if (!m.eds.empty()) os << " eds " << m.eds;
    if (m.store_config) os << " store";
    if (m.input_group_bits != 0) os << " inputs " << m.input_group_bits << "-bit";
    os << "]";
  }
  return os.str();
}

}  // namespace loom::firmware

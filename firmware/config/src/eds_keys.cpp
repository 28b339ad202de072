// The `eds` keys of a loom file: the path of each node's electronic data sheet, the description read
// when the file is, and the keys it contradicts refused at their line with the EDS's file:line.
#include "eds_keys.hpp"

#include <cstdio>
#include <filesystem>
#include <optional>

#include "loom/drivers/can_io_config.hpp"
#include "loom/drivers/eds.hpp"
#include "loom/drivers/eds_check.hpp"
#include "loom/drivers/pdo.hpp"

namespace loom::firmware::detail {
namespace {

namespace eds = drivers::eds;

std::string hex32(std::uint64_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%08llX", static_cast<unsigned long long>(v));
  return b;
}

std::string quoted(const std::string& s) {
  return "\"" + s + "\"";
}

std::optional<std::uint64_t> value_bits(const eds::Value& v, const eds::Entry& e) {
  return v.bits(0, e.type);
}

// The description at `key` read, or the key refused with the file's first error (and how many more).
eds::Description read_or_fail(const TomlReader& r, const std::string& key, const std::string& path) {
  eds::Description d = eds::read_eds_file(path);
  if (!d.has_errors()) return d;
  int errors = 0;
  const eds::Diagnostic* first = nullptr;
  for (const eds::Diagnostic& x : d.diagnostics) {
    if (x.severity != eds::Severity::kError) continue;
    // The earliest line first (a missing object, line 0, is often the consequence of a broken section).
    if (first == nullptr || (x.line > 0 && (first->line == 0 || x.line < first->line))) first = &x;
    ++errors;
  }
  std::string why = "the EDS cannot be used: " + eds::format(path, *first);
  if (errors > 1) why += " (and " + std::to_string(errors - 1) + " more errors)";
  r.fail(key, quoted(path), why);
}

// 0x1000's profile: 402 (a drive) or 401 (an I/O module); the other kind's file is refused at `key`.
void check_profile(const TomlReader& r, const std::string& key, const std::string& path,
                   const eds::Description& d, bool drive) {
  const eds::Entry* e = d.entry(drivers::od::kDeviceType, 0);
  if (e == nullptr) return;
  const auto v = value_bits(e->value(), *e);
  if (!v) return;
  const unsigned profile = static_cast<unsigned>(*v & 0xFFFFu);
  const unsigned wrong = drive ? drivers::od401::kDeviceProfile401 : 0x0192u;
  if (profile != wrong) return;
  r.fail(key, quoted(path),
         d.at(e->value_line()) + ": 0x1000 device type " + hex32(*v) + " is CiA " + std::to_string(profile) +
             (drive ? " (an I/O module), not a drive: name the drive's own EDS here"
                    : " (a drive), not an I/O module: name the module's own EDS here"));
}

// can.heartbeat_ms is written to every node's 0x1017: within the EDS's LowLimit..HighLimit.
void check_heartbeat(const TomlReader& r, const LoomConfig& c, const eds::Description& d,
                     const std::string& node_key) {
  const eds::Entry* e = d.entry(drivers::od::kHeartbeatProducer, 0);
  if (e == nullptr) return;
  const auto lo = value_bits(e->low_limit, *e), hi = value_bits(e->high_limit, *e);
  const std::uint64_t ms = c.can.heartbeat_ms;
  if ((lo && ms < *lo) || (hi && ms > *hi)) {
    const int line = (lo && ms < *lo) ? e->low_line : e->high_line;
    r.fail("can.heartbeat_ms", std::to_string(ms),
           d.at(line) + ": " + node_key + "'s 0x1017 producer heartbeat time takes " +
               (lo ? e->low_limit.text : std::string("0")) + ".." +
               (hi ? e->high_limit.text : std::string("65535")) + " ms only: choose a heartbeat within it");
  }
}

// store_config = true: the node's EDS must say it can store (a writable 0x1010:01), so the master never
// asks a node that would abort.
void check_store(const TomlReader& r, const std::string& table, const std::string& path, bool store) {
  if (!store) return;
  if (path.empty()) {
    r.fail(table + ".store_config", "true",
           "needs " + table +
               ".eds: the master stores a node's configuration (0x1010:01 = \"save\") only "
               "where its EDS says it has 0x1010");
  }
  const eds::Description d = eds::read_eds_file(path);
  const eds::Entry* e = d.entry(drivers::od::kStoreParameters, 1);
  if (e != nullptr && eds::writable(e->access)) return;
  const eds::Object* o = d.object(drivers::od::kStoreParameters);
  r.fail(
      table + ".store_config", "true",
      (o == nullptr   ? d.at(0) + ": the node has no 0x1010 store parameters"
       : e == nullptr ? d.at(o->line) + ": the node's 0x1010 store parameters has no sub-index 1 (save all)"
                      : d.at(e->access_line) + ": the node's 0x1010:01 store parameters is " +
                            eds::access_name(e->access)) +
          ": it cannot store its configuration; leave store_config out (the master configures it at "
          "every bring-up anyway)");
}

// io.input_group_bits = 8 | 16 with an EDS: the module must have every input group of that form the
// wiring reads.
void check_input_groups(const TomlReader& r, const LoomConfig& c, const std::string& table,
                        const eds::Description& d, int bits, std::uint8_t module) {
  if (bits == 0) return;
  const drivers::IoWiring w = drivers::module_wiring(c.io.wiring, module);
  const std::uint16_t index = drivers::input_object(bits);
  const std::uint8_t groups = drivers::io_input_subs(w, bits);
  const eds::Object* o = d.object(index);
  for (std::uint8_t s = 1; s <= groups; ++s) {
    if (o != nullptr && o->entry(s) != nullptr) continue;
    char obj[16];
    std::snprintf(obj, sizeof obj, "0x%04X:%02X", index, s);
    r.fail(table + ".input_group_bits", std::to_string(bits),
           (o == nullptr ? d.at(0) + ": the module has no " + std::string(obj).substr(0, 6)
                         : d.at(o->line) + ": the module has no " + obj) +
               " (" + std::to_string(bits) + "-bit input groups), which the wiring reads: leave " + table +
               ".input_group_bits out (the EDS says which form it has)");
  }
}

void check_axis(const TomlReader& r, const LoomConfig& c, const AxisSpec& a) {
  const std::string p = "axes." + a.name + ".";
  const eds::Description d = read_or_fail(r, p + "eds", a.eds);
  check_profile(r, p + "eds", a.eds, d, true);
  const eds::NodeProfile profile = eds::profile_of(d);
  if (a.homing && profile.supported_modes && !profile.homing) {
    const eds::Entry* e = d.entry(drivers::od::kSupportedDriveModes, 0);
    r.fail(p + "referencing", "\"homing\"",
           d.at(e->value_line()) + ": the drive's 0x6502 supported drive modes " +
               hex32(*profile.supported_modes) + " (" + eds::describe_modes(*profile.supported_modes) +
               ") has no homing mode (HM): give the axis an absolute encoder (referencing = \"absolute\") or "
               "choose a drive with homing");
  }
  check_heartbeat(r, c, d, "axes." + a.name);
}

void check_module(const TomlReader& r, const LoomConfig& c, const std::string& key, const std::string& path,
                  std::uint8_t module, int input_group_bits) {
  const eds::Description d = read_or_fail(r, key + ".eds", path);
  check_profile(r, key + ".eds", path, d, false);
  check_input_groups(r, c, key, d, input_group_bits, module);
  const drivers::IoWiring& w = c.io.wiring;
  if (w.load_cell_channel > 0 && w.load_cell_module == module) {
    const eds::Object* o = d.object(drivers::od401::kAnalogInput16);
    const auto ch = static_cast<std::uint8_t>(w.load_cell_channel);
    if (o == nullptr || o->entry(ch) == nullptr) {
      r.fail("io.load_cell_channel", std::to_string(w.load_cell_channel),
             (o == nullptr ? d.at(0) + ": the module " + key + " has no 0x6401 analog input 16-bit"
                           : d.at(o->line) + ": the module " + key +
                                 "'s 0x6401 analog input 16-bit has no sub-index " +
                                 std::to_string(w.load_cell_channel)) +
                 ": wire the load cell to a channel it has, or set io.load_cell_channel = 0 (no load cell)");
    }
  }
  check_heartbeat(r, c, d, key);
}

}  // namespace

void read_eds_key(TomlReader& r, const std::string& path, std::string& out) {
  std::string value = out;
  r.string(path, value);
  if (value == out) return;
  if (value.empty())
    r.fail(path, "\"\"", "the path of the node's EDS (CiA 306) file; leave the key out for none");
  std::filesystem::path p(value);
  if (p.is_relative()) p = std::filesystem::path(r.source()).parent_path() / p;
  out = p.lexically_normal().string();
}

void read_input_group_bits(TomlReader& r, const std::string& path, int& out) {
  std::int64_t v = out;  // stays 0 (from the EDS) when the key is absent
  r.integer(path, v, 8, 16);
  if (v != out && v != 8 && v != 16) {
    r.fail(path, std::to_string(v),
           "the digital inputs are read as 8-bit (0x6000) or 16-bit (0x6100) groups");
  }
  out = static_cast<int>(v);
}

void check_eds_keys(const TomlReader& r, const LoomConfig& c) {
  for (const AxisSpec& a : c.axes) {
    if (!a.eds.empty()) check_axis(r, c, a);
    check_store(r, "axes." + a.name, a.eds, a.store_config);
  }
  if (c.io.kind != IoKind::kCan) return;
  if (!c.io.eds.empty()) check_module(r, c, "io", c.io.eds, 0, c.io.input_group_bits);
  check_store(r, "io", c.io.eds, c.io.store_config);
  for (std::size_t k = 0; k < c.io.modules.size(); ++k) {
    const IoModuleSpec& m = c.io.modules[k];
    const std::string table = "io_modules." + m.name;
    if (!m.eds.empty())
      check_module(r, c, table, m.eds, static_cast<std::uint8_t>(k + 1), m.input_group_bits);
    check_store(r, table, m.eds, m.store_config);
  }
}

}  // namespace loom::firmware::detail

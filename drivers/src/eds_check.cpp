// The comparison of a node's EDS with what the master needs of it. The needs are built from the same
// constants the master configures with (pdo.hpp's layouts, od:: and od401:: indices, required_objects'
// names and reasons), so the check cannot drift from what bring-up really reads and writes.
#include "loom/drivers/eds_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "loom/drivers/cia402.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/drivers/required_objects.hpp"

namespace loom::drivers::eds {

namespace {

std::string hex(std::uint64_t v, int digits) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%0*llX", digits, static_cast<unsigned long long>(v));
  return buf;
}

std::string object_text(std::uint16_t index, std::uint8_t sub, bool whole) {
  return whole ? hex(index, 4) : hex(index, 4) + ":" + (sub < 16 ? "0" : "") + [&] {
    char b[4];
    std::snprintf(b, sizeof b, "%X", sub);
    return std::string(b);
  }();
}

// The CiA 301/401/402 data types of the objects the master uses (the master's SDO sizes and the PDO
// layouts of pdo.hpp are these widths).
struct TypeFact {
  std::uint16_t index;
  DataType type;
};
constexpr TypeFact kTypes[] = {
    {od::kDeviceType, DataType::kUnsigned32},
    {od::kErrorRegister, DataType::kUnsigned8},
    {od::kHeartbeatProducer, DataType::kUnsigned16},
    {od401::kConsumerHeartbeat, DataType::kUnsigned32},
    {od::kErrorCode, DataType::kUnsigned16},
    {od::kControlword, DataType::kUnsigned16},
    {od::kStatusword, DataType::kUnsigned16},
    {od::kModesOfOperation, DataType::kInteger8},
    {od::kModesOfOperationDisplay, DataType::kInteger8},
    {od::kPositionActual, DataType::kInteger32},
    {od::kVelocityActual, DataType::kInteger32},
    {od::kTorqueActual, DataType::kInteger16},
    {od::kTargetPosition, DataType::kInteger32},
    {od::kSupportedDriveModes, DataType::kUnsigned32},
    {od::kHomeOffset, DataType::kInteger32},
    {od::kHomingMethod, DataType::kInteger8},
    {od::kHomingSpeeds, DataType::kUnsigned32},
    {od::kHomingAcceleration, DataType::kUnsigned32},
    {od401::kDigitalInputs8, DataType::kUnsigned8},
    {od401::kDigitalInputs16, DataType::kUnsigned16},
    {od401::kDigitalOutputs8, DataType::kUnsigned8},
    {od401::kOutputErrorMode, DataType::kUnsigned8},
    {od401::kOutputErrorValue, DataType::kUnsigned8},
    {od401::kAnalogInput16, DataType::kInteger16},
};

DataType type_of(std::uint16_t index, std::uint8_t sub) {
  if (index == od::kInterpolationPeriod) return sub == 2 ? DataType::kInteger8 : DataType::kUnsigned8;
  for (const TypeFact& f : kTypes) {
    if (f.index == index) return f.type;
  }
  return DataType::kUnsigned32;
}

// The master's use of each object (what it reads, writes, maps).
Use use_of(std::uint16_t index) {
  switch (index) {
    case od::kHeartbeatProducer:
    case od401::kConsumerHeartbeat:
    case od::kModesOfOperation:
    case od::kInterpolationPeriod:
    case od::kHomeOffset:
    case od::kHomingMethod:
    case od::kHomingSpeeds:
    case od::kHomingAcceleration:
    case od401::kOutputErrorMode:
    case od401::kOutputErrorValue:
      return Use::kWrite;
    case od::kControlword:
    case od::kTargetPosition:
    case od401::kDigitalOutputs8:
      return Use::kWrite;
    default:
      return Use::kRead;
  }
}

ObjectNeed need_of(const RequiredObject& r, std::uint8_t sub) {
  ObjectNeed n;
  n.index = r.index;
  n.sub = sub;
  n.type = type_of(r.index, sub);
  n.use = use_of(r.index);
  n.optional = r.optional;
  n.name = r.name;
  n.why = r.why;
  return n;
}

bool is_pdo_object(std::uint16_t index) {
  return index >= 0x1400 && index < 0x1C00;
}

void add_objects(NodeNeeds& needs, const std::vector<RequiredObject>& list) {
  for (const RequiredObject& r : list) {
    if (is_pdo_object(r.index)) continue;  // PDOs are checked as PdoNeeds
    const bool dup = std::any_of(needs.objects.begin(), needs.objects.end(),
                                 [&](const ObjectNeed& n) { return n.index == r.index; });
    if (dup) continue;
    if (r.index == od::kInterpolationPeriod) {
      needs.objects.push_back(need_of(r, 1));
      needs.objects.push_back(need_of(r, 2));
    } else if (r.index == od::kHomingSpeeds) {
      needs.objects.push_back(need_of(r, 1));
      needs.objects.push_back(need_of(r, 2));
    } else if (r.index == od401::kConsumerHeartbeat) {
      needs.objects.push_back(need_of(r, 1));
    } else if (r.subs > 0) {
      for (std::uint8_t s = 1; s <= r.subs; ++s) needs.objects.push_back(need_of(r, s));
    } else if (r.index == od401::kAnalogInput16 || r.index == od401::kOutputErrorMode ||
               r.index == od401::kOutputErrorValue) {
      needs.objects.push_back(need_of(r, 1));
    } else {
      needs.objects.push_back(need_of(r, 0));
    }
  }
}

ObjectNeed* find_need(NodeNeeds& needs, std::uint16_t index, std::uint8_t sub) {
  for (ObjectNeed& n : needs.objects) {
    if (n.index == index && n.sub == sub) return &n;
  }
  return nullptr;
}

template <std::size_t N>
std::vector<MapEntry> entries_of(const std::array<PdoMapEntry, N>& layout) {
  std::vector<MapEntry> v;
  for (const PdoMapEntry& e : layout) v.push_back(MapEntry{e.index, e.sub, e.bits});
  return v;
}

std::uint32_t encode(const MapEntry& e) {
  return (static_cast<std::uint32_t>(e.index) << 16) | (static_cast<std::uint32_t>(e.sub) << 8) | e.bits;
}

std::string entries_text(const std::vector<MapEntry>& v) {
  std::string s = "{";
  for (const MapEntry& e : v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s0x%04X:%02X/%u", s.size() > 1 ? ", " : "", e.index, e.sub, e.bits);
    s += buf;
  }
  return s + "}";
}

}  // namespace

std::string describe_modes(std::uint32_t bits) {
  static const char* const kNames[] = {"PP", "VL",  "PV",  "TQ",  "bit 4", "HM",
                                       "IP", "CSP", "CSV", "CST", "CSTCA"};
  std::string s;
  for (unsigned b = 0; b < 32; ++b) {
    if ((bits & (1U << b)) == 0) continue;
    s += (s.empty() ? "" : ", ") + std::string(b < 11 ? kNames[b] : ("bit " + std::to_string(b)).c_str());
  }
  return s.empty() ? "none" : s;
}

NodeNeeds drive_needs(const CanAxisConfig& axis, const CanAxisPortConfig& port) {
  NodeNeeds needs;
  needs.node = "axes." + axis.name + " (node " + std::to_string(axis.node_id) + ")";
  needs.node_id = axis.node_id;
  needs.device_profile = 402;
  const bool homed = axis.homing_method != 0;
  needs.modes = od::kSupportsCspBit | (homed ? od::kSupportsHomingBit : 0U);
  needs.heartbeat_ms = static_cast<std::uint16_t>(std::lround(port.heartbeat_producer_s * 1000.0));
  add_objects(needs, drive_objects());
  if (homed) add_objects(needs, homing_drive_objects());
  if (ObjectNeed* n = find_need(needs, od::kHeartbeatProducer, 0)) n->value = needs.heartbeat_ms;
  if (ObjectNeed* n = find_need(needs, od::kModesOfOperation, 0)) n->value = od::kModeCsp;
  if (ObjectNeed* n = find_need(needs, od::kHomingMethod, 0)) n->value = axis.homing_method;
  if (ObjectNeed* n = find_need(needs, od401::kConsumerHeartbeat, 1);
      n != nullptr && port.master_node_id != 0) {
    n->value =
        (static_cast<std::int64_t>(port.master_node_id) << 16) | std::lround(port.master_consumer_s * 1000.0);
  }
  if (const auto ip = encode_interpolation_period(port.cycle_period_s)) {
    if (ObjectNeed* n = find_need(needs, od::kInterpolationPeriod, 1)) n->value = ip->value;
    if (ObjectNeed* n = find_need(needs, od::kInterpolationPeriod, 2)) n->value = ip->index;
  }
  // Objects carried in PDOs.
  for (ObjectNeed& n : needs.objects) {
    if (n.index == od::kControlword || n.index == od::kTargetPosition) n.pdo = PdoUse::kRpdo;
    if (n.index == od::kStatusword || n.index == od::kPositionActual) n.pdo = PdoUse::kTpdo;
    if (port.tpdo2 && (n.index == od::kVelocityActual || n.index == od::kTorqueActual)) n.pdo = PdoUse::kTpdo;
    if (homed && n.index == od::kModesOfOperation) n.pdo = PdoUse::kRpdo;
    if (homed && n.index == od::kModesOfOperationDisplay) n.pdo = PdoUse::kTpdo;
  }
  needs.pdos.push_back(PdoNeed{true, 1, false, false,
                               homed ? entries_of(kRpdo1HomingMapping) : entries_of(kRpdo1Mapping), 1,
                               "controlword + target position every SYNC"});
  needs.pdos.push_back(PdoNeed{false, 1, false, false,
                               homed ? entries_of(kTpdo1HomingMapping) : entries_of(kTpdo1Mapping), 1,
                               "statusword + position actual every SYNC"});
  if (port.tpdo2) {
    needs.pdos.push_back(PdoNeed{false, 2, false, true, entries_of(kTpdo2Mapping), port.tpdo2_every_n_sync,
                                 "velocity + torque actual (can.tpdo2)"});
  }
  return needs;
}

NodeNeeds io_module_needs(const CanIoConfig& config) {
  NodeNeeds needs;
  needs.node = (config.name.empty() ? std::string("io") : "io_modules." + config.name) + " (node " +
               std::to_string(config.node_id) + ")";
  needs.node_id = config.node_id;
  needs.device_profile = 401;
  needs.heartbeat_ms = static_cast<std::uint16_t>(std::lround(config.heartbeat_producer_s * 1000.0));
  const IoWiring w = module_wiring(config.wiring, config.module);
  const int group_bits = config.input_group_bits == kInputGroupBits16 ? kInputGroupBits16 : kInputGroupBits8;
  const std::uint16_t input_index = input_object(group_bits);
  add_objects(needs, io_module_objects(w, group_bits));
  if (ObjectNeed* n = find_need(needs, od::kHeartbeatProducer, 0)) n->value = needs.heartbeat_ms;
  if (ObjectNeed* n = find_need(needs, od401::kConsumerHeartbeat, 1);
      n != nullptr && config.master_node_id != 0) {
    n->value = (static_cast<std::int64_t>(config.master_node_id) << 16) |
               std::lround(config.master_consumer_s * 1000.0);
  }
  std::vector<MapEntry> inputs, outputs;
  for (std::uint8_t s = 1; s <= io_input_subs(w, group_bits); ++s)
    inputs.push_back(MapEntry{input_index, s, static_cast<std::uint8_t>(group_bits)});
  for (std::uint8_t s = 1; s <= io_output_subs(w); ++s)
    outputs.push_back(MapEntry{od401::kDigitalOutputs8, s, 8});
  for (ObjectNeed& n : needs.objects) {
    if (n.index == input_index || n.index == od401::kAnalogInput16) n.pdo = PdoUse::kTpdo;
    if (n.index == od401::kDigitalOutputs8) n.pdo = PdoUse::kRpdo;
    if (n.index == od401::kAnalogInput16) n.sub = static_cast<std::uint8_t>(w.load_cell_channel);
  }
  if (!outputs.empty()) needs.pdos.push_back(PdoNeed{true, 1, true, false, outputs, 1, "digital outputs"});
  if (!inputs.empty())
    needs.pdos.push_back(PdoNeed{false, 1, true, false, inputs, 1, "digital inputs, one sample"});
  if (w.load_cell_channel > 0) {
    needs.pdos.push_back(
        PdoNeed{false,
                2,
                true,
                false,
                {MapEntry{od401::kAnalogInput16, static_cast<std::uint8_t>(w.load_cell_channel), 16}},
                1,
                "the load cell"});
  }
  return needs;
}

int input_group_bits_of(const Description& eds, const IoWiring& wiring) {
  for (const int bits : {kInputGroupBits8, kInputGroupBits16}) {
    const std::uint8_t groups = io_input_subs(wiring, bits);
    bool all = true;
    for (std::uint8_t s = 1; s <= groups && all; ++s) all = eds.entry(input_object(bits), s) != nullptr;
    if (all) return bits;
  }
  return 0;
}

NodeProfile profile_of(const Description& eds) {
  NodeProfile p;
  if (const Entry* e = eds.entry(od::kDeviceType, 0)) {
    if (const auto v = e->value().bits(0, e->type)) p.device_type = static_cast<std::uint32_t>(*v);
  }
  if (const Entry* e = eds.entry(od::kSupportedDriveModes, 0)) {
    if (const auto v = e->value().bits(0, e->type)) {
      p.supported_modes = static_cast<std::uint32_t>(*v);
      p.csp = (*v & od::kSupportsCspBit) != 0;
      p.homing = (*v & od::kSupportsHomingBit) != 0;
    }
  }
  for (const PdoDescription& d : pdos(eds)) {
    (d.receive ? p.rpdos : p.tpdos) += 1;
    if (d.receive && d.number == 1) p.rpdo1 = d.kind;
    if (!d.receive && d.number == 1) p.tpdo1 = d.kind;
    if (!d.receive && d.number == 2) p.tpdo2 = d.kind;
  }
  p.fixed_mapping = p.rpdo1 == MappingKind::kFixed || p.tpdo1 == MappingKind::kFixed;
  p.consumer_heartbeat = eds.object(od401::kConsumerHeartbeat) != nullptr;
  p.vendor = eds.device.vendor_number;
  p.product = eds.device.product_number;
  p.revision = eds.device.revision_number;
  // 0x1018's own DefaultValues where [DeviceInfo] leaves them out.
  const auto identity = [&](std::uint8_t sub, std::optional<std::uint32_t>& out) {
    if (out) return;
    if (const Entry* e = eds.entry(0x1018, sub)) {
      if (const auto v = e->value().bits(0, e->type)) out = static_cast<std::uint32_t>(*v);
    }
  };
  identity(1, p.vendor);
  identity(2, p.product);
  identity(3, p.revision);
  return p;
}

bool NodeCheck::ok() const {
  return std::none_of(findings.begin(), findings.end(),
                      [](const Finding& f) { return f.level == Level::kError; });
}

namespace {

class Checker {
 public:
  Checker(const Description& eds, const NodeNeeds& needs, NodeCheck& out)
      : eds_(eds), needs_(needs), out_(out) {}

  void run() {
    device_type();
    for (const ObjectNeed& n : needs_.objects) object(n);
    pdo_counts();
    for (std::size_t k = 0; k < needs_.pdos.size(); ++k) {
      need_ = k;
      pdo(needs_.pdos[k]);
    }
    modes();
    sync();
    scaling();
  }

 private:
  void add(Level level, int line, std::string message, std::string remedy = {}) {
    out_.findings.push_back(Finding{level, line, std::move(message), std::move(remedy)});
  }
  // An optional need's lack is a warning, a required one's an error.
  Level lack(bool optional) const { return optional ? Level::kWarning : Level::kError; }

  // A digital input group the file lacks: the same terminals in the other form (8-bit group s is half of
  // 16-bit group (s - 1) / 2 + 1) would do — the master uses 0x6100 whenever the file has every 16-bit
  // group the wiring needs and 0x6000 does not (input_group_bits_of()) — so name both.
  std::string input_groups_remedy(const ObjectNeed& n) const {
    const bool eight = n.index == od401::kDigitalInputs8;
    std::string other;
    if (eight) {
      other = object_text(od401::kDigitalInputs16, static_cast<std::uint8_t>((n.sub - 1) / 2 + 1), false);
    } else {
      other = object_text(od401::kDigitalInputs8, static_cast<std::uint8_t>(2 * n.sub - 1), false) + "/" +
              object_text(od401::kDigitalInputs8, static_cast<std::uint8_t>(2 * n.sub), false).substr(7);
    }
    const bool has_other =
        eight ? eds_.entry(od401::kDigitalInputs16, static_cast<std::uint8_t>((n.sub - 1) / 2 + 1))
              : eds_.entry(od401::kDigitalInputs8, static_cast<std::uint8_t>(2 * n.sub));
    if (eight && has_other) {
      return "the file's 16-bit groups (0x6100) do not hold every wired input either: wire the signals "
             "to lower bits (fewer groups) or choose a module with more I/O";
    }
    if (!eight && has_other) {
      return "the file has these inputs as 8-bit groups " + other + ": leave io.input_group_bits out (or 8)";
    }
    return std::string("the file has ") + (eight ? "no 16-bit group " : "no 8-bit groups ") + other +
           " for these inputs either: wire the signals to lower bits (fewer groups) or choose a module with "
           "more I/O";
  }

  std::string label(const ObjectNeed& n) const {
    const bool whole =
        n.sub == 0 && (eds_.object(n.index) == nullptr || eds_.object(n.index)->type == ObjectType::kVar);
    return object_text(n.index, n.sub, whole) + " " + n.name;
  }

  void device_type() {
    const Entry* e = eds_.entry(od::kDeviceType, 0);
    if (e == nullptr || needs_.device_profile == 0) return;
    const auto v = e->value().bits(0, e->type);
    if (!v) {
      add(Level::kInfo, e->line,
          "0x1000 device type has no DefaultValue: the profile is checked at bring-up");
      return;
    }
    if ((*v & 0xFFFF) != needs_.device_profile) {
      add(Level::kError, e->value_line(),
          "0x1000 device type " + hex(*v, 8) + " is profile " + std::to_string(*v & 0xFFFF) + ", not CiA " +
              std::to_string(needs_.device_profile),
          needs_.device_profile == 402
              ? "give this axis a CiA 402 servo drive's EDS (is this the I/O module's file?)"
              : "give this module a CiA 401 I/O module's EDS (is this a drive's file?)");
    }
  }

  void object(const ObjectNeed& n) {
    const Object* o = eds_.object(n.index);
    const Entry* e = eds_.entry(n.index, n.sub);
    if (e == nullptr) {
      const std::string where =
          o == nullptr ? "is not in the file" : "has no sub-index " + std::to_string(n.sub);
      std::string remedy;
      if (n.optional) {
        remedy = "the loom runs without it";
      } else if (n.index == od::kHeartbeatProducer) {
        remedy = "the loom supervises nodes by heartbeat only (no node guarding): choose a node with 0x1017";
      } else if (n.index == od401::kDigitalInputs8 || n.index == od401::kDigitalInputs16) {
        remedy = input_groups_remedy(n);
      } else if (n.index == od401::kDigitalOutputs8) {
        remedy = "wire the signals to lower bits (fewer 8-bit groups) or choose a module with more I/O";
      } else if (n.index == od::kHomingMethod || n.index == od::kHomeOffset || n.index == od::kHomingSpeeds ||
                 n.index == od::kHomingAcceleration) {
        remedy = "use an absolute encoder (referencing without homing) or a drive with CiA 402 homing";
      } else {
        remedy = "the loom cannot run this node without it: choose a node whose EDS has it";
      }
      add(lack(n.optional), o == nullptr ? 0 : o->line, label(n) + " " + where + " (" + n.why + ")", remedy);
      return;
    }
    if (type_bits(e->type) != type_bits(n.type)) {
      add(Level::kError, e->type_line,
          label(n) + " is " + type_name(e->type) + ", the loom exchanges it as " + type_name(n.type),
          "the loom's PDO layout and SDO sizes are CiA 402/401's; this node is not usable as described");
    } else if (e->type != n.type) {
      add(Level::kWarning, e->type_line,
          label(n) + " is " + type_name(e->type) + " where CiA 301/402/401 say " + type_name(n.type) +
              ": same width, read as " + type_name(n.type));
    }
    const bool need_read = n.use != Use::kWrite || n.pdo == PdoUse::kTpdo;
    const bool need_write = n.use != Use::kRead || n.pdo == PdoUse::kRpdo;
    if (need_write && !writable(e->access)) {
      add(lack(n.optional), e->access_line,
          label(n) + " is " + access_name(e->access) + "; the loom writes it (" + n.why + ")",
          n.optional ? "the loom runs without it" : "this node cannot be configured as the loom needs");
    }
    if (need_read && !readable(e->access)) {
      add(lack(n.optional), e->access_line, label(n) + " is write-only; the loom reads it (" + n.why + ")",
          "this node cannot be supervised as the loom needs");
    }
    if (n.value) range(n, *e);
  }

  void range(const ObjectNeed& n, const Entry& e) {
    const auto as_i = [](const Value& v) -> std::optional<long double> {
      if (v.plus_node_id) return std::nullopt;
      if (const auto* i = std::get_if<std::int64_t>(&v.v)) return static_cast<long double>(*i);
      if (const auto* u = std::get_if<std::uint64_t>(&v.v)) return static_cast<long double>(*u);
      return std::nullopt;
    };
    const auto lo = as_i(e.low_limit), hi = as_i(e.high_limit);
    const long double v = static_cast<long double>(*n.value);
    if ((lo && v < *lo) || (hi && v > *hi)) {
      std::string remedy = "choose a setting within the limits";
      if (n.index == od::kHeartbeatProducer)
        remedy = "set can.heartbeat_producer_ms (io: heartbeat) within them";
      if (n.index == od::kInterpolationPeriod)
        remedy = "choose a control period (timing.period_ms) within them";
      if (n.index == od::kHomingMethod) remedy = "choose a homing method the drive offers";
      add(Level::kError, lo && v < *lo ? e.low_line : e.high_line,
          label(n) + ": the loom writes " + std::to_string(*n.value) + ", outside the EDS's limits " +
              (e.low_limit.empty() ? "-" : e.low_limit.text) + ".." +
              (e.high_limit.empty() ? "-" : e.high_limit.text),
          remedy);
    }
  }

  void pdo_counts() {
    const NodeProfile& p = out_.profile;
    int rx = 0, tx = 0;
    for (const PdoNeed& n : needs_.pdos) {
      if (n.optional) continue;
      (n.receive ? rx : tx) = std::max(n.receive ? rx : tx, n.any_pdo ? 1 : n.number);
    }
    add(Level::kInfo, eds_.device.line,
        std::to_string(p.rpdos) + " RPDO(s), " + std::to_string(p.tpdos) + " TPDO(s); RPDO1 mapping " +
            mapping_kind_name(p.rpdo1) + ", TPDO1 mapping " + mapping_kind_name(p.tpdo1) +
            (p.consumer_heartbeat ? "; watches the controller's heartbeat (0x1016)" : "; no 0x1016"));
    if (p.rpdos < rx) {
      add(Level::kError, eds_.device.rxpdo_line,
          "the node has " + std::to_string(p.rpdos) + " RPDO(s); the loom needs " + std::to_string(rx),
          "choose a node with more receive PDOs");
    }
    if (p.tpdos < tx) {
      add(Level::kError, eds_.device.txpdo_line,
          "the node has " + std::to_string(p.tpdos) + " TPDO(s); the loom needs " + std::to_string(tx),
          "choose a node with more transmit PDOs");
    }
  }

  const Entry* mappable_entry(const MapEntry& m) const { return eds_.entry(m.index, m.sub); }

  // Every entry can be mapped into a dynamic PDO; "" when so, else why not.
  std::string dynamic_fits(const PdoNeed& n) const {
    unsigned bits = 0;
    for (const MapEntry& m : n.entries) {
      bits += m.bits;
      const Entry* e = mappable_entry(m);
      if (e == nullptr) continue;  // reported as a missing object
      if (!e->pdo_mapping)
        return hex(m.index, 4) + ":" + hex(m.sub, 2).substr(2) + " is not PDO-mappable (PDOMapping=0)";
      const unsigned g = eds_.device.granularity;
      if (g > 1 && m.bits % g != 0)
        return "granularity " + std::to_string(g) + " bits cannot map a " + std::to_string(m.bits) +
               "-bit entry";
    }
    if (bits > 64) return std::to_string(bits) + " bits exceed one PDO's 64";
    return {};
  }

  void pdo(const PdoNeed& n) {
    const char* dir = n.receive ? "RPDO" : "TPDO";
    const std::string name = std::string(dir) + (n.any_pdo ? "" : std::to_string(n.number)) + " " +
                             entries_text(n.entries) + " (" + n.why + ")";
    // An entry the file lacks is reported as a missing object; no PDO can carry it.
    for (const MapEntry& m : n.entries) {
      if (mappable_entry(m) == nullptr) return;
    }
    std::vector<PdoDescription> candidates;
    for (PdoDescription& d : pdos(eds_)) {
      const bool taken = std::count(used_.begin(), used_.end(), std::make_pair(d.receive, d.number)) > 0;
      if (d.receive == n.receive && (n.any_pdo || d.number == n.number) && !taken) {
        candidates.push_back(std::move(d));
      }
    }
    if (candidates.empty()) {
      add(lack(n.optional), 0,
          name + (n.any_pdo ? std::string(": no ") + dir + " of the node is left for it"
                            : ": the node has no such PDO"),
          n.optional ? "the loom runs without it" : std::string("choose a node with another ") + dir);
      return;
    }
    std::string why_not;
    const PdoDescription* used = nullptr;
    for (const PdoDescription& d : candidates) {
      if (d.kind == MappingKind::kDynamic) {
        const std::string reason = dynamic_fits(n);
        if (reason.empty()) {
          used = &d;
          break;
        }
        why_not = std::string(dir) + std::to_string(d.number) + " (dynamic): " + reason;
        if (reason.find("PDO-mappable") != std::string::npos) {
          const Entry* e = nullptr;
          for (const MapEntry& m : n.entries) {
            if (const Entry* x = mappable_entry(m); x != nullptr && !x->pdo_mapping) e = x;
          }
          if (e != nullptr && e->pdo_line > 0) {
            add(lack(n.optional), e->pdo_line, name + ": " + reason,
                n.optional ? "the loom runs without it" : "choose a node that maps it");
            return;
          }
        }
        continue;
      }
      // Fixed: the drive's layout must be exactly the codec's; the I/O module's may hold the entries
      // anywhere.
      bool carries = false;
      if (n.any_pdo) {
        carries = std::all_of(n.entries.begin(), n.entries.end(), [&](const MapEntry& m) {
          return std::any_of(d.mapping.begin(), d.mapping.end(),
                             [&](const MapEntry& x) { return encode(x) == encode(m); });
        });
      } else {
        carries = d.mapping.size() == n.entries.size() &&
                  std::equal(d.mapping.begin(), d.mapping.end(), n.entries.begin(),
                             [](const MapEntry& a, const MapEntry& b) { return encode(a) == encode(b); });
      }
      if (carries) {
        used = &d;
        break;
      }
      why_not =
          std::string(dir) + std::to_string(d.number) + " mapping is fixed to " + entries_text(d.mapping);
    }
    if (used != nullptr) {
      used_.emplace_back(used->receive, used->number);
      out_.pdo_plan.push_back(PdoAssignment{need_, used->receive, used->number, used->kind});
    }
    if (used == nullptr) {
      std::string remedy = "choose a node whose mapping can carry it";
      if (!n.receive && n.number == 2)
        remedy = "set can.tpdo2 = false (velocity is then derived from positions)";
      if (n.entries.size() == 3)
        remedy = "use an absolute encoder (no homing: 6-byte PDOs) or a drive with dynamic mapping";
      add(lack(n.optional), candidates.front().line, name + ": " + why_not, remedy);
      return;
    }
    add(Level::kInfo, used->line,
        std::string(dir) + std::to_string(used->number) + " carries " + entries_text(n.entries) +
            (used->kind == MappingKind::kFixed ? " (fixed mapping, read back at bring-up)"
                                               : " (mapping written at bring-up)"));
    transmission(n, *used);
  }

  void transmission(const PdoNeed& n, const PdoDescription& d) {
    const Object* comm =
        eds_.object(static_cast<std::uint16_t>((n.receive ? 0x1400 : 0x1800) + d.number - 1));
    const Entry* tt = comm != nullptr ? comm->entry(2) : nullptr;
    const std::string who = std::string(n.receive ? "RPDO" : "TPDO") + std::to_string(d.number);
    if (tt == nullptr) {
      add(Level::kWarning, comm != nullptr ? comm->line : 0,
          who + " has no transmission type (sub-index 2) in the file",
          "check at bring-up that the node transmits on SYNC");
      return;
    }
    if (!writable(tt->access)) {
      const auto v = tt->value().bits(0, tt->type);
      const bool sync = v && *v >= 1 && *v <= 240;
      if (!n.receive && !sync) {
        add(lack(n.optional), tt->access_line,
            who + " transmission type is " +
                (tt->value().empty() ? std::string("not given") : tt->value().text) + " (" +
                access_name(tt->access) +
                ") and cannot be changed; the loom needs a synchronous TPDO (1..240) so that silence is seen "
                "every cycle",
            "choose a node whose TPDO transmission type is writable or synchronous");
      }
      return;
    }
    const auto lo = tt->low_limit.bits(0, tt->type), hi = tt->high_limit.bits(0, tt->type);
    if ((lo && n.transmission_type < *lo) || (hi && n.transmission_type > *hi)) {
      add(lack(n.optional), tt->low_line > 0 ? tt->low_line : tt->high_line,
          who + " transmission type " + std::to_string(n.transmission_type) +
              " is outside the EDS's limits " + tt->low_limit.text + ".." + tt->high_limit.text,
          "the node cannot transmit on SYNC as the loom needs");
    }
  }

  void modes() {
    if (needs_.modes == 0) return;
    const Entry* e = eds_.entry(od::kSupportedDriveModes, 0);
    if (e == nullptr) return;  // reported as a missing object
    const auto v = e->value().bits(0, e->type);
    if (!v) {
      add(Level::kWarning, e->line,
          "0x6502 supported drive modes has no DefaultValue: CSP is checked at bring-up");
      return;
    }
    const std::uint32_t missing = needs_.modes & ~static_cast<std::uint32_t>(*v);
    if (missing == 0) {
      add(Level::kInfo, e->value_line(), "0x6502 offers " + describe_modes(static_cast<std::uint32_t>(*v)));
      return;
    }
    std::string remedy =
        "the loom drives its axes in cyclic synchronous position (CSP, mode 8) only: choose a drive (or "
        "firmware) with CSP";
    if ((missing & od::kSupportsCspBit) == 0) {
      remedy =
          "reference the axis without homing (an absolute encoder) or choose a drive with CiA 402 homing";
    }
    add(Level::kError, e->value_line(),
        "0x6502 supported drive modes " + hex(*v, 8) + " (" + describe_modes(static_cast<std::uint32_t>(*v)) +
            ") lacks " + describe_modes(missing),
        remedy);
  }

  void sync() {
    if (eds_.object(0x1005) == nullptr) {
      add(Level::kInfo, 0,
          "0x1005 COB-ID SYNC is not described: the node is assumed to take SYNC on 0x080 (the default)");
    }
  }

  void scaling() {
    if (needs_.modes == 0) return;
    const auto value = [&](std::uint16_t index, std::uint8_t sub) -> std::optional<std::uint64_t> {
      const Entry* e = eds_.entry(index, sub);
      return e == nullptr ? std::nullopt : e->value().bits(0, e->type);
    };
    const auto inc = value(0x608F, 1), revs = value(0x608F, 2);
    if (inc && revs && *revs != 0) {
      add(Level::kInfo, eds_.object(0x608F)->line,
          "0x608F position encoder resolution: " + std::to_string(*inc) + " increments per " +
              std::to_string(*revs) + " motor revolution(s); counts_per_unit must count 0x6064's units");
    }
    for (const std::uint16_t index : {std::uint16_t{0x6091}, std::uint16_t{0x6092}}) {
      const auto a = value(index, 1), b = value(index, 2);
      if (a && b && *a != *b) {
        add(Level::kWarning, eds_.object(index)->line,
            hex(index, 4) + (index == 0x6091 ? " gear ratio " : " feed constant ") + std::to_string(*a) +
                "/" + std::to_string(*b) + ": 0x6064/0x607A are in user units, not encoder increments",
            "set counts_per_unit in those units, or set the factor to 1/1 with the drive's tool");
      }
    }
  }

  const Description& eds_;
  const NodeNeeds& needs_;
  NodeCheck& out_;
  std::vector<std::pair<bool, int>> used_;
  std::size_t need_ = 0;  // the PdoNeed being checked  // PDOs already given to a need (receive, number)
};

}  // namespace

NodeCheck check_node(const Description& eds, const NodeNeeds& needs) {
  NodeCheck out;
  for (const Diagnostic& d : eds.diagnostics) {
    out.findings.push_back(Finding{d.severity == Severity::kError ? Level::kError : Level::kWarning, d.line,
                                   d.message,
                                   d.severity == Severity::kError ? "correct the file (CiA 306)" : ""});
  }
  if (eds.has_errors()) return out;
  out.profile = profile_of(eds);
  Checker(eds, needs, out).run();
  return out;
}

std::string format(const Description& eds, const NodeNeeds& needs, const Finding& f) {
  const char* level = f.level == Level::kError ? "error" : (f.level == Level::kWarning ? "warning" : "note");
  std::string s = eds.at(f.line) + ": " + level + ": " + needs.node + ": " + f.message;
  if (!f.remedy.empty()) s += " — " + f.remedy;
  return s;
}

}  // namespace loom::drivers::eds

// Concise DCF, DCF writer and identity check (eds_dcf.hpp).
#include "loom/drivers/eds_dcf.hpp"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <map>

#include "loom/drivers/cob_id.hpp"

namespace loom::drivers::eds {

namespace {

std::string hex(std::uint64_t v, int digits) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%0*" PRIX64, digits, v);
  return buf;
}

std::uint8_t bytes_of(DataType t) {
  return static_cast<std::uint8_t>((type_bits(t) + 7) / 8);
}

bool numeric(DataType t) {
  return is_signed_integer(t) || is_unsigned_integer(t) || is_real(t);
}

std::uint64_t key_of(std::uint16_t index, std::uint8_t sub) {
  return (std::uint64_t{index} << 8) | sub;
}

}  // namespace

std::string describe(const SdoWrite& w) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "0x%04X:%02X = %s (%u byte%s)", w.index, w.sub,
                hex(w.value, w.size * 2).c_str(), w.size, w.size == 1 ? "" : "s");
  return buf;
}

std::vector<SdoWrite> parameter_writes(const Description& dcf, std::uint8_t node_id) {
  std::vector<SdoWrite> out;
  for (const auto& [index, o] : dcf.objects) {
    if (index < 0x1000) continue;  // data type definitions: not configured (write_dcf leaves them out too)
    for (const auto& [sub, e] : o.entries) {
      if (e.parameter_value.empty() || !writable(e.access) || !numeric(e.type)) continue;
      const auto bits = e.parameter_value.bits(node_id, e.type);
      if (!bits) continue;
      out.push_back(SdoWrite{index, sub, bytes_of(e.type), *bits});
    }
  }
  return out;
}

std::vector<SdoWrite> loom_writes(const Description& eds, const NodeNeeds& needs, const NodeCheck& check) {
  std::map<std::uint64_t, SdoWrite> by_key;  // index/sub order, one value per entry
  const auto put = [&](std::uint16_t index, std::uint8_t sub, std::uint64_t value) {
    const Entry* e = eds.entry(index, sub);
    if (e == nullptr || !writable(e->access)) return;  // read back at bring-up, not written
    // Integers of 1..4 bytes (expedited SDO); another type is the check's error, not a write.
    const bool integer = is_signed_integer(e->type) || is_unsigned_integer(e->type);
    if (!integer || bytes_of(e->type) < 1 || bytes_of(e->type) > 4) return;
    const unsigned bits = type_bits(e->type);
    const std::uint64_t mask = bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
    by_key[key_of(index, sub)] = SdoWrite{index, sub, bytes_of(e->type), value & mask};
  };
  for (const ObjectNeed& n : needs.objects) {
    if (n.value) put(n.index, n.sub, static_cast<std::uint64_t>(*n.value));
  }
  for (const PdoAssignment& a : check.pdo_plan) {
    const PdoNeed& n = needs.pdos[a.need];
    const int k = a.number - 1;
    const auto comm = static_cast<std::uint16_t>((a.receive ? 0x1400 : 0x1800) + k);
    const auto map = static_cast<std::uint16_t>((a.receive ? 0x1600 : 0x1A00) + k);
    if (a.number <= 4) {
      put(comm, 1, a.receive ? cob::rpdo(a.number, needs.node_id) : cob::tpdo(a.number, needs.node_id));
    }
    put(comm, 2, n.transmission_type);
    if (a.kind != MappingKind::kDynamic) continue;
    put(map, 0, n.entries.size());
    for (std::size_t e = 0; e < n.entries.size(); ++e) {
      const MapEntry& m = n.entries[e];
      put(map, static_cast<std::uint8_t>(e + 1),
          (std::uint64_t{m.index} << 16) | (std::uint64_t{m.sub} << 8) | m.bits);
    }
  }
  std::vector<SdoWrite> out;
  for (const auto& [key, w] : by_key) out.push_back(w);
  return out;
}

std::vector<std::uint8_t> encode_concise_dcf(const std::vector<SdoWrite>& writes) {
  std::vector<std::uint8_t> out;
  const auto le = [&](std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  };
  le(writes.size(), 4);
  for (const SdoWrite& w : writes) {
    le(w.index, 2);
    le(w.sub, 1);
    le(w.size, 4);
    le(w.value, w.size);
  }
  return out;
}

std::optional<std::vector<SdoWrite>> decode_concise_dcf(const std::vector<std::uint8_t>& bytes) {
  std::size_t at = 0;
  const auto le = [&](int n) -> std::optional<std::uint64_t> {
    if (bytes.size() - at < static_cast<std::size_t>(n)) return std::nullopt;
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= std::uint64_t{bytes[at + static_cast<std::size_t>(i)]} << (8 * i);
    at += static_cast<std::size_t>(n);
    return v;
  };
  const auto count = le(4);
  if (!count) return std::nullopt;
  std::vector<SdoWrite> out;
  for (std::uint64_t k = 0; k < *count; ++k) {
    const auto index = le(2), sub = le(1), size = le(4);
    if (!index || !sub || !size || *size < 1 || *size > 8) return std::nullopt;
    const auto value = le(static_cast<int>(*size));
    if (!value) return std::nullopt;
    out.push_back(SdoWrite{static_cast<std::uint16_t>(*index), static_cast<std::uint8_t>(*sub),
                           static_cast<std::uint8_t>(*size), *value});
  }
  if (at != bytes.size()) return std::nullopt;
  return out;
}

namespace {

// A value as CiA 306 writes it: decimal for signed integers, hex for unsigned, "$NODEID+0x.." when it is
// relative to the node id, %.17g for reals (read back to the same double), strings as they were.
std::string text_of(const Value& v, DataType type) {
  if (const auto* i = std::get_if<std::int64_t>(&v.v)) {
    const std::string n = std::to_string(*i);
    return v.plus_node_id ? "$NODEID+" + n : n;
  }
  if (const auto* u = std::get_if<std::uint64_t>(&v.v)) {
    const std::string n = hex(*u, 1);
    return v.plus_node_id ? "$NODEID+" + n : n;
  }
  if (const auto* d = std::get_if<double>(&v.v)) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", *d);
    return buf;
  }
  if (const auto* s = std::get_if<std::string>(&v.v)) return *s;
  (void)type;
  return "";
}

// The value written to an entry as text of its type (signed types sign-extended from `size` bytes).
std::string text_of_write(const SdoWrite& w, DataType type) {
  if (is_signed_integer(type)) {
    const unsigned bits = type_bits(type);
    const std::uint64_t sign = std::uint64_t{1} << (bits - 1);
    const std::uint64_t mask = bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
    const std::uint64_t v = w.value & mask;
    return std::to_string(static_cast<std::int64_t>((v & sign) != 0 ? (v | ~mask) : v));
  }
  if (type == DataType::kReal32) {
    float f = 0;
    const auto b = static_cast<std::uint32_t>(w.value);
    std::memcpy(&f, &b, sizeof f);
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(f));
    return buf;
  }
  if (type == DataType::kReal64) {
    double d = 0;
    std::memcpy(&d, &w.value, sizeof d);
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", d);
    return buf;
  }
  return hex(w.value, 1);
}

void write_entry(std::string& out, const Entry& e, bool var, const SdoWrite* w) {
  out += "ParameterName=" + e.name + "\n";
  if (var) out += "ObjectType=0x7\n";
  out += "DataType=" + hex(static_cast<std::uint16_t>(e.type), 4) + "\n";
  out += std::string("AccessType=") + access_name(e.access) + "\n";
  if (!e.default_value.empty()) out += "DefaultValue=" + text_of(e.default_value, e.type) + "\n";
  if (!e.low_limit.empty()) out += "LowLimit=" + text_of(e.low_limit, e.type) + "\n";
  if (!e.high_limit.empty()) out += "HighLimit=" + text_of(e.high_limit, e.type) + "\n";
  out += std::string("PDOMapping=") + (e.pdo_mapping ? "1" : "0") + "\n";
  if (w != nullptr) {
    out += "ParameterValue=" + text_of_write(*w, e.type) + "\n";
  } else if (!e.parameter_value.empty()) {
    out += "ParameterValue=" + text_of(e.parameter_value, e.type) + "\n";
  }
}

}  // namespace

std::string write_dcf(const Description& eds, std::uint8_t node_id, std::uint32_t baud_kbit,
                      const std::vector<SdoWrite>& writes, const std::string& node_name) {
  std::map<std::uint64_t, const SdoWrite*> by_key;
  for (const SdoWrite& w : writes) by_key[key_of(w.index, w.sub)] = &w;
  const auto write_of = [&](const Entry& e) -> const SdoWrite* {
    const auto it = by_key.find(key_of(e.index, e.sub));
    return it == by_key.end() || !writable(e.access) ? nullptr : it->second;
  };
  const DeviceInfo& di = eds.device;
  std::string out = "; DCF written by loomctl: the values the loom configures on this node\n";
  out += "[FileInfo]\nFileName=node" + std::to_string(node_id) + ".dcf\nEDSVersion=4.0\n";
  out += "Description=" + (di.product_name.empty() ? std::string("node") : di.product_name) +
         " as the loom configures it\n";
  out += "\n[DeviceInfo]\n";
  out += "VendorName=" + di.vendor_name + "\n";
  if (di.vendor_number) out += "VendorNumber=" + hex(*di.vendor_number, 8) + "\n";
  out += "ProductName=" + di.product_name + "\n";
  if (di.product_number) out += "ProductNumber=" + hex(*di.product_number, 8) + "\n";
  if (di.revision_number) out += "RevisionNumber=" + hex(*di.revision_number, 8) + "\n";
  out += "OrderCode=" + di.order_code + "\n";
  for (const std::uint32_t rate : {10U, 20U, 50U, 125U, 250U, 500U, 800U, 1000U}) {
    const bool has =
        std::find(di.baud_rates_kbit.begin(), di.baud_rates_kbit.end(), rate) != di.baud_rates_kbit.end();
    out += "BaudRate_" + std::to_string(rate) + "=" + (has ? "1" : "0") + "\n";
  }
  out += "Granularity=" + std::to_string(di.granularity) + "\n";
  int rx = 0, tx = 0;
  for (const PdoDescription& p : pdos(eds)) (p.receive ? rx : tx) += 1;
  out += "NrOfRXPDO=" + std::to_string(rx) + "\nNrOfTXPDO=" + std::to_string(tx) + "\n";
  out += std::string("LSS_Supported=") + (di.lss_supported ? "1" : "0") + "\n";
  out += "\n[DeviceComissioning]\nNodeID=" + std::to_string(node_id) + "\nNodeName=" + node_name +
         "\nBaudrate=" + std::to_string(baud_kbit) + "\n";
  if (!eds.dummy_usage.empty()) {
    out += "\n[DummyUsage]\n";
    for (const auto& [index, used] : eds.dummy_usage) {
      char key[16];
      std::snprintf(key, sizeof key, "Dummy%04X", index);
      out += std::string(key) + "=" + (used ? "1" : "0") + "\n";
    }
  }
  // Object lists: 0x1000, 0x1001, 0x1018 mandatory; manufacturer range 0x2000..0x5FFF; the rest optional.
  std::vector<std::uint16_t> mandatory, optional, manufacturer;
  for (const auto& [index, o] : eds.objects) {
    if (index == 0x1000 || index == 0x1001 || index == 0x1018) {
      mandatory.push_back(index);
    } else if (index >= 0x2000 && index < 0x6000) {
      manufacturer.push_back(index);
    } else if (index >= 0x1000) {
      optional.push_back(index);
    }
  }
  const auto list = [&](const char* name, const std::vector<std::uint16_t>& v) {
    out += std::string("\n[") + name + "]\nSupportedObjects=" + std::to_string(v.size()) + "\n";
    for (std::size_t k = 0; k < v.size(); ++k) out += std::to_string(k + 1) + "=" + hex(v[k], 4) + "\n";
  };
  list("MandatoryObjects", mandatory);
  list("OptionalObjects", optional);
  list("ManufacturerObjects", manufacturer);
  for (const auto& [index, o] : eds.objects) {
    if (index < 0x1000) continue;  // data type definitions: not configured, not listed
    char name[8];
    std::snprintf(name, sizeof name, "%04X", index);
    out += std::string("\n[") + name + "]\n";
    const bool var =
        o.type == ObjectType::kVar || o.type == ObjectType::kDomain || o.type == ObjectType::kNull;
    if (var) {
      if (const Entry* e = o.entry(0)) {
        write_entry(out, *e, true, write_of(*e));
        if (o.type == ObjectType::kDomain) out.replace(out.rfind("ObjectType=0x7"), 14, "ObjectType=0x2");
      }
      continue;
    }
    out += "ParameterName=" + o.name + "\n";
    out += "ObjectType=" + hex(static_cast<std::uint8_t>(o.type), 1) + "\n";
    out += "SubNumber=" + std::to_string(o.entries.size()) + "\n";
    for (const auto& [sub, e] : o.entries) {
      char sname[16];
      std::snprintf(sname, sizeof sname, "%04Xsub%X", index, sub);
      out += std::string("\n[") + sname + "]\n";
      write_entry(out, e, false, write_of(e));
    }
  }
  return out;
}

Status check_identity(const Description& eds, const std::string& node_label, const Identity& found) {
  const NodeProfile p = profile_of(eds);
  const bool vendor = !p.vendor || *p.vendor == found.vendor;
  const bool product = !p.product || *p.product == found.product;
  const bool revision = !p.revision || *p.revision == found.revision;
  if (vendor && product && revision) return Status::ok();
  const auto id = [](std::optional<std::uint32_t> v, std::uint32_t f, const char* what) {
    return std::string(what) + " " + (v ? hex(*v, 8) : hex(f, 8) + " (any)");
  };
  return Status::error(
      node_label + " is vendor " + hex(found.vendor, 8) + " product " + hex(found.product, 8) + " revision " +
      hex(found.revision, 8) + ", but " + eds.file + " describes " + id(p.vendor, found.vendor, "vendor") +
      " " + id(p.product, found.product, "product") + " " + id(p.revision, found.revision, "revision") +
      ": a swapped cable, or a replaced node of another model? Bring-up stopped");
}

}  // namespace loom::drivers::eds

// Identity read and configuration writes over SDO (eds_boot.hpp).
#include "loom/drivers/eds_boot.hpp"

#include <map>
#include <string>

#include "loom/drivers/pdo.hpp"

namespace loom::drivers {

namespace {

constexpr std::uint16_t kIdentity = 0x1018;

bool is_map(std::uint16_t index) {
  return (index >= od::kRpdoMap && index < od::kRpdoMap + 0x200) ||
         (index >= od::kTpdoMap && index < od::kTpdoMap + 0x200);
}
// The communication object of mapping object `map` (0x1600 → 0x1400, 0x1A00 → 0x1800).
std::uint16_t comm_of(std::uint16_t map) {
  return static_cast<std::uint16_t>(map - 0x200);
}

std::uint32_t masked(std::uint64_t v, std::uint8_t size) {
  return size >= 4 ? static_cast<std::uint32_t>(v)
                   : static_cast<std::uint32_t>(v & ((1ULL << (8 * size)) - 1));
}

}  // namespace

Result<eds::Identity> read_identity(SdoClient& sdo, std::uint8_t node) {
  eds::Identity id;
  Result<std::uint32_t> vendor = sdo.read(node, kIdentity, 1);
  if (!vendor) return vendor.status();
  id.vendor = vendor.value();
  Result<std::uint32_t> product = sdo.read(node, kIdentity, 2);
  if (product) id.product = product.value();
  Result<std::uint32_t> revision = sdo.read(node, kIdentity, 3);
  if (revision) id.revision = revision.value();
  return id;
}

Result<ApplyReport> apply_configuration(SdoClient& sdo, std::uint8_t node,
                                        const std::vector<eds::SdoWrite>& writes, bool store) {
  ApplyReport report;
  const std::string who = "node " + std::to_string(node) + ": ";
  for (const eds::SdoWrite& w : writes) {
    if (w.size < 1 || w.size > 4) {
      return Status::error(who + eds::describe(w) + ": only expedited (1..4 byte) writes are made at boot");
    }
  }
  // Reads every value back; 0 differences → nothing to write.
  const auto differs = [&](const eds::SdoWrite& w) -> Result<bool> {
    Result<std::uint32_t> now = sdo.read(node, w.index, w.sub);
    if (!now) return Status::error(who + now.error());
    return masked(now.value(), w.size) != masked(w.value, w.size);
  };
  const auto write = [&](std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                         std::uint8_t size) -> Status {
    if (Status s = sdo.write(node, index, sub, value, size); !s) return Status::error(who + s.message());
    ++report.written;
    return Status::ok();
  };
  // Mapping objects, grouped: one re-map per PDO whose mapping differs anywhere.
  std::map<std::uint16_t, std::vector<const eds::SdoWrite*>> maps;
  for (const eds::SdoWrite& w : writes) {
    if (is_map(w.index)) maps[w.index].push_back(&w);
  }
  for (const eds::SdoWrite& w : writes) {
    if (is_map(w.index)) continue;
    Result<bool> d = differs(w);
    if (!d) return d.status();
    if (!d.value()) {
      ++report.skipped;
      continue;
    }
    if (Status s = write(w.index, w.sub, masked(w.value, w.size), w.size); !s) return s;
  }
  for (const auto& [map, entries] : maps) {
    bool any = false;
    for (const eds::SdoWrite* w : entries) {
      Result<bool> d = differs(*w);
      if (!d) return d.status();
      any = any || d.value();
    }
    if (!any) {
      report.skipped += static_cast<int>(entries.size());
      continue;
    }
    const std::uint16_t comm = comm_of(map);
    Result<std::uint32_t> cob = sdo.read(node, comm, 1);
    if (!cob) return Status::error(who + cob.error());
    const std::uint32_t valid = cob.value() & ~od::kPdoInvalidBit;
    if (Status s = write(comm, 1, valid | od::kPdoInvalidBit, 4); !s) return s;
    if (Status s = write(map, 0, 0, 1); !s) return s;
    std::uint32_t count = 0;
    for (const eds::SdoWrite* w : entries) {
      if (w->sub == 0) {
        count = masked(w->value, w->size);
        continue;
      }
      if (Status s = write(map, w->sub, masked(w->value, w->size), w->size); !s) return s;
    }
    if (Status s = write(map, 0, count, 1); !s) return s;
    if (Status s = write(comm, 1, valid, 4); !s) return s;
  }
  if (store && report.written > 0) {
    if (Status s = write(od::kStoreParameters, 1, od::kSaveSignature, 4); !s) return s;
    report.stored = true;
  }
  return report;
}

bool can_store(const eds::Description& description) {
  const eds::Entry* e = description.entry(od::kStoreParameters, 1);
  return e != nullptr && eds::writable(e->access);
}

Status store_parameters(SdoClient& sdo, std::uint8_t node, const std::string& label) {
  if (Status s = sdo.write(node, od::kStoreParameters, 1, od::kSaveSignature, 4); !s) {
    return Status::error(label +
                         ": storing the configuration failed (bring-up fault store_refused): " + s.message() +
                         " — the node holds what was written only until its next reset; bring-up stopped "
                         "(store_config = false runs without storing)");
  }
  return Status::ok();
}

}  // namespace loom::drivers

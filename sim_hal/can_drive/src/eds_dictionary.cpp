// Slave dictionary tables from an EDS (eds_dictionary.hpp).
#include "loom/sim_can/eds_dictionary.hpp"

#include <algorithm>

namespace loom::sim_can {

namespace eds = drivers::eds;

std::vector<slave::Entry> dictionary_from_eds(const eds::Description& d) {
  std::vector<slave::Entry> table;
  for (const auto& [index, o] : d.objects) {
    for (const auto& [sub, e] : o.entries) {
      const unsigned bits = eds::type_bits(e.type);
      const bool integer = eds::is_signed_integer(e.type) || eds::is_unsigned_integer(e.type);
      if (!integer || (bits != 1 && bits != 8 && bits != 16 && bits != 32)) continue;
      slave::Entry s;
      s.index = index;
      s.sub = sub;
      s.bytes = static_cast<std::uint8_t>(bits <= 8 ? 1 : bits / 8);
      s.access = e.access == eds::Access::kConst ? slave::Access::kConst
                 : eds::writable(e.access)       ? slave::Access::kRw
                                                 : slave::Access::kRo;
      s.pdo =
          !e.pdo_mapping ? slave::Pdo::kNone : (eds::writable(e.access) ? slave::Pdo::kRx : slave::Pdo::kTx);
      s.default_value = static_cast<std::uint32_t>(e.default_value.bits(0, e.type).value_or(0));
      table.push_back(s);
    }
  }
  return table;  // the objects map and each entries map are ordered: sorted by (index, sub)
}

SimDriveConfig drive_from_eds(const eds::Description& d, std::uint8_t node_id) {
  SimDriveConfig c;
  c.node_id = node_id;
  c.dictionary = dictionary_from_eds(d);
  std::uint64_t modes = 0;
  if (const eds::Entry* e = d.entry(0x6502, 0)) modes = e->default_value.bits(0, e->type).value_or(0);
  c.supports_csp = (modes & (1U << 7)) != 0;
  c.supports_homing = (modes & (1U << 5)) != 0;
  return c;
}

SimIoConfig io_from_eds(const eds::Description& d, std::uint8_t node_id) {
  SimIoConfig c;
  c.node_id = node_id;
  c.dictionary = dictionary_from_eds(d);
  const auto subs = [&](std::uint16_t index) {
    const eds::Object* o = d.object(index);
    int n = 0;
    if (o != nullptr) {
      for (const auto& [sub, e] : o->entries) n += sub >= 1 ? 1 : 0;
    }
    return n;
  };
  c.digital_input_groups = std::min(8, std::max(subs(0x6000), 2 * subs(0x6100)));
  return c;
}

}  // namespace loom::sim_can

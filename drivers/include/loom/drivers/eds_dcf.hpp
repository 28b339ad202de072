// From a node's description to its configuration: the SDO writes the master makes at boot (CiA 302's
// concise DCF, 0x1F22), a DCF (CiA 306) carrying the values the loom configures for the builder's other
// CANopen tools, and the identity check of a booted node against its description. Configure-time only;
// no SocketCAN (eds_boot.hpp makes the writes over SDO).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loom/drivers/eds.hpp"
#include "loom/drivers/eds_check.hpp"
#include "loom/drivers/status.hpp"

namespace loom::drivers::eds {

// One expedited SDO download: `size` bytes (1..8) of `value`, little-endian.
struct SdoWrite {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t size = 4;
  std::uint64_t value = 0;
  bool operator==(const SdoWrite&) const = default;
};
// "0x1017:00 = 0x0064 (2 bytes)".
std::string describe(const SdoWrite& w);

// Configure-time only. Every ParameterValue of a DCF on a writable entry of an integer or real type of an
// object from 0x1000 on (below it: data type definitions, never configured), in index/sub order, $NODEID
// resolved with `node_id` (an EDS has none: empty).
std::vector<SdoWrite> parameter_writes(const Description& dcf, std::uint8_t node_id);

// Configure-time only. What the loom configures on the node: every value it writes (NodeNeeds::objects
// with a value) and, for each PDO of check.pdo_plan, the COB-ID (pre-defined connection set, valid), the
// transmission type and — where the mapping is dynamic — the mapping. In the order a DCF lists them
// (index, sub); eds_boot's apply_configuration() turns a changed mapping into CiA 301's re-map sequence.
std::vector<SdoWrite> loom_writes(const Description& eds, const NodeNeeds& needs, const NodeCheck& check);

// Configure-time only. The writes as CiA 302's concise DCF (the domain of 0x1F22): UNSIGNED32 count,
// then per write UNSIGNED16 index, UNSIGNED8 sub, UNSIGNED32 size, the data; all little-endian.
std::vector<std::uint8_t> encode_concise_dcf(const std::vector<SdoWrite>& writes);
// Configure-time only. The inverse; nullopt for a truncated or over-long domain.
std::optional<std::vector<SdoWrite>> decode_concise_dcf(const std::vector<std::uint8_t>& bytes);

// Configure-time only. A DCF of `eds` for node `node_id` at `baud_kbit` with every write's value as the
// entry's ParameterValue (CompactSubObj arrays written out as sub-index sections, object lists and PDO
// counts as they are). read_eds() of the text has none of the EDS's deviations in form (only a value
// outside its own limits stays), and parameter_writes() of it gives `writes` back (those on writable
// entries of the description).
std::string write_dcf(const Description& eds, std::uint8_t node_id, std::uint32_t baud_kbit,
                      const std::vector<SdoWrite>& writes, const std::string& node_name = "");

// 0x1018:01..03 as a node reports them.
struct Identity {
  std::uint32_t vendor = 0;
  std::uint32_t product = 0;
  std::uint32_t revision = 0;
};
// Configure-time only. A node whose identity differs from its description's (vendor, product code, and
// revision where the description gives one) is refused: "node 2 (axes.carriage) is vendor 0x000004A2
// product 0x00000202 revision 0x00010000, but acme.eds describes vendor 0x000004A2 product 0x00401234
// revision 0x00020001: a swapped cable or a replaced drive of another model?".
Status check_identity(const Description& eds, const std::string& node_label, const Identity& found);

}  // namespace loom::drivers::eds

// Boot from the description, over SDO (configure-time, between boot-up and NMT start): read a node's
// identity (0x1018) for check_identity(), and make the description's configuration writes, reading each
// value back first and writing only what differs (CanFestival's configuration manager does the same), a
// changed PDO mapping with CiA 301's re-map sequence, optionally storing the result (0x1010:01 "save").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "loom/drivers/eds_dcf.hpp"
#include "loom/drivers/sdo_client.hpp"
#include "loom/drivers/status.hpp"

namespace loom::drivers {

// Configure-time only. 0x1018:01..03 of `node`; a node without sub 3 (revision) reads 0 there.
Result<eds::Identity> read_identity(SdoClient& sdo, std::uint8_t node);

struct ApplyReport {
  int written = 0;  // SDO writes made (the re-map sequence's invalidate/clear/set count too)
  int skipped = 0;  // values already as described
  bool stored = false;
};

// Configure-time only. Makes `writes` (at most 4 bytes each: expedited) on `node`, each read back first
// and skipped when equal. A mapping object (0x16xx/0x1Axx) with any differing entry is re-mapped whole:
// its PDO invalidated (0x14xx/0x18xx:01 bit 31), sub 0 cleared, the entries, sub 0 set, the COB-ID
// valid again. `store`: 0x1010:01 = "save" when anything was written. Errors name the node and object.
Result<ApplyReport> apply_configuration(SdoClient& sdo, std::uint8_t node,
                                        const std::vector<eds::SdoWrite>& writes, bool store);

// Configure-time only. The description has a writable 0x1010:01 (store parameters): the only case in
// which the master asks the node to store (a node without it could not, and would abort).
bool can_store(const eds::Description& description);
// Configure-time only. 0x1010:01 = "save" (0x65766173), after the bring-up's configuration writes; an
// abort or a missing reply is the bring-up fault "store_refused", naming `label` (the node), the object,
// the abort code and what to do.
Status store_parameters(SdoClient& sdo, std::uint8_t node, const std::string& label);

}  // namespace loom::drivers

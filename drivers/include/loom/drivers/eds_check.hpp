// What the loom needs of a node, compared with the node's EDS: every object the master reads or writes
// (exists, access, type, the written value within the EDS's limits, PDO-mappable), the PDOs it maps
// against the EDS's PDOs (dynamic or fixed, and a fixed mapping carrying what is needed), the modes of
// operation against 0x6502, the heartbeat producer, synchronous transmission and the scaling objects.
// Each finding names the EDS's file:line and says what the builder can do. The node's profile (PDO
// counts, fixed or dynamic mapping, 0x1016, supported modes, identity) is derived from the EDS, so no
// configuration key has to repeat it. Configure-time only; no SocketCAN.
//
// Wiring into the loom config: for an axis, check_node(read_eds_file(path), drive_needs(axis, port));
// for an I/O module, check_node(read_eds_file(path), io_module_needs(module_config)); print format()
// of every finding and refuse the config when NodeCheck::ok() is false.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loom/drivers/can_axis_config.hpp"
#include "loom/drivers/can_io_config.hpp"
#include "loom/drivers/eds.hpp"

namespace loom::drivers::eds {

enum class Use : std::uint8_t { kRead, kWrite, kReadWrite };
enum class PdoUse : std::uint8_t { kNone, kRpdo, kTpdo };

// One object (sub-index) the master uses.
struct ObjectNeed {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  DataType type = DataType::kUnsigned8;
  Use use = Use::kRead;
  PdoUse pdo = PdoUse::kNone;
  bool optional = false;              // used when present
  std::string name;                   // "target position"
  std::string why;                    // "the profile, every SYNC"
  std::optional<std::int64_t> value;  // what the master writes (checked against Low/HighLimit)
};

// A PDO the master needs: these entries in PDO `number` (`any_pdo`: in any one PDO of that direction,
// at any offset, as the I/O module's mapping is read back and used wherever it sits).
struct PdoNeed {
  bool receive = false;
  int number = 1;
  bool any_pdo = false;
  bool optional = false;
  std::vector<MapEntry> entries;
  std::uint8_t transmission_type = 1;  // what the master sets (TPDO: 1..240 synchronous)
  std::string why;
};

struct NodeNeeds {
  std::string node;  // "axes.carriage (node 2)", the prefix of every finding
  std::uint8_t node_id = 1;
  std::uint16_t device_profile = 0;  // 0x1000 low word: 402 (0x0192) or 401 (0x0191)
  std::uint32_t modes = 0;           // 0x6502 bits the node must offer (0 = none: not a drive)
  std::uint16_t heartbeat_ms = 0;    // written to 0x1017
  std::vector<ObjectNeed> objects;
  std::vector<PdoNeed> pdos;
};

// Configure-time only. What an axis' drive must offer with this port configuration (CSP, the PDO
// layouts of pdo.hpp, TPDO2 when port.tpdo2, homing objects when the axis is referenced by homing).
NodeNeeds drive_needs(const CanAxisConfig& axis, const CanAxisPortConfig& port);
// Configure-time only. What an I/O module must offer for its wiring (module_wiring(config.wiring, module)).
NodeNeeds io_module_needs(const CanIoConfig& config);

// Configure-time only. How the module `eds` describes serves the inputs of `wiring` (its own,
// module_wiring()): 8 when 0x6000 has every 8-bit group they need (CiA 401's usual form, preferred), else
// 16 when 0x6100 has every 16-bit group, else 0 (neither form: check_node() with 8-bit groups then names
// the first group missing, at the file's line, and both forms in the remedy).
int input_group_bits_of(const Description& eds, const IoWiring& wiring);

// The node as its EDS describes it: what configuration keys would otherwise have to say by hand.
struct NodeProfile {
  std::optional<std::uint32_t> device_type;      // 0x1000 value
  std::optional<std::uint32_t> supported_modes;  // 0x6502 value
  int rpdos = 0, tpdos = 0;
  MappingKind rpdo1 = MappingKind::kAbsent, tpdo1 = MappingKind::kAbsent, tpdo2 = MappingKind::kAbsent;
  bool fixed_mapping = false;        // RPDO1 or TPDO1 fixed: the mapping is read back, not written
  bool consumer_heartbeat = false;   // 0x1016: the node can watch the controller
  bool csp = false, homing = false;  // from 0x6502 (false when the EDS gives no value)
  std::optional<std::uint32_t> vendor, product, revision;  // [DeviceInfo] (0x1018's)
};
// Configure-time only.
NodeProfile profile_of(const Description& eds);

enum class Level : std::uint8_t { kInfo, kWarning, kError };

struct Finding {
  Level level = Level::kInfo;
  int line = 0;         // in the EDS (0 = the file as a whole)
  std::string message;  // "0x607A target position is ro; the loom writes it every SYNC"
  std::string remedy;   // what the builder can do ("" for info)
};

// Which of the node's PDOs serves which PdoNeed (NodeNeeds::pdos[need]).
struct PdoAssignment {
  std::size_t need = 0;
  bool receive = false;
  int number = 1;
  MappingKind kind = MappingKind::kDynamic;
};

struct NodeCheck {
  NodeProfile profile;
  std::vector<Finding> findings;
  std::vector<PdoAssignment> pdo_plan;  // the needs a PDO of the node can serve
  bool ok() const;                      // no error
};

// Configure-time only. The EDS's own read errors come first (an EDS with errors is not compared).
NodeCheck check_node(const Description& eds, const NodeNeeds& needs);
// "vendor.eds:123: error: axes.carriage (node 2): 0x607A target position is ro ... — remedy: ..."
std::string format(const Description& eds, const NodeNeeds& needs, const Finding& f);

// "CSP, PP, HM" for the bits of 0x6502.
std::string describe_modes(std::uint32_t bits);

}  // namespace loom::drivers::eds

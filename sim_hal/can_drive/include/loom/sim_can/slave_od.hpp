// The slave side of CiA 301, shared by the simulated nodes (SimDriveNode, SimIoNode): an object
// dictionary described once as a constexpr table, the expedited SDO server that reads and writes it,
// the PDO communication/mapping rules, PDO packing, and the few fixed frame layouts (NMT, SYNC,
// heartbeat, EMCY).
//
// Written from CiA 301 on purpose, independently of the master's codecs in drivers/: a simulated peer
// that encoded frames with the master's own encoders would agree with any bug in them. Only the
// transport (drivers::CanBus, drivers::CanFrame) is shared.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "loom/drivers/can_frame.hpp"

namespace loom::sim_can::slave {

// Pre-defined connection set (CiA 301 §7.3.5): function codes, the node id is added.
namespace cob {
inline constexpr std::uint32_t kNmt = 0x000;
inline constexpr std::uint32_t kSync = 0x080;
inline constexpr std::uint32_t kEmcy = 0x080;
inline constexpr std::uint32_t kTpdo1 = 0x180;
inline constexpr std::uint32_t kRpdo1 = 0x200;
inline constexpr std::uint32_t kTpdo2 = 0x280;
inline constexpr std::uint32_t kRpdo2 = 0x300;
inline constexpr std::uint32_t kTpdo3 = 0x380;
inline constexpr std::uint32_t kRpdo3 = 0x400;
inline constexpr std::uint32_t kTpdo4 = 0x480;
inline constexpr std::uint32_t kRpdo4 = 0x500;
inline constexpr std::uint32_t kSdoTx = 0x580;         // server → client
inline constexpr std::uint32_t kSdoRx = 0x600;         // client → server
inline constexpr std::uint32_t kErrorControl = 0x700;  // heartbeat and boot-up
// PDO COB-ID entry (0x14xx/0x18xx:01): bit 31 = PDO not valid, bit 29 = 29-bit identifier.
inline constexpr std::uint32_t kPdoInvalid = 0x80000000U;
inline constexpr std::uint32_t kPdoExtended = 1U << 29;
inline constexpr std::uint32_t kCanIdMask = 0x7FF;
}  // namespace cob

// SDO abort codes (CiA 301 table 22) the server uses.
namespace abort_code {
inline constexpr std::uint32_t kCommand = 0x05040001;            // command specifier not valid
inline constexpr std::uint32_t kUnsupportedAccess = 0x06010000;  // unsupported access to an object
inline constexpr std::uint32_t kReadOnly = 0x06010002;           // attempt to write a read-only object
inline constexpr std::uint32_t kNoObject = 0x06020000;           // object does not exist
inline constexpr std::uint32_t kNotMappable = 0x06040041;        // object cannot be mapped to the PDO
inline constexpr std::uint32_t kPdoLength = 0x06040042;          // mapped objects exceed the PDO length
inline constexpr std::uint32_t kLengthHigh = 0x06070012;         // length of service parameter too high
inline constexpr std::uint32_t kLengthLow = 0x06070013;          // length of service parameter too low
inline constexpr std::uint32_t kNoSubIndex = 0x06090011;         // sub-index does not exist
inline constexpr std::uint32_t kValueRange = 0x06090030;         // value range exceeded
}  // namespace abort_code

// NMT states as the heartbeat byte carries them, and the NMT commands (CiA 301 §7.2.8).
namespace nmt {
inline constexpr std::uint8_t kBootUp = 0x00;
inline constexpr std::uint8_t kStopped = 0x04;
inline constexpr std::uint8_t kOperational = 0x05;
inline constexpr std::uint8_t kPreOperational = 0x7F;
inline constexpr std::uint8_t kStart = 0x01;
inline constexpr std::uint8_t kStop = 0x02;
inline constexpr std::uint8_t kEnterPreOperational = 0x80;
inline constexpr std::uint8_t kResetNode = 0x81;
inline constexpr std::uint8_t kResetCommunication = 0x82;
}  // namespace nmt

// EMCY codes (CiA 301 table 21 / CiA 402) the simulated nodes raise.
namespace emcy_code {
inline constexpr std::uint16_t kErrorReset = 0x0000;
inline constexpr std::uint16_t kHeartbeatLost = 0x8130;
inline constexpr std::uint16_t kPdoLength = 0x8210;
inline constexpr std::uint16_t kFollowingError = 0x8611;
}  // namespace emcy_code

// Error register 0x1001 bits (CiA 301 §7.5.2.2).
inline constexpr std::uint8_t kErrorRegisterGeneric = 0x01;
inline constexpr std::uint8_t kErrorRegisterCommunication = 0x10;

// PDO parameter objects: communication at base + n, mapping at base + 0x200 + n (n = 0..3 here).
inline constexpr std::uint16_t kRpdoComm = 0x1400;
inline constexpr std::uint16_t kRpdoMap = 0x1600;
inline constexpr std::uint16_t kTpdoComm = 0x1800;
inline constexpr std::uint16_t kTpdoMap = 0x1A00;
inline constexpr int kPdos = 4;           // PDOs per direction the simulated nodes implement
inline constexpr int kMapEntries = 8;     // mapping sub-indices 1..8 (8 bytes of 8 bits at most)
inline constexpr unsigned kPdoBits = 64;  // classic CAN payload

// One mapping entry (index << 16 | sub << 8 | bit length), as written into 0x16xx/0x1Axx.
constexpr std::uint32_t map_entry(std::uint16_t index, std::uint8_t sub, std::uint8_t bits) {
  return static_cast<std::uint32_t>(index) << 16 | static_cast<std::uint32_t>(sub) << 8 | bits;
}

// ---------------------------------------------------------------------------------------------------
// Object dictionary table
// ---------------------------------------------------------------------------------------------------
enum class Access : std::uint8_t { kConst, kRo, kRw };
enum class Pdo : std::uint8_t { kNone, kTx, kRx };  // into which PDO direction the object maps

struct Entry {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t bytes = 0;  // 1, 2 or 4 (expedited SDO only)
  Access access = Access::kConst;
  Pdo pdo = Pdo::kNone;
  std::uint32_t default_value = 0;  // PDO COB-IDs: function code only, the node id is added at reset
};

// Table building blocks, so a node's dictionary reads as one list of objects.
template <std::size_t N>
using Objects = std::array<Entry, N>;

// A PDO communication parameter object: :00 = 2 sub-indices, :01 COB-ID, :02 transmission type.
constexpr Objects<3> pdo_comm(std::uint16_t index, std::uint32_t cob_id, std::uint8_t type) {
  return {{{index, 0, 1, Access::kConst, Pdo::kNone, 2},
           {index, 1, 4, Access::kRw, Pdo::kNone, cob_id},
           {index, 2, 1, Access::kRw, Pdo::kNone, type}}};
}

// A transmit PDO's communication parameters with its inhibit time and event timer (CiA 301): :00 = 5,
// :01 COB-ID, :02 transmission type, :03 inhibit time (100 µs units), :05 event timer (ms).
constexpr Objects<5> tpdo_comm_timed(std::uint16_t index, std::uint32_t cob_id, std::uint8_t type) {
  return {{{index, 0, 1, Access::kConst, Pdo::kNone, 5},
           {index, 1, 4, Access::kRw, Pdo::kNone, cob_id},
           {index, 2, 1, Access::kRw, Pdo::kNone, type},
           {index, 3, 2, Access::kRw, Pdo::kNone, 0},
           {index, 5, 2, Access::kRw, Pdo::kNone, 0}}};
}

// A PDO mapping object: :00 = number of entries, :01..:08 the entries (unused ones 0).
constexpr Objects<1 + kMapEntries> pdo_map(std::uint16_t index,
                                           std::array<std::uint32_t, kMapEntries> entries = {}) {
  Objects<1 + kMapEntries> o{};
  std::uint8_t n = 0;
  for (std::size_t k = 0; k < entries.size(); ++k) {
    o[k + 1] = {index, static_cast<std::uint8_t>(k + 1), 4, Access::kRw, Pdo::kNone, entries[k]};
    if (entries[k] != 0) n = static_cast<std::uint8_t>(k + 1);
  }
  o[0] = {index, 0, 1, Access::kRw, Pdo::kNone, n};
  return o;
}

// The CiA 301 communication objects every simulated node has, the device type aside.
inline constexpr std::uint16_t kErrorRegisterObject = 0x1001;
inline constexpr std::uint16_t kConsumerHeartbeatObject = 0x1016;
inline constexpr std::uint16_t kProducerHeartbeatObject = 0x1017;
constexpr Objects<5> communication_objects(std::uint32_t device_type) {
  return {{{0x1000, 0, 4, Access::kConst, Pdo::kNone, device_type},
           {kErrorRegisterObject, 0, 1, Access::kRo, Pdo::kNone, 0},
           {kConsumerHeartbeatObject, 0, 1, Access::kConst, Pdo::kNone, 1},
           {kConsumerHeartbeatObject, 1, 4, Access::kRw, Pdo::kNone, 0},    // master node << 16 | ms
           {kProducerHeartbeatObject, 0, 2, Access::kRw, Pdo::kNone, 0}}};  // ms
}

// One table from several blocks (kept in the order given: the caller lists objects by index).
template <std::size_t... N>
constexpr auto concat(const Objects<N>&... parts) {
  Objects<(N + ...)> out{};
  std::size_t at = 0;
  ((std::copy(parts.begin(), parts.end(), out.begin() + static_cast<std::ptrdiff_t>(at)), at += N), ...);
  return out;
}

// Lookups binary-search the table: it must be sorted by (index, sub) without duplicates.
constexpr bool sorted(std::span<const Entry> table) {
  for (std::size_t k = 1; k < table.size(); ++k) {
    const Entry& a = table[k - 1];
    const Entry& b = table[k];
    if (a.index > b.index || (a.index == b.index && a.sub >= b.sub)) return false;
  }
  return true;
}

// ---------------------------------------------------------------------------------------------------
// Object dictionary (values of one node)
// ---------------------------------------------------------------------------------------------------
// The node's reactions to what the bus writes. Both are called from the RT path.
class ObjectHooks {
 public:
  virtual ~ObjectHooks() = default;
  // Device-specific value rule after the CiA 301 ones: 0 accepts, otherwise the abort code.
  virtual std::uint32_t check(std::uint16_t index, std::uint8_t sub, std::uint32_t value) const;
  // A value was stored by an SDO download or an RPDO (timers, state machines react here).
  virtual void written(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::int64_t now_us);
};

struct OdOptions {
  std::vector<std::uint16_t> absent;  // indices the device lacks: SDO abort 0x06020000, never mapped
  bool fixed_mapping = false;         // 0x16xx/0x1Axx read-only, sub-index 0 included
};

class ObjectDictionary {
 public:
  // Configure-time only: `table` must outlive the dictionary and be sorted (see sorted()).
  ObjectDictionary(std::span<const Entry> table, OdOptions options);

  // --- as the bus sees it (absent objects do not exist) -------------------------------------------
  bool exists(std::uint16_t index) const;
  // The entry of a present object's sub-index, nullptr when there is none.
  const Entry* entry(std::uint16_t index, std::uint8_t sub) const;

  // --- as the device sees it: absent objects keep their defaults, unknown ones read 0 -------------
  std::uint32_t get(std::uint16_t index, std::uint8_t sub) const;
  void set(std::uint16_t index, std::uint8_t sub, std::uint32_t value);  // unknown: ignored

  // Communication area 0x1000..0x1FFF back to defaults (PDO COB-IDs get `node_id` added).
  void reset_communication(std::uint8_t node_id);
  // Manufacturer and profile areas 0x2000..0xFFFF back to defaults.
  void reset_application();

  // --- SDO server -----------------------------------------------------------------------------------
  // Read for an upload: 0 and value/size, or the abort code.
  std::uint32_t read(std::uint16_t index, std::uint8_t sub, std::uint32_t& value, std::uint8_t& size) const;
  // Write from a download (`size` 0 = not indicated): every CiA 301 rule, then hooks.check, then the
  // value is stored and hooks.written told. 0 or the abort code.
  std::uint32_t write(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::uint8_t size,
                      ObjectHooks& hooks, std::int64_t now_us);

  // --- PDOs (pdo = 0..3) -------------------------------------------------------------------------------
  bool pdo_valid(std::uint16_t comm_index) const;  // present and COB-ID bit 31 clear
  std::uint32_t pdo_can_id(std::uint16_t comm_index) const;
  std::uint8_t pdo_type(std::uint16_t comm_index) const;
  // The RPDO listening on `can_id`, −1 none.
  int rpdo_for(std::uint32_t can_id) const;
  // Sum of the mapped lengths in bits.
  unsigned mapped_bits(std::uint16_t map_index) const;
  // Store the mapped objects of RPDO `pdo` from `data` (receive-mappable ones only) and tell hooks.
  // The caller has checked the length (rpdo_length_ok).
  void unpack_rpdo(int pdo, const std::array<std::uint8_t, 8>& data, ObjectHooks& hooks, std::int64_t now_us);
  bool rpdo_length_ok(int pdo, std::uint8_t dlc) const;
  // Fill TPDO `pdo`'s payload from the mapped objects; the returned length is its DLC.
  std::uint8_t pack_tpdo(int pdo, std::array<std::uint8_t, 8>& data) const;

 private:
  int position(std::uint16_t index, std::uint8_t sub) const;  // table position, −1 none
  Access access(const Entry& e) const;
  bool mappable(std::uint32_t map_entry, Pdo direction) const;
  std::uint32_t write_pdo_comm(const Entry& e, std::uint32_t value) const;
  std::uint32_t write_pdo_map(const Entry& e, std::uint32_t value) const;

  std::span<const Entry> table_;
  OdOptions options_;
  std::vector<std::uint32_t> values_;  // one per table entry
  std::vector<std::uint8_t> present_;  // one per table entry: the device has this object
};

// ---------------------------------------------------------------------------------------------------
// Frames (CiA 301 layouts, little-endian)
// ---------------------------------------------------------------------------------------------------
// SDO server: the answer to one request on 0x600+id (expedited transfers only; a segmented or block
// transfer is refused). std::nullopt when no answer is due (the client aborted).
std::optional<drivers::CanFrame> sdo_serve(ObjectDictionary& od, ObjectHooks& hooks, std::uint8_t node_id,
                                           const drivers::CanFrame& request, std::int64_t now_us);
drivers::CanFrame sdo_abort(std::uint8_t node_id, std::uint16_t index, std::uint8_t sub, std::uint32_t code);

struct NmtRequest {
  std::uint8_t command = 0;
};
// An NMT command addressed to `node_id` (or to all), std::nullopt otherwise.
std::optional<NmtRequest> parse_nmt(const drivers::CanFrame& f, std::uint8_t node_id);
bool is_sync(const drivers::CanFrame& f);
drivers::CanFrame heartbeat(std::uint8_t node_id, std::uint8_t nmt_state);
drivers::CanFrame emcy(std::uint8_t node_id, std::uint16_t code, std::uint8_t error_register);
drivers::CanFrame pdo_frame(std::uint32_t can_id, std::uint8_t dlc, const std::array<std::uint8_t, 8>& data);

// TPDO due at this SYNC (`syncs` counted since NMT reset): synchronous types 0 and 1 every SYNC,
// 2..240 every n-th; event-driven types (254/255) never on SYNC.
bool tpdo_due_on_sync(std::uint8_t type, std::uint32_t syncs);
// Synchronous RPDO (types 0..240): buffered and applied at the next SYNC.
bool rpdo_synchronous(std::uint8_t type);

// ---------------------------------------------------------------------------------------------------
// Communication both simulated nodes share (the drive and the I/O module)
// ---------------------------------------------------------------------------------------------------
// `f` is the heartbeat of the node this one's 0x1016:01 consumer watches (node << 16 | ms; an absent
// object or 0 watches nothing).
bool is_watched_heartbeat(const ObjectDictionary& od, const drivers::CanFrame& f);

// Which service of node `node_id` (in NMT state `nmt_state`) a received data frame is for: an NMT command
// to it, the watched heartbeat, its SDO server (not while stopped), and only while operational SYNC and
// its RPDOs. Error and remote frames, and what is for other nodes, go nowhere.
struct Route {
  enum class To : std::uint8_t { kNothing, kNmt, kWatchedHeartbeat, kSdo, kSync, kRpdo };
  To to = To::kNothing;
  std::uint8_t nmt_command = 0;  // kNmt
  int pdo = -1;                  // kRpdo
};
Route route(const ObjectDictionary& od, std::uint8_t node_id, std::uint8_t nmt_state,
            const drivers::CanFrame& f);

// What a simulated node does with each service route() sends a frame to.
class FrameHandlers {
 public:
  virtual void on_nmt(std::uint8_t command, std::int64_t now_us) = 0;
  virtual void on_watched_heartbeat(std::int64_t now_us) = 0;
  virtual void on_sdo(const drivers::CanFrame& f, std::int64_t now_us) = 0;
  virtual void on_sync(std::int64_t now_us) = 0;
  virtual void on_rpdo(int pdo, const drivers::CanFrame& f, std::int64_t now_us) = 0;

 protected:
  ~FrameHandlers() = default;
};

// RT-safe. Routes `f` (route()) to the handler of `node` it is for.
void deliver(const ObjectDictionary& od, std::uint8_t node_id, std::uint8_t nmt_state,
             const drivers::CanFrame& f, std::int64_t now_us, FrameHandlers& node);

// Received RPDOs (CiA 301): a synchronous one is held and its objects written at the next SYNC, an
// event-driven one at once. RT-safe.
class RpdoInbox {
 public:
  // A frame for RPDO `pdo`. False when its length does not match the mapping (nothing written; the node
  // answers with its own EMCY 0x8210).
  bool receive(ObjectDictionary& od, ObjectHooks& hooks, int pdo, const drivers::CanFrame& f,
               std::int64_t now_us);
  // At SYNC: writes every held RPDO's objects, in PDO order.
  void apply_at_sync(ObjectDictionary& od, ObjectHooks& hooks, std::int64_t now_us);
  // Communication reset: nothing held.
  void clear() { pending_.fill(false); }

 private:
  std::array<bool, kPdos> pending_{};
  std::array<std::array<std::uint8_t, 8>, kPdos> data_{};
};

// Hands every TPDO due at this SYNC (`syncs` counted since NMT reset), packed from the dictionary, to
// `send(frame)`. RT-safe.
template <class Send>
void send_due_tpdos(const ObjectDictionary& od, std::uint32_t syncs, Send&& send) {
  for (int k = 0; k < kPdos; ++k) {
    const auto comm = static_cast<std::uint16_t>(kTpdoComm + k);
    if (!od.pdo_valid(comm) || !tpdo_due_on_sync(od.pdo_type(comm), syncs)) continue;
    std::array<std::uint8_t, 8> data{};
    const std::uint8_t dlc = od.pack_tpdo(k, data);
    send(pdo_frame(od.pdo_can_id(comm), dlc, data));
  }
}

}  // namespace loom::sim_can::slave

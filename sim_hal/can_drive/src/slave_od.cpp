// Slave-side CiA 301 (see slave_od.hpp). Byte layouts follow CiA 301 §7.2.4.3 (SDO), §7.2.2 (PDO),
// §7.2.7 (EMCY), §7.2.8 (NMT, heartbeat); the object rules follow §7.5.2.35-38 (PDO parameters).
#include "loom/sim_can/slave_od.hpp"

namespace loom::sim_can::slave {

using drivers::CanFrame;

namespace {

bool is_comm(std::uint16_t index) {
  return (index >= kRpdoComm && index < kRpdoComm + kPdos) ||
         (index >= kTpdoComm && index < kTpdoComm + kPdos);
}
bool is_map(std::uint16_t index) {
  return (index >= kRpdoMap && index < kRpdoMap + kPdos) || (index >= kTpdoMap && index < kTpdoMap + kPdos);
}
bool is_receive(std::uint16_t pdo_index) {
  return pdo_index < kTpdoComm;
}

std::uint16_t map_index_of(std::uint32_t entry) {
  return static_cast<std::uint16_t>(entry >> 16);
}
std::uint8_t map_sub_of(std::uint32_t entry) {
  return static_cast<std::uint8_t>((entry >> 8) & 0xFF);
}
std::uint8_t map_bits_of(std::uint32_t entry) {
  return static_cast<std::uint8_t>(entry & 0xFF);
}

// The value truncated to the object's width (an expedited transfer carries up to 4 bytes).
std::uint32_t fit(std::uint32_t value, std::uint8_t bytes) {
  return bytes >= 4 ? value : value & ((1U << (8U * bytes)) - 1U);
}

void put_le(std::array<std::uint8_t, 8>& d, std::size_t at, std::uint32_t v, std::size_t bytes) {
  for (std::size_t b = 0; b < bytes; ++b) d[at + b] = static_cast<std::uint8_t>(v >> (8 * b));
}
std::uint32_t get_le(const std::array<std::uint8_t, 8>& d, std::size_t at, std::size_t bytes) {
  std::uint32_t v = 0;
  for (std::size_t b = 0; b < bytes; ++b) v |= static_cast<std::uint32_t>(d[at + b]) << (8 * b);
  return v;
}

// Length check of an expedited download against the object (size 0 = not indicated: accepted).
std::uint32_t check_length(std::uint8_t given, std::uint8_t expected) {
  if (given == 0 || given == expected) return 0;
  return given > expected ? abort_code::kLengthHigh : abort_code::kLengthLow;
}

// SDO frame with the multiplexer (index LE, sub) and command byte; the 4 data bytes follow.
CanFrame sdo_frame(std::uint8_t node_id, std::uint8_t command, std::uint16_t index, std::uint8_t sub) {
  CanFrame f;
  f.id = cob::kSdoTx + node_id;
  f.dlc = 8;
  f.data[0] = command;
  put_le(f.data, 1, index, 2);
  f.data[3] = sub;
  return f;
}

// Command bytes (CiA 301 §7.2.4.3.3-6): ccs/scs in bits 7..5; expedited: n (unused bytes) in 3..2,
// e = bit 1, s = bit 0.
constexpr std::uint8_t kCcsDownloadInitiate = 1;
constexpr std::uint8_t kCcsUploadInitiate = 2;
constexpr std::uint8_t kCsAbort = 4;
constexpr std::uint8_t kScsUploadExpedited = 0x43;  // 010 0 nn 1 1 with n = 0
constexpr std::uint8_t kScsDownloadAck = 0x60;      // 011 00000
constexpr std::uint8_t kAbortCommand = 0x80;        // 100 00000
constexpr std::uint8_t kExpedited = 0x02;
constexpr std::uint8_t kSizeIndicated = 0x01;

CanFrame sdo_upload_reply(std::uint8_t node_id, std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                          std::uint8_t size) {
  CanFrame f =
      sdo_frame(node_id, static_cast<std::uint8_t>(kScsUploadExpedited | ((4 - size) << 2)), index, sub);
  put_le(f.data, 4, fit(value, size), 4);
  return f;
}

// Bytes of an expedited download: 4 − n when the size is indicated, else 0 (unknown).
std::uint8_t download_size(std::uint8_t command) {
  if ((command & kSizeIndicated) == 0) return 0;
  return static_cast<std::uint8_t>(4 - ((command >> 2) & 0x03));
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Hooks: default accepts everything and reacts to nothing
// ---------------------------------------------------------------------------------------------------
std::uint32_t ObjectHooks::check(std::uint16_t, std::uint8_t, std::uint32_t) const {
  return 0;
}
void ObjectHooks::written(std::uint16_t, std::uint8_t, std::uint32_t, std::int64_t) {}

// ---------------------------------------------------------------------------------------------------
// Dictionary
// ---------------------------------------------------------------------------------------------------
ObjectDictionary::ObjectDictionary(std::span<const Entry> table, OdOptions options)
    : table_(table), options_(std::move(options)), values_(table.size(), 0), present_(table.size(), 1) {
  for (std::size_t k = 0; k < table_.size(); ++k) {
    values_[k] = table_[k].default_value;
    const auto& absent = options_.absent;
    if (std::find(absent.begin(), absent.end(), table_[k].index) != absent.end()) present_[k] = 0;
  }
}

int ObjectDictionary::position(std::uint16_t index, std::uint8_t sub) const {
  const auto less = [](const Entry& e, std::pair<std::uint16_t, std::uint8_t> key) {
    return e.index < key.first || (e.index == key.first && e.sub < key.second);
  };
  const auto it = std::lower_bound(table_.begin(), table_.end(), std::pair{index, sub}, less);
  if (it == table_.end() || it->index != index || it->sub != sub) return -1;
  return static_cast<int>(it - table_.begin());
}

bool ObjectDictionary::exists(std::uint16_t index) const {
  // Every object has sub-index 0 (the value itself or the number of sub-indices).
  const int k = position(index, 0);
  return k >= 0 && present_[static_cast<std::size_t>(k)] != 0;
}

const Entry* ObjectDictionary::entry(std::uint16_t index, std::uint8_t sub) const {
  const int k = position(index, sub);
  if (k < 0 || present_[static_cast<std::size_t>(k)] == 0) return nullptr;
  return &table_[static_cast<std::size_t>(k)];
}

std::uint32_t ObjectDictionary::get(std::uint16_t index, std::uint8_t sub) const {
  const int k = position(index, sub);
  return k < 0 ? 0 : values_[static_cast<std::size_t>(k)];
}

void ObjectDictionary::set(std::uint16_t index, std::uint8_t sub, std::uint32_t value) {
  const int k = position(index, sub);
  if (k >= 0) values_[static_cast<std::size_t>(k)] = fit(value, table_[static_cast<std::size_t>(k)].bytes);
}

void ObjectDictionary::reset_communication(std::uint8_t node_id) {
  for (std::size_t k = 0; k < table_.size(); ++k) {
    const Entry& e = table_[k];
    if (e.index < 0x1000 || e.index >= 0x2000) continue;
    values_[k] = e.default_value;
    if (is_comm(e.index) && e.sub == 1) values_[k] += node_id;
  }
}

void ObjectDictionary::reset_application() {
  for (std::size_t k = 0; k < table_.size(); ++k) {
    if (table_[k].index >= 0x2000) values_[k] = table_[k].default_value;
  }
}

Access ObjectDictionary::access(const Entry& e) const {
  if (options_.fixed_mapping && is_map(e.index)) return Access::kRo;
  return e.access;
}

// ---------------------------------------------------------------------------------------------------
// SDO access
// ---------------------------------------------------------------------------------------------------
std::uint32_t ObjectDictionary::read(std::uint16_t index, std::uint8_t sub, std::uint32_t& value,
                                     std::uint8_t& size) const {
  if (!exists(index)) return abort_code::kNoObject;
  const Entry* e = entry(index, sub);
  if (e == nullptr) return abort_code::kNoSubIndex;
  value = get(index, sub);
  size = e->bytes;
  return 0;
}

std::uint32_t ObjectDictionary::write(std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                                      std::uint8_t size, ObjectHooks& hooks, std::int64_t now_us) {
  if (!exists(index)) return abort_code::kNoObject;
  const Entry* e = entry(index, sub);
  if (e == nullptr) return abort_code::kNoSubIndex;
  if (access(*e) != Access::kRw) return abort_code::kReadOnly;
  if (const std::uint32_t err = check_length(size, e->bytes)) return err;
  value = fit(value, e->bytes);
  if (is_comm(index)) {
    if (const std::uint32_t err = write_pdo_comm(*e, value)) return err;
  } else if (is_map(index)) {
    if (const std::uint32_t err = write_pdo_map(*e, value)) return err;
  }
  if (const std::uint32_t err = hooks.check(index, sub, value)) return err;
  set(index, sub, value);
  hooks.written(index, sub, value, now_us);
  return 0;
}

std::uint32_t ObjectDictionary::write_pdo_comm(const Entry& e, std::uint32_t value) const {
  if (e.sub == 1) {
    const std::uint32_t current = get(e.index, 1);
    if ((value & cob::kPdoExtended) != 0) return abort_code::kValueRange;  // 11-bit identifiers only
    // A valid PDO's COB-ID may not change in one step: invalidate (bit 31) first.
    const bool both_valid = (current & cob::kPdoInvalid) == 0 && (value & cob::kPdoInvalid) == 0;
    if (both_valid && value != current) return abort_code::kValueRange;
    return 0;
  }
  if (e.sub == 2) {
    // 0..240 synchronous, 241..251 reserved, 252/253 RTR-only (transmit PDOs), 254/255 event-driven.
    const bool rtr_only = value == 252 || value == 253;
    const bool ok = value <= 240 || value == 254 || value == 255 || (rtr_only && !is_receive(e.index));
    return ok ? 0 : abort_code::kValueRange;
  }
  return 0;
}

std::uint32_t ObjectDictionary::write_pdo_map(const Entry& e, std::uint32_t value) const {
  const bool rx = is_receive(e.index);
  const auto comm = static_cast<std::uint16_t>((rx ? kRpdoComm : kTpdoComm) + (e.index & 0xFF));
  // The mapping may change only while its PDO is invalid, and the entries only while :00 = 0.
  if (pdo_valid(comm)) return abort_code::kUnsupportedAccess;
  const Pdo direction = rx ? Pdo::kRx : Pdo::kTx;
  if (e.sub != 0) {
    if (get(e.index, 0) != 0) return abort_code::kUnsupportedAccess;
    return mappable(value, direction) ? 0 : abort_code::kNotMappable;
  }
  // :00 = n enables the mapping: entries 1..n are checked now, as a whole.
  if (value > kMapEntries) return abort_code::kValueRange;
  unsigned bits = 0;
  for (std::uint8_t n = 1; n <= value; ++n) {
    const std::uint32_t m = get(e.index, n);
    if (!mappable(m, direction)) return abort_code::kNotMappable;
    bits += map_bits_of(m);
  }
  return bits > kPdoBits ? abort_code::kPdoLength : 0;
}

bool ObjectDictionary::mappable(std::uint32_t m, Pdo direction) const {
  const Entry* target = entry(map_index_of(m), map_sub_of(m));
  return target != nullptr && target->pdo == direction && target->bytes * 8U == map_bits_of(m);
}

// ---------------------------------------------------------------------------------------------------
// PDOs
// ---------------------------------------------------------------------------------------------------
bool ObjectDictionary::pdo_valid(std::uint16_t comm_index) const {
  return exists(comm_index) && (get(comm_index, 1) & cob::kPdoInvalid) == 0;
}

std::uint32_t ObjectDictionary::pdo_can_id(std::uint16_t comm_index) const {
  return get(comm_index, 1) & cob::kCanIdMask;
}

std::uint8_t ObjectDictionary::pdo_type(std::uint16_t comm_index) const {
  return static_cast<std::uint8_t>(get(comm_index, 2));
}

int ObjectDictionary::rpdo_for(std::uint32_t can_id) const {
  for (int k = 0; k < kPdos; ++k) {
    const auto comm = static_cast<std::uint16_t>(kRpdoComm + k);
    if (pdo_valid(comm) && pdo_can_id(comm) == can_id) return k;
  }
  return -1;
}

unsigned ObjectDictionary::mapped_bits(std::uint16_t map_index) const {
  unsigned bits = 0;
  const std::uint32_t n = get(map_index, 0);
  for (std::uint8_t e = 1; e <= n; ++e) bits += map_bits_of(get(map_index, e));
  return bits;
}

bool ObjectDictionary::rpdo_length_ok(int pdo, std::uint8_t dlc) const {
  return dlc * 8U >= mapped_bits(static_cast<std::uint16_t>(kRpdoMap + pdo));
}

void ObjectDictionary::unpack_rpdo(int pdo, const std::array<std::uint8_t, 8>& data, ObjectHooks& hooks,
                                   std::int64_t now_us) {
  const auto map = static_cast<std::uint16_t>(kRpdoMap + pdo);
  const std::uint32_t n = get(map, 0);
  std::size_t offset = 0;
  for (std::uint8_t e = 1; e <= n; ++e) {
    const std::uint32_t m = get(map, e);
    const std::size_t bytes = map_bits_of(m) / 8U;
    if (offset + bytes > data.size()) return;
    const std::uint32_t v = get_le(data, offset, bytes);
    offset += bytes;
    const Entry* target = entry(map_index_of(m), map_sub_of(m));
    if (target == nullptr || target->pdo != Pdo::kRx) continue;
    set(target->index, target->sub, v);
    hooks.written(target->index, target->sub, v, now_us);
  }
}

std::uint8_t ObjectDictionary::pack_tpdo(int pdo, std::array<std::uint8_t, 8>& data) const {
  const auto map = static_cast<std::uint16_t>(kTpdoMap + pdo);
  const std::uint32_t n = get(map, 0);
  std::size_t offset = 0;
  for (std::uint8_t e = 1; e <= n; ++e) {
    const std::uint32_t m = get(map, e);
    const std::size_t bytes = map_bits_of(m) / 8U;
    if (offset + bytes > data.size()) break;
    put_le(data, offset, get(map_index_of(m), map_sub_of(m)), bytes);
    offset += bytes;
  }
  return static_cast<std::uint8_t>(offset);
}

// ---------------------------------------------------------------------------------------------------
// Frames
// ---------------------------------------------------------------------------------------------------
CanFrame sdo_abort(std::uint8_t node_id, std::uint16_t index, std::uint8_t sub, std::uint32_t code) {
  CanFrame f = sdo_frame(node_id, kAbortCommand, index, sub);
  put_le(f.data, 4, code, 4);
  return f;
}

std::optional<CanFrame> sdo_serve(ObjectDictionary& od, ObjectHooks& hooks, std::uint8_t node_id,
                                  const CanFrame& request, std::int64_t now_us) {
  // SDO frames always carry 8 bytes; a shorter one has no reliable multiplexer to echo.
  if (request.dlc != 8) return sdo_abort(node_id, 0, 0, abort_code::kCommand);
  const std::uint8_t command = request.data[0];
  const auto index = static_cast<std::uint16_t>(get_le(request.data, 1, 2));
  const std::uint8_t sub = request.data[3];
  switch (command >> 5) {
    case kCcsUploadInitiate: {
      std::uint32_t value = 0;
      std::uint8_t size = 0;
      if (const std::uint32_t err = od.read(index, sub, value, size))
        return sdo_abort(node_id, index, sub, err);
      return sdo_upload_reply(node_id, index, sub, value, size);
    }
    case kCcsDownloadInitiate: {
      // Every object here fits an expedited transfer: a segmented download is an access we do not offer.
      if ((command & kExpedited) == 0) return sdo_abort(node_id, index, sub, abort_code::kUnsupportedAccess);
      const std::uint8_t size = download_size(command);
      const std::uint32_t value = fit(get_le(request.data, 4, 4), size == 0 ? 4 : size);
      if (const std::uint32_t err = od.write(index, sub, value, size, hooks, now_us)) {
        return sdo_abort(node_id, index, sub, err);
      }
      return sdo_frame(node_id, kScsDownloadAck, index, sub);
    }
    case kCsAbort:
      return std::nullopt;  // the client gave up: nothing to answer
    default:
      return sdo_abort(node_id, index, sub, abort_code::kCommand);
  }
}

std::optional<NmtRequest> parse_nmt(const CanFrame& f, std::uint8_t node_id) {
  if (f.id != cob::kNmt || f.dlc != 2) return std::nullopt;
  if (f.data[1] != 0 && f.data[1] != node_id) return std::nullopt;  // 0 addresses every node
  switch (f.data[0]) {
    case nmt::kStart:
    case nmt::kStop:
    case nmt::kEnterPreOperational:
    case nmt::kResetNode:
    case nmt::kResetCommunication:
      return NmtRequest{f.data[0]};
    default:
      return std::nullopt;
  }
}

bool is_sync(const CanFrame& f) {
  return f.id == cob::kSync && f.dlc <= 1;  // DLC 1 carries the optional SYNC counter
}

CanFrame heartbeat(std::uint8_t node_id, std::uint8_t nmt_state) {
  CanFrame f;
  f.id = cob::kErrorControl + node_id;
  f.dlc = 1;
  f.data[0] = nmt_state;
  return f;
}

CanFrame emcy(std::uint8_t node_id, std::uint16_t code, std::uint8_t error_register) {
  CanFrame f;
  f.id = cob::kEmcy + node_id;
  f.dlc = 8;
  put_le(f.data, 0, code, 2);
  f.data[2] = error_register;  // bytes 3..7: manufacturer-specific, zero
  return f;
}

CanFrame pdo_frame(std::uint32_t can_id, std::uint8_t dlc, const std::array<std::uint8_t, 8>& data) {
  CanFrame f;
  f.id = can_id;
  f.dlc = dlc;
  f.data = data;
  return f;
}

bool tpdo_due_on_sync(std::uint8_t type, std::uint32_t syncs) {
  if (type > 240) return false;
  return type <= 1 || syncs % type == 0;
}

bool rpdo_synchronous(std::uint8_t type) {
  return type <= 240;
}

// ---------------------------------------------------------------------------------------------------
// Shared communication
// ---------------------------------------------------------------------------------------------------
bool is_watched_heartbeat(const ObjectDictionary& od, const drivers::CanFrame& f) {
  const std::uint32_t consumer =
      od.exists(kConsumerHeartbeatObject) ? od.get(kConsumerHeartbeatObject, 1) : 0;
  return consumer != 0 && f.id == cob::kErrorControl + ((consumer >> 16) & 0x7F) && f.dlc >= 1;
}

Route route(const ObjectDictionary& od, std::uint8_t node_id, std::uint8_t nmt_state,
            const drivers::CanFrame& f) {
  using To = Route::To;
  if (f.is_error() || f.is_rtr()) return {};
  if (const auto request = parse_nmt(f, node_id)) return {To::kNmt, request->command, -1};
  if (is_watched_heartbeat(od, f)) return {To::kWatchedHeartbeat, 0, -1};
  if (f.id == cob::kSdoRx + node_id) return nmt_state != nmt::kStopped ? Route{To::kSdo, 0, -1} : Route{};
  if (nmt_state != nmt::kOperational) return {};
  if (is_sync(f)) return {To::kSync, 0, -1};
  if (const int pdo = od.rpdo_for(f.id); pdo >= 0) return {To::kRpdo, 0, pdo};
  return {};
}

void deliver(const ObjectDictionary& od, std::uint8_t node_id, std::uint8_t nmt_state,
             const drivers::CanFrame& f, std::int64_t now_us, FrameHandlers& node) {
  const Route r = route(od, node_id, nmt_state, f);
  switch (r.to) {
    case Route::To::kNmt:
      node.on_nmt(r.nmt_command, now_us);
      break;
    case Route::To::kWatchedHeartbeat:
      node.on_watched_heartbeat(now_us);
      break;
    case Route::To::kSdo:
      node.on_sdo(f, now_us);
      break;
    case Route::To::kSync:
      node.on_sync(now_us);
      break;
    case Route::To::kRpdo:
      node.on_rpdo(r.pdo, f, now_us);
      break;
    case Route::To::kNothing:
      break;
  }
}

bool RpdoInbox::receive(ObjectDictionary& od, ObjectHooks& hooks, int pdo, const drivers::CanFrame& f,
                        std::int64_t now_us) {
  if (!od.rpdo_length_ok(pdo, f.dlc)) return false;
  const auto k = static_cast<std::size_t>(pdo);
  if (rpdo_synchronous(od.pdo_type(static_cast<std::uint16_t>(kRpdoComm + pdo)))) {
    data_[k] = f.data;
    pending_[k] = true;  // applied at the next SYNC
  } else {
    od.unpack_rpdo(pdo, f.data, hooks, now_us);
  }
  return true;
}

void RpdoInbox::apply_at_sync(ObjectDictionary& od, ObjectHooks& hooks, std::int64_t now_us) {
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    if (!pending_[k]) continue;
    pending_[k] = false;
    od.unpack_rpdo(static_cast<int>(k), data_[k], hooks, now_us);
  }
}

}  // namespace loom::sim_can::slave

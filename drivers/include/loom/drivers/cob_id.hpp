// CANopen pre-defined connection set (CiA 301): which 11-bit identifier carries which service for which
// node. Every encoder and the frame dispatcher use these, so a wrong base offset shows up in one place.
#pragma once

#include <cstdint>

namespace loom::drivers {

inline constexpr std::uint8_t kMinNodeId = 1;
inline constexpr std::uint8_t kMaxNodeId = 127;

namespace cob {
inline constexpr std::uint32_t kNmt = 0x000;
inline constexpr std::uint32_t kSync = 0x080;
inline constexpr std::uint32_t kEmcyBase = 0x080;
inline constexpr std::uint32_t kTpdoBase[4] = {0x180, 0x280, 0x380, 0x480};
inline constexpr std::uint32_t kRpdoBase[4] = {0x200, 0x300, 0x400, 0x500};
inline constexpr std::uint32_t kSdoTxBase = 0x580;  // server → client (the drive answers here)
inline constexpr std::uint32_t kSdoRxBase = 0x600;  // client → server (the master asks here)
inline constexpr std::uint32_t kHeartbeatBase = 0x700;

// RT-safe. `pdo` is 1-based (TPDO1..4 / RPDO1..4), as the objects 0x1800+n-1 / 0x1400+n-1 count them.
constexpr std::uint32_t emcy(std::uint8_t node) noexcept {
  return kEmcyBase + node;
}
constexpr std::uint32_t tpdo(int pdo, std::uint8_t node) noexcept {
  return kTpdoBase[pdo - 1] + node;
}
constexpr std::uint32_t rpdo(int pdo, std::uint8_t node) noexcept {
  return kRpdoBase[pdo - 1] + node;
}
constexpr std::uint32_t sdo_tx(std::uint8_t node) noexcept {
  return kSdoTxBase + node;
}
constexpr std::uint32_t sdo_rx(std::uint8_t node) noexcept {
  return kSdoRxBase + node;
}
constexpr std::uint32_t heartbeat(std::uint8_t node) noexcept {
  return kHeartbeatBase + node;
}
}  // namespace cob

// The function a received COB-ID belongs to, and the node it names (0 for NMT/SYNC).
enum class CobFunction : std::uint8_t {
  kNmt,
  kSync,
  kEmcy,
  kTpdo1,
  kTpdo2,
  kTpdo3,
  kTpdo4,
  kRpdo1,
  kRpdo2,
  kRpdo3,
  kRpdo4,
  kSdoTx,
  kSdoRx,
  kHeartbeat,
  kOther,
};
struct CobDecoded {
  CobFunction function = CobFunction::kOther;
  std::uint8_t node = 0;
};

// RT-safe.
constexpr CobDecoded decode_cob_id(std::uint32_t id) noexcept {
  if (id == cob::kNmt) return {CobFunction::kNmt, 0};
  if (id == cob::kSync) return {CobFunction::kSync, 0};
  const auto node = static_cast<std::uint8_t>(id & 0x7F);
  if (node == 0) return {CobFunction::kOther, 0};
  switch (id & 0x780) {
    case 0x080:
      return {CobFunction::kEmcy, node};
    case 0x180:
      return {CobFunction::kTpdo1, node};
    case 0x280:
      return {CobFunction::kTpdo2, node};
    case 0x380:
      return {CobFunction::kTpdo3, node};
    case 0x480:
      return {CobFunction::kTpdo4, node};
    case 0x200:
      return {CobFunction::kRpdo1, node};
    case 0x300:
      return {CobFunction::kRpdo2, node};
    case 0x400:
      return {CobFunction::kRpdo3, node};
    case 0x500:
      return {CobFunction::kRpdo4, node};
    case 0x580:
      return {CobFunction::kSdoTx, node};
    case 0x600:
      return {CobFunction::kSdoRx, node};
    case 0x700:
      return {CobFunction::kHeartbeat, node};
    default:
      return {CobFunction::kOther, 0};
  }
}

}  // namespace loom::drivers

// The fixed PDO mapping the master writes into every servo drive (by SDO, before NMT start), and the
// packing of those PDOs. One place defines what a 6-byte RPDO1/TPDO1 contains, so the master, the
// simulated drive and the bus-load arithmetic agree.
//
//   RPDO1 (0x200+id, sync, 6 B): controlword 0x6040 u16 | target position 0x607A i32
//   TPDO1 (0x180+id, every SYNC, 6 B): statusword 0x6041 u16 | position actual 0x6064 i32
//   TPDO2 (0x280+id, every n-th SYNC, optional, 6 B): velocity actual 0x606C i32 | torque actual 0x6077 i16
//   TPDO2 is disabled when not used, TPDO3/TPDO4 always (drive defaults would load the bus).
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "loom/drivers/can_frame.hpp"

namespace loom::drivers {

// One mapping entry as written to 0x16xx/0x1Axx:n: index<<16 | sub<<8 | bit length.
struct PdoMapEntry {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t bits = 0;
};
// RT-safe.
constexpr std::uint32_t encode_map_entry(PdoMapEntry e) noexcept {
  return (static_cast<std::uint32_t>(e.index) << 16) | (static_cast<std::uint32_t>(e.sub) << 8) | e.bits;
}
constexpr PdoMapEntry decode_map_entry(std::uint32_t v) noexcept {
  return PdoMapEntry{static_cast<std::uint16_t>(v >> 16), static_cast<std::uint8_t>((v >> 8) & 0xFF),
                     static_cast<std::uint8_t>(v & 0xFF)};
}

// CiA 402 objects the mapping uses.
namespace od {
inline constexpr std::uint16_t kControlword = 0x6040;
inline constexpr std::uint16_t kStatusword = 0x6041;
inline constexpr std::uint16_t kModesOfOperation = 0x6060;
inline constexpr std::uint16_t kModesOfOperationDisplay = 0x6061;
inline constexpr std::uint16_t kPositionActual = 0x6064;
inline constexpr std::uint16_t kVelocityActual = 0x606C;
inline constexpr std::uint16_t kTorqueActual = 0x6077;
inline constexpr std::uint16_t kTargetPosition = 0x607A;
inline constexpr std::uint16_t kInterpolationPeriod = 0x60C2;
inline constexpr std::uint16_t kSupportedDriveModes = 0x6502;
inline constexpr std::uint16_t kErrorCode = 0x603F;
inline constexpr std::uint16_t kDeviceType = 0x1000;
inline constexpr std::uint16_t kErrorRegister = 0x1001;
inline constexpr std::uint16_t kHeartbeatProducer = 0x1017;
// Store parameters (CiA 301): writing "save" to sub 1 makes the node keep its configuration over a reset.
inline constexpr std::uint16_t kStoreParameters = 0x1010;
inline constexpr std::uint32_t kSaveSignature = 0x65766173;  // "save", little-endian
inline constexpr std::uint16_t kRpdoComm = 0x1400;           // + pdo-1
inline constexpr std::uint16_t kRpdoMap = 0x1600;
inline constexpr std::uint16_t kTpdoComm = 0x1800;
inline constexpr std::uint16_t kTpdoMap = 0x1A00;
inline constexpr std::int8_t kModeCsp = 8;                    // cyclic synchronous position
inline constexpr std::int8_t kModeHoming = 6;                 // homing mode
inline constexpr std::uint32_t kSupportsCspBit = 1U << 7;     // in 0x6502
inline constexpr std::uint32_t kSupportsHomingBit = 1U << 5;  // in 0x6502
inline constexpr std::uint16_t kHomeOffset = 0x607C;          // i32, counts: the reading at the home point
inline constexpr std::uint16_t kHomingMethod = 0x6098;        // i8
inline constexpr std::uint16_t kHomingSpeeds =
    0x6099;  // :01 search for switch, :02 search for zero, counts/s
inline constexpr std::uint16_t kHomingAcceleration = 0x609A;  // u32, counts/s²
inline constexpr std::uint32_t kPdoInvalidBit = 1U << 31;     // in 0x14xx/0x18xx:01
// Profile position (mode 1): the drive's own profile toward a set-point given with the handshake.
inline constexpr std::int8_t kModeProfilePosition = 1;
inline constexpr std::uint32_t kSupportsPpBit = 1U << 0;       // in 0x6502
inline constexpr std::uint16_t kProfileVelocity = 0x6081;      // u32, counts/s
inline constexpr std::uint16_t kProfileAcceleration = 0x6083;  // u32, counts/s²
inline constexpr std::uint16_t kProfileDeceleration = 0x6084;  // u32, counts/s²
inline constexpr std::uint16_t kMotionProfileType = 0x6086;  // i16: 0 linear ramp (trapezoid), 3 jerk-limited
inline constexpr std::int16_t kProfileLinearRamp = 0;
inline constexpr std::int16_t kProfileJerkLimited = 3;
inline constexpr std::uint8_t kTransmissionEvent = 255;  // 0x14xx/0x18xx:02: event-driven (profile specific)
inline constexpr std::uint8_t kPdoInhibitSub = 3;        // 0x18xx:03, units of 100 µs
inline constexpr std::uint8_t kPdoEventTimerSub = 5;     // 0x18xx:05, ms
}  // namespace od

// RT-safe. Human-readable name of an object the master touches ("modes of operation"), or "object".
const char* object_name(std::uint16_t index) noexcept;

inline constexpr std::array<PdoMapEntry, 2> kRpdo1Mapping{
    {{od::kControlword, 0, 16}, {od::kTargetPosition, 0, 32}}};
inline constexpr std::array<PdoMapEntry, 2> kTpdo1Mapping{
    {{od::kStatusword, 0, 16}, {od::kPositionActual, 0, 32}}};
inline constexpr std::array<PdoMapEntry, 2> kTpdo2Mapping{
    {{od::kVelocityActual, 0, 32}, {od::kTorqueActual, 0, 16}}};
inline constexpr std::uint8_t kRpdo1Bytes = 6;
inline constexpr std::uint8_t kTpdo1Bytes = 6;
inline constexpr std::uint8_t kTpdo2Bytes = 6;
// A homed axis switches between homing (6) and CSP (8) in the RT path, so the mode travels in the PDOs
// beside the controlword and the statusword (the layout of CiA 402's "modes of operation" PDO sets):
// RPDO1 {controlword, target, 0x6060}, TPDO1 {statusword, position actual, 0x6061}; 7 bytes each.
inline constexpr std::array<PdoMapEntry, 3> kRpdo1HomingMapping{
    {{od::kControlword, 0, 16}, {od::kTargetPosition, 0, 32}, {od::kModesOfOperation, 0, 8}}};
inline constexpr std::array<PdoMapEntry, 3> kTpdo1HomingMapping{
    {{od::kStatusword, 0, 16}, {od::kPositionActual, 0, 32}, {od::kModesOfOperationDisplay, 0, 8}}};
inline constexpr std::uint8_t kRpdo1HomingBytes = 7;
inline constexpr std::uint8_t kTpdo1HomingBytes = 7;

struct Rpdo1 {
  std::uint16_t controlword = 0;
  std::int32_t target_position = 0;  // counts
};
struct Tpdo1 {
  std::uint16_t statusword = 0;
  std::int32_t position_actual = 0;  // counts
};
// The homed axes' 7-byte layouts (kRpdo1HomingMapping, kTpdo1HomingMapping).
struct Rpdo1Mode {
  std::uint16_t controlword = 0;
  std::int32_t target_position = 0;  // counts
  std::int8_t mode = 8;              // 0x6060
};
struct Tpdo1Mode {
  std::uint16_t statusword = 0;
  std::int32_t position_actual = 0;  // counts
  std::int8_t mode_display = 0;      // 0x6061
};
struct Tpdo2 {
  std::int32_t velocity_actual = 0;  // counts/s
  std::int16_t torque_actual = 0;    // ‰ of rated torque
};

// RT-safe. Pack/unpack with the mapping above; unpack returns nullopt for a wrong id or DLC.
CanFrame pack_rpdo1(std::uint8_t node, const Rpdo1& p) noexcept;
std::optional<Rpdo1> unpack_rpdo1(const CanFrame& frame, std::uint8_t node) noexcept;
CanFrame pack_tpdo1(std::uint8_t node, const Tpdo1& p) noexcept;
std::optional<Tpdo1> unpack_tpdo1(const CanFrame& frame, std::uint8_t node) noexcept;
CanFrame pack_rpdo1_mode(std::uint8_t node, const Rpdo1Mode& p) noexcept;
std::optional<Rpdo1Mode> unpack_rpdo1_mode(const CanFrame& frame, std::uint8_t node) noexcept;
CanFrame pack_tpdo1_mode(std::uint8_t node, const Tpdo1Mode& p) noexcept;
std::optional<Tpdo1Mode> unpack_tpdo1_mode(const CanFrame& frame, std::uint8_t node) noexcept;
CanFrame pack_tpdo2(std::uint8_t node, const Tpdo2& p) noexcept;
std::optional<Tpdo2> unpack_tpdo2(const CanFrame& frame, std::uint8_t node) noexcept;

}  // namespace loom::drivers

// CiA 301 emergency (EMCY) messages and the table of fault codes the drivers report in
// hal::AxisFeedback::fault_code / LinkStatus::link_fault_code. Drive codes come from the drive's EMCY;
// the master's own detections (heartbeat loss, bus-off, state-machine timeout) use codes from the same
// CiA 301 space so the firmware's fault model has one vocabulary.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "loom/drivers/can_frame.hpp"
#include "loom/hal/types.hpp"

namespace loom::drivers {

struct Emcy {
  std::uint8_t node = 0;
  std::uint16_t code = 0;           // 0x0000 = error reset / no error
  std::uint8_t error_register = 0;  // object 0x1001
  std::array<std::uint8_t, 5> vendor{};
};

// RT-safe. nullopt unless id 0x081..0x0FF and DLC 8.
std::optional<Emcy> parse_emcy(const CanFrame& frame) noexcept;
// RT-safe.
CanFrame make_emcy(std::uint8_t node, std::uint16_t code, std::uint8_t error_register) noexcept;

// Codes the master itself raises.
namespace fault_code {
inline constexpr std::uint16_t kNone = 0x0000;
inline constexpr std::uint16_t kCommunication = 0x8100;  // used for bus-off / socket failure
inline constexpr std::uint16_t kHeartbeatLost = 0x8130;  // heartbeat consumer timeout
inline constexpr std::uint16_t kPdoLength = 0x8210;      // PDO not processed due to length error
inline constexpr std::uint16_t kFollowingError = 0x8611;
// Device-specific range 0xFF00..0xFFFF: detections with no CiA 301 code of their own.
inline constexpr std::uint16_t kStateTimeout = 0xFF01;        // CiA 402 transition not confirmed in time
inline constexpr std::uint16_t kNodeRebooted = 0xFF02;        // boot-up seen while operating: mapping lost
inline constexpr std::uint16_t kNodeNotOperational = 0xFF03;  // heartbeat says stopped/pre-operational
// Profile position: the drive did not acknowledge a set-point (statusword bit 12) within the state
// timeout, or did not report target reached (bit 10) within the move's planned duration and its margin.
inline constexpr std::uint16_t kSetpointNotAcknowledged = 0xFF04;
inline constexpr std::uint16_t kTargetNotReached = 0xFF05;
}  // namespace fault_code

// RT-safe. The kind of a fault the master reports with `code` on a node's link: its own detections of
// a lost node (heartbeat lost, rebooted, not operational) and of the bus, else an EMCY the node sent.
hal::FaultKind link_fault_kind(std::uint16_t code) noexcept;

// RT-safe (returns a static string). The specific text for codes in the table above and the common
// drive codes, else the CiA 301 error class of the code ("current", "voltage", ...).
const char* fault_code_text(std::uint16_t code) noexcept;

}  // namespace loom::drivers

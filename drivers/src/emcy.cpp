// EMCY codec (CiA 301 §7.2.7) and fault-code texts (CiA 301 Table 21 error classes, CiA 402 codes).
#include "loom/drivers/emcy.hpp"

#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/le_bytes.hpp"

namespace loom::drivers {

std::optional<Emcy> parse_emcy(const CanFrame& frame) noexcept {
  if (frame.is_error() || frame.is_rtr() || frame.dlc != 8) return std::nullopt;
  const CobDecoded c = decode_cob_id(frame.id);
  if (c.function != CobFunction::kEmcy) return std::nullopt;
  Emcy e;
  e.node = c.node;
  e.code = get_u16(&frame.data[0]);
  e.error_register = frame.data[2];
  for (std::size_t i = 0; i < e.vendor.size(); ++i) e.vendor[i] = frame.data[3 + i];
  return e;
}

CanFrame make_emcy(std::uint8_t node, std::uint16_t code, std::uint8_t error_register) noexcept {
  CanFrame f;
  f.id = cob::emcy(node);
  f.dlc = 8;
  put_u16(&f.data[0], code);
  f.data[2] = error_register;
  return f;
}

const char* fault_code_text(std::uint16_t code) noexcept {
  switch (code) {
    case fault_code::kNone:
      return "no error";
    case fault_code::kCommunication:
      return "communication error (CAN bus-off or socket failure)";
    case 0x8110:
      return "CAN overrun (objects lost)";
    case 0x8120:
      return "CAN in error passive mode";
    case fault_code::kHeartbeatLost:
      return "heartbeat lost (life guard / heartbeat error)";
    case 0x8140:
      return "recovered from bus-off";
    case fault_code::kPdoLength:
      return "PDO not processed due to length error";
    case 0x8220:
      return "PDO length exceeded";
    case fault_code::kFollowingError:
      return "following error";
    case fault_code::kStateTimeout:
      return "CiA 402 state transition not confirmed in time";
    case fault_code::kNodeRebooted:
      return "drive rebooted while operating (boot-up received)";
    case fault_code::kNodeNotOperational:
      return "drive left NMT operational";
    case fault_code::kSetpointNotAcknowledged:
      return "profile position set-point not acknowledged (statusword bit 12) in time";
    case fault_code::kTargetNotReached:
      return "profile position target not reached (statusword bit 10) within the move's time";
    default:
      break;
  }
  switch (code >> 8) {
    case 0x10:
      return "generic error";
    case 0x20:
    case 0x21:
    case 0x22:
    case 0x23:
      return "current";
    case 0x30:
    case 0x31:
    case 0x32:
    case 0x33:
      return "voltage";
    case 0x40:
    case 0x41:
    case 0x42:
      return "temperature";
    case 0x50:
      return "device hardware";
    case 0x60:
    case 0x61:
    case 0x62:
    case 0x63:
      return "device software";
    case 0x70:
      return "additional modules";
    case 0x80:
    case 0x81:
    case 0x82:
    case 0x83:
    case 0x84:
    case 0x85:
    case 0x86:
    case 0x87:
      return "monitoring";
    case 0x90:
      return "external error";
    case 0xF0:
      return "additional functions";
    case 0xFF:
      return "device specific";
    default:
      return "unknown error code";
  }
}

hal::FaultKind link_fault_kind(std::uint16_t code) noexcept {
  switch (code) {
    case fault_code::kNone:
      return hal::FaultKind::kNone;
    case fault_code::kHeartbeatLost:
    case fault_code::kNodeRebooted:
    case fault_code::kNodeNotOperational:
      return hal::FaultKind::kNodeLost;
    case fault_code::kCommunication:
      return hal::FaultKind::kCommunication;
    default:
      return hal::FaultKind::kEmcy;
  }
}

}  // namespace loom::drivers

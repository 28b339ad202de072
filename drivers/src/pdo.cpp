// Packing of the fixed servo PDO mapping (see pdo.hpp); byte offsets follow the mapping entry order.
#include "loom/drivers/pdo.hpp"

#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/le_bytes.hpp"

namespace loom::drivers {
namespace {
bool is_data_frame(const CanFrame& f, std::uint32_t id, std::uint8_t dlc) {
  return !f.is_error() && !f.is_rtr() && f.id == id && f.dlc == dlc;
}
}  // namespace

const char* object_name(std::uint16_t index) noexcept {
  if (index >= od::kRpdoComm && index < od::kRpdoComm + 4) return "RPDO communication parameter";
  if (index >= od::kRpdoMap && index < od::kRpdoMap + 4) return "RPDO mapping";
  if (index >= od::kTpdoComm && index < od::kTpdoComm + 4) return "TPDO communication parameter";
  if (index >= od::kTpdoMap && index < od::kTpdoMap + 4) return "TPDO mapping";
  switch (index) {
    case od::kDeviceType:
      return "device type";
    case od::kErrorRegister:
      return "error register";
    case od::kHeartbeatProducer:
      return "producer heartbeat time";
    case od::kStoreParameters:
      return "store parameters";
    case od::kErrorCode:
      return "error code";
    case od::kControlword:
      return "controlword";
    case od::kStatusword:
      return "statusword";
    case od::kModesOfOperation:
      return "modes of operation";
    case od::kModesOfOperationDisplay:
      return "modes of operation display";
    case od::kPositionActual:
      return "position actual value";
    case od::kVelocityActual:
      return "velocity actual value";
    case od::kTorqueActual:
      return "torque actual value";
    case od::kTargetPosition:
      return "target position";
    case od::kInterpolationPeriod:
      return "interpolation time period";
    case od::kProfileVelocity:
      return "profile velocity";
    case od::kProfileAcceleration:
      return "profile acceleration";
    case od::kProfileDeceleration:
      return "profile deceleration";
    case od::kMotionProfileType:
      return "motion profile type";
    case od::kSupportedDriveModes:
      return "supported drive modes";
    default:
      return "object";
  }
}

CanFrame pack_rpdo1(std::uint8_t node, const Rpdo1& p) noexcept {
  CanFrame f;
  f.id = cob::rpdo(1, node);
  f.dlc = kRpdo1Bytes;
  put_u16(&f.data[0], p.controlword);
  put_i32(&f.data[2], p.target_position);
  return f;
}

std::optional<Rpdo1> unpack_rpdo1(const CanFrame& frame, std::uint8_t node) noexcept {
  if (!is_data_frame(frame, cob::rpdo(1, node), kRpdo1Bytes)) return std::nullopt;
  return Rpdo1{get_u16(&frame.data[0]), get_i32(&frame.data[2])};
}

CanFrame pack_tpdo1(std::uint8_t node, const Tpdo1& p) noexcept {
  CanFrame f;
  f.id = cob::tpdo(1, node);
  f.dlc = kTpdo1Bytes;
  put_u16(&f.data[0], p.statusword);
  put_i32(&f.data[2], p.position_actual);
  return f;
}

std::optional<Tpdo1> unpack_tpdo1(const CanFrame& frame, std::uint8_t node) noexcept {
  if (!is_data_frame(frame, cob::tpdo(1, node), kTpdo1Bytes)) return std::nullopt;
  return Tpdo1{get_u16(&frame.data[0]), get_i32(&frame.data[2])};
}

CanFrame pack_rpdo1_mode(std::uint8_t node, const Rpdo1Mode& p) noexcept {
  CanFrame f = pack_rpdo1(node, Rpdo1{p.controlword, p.target_position});
  f.dlc = kRpdo1HomingBytes;
  f.data[6] = static_cast<std::uint8_t>(p.mode);
  return f;
}

std::optional<Rpdo1Mode> unpack_rpdo1_mode(const CanFrame& frame, std::uint8_t node) noexcept {
  if (!is_data_frame(frame, cob::rpdo(1, node), kRpdo1HomingBytes)) return std::nullopt;
  return Rpdo1Mode{get_u16(&frame.data[0]), get_i32(&frame.data[2]), static_cast<std::int8_t>(frame.data[6])};
}

CanFrame pack_tpdo1_mode(std::uint8_t node, const Tpdo1Mode& p) noexcept {
  CanFrame f = pack_tpdo1(node, Tpdo1{p.statusword, p.position_actual});
  f.dlc = kTpdo1HomingBytes;
  f.data[6] = static_cast<std::uint8_t>(p.mode_display);
  return f;
}

std::optional<Tpdo1Mode> unpack_tpdo1_mode(const CanFrame& frame, std::uint8_t node) noexcept {
  if (!is_data_frame(frame, cob::tpdo(1, node), kTpdo1HomingBytes)) return std::nullopt;
  return Tpdo1Mode{get_u16(&frame.data[0]), get_i32(&frame.data[2]), static_cast<std::int8_t>(frame.data[6])};
}

CanFrame pack_tpdo2(std::uint8_t node, const Tpdo2& p) noexcept {
  CanFrame f;
  f.id = cob::tpdo(2, node);
  f.dlc = kTpdo2Bytes;
  put_i32(&f.data[0], p.velocity_actual);
  put_i16(&f.data[4], p.torque_actual);
  return f;
}

std::optional<Tpdo2> unpack_tpdo2(const CanFrame& frame, std::uint8_t node) noexcept {
  if (!is_data_frame(frame, cob::tpdo(2, node), kTpdo2Bytes)) return std::nullopt;
  return Tpdo2{get_i32(&frame.data[0]), get_i16(&frame.data[4])};
}

}  // namespace loom::drivers

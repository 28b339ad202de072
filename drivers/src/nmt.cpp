// NMT, SYNC and heartbeat frame codecs (CiA 301 §7.2.8 NMT, §7.2.5 SYNC, §7.2.8.3 error control).
#include "loom/drivers/nmt.hpp"

#include "loom/drivers/cob_id.hpp"

namespace loom::drivers {

const char* nmt_state_name(NmtState s) noexcept {
  switch (s) {
    case NmtState::kBootUp:
      return "boot-up";
    case NmtState::kStopped:
      return "stopped";
    case NmtState::kOperational:
      return "operational";
    case NmtState::kPreOperational:
      return "pre-operational";
  }
  return "?";
}

CanFrame make_nmt(NmtCommand command, std::uint8_t node) noexcept {
  CanFrame f;
  f.id = cob::kNmt;
  f.dlc = 2;
  f.data[0] = static_cast<std::uint8_t>(command);
  f.data[1] = node;
  return f;
}

std::optional<NmtMessage> parse_nmt(const CanFrame& frame) noexcept {
  if (frame.is_error() || frame.is_rtr() || frame.id != cob::kNmt || frame.dlc != 2) return std::nullopt;
  if (frame.data[1] > kMaxNodeId) return std::nullopt;
  switch (frame.data[0]) {
    case 0x01:
    case 0x02:
    case 0x80:
    case 0x81:
    case 0x82:
      return NmtMessage{static_cast<NmtCommand>(frame.data[0]), frame.data[1]};
    default:
      return std::nullopt;
  }
}

CanFrame make_sync() noexcept {
  CanFrame f;
  f.id = cob::kSync;
  f.dlc = 0;
  return f;
}

bool is_sync(const CanFrame& frame) noexcept {
  return !frame.is_error() && !frame.is_rtr() && frame.id == cob::kSync && frame.dlc <= 1;
}

CanFrame make_heartbeat(std::uint8_t node, NmtState state) noexcept {
  CanFrame f;
  f.id = cob::heartbeat(node);
  f.dlc = 1;
  f.data[0] = static_cast<std::uint8_t>(state);
  return f;
}

std::optional<Heartbeat> parse_heartbeat(const CanFrame& frame) noexcept {
  if (frame.is_error() || frame.is_rtr() || frame.dlc != 1) return std::nullopt;
  const CobDecoded cob_fn = decode_cob_id(frame.id);
  if (cob_fn.function != CobFunction::kHeartbeat) return std::nullopt;
  const std::uint8_t s = frame.data[0] & 0x7F;  // bit 7 is the node-guarding toggle bit
  switch (s) {
    case 0x00:
    case 0x04:
    case 0x05:
    case 0x7F:
      return Heartbeat{cob_fn.node, static_cast<NmtState>(s)};
    default:
      return std::nullopt;
  }
}

}  // namespace loom::drivers

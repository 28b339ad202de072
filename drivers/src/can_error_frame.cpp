// SocketCAN error-frame decoding, using the kernel's own bit definitions so the meaning cannot drift.
#include "loom/drivers/can_error_frame.hpp"

#include <linux/can.h>
#include <linux/can/error.h>

namespace loom::drivers {

CanErrorInfo decode_error_frame(const CanFrame& frame) noexcept {
  CanErrorInfo info;
  if (!frame.is_error()) return info;
  const std::uint32_t cls = frame.id;
  const std::uint8_t ctrl = frame.dlc > 1 ? frame.data[1] : std::uint8_t{0};
  info.bus_off = (cls & CAN_ERR_BUSOFF) != 0;
  info.restarted = (cls & CAN_ERR_RESTARTED) != 0;
  info.no_ack = (cls & CAN_ERR_ACK) != 0;
  info.tx_timeout = (cls & CAN_ERR_TX_TIMEOUT) != 0;
  info.protocol = (cls & (CAN_ERR_PROT | CAN_ERR_BUSERROR | CAN_ERR_LOSTARB)) != 0;
  if ((cls & CAN_ERR_CRTL) != 0) {
    info.error_passive = (ctrl & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0;
    info.warning = (ctrl & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0;
    info.overflow = (ctrl & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) != 0;
  }
  return info;
}

namespace {

CanFrame error_frame(std::uint32_t error_class) {
  CanFrame f;
  f.flags = CanFrame::kError;
  f.id = error_class;
  f.dlc = CAN_ERR_DLC;
  return f;
}

}  // namespace

CanFrame make_bus_off_error_frame() noexcept {
  return error_frame(CAN_ERR_BUSOFF);
}
CanFrame make_restarted_error_frame() noexcept {
  return error_frame(CAN_ERR_RESTARTED);
}

}  // namespace loom::drivers

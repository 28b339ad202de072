// The real CAN endpoint: a Linux SocketCAN raw socket, non-blocking, with error frames enabled so
// bus-off and controller problems reach the CANopen master as data. A full transmit queue is counted
// and the frame dropped — the RT loop never sleeps on the bus.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "loom/drivers/can_frame.hpp"
#include "loom/drivers/status.hpp"

namespace loom::drivers {

class SocketCanBus final : public CanBus {
 public:
  // Configure-time only. Open and bind a raw CAN socket on `iface`. The error names the interface and
  // says what is missing: no CAN in the kernel, no such interface, not a CAN interface, interface down.
  static Result<std::unique_ptr<SocketCanBus>> open(const std::string& iface);

  ~SocketCanBus() override;
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;

  SendResult send(const CanFrame& frame) noexcept override;  // RT-safe (one non-blocking send syscall)
  bool receive(CanFrame& frame) noexcept override;           // RT-safe (bounded non-blocking recv syscalls)

  // Configure-time only (used by poll() loops in non-RT tools such as the simulated drive node).
  int fd() const { return fd_; }
  const std::string& iface() const { return iface_; }

  // Cumulative counters; RT-safe to read.
  std::uint32_t tx_would_block() const noexcept { return tx_would_block_; }  // ENOBUFS / EAGAIN
  std::uint32_t tx_errors() const noexcept { return tx_errors_; }            // any other send failure
  std::uint32_t rx_errors() const noexcept { return rx_errors_; }            // failed or truncated reads
  std::uint32_t rx_skipped() const { return rx_skipped_; }                   // 29-bit frames (not CANopen)

 private:
  SocketCanBus(int fd, std::string iface) : fd_(fd), iface_(std::move(iface)) {}

  int fd_ = -1;
  std::string iface_;
  std::uint32_t tx_would_block_ = 0;
  std::uint32_t tx_errors_ = 0;
  std::uint32_t rx_errors_ = 0;
  std::uint32_t rx_skipped_ = 0;
};

}  // namespace loom::drivers

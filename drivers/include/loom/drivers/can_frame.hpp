// The CAN frame the drivers exchange and the small bus interface behind which the real SocketCAN socket
// and the tests' fault-injecting in-memory bus both sit. Classic CAN 2.0A only (11-bit ids, ≤ 8 bytes):
// the CANopen pre-defined connection set needs nothing else.
#pragma once

#include <array>
#include <cstdint>

namespace loom::drivers {

struct CanFrame {
  // kError: `id` holds the SocketCAN error class bits (CAN_ERR_*) and `data` the error details.
  // kRtr: remote transmission request (CANopen masters never send these; decoded only to reject them).
  static constexpr std::uint8_t kError = 0x01;
  static constexpr std::uint8_t kRtr = 0x02;

  std::uint32_t id = 0;  // 11-bit identifier (COB-ID) for data frames
  std::uint8_t dlc = 0;  // 0..8
  std::uint8_t flags = 0;
  std::array<std::uint8_t, 8> data{};

  bool is_error() const { return (flags & kError) != 0; }
  bool is_rtr() const { return (flags & kRtr) != 0; }
};

inline constexpr std::uint32_t kMaxStandardId = 0x7FF;

enum class SendResult : std::uint8_t {
  kOk = 0,
  kWouldBlock,  // transmit queue full (ENOBUFS/EAGAIN): the frame is dropped and counted, never waited on
  kError,       // the bus refused the frame (bus-off, interface down, invalid frame)
};

// A non-blocking CAN endpoint. Implementations never sleep and never allocate in send/receive.
class CanBus {
 public:
  virtual ~CanBus() = default;
  // RT-safe. Queue one frame for transmission.
  virtual SendResult send(const CanFrame& frame) noexcept = 0;
  // RT-safe. Take the next received frame (data or error frame); false when none is waiting.
  virtual bool receive(CanFrame& frame) noexcept = 0;
};

}  // namespace loom::drivers

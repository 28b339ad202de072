// The master's supervision of ONE remote node (CANopenNode's CO_HBconsumer is the model): heartbeat
// consumer, boot-up and "not operational" detection, the node's EMCY latch with the operator's
// acknowledgement, and whether a lost node has been heard again (recovery). Every remote node on a bus
// has one, whatever its profile (CiA 402 drive, CiA 401 I/O module); the profile drivers never look at
// heartbeats or EMCYs themselves. Plain data, RT-safe after arm().
#pragma once

#include <cstdint>

#include "loom/drivers/can_frame.hpp"
#include "loom/hal/types.hpp"

namespace loom::drivers {

class NodeSupervisor {
 public:
  // Configure-time (after the node's bring-up): clears every latch and starts a consumer of
  // `consumer_ticks` cycles. The consumer starts counting at the first supervised tick.
  void arm(std::uint32_t consumer_ticks);
  // Configure-time: not supervised (before bring-up, or after a failed one).
  void disarm() { *this = NodeSupervisor{}; }

  // RT-safe. A heartbeat (0x700 + id) of this node; false when malformed (counted by the caller).
  bool on_heartbeat(hal::Tick now, const CanFrame& frame) noexcept;
  // RT-safe. An EMCY (0x080 + id) of this node; false when malformed. A non-zero code latches (even
  // while the node says it is fine) until the operator acknowledges; the node's 0x0000 (error reset)
  // after that acknowledgement clears it.
  bool on_emcy(const CanFrame& frame) noexcept;
  // RT-safe. After the tick's frames: the heartbeat consumer.
  void supervise(hal::Tick now) noexcept;
  // RT-safe. The operator acknowledged. `still_in_fault`: the node still says it is in Fault (a drive's
  // statusword), so its EMCY stays latched until its own error reset.
  void acknowledge(bool still_in_fault) noexcept;

  // RT-safe. The master's own link verdict on the node: 0, or kHeartbeatLost / kNodeRebooted /
  // kNodeNotOperational (emcy.hpp), latched until the next bring-up.
  std::uint16_t link_fault() const noexcept { return link_fault_; }
  // RT-safe. The latched EMCY code, 0 = none.
  std::uint16_t emcy_code() const noexcept { return emcy_code_; }
  // RT-safe. After a link fault: the node is on the bus again (heard within the consumer time, or booted
  // since), so a new bring-up can work.
  bool heard_again(hal::Tick now) const noexcept;
  bool armed() const noexcept { return armed_; }

 private:
  bool armed_ = false;
  std::uint32_t consumer_ticks_ = 0;
  hal::Tick last_heartbeat_ = hal::kNeverTick;
  bool booted_ = false;        // a boot-up since arm(): back on the bus, needing configuration
  bool acknowledged_ = false;  // operator acked while the node was in Fault: its EMCY 0x0000 clears
  std::uint16_t link_fault_ = 0;
  std::uint16_t emcy_code_ = 0;
};

}  // namespace loom::drivers

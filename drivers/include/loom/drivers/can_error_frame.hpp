// Meaning of a SocketCAN error frame (CAN_ERR_FLAG set) for the CANopen master: bus-off must latch a
// link fault, error-passive/overflow are worth counting, a controller restart ends bus-off. The bit
// layout is the kernel's (linux/can/error.h); this header keeps the rest of the driver free of it.
#pragma once

#include <cstdint>

#include "loom/drivers/can_frame.hpp"

namespace loom::drivers {

struct CanErrorInfo {
  bool bus_off = false;        // controller left the bus: nothing is sent until it restarts
  bool restarted = false;      // controller restarted after bus-off
  bool error_passive = false;  // error counters ≥ 128 (rx or tx)
  bool warning = false;        // error counters ≥ 96
  bool overflow = false;       // controller rx/tx buffer overflow: frames were lost
  bool no_ack = false;         // nobody acknowledged our frame (no other node on the bus)
  bool protocol = false;       // bit/form/stuff errors or other bus errors
  bool tx_timeout = false;
};

// RT-safe. Decode an error frame (`frame.is_error()`); all false for a data frame.
CanErrorInfo decode_error_frame(const CanFrame& frame) noexcept;

// Error-frame content a simulated or fake bus injects to signal bus-off (same bits as the kernel's).
// RT-safe.
CanFrame make_bus_off_error_frame() noexcept;
// ... and that the controller restarted after bus-off (CAN_ERR_RESTARTED, as the kernel sends it).
CanFrame make_restarted_error_frame() noexcept;

}  // namespace loom::drivers

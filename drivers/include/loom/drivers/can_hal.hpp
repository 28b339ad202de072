// The HAL of a machine on CAN: the network polled once per tick, then its ports read as views on it; the
// network's cycle started (SYNC on every bus, the master heartbeat when due), then the ports write. The
// order is CANopen's synchronous cycle: what the nodes sent since the last SYNC is consumed before the
// loop decides, and the RPDOs follow this tick's SYNC so the drives apply them at the next one.
#pragma once

#include "loom/drivers/can_network.hpp"
#include "loom/hal/hal.hpp"

namespace loom::drivers {

class CanHal final : public hal::Hal {
 public:
  // `io` may be another HAL's (the simulated I/O node beside real drives, when asked for on purpose).
  // None is owned; all outlive the HAL.
  CanHal(CanNetwork& network, hal::AxisPort& axes, hal::IoPort& io) : network_(network), ports_(axes, io) {}

  void read(hal::Tick now, hal::HalInputs& in) noexcept override {  // RT-safe
    network_.poll(now);
    ports_.read(now, in);
  }
  void write(hal::Tick now, const hal::HalOutputs& out) noexcept override {  // RT-safe
    network_.start_cycle(now);
    ports_.write(now, out);
  }

 private:
  CanNetwork& network_;
  hal::PortHal ports_;
};

}  // namespace loom::drivers

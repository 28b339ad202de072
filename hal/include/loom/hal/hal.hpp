// The small interfaces the loop drives. A HAL is read once and written once per tick; both calls are
// RT-safe in every implementation (no allocation, no locks, no blocking; only the HAL's own I/O).
// The axis side and the I/O side are separate ports so a machine can mix them (CAN drives with a
// simulated I/O node while the real one is not wired yet).
#pragma once

#include "loom/hal/types.hpp"

namespace loom::hal {

class AxisPort {
 public:
  virtual ~AxisPort() = default;
  // RT-safe. Fill the latest feedback for every axis (values keep their `refreshed` tick when no new
  // data came) and the link status.
  virtual void read_axes(Tick now, AxisFeedbacks& axes, LinkStatus& link) noexcept = 0;
  // RT-safe. Send this tick's commands.
  virtual void write_axes(Tick now, const AxisCommands& axes) noexcept = 0;
};

class IoPort {
 public:
  virtual ~IoPort() = default;
  // RT-safe. `axes` is this tick's fresh axis feedback: a simulated I/O node uses the helix shaft
  // position to decide when the shuttle arrives; real I/O ignores it.
  virtual void read_io(Tick now, const AxisFeedbacks& axes, DigitalInputs& io) noexcept = 0;
  // RT-safe. Analog channels (beater load cell). Default: none fitted.
  virtual void read_analog(Tick now, AnalogInputs& analog) noexcept {
    analog = AnalogInputs{};
    (void)now;
  }
  // RT-safe.
  virtual void write_io(Tick now, const DigitalOutputs& io) noexcept = 0;
};

// The HAL the loop sees: one read, one write per tick.
class Hal {
 public:
  virtual ~Hal() = default;
  virtual void read(Tick now, HalInputs& in) noexcept = 0;           // RT-safe
  virtual void write(Tick now, const HalOutputs& out) noexcept = 0;  // RT-safe
};

// Joins an axis port and an I/O port into one HAL. Reads axes first so the I/O side sees them.
class PortHal final : public Hal {
 public:
  PortHal(AxisPort& axes, IoPort& io) : axes_(axes), io_(io) {}
  void read(Tick now, HalInputs& in) noexcept override {
    axes_.read_axes(now, in.axes, in.link);
    io_.read_io(now, in.axes, in.io);
    io_.read_analog(now, in.analog);
  }
  void write(Tick now, const HalOutputs& out) noexcept override {
    axes_.write_axes(now, out.axes);
    io_.write_io(now, out.io);
  }

 private:
  AxisPort& axes_;
  IoPort& io_;
};

}  // namespace loom::hal

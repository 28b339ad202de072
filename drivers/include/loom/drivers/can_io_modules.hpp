// The loom's I/O as one hal::IoPort over its CiA 401 modules (one CanIoPort each, on any bus): a loom
// that outgrows one module's 64 inputs, or puts a module beside its knotting heads or its operator
// panel, spreads its signals over several (IoBit::module). Every tick the modules' signals are read into
// one sample and each module is written the outputs wired to it.
//
// The sample is as old as the oldest module's inputs: a module that falls silent makes the whole sample
// stale (the sequencer's stale-input fault), even before that node's heartbeat supervision expires, so
// no decision is ever taken on one module's fresh sensors beside another's old ones.
#pragma once

#include <array>
#include <cstddef>

#include "loom/drivers/can_io_port.hpp"
#include "loom/hal/hal.hpp"

namespace loom::drivers {

class CanIoModules final : public hal::IoPort {
 public:
  // Configure-time only. Module `module.config().module`, not owned; at most kMaxIoModules, each module
  // index once (the machine description numbers them 0..n-1).
  void add(CanIoPort& module);
  std::size_t size() const { return n_; }

  // hal::IoPort (RT-safe).
  void read_io(hal::Tick now, const hal::AxisFeedbacks& axes, hal::DigitalInputs& io) noexcept override;
  void read_analog(hal::Tick now, hal::AnalogInputs& analog) noexcept override;
  void write_io(hal::Tick now, const hal::DigitalOutputs& io) noexcept override;

 private:
  std::array<CanIoPort*, kMaxIoModules> modules_{};
  std::size_t n_ = 0;
  CanIoPort* load_cell_ = nullptr;  // the module the load cell is wired to, if any
};

}  // namespace loom::drivers

// One hal::IoPort over the loom's CiA 401 modules (see can_io_modules.hpp).
#include "loom/drivers/can_io_modules.hpp"

#include <algorithm>

namespace loom::drivers {

void CanIoModules::add(CanIoPort& module) {
  if (n_ == modules_.size()) return;
  modules_[n_++] = &module;
  if (module.has_load_cell()) load_cell_ = &module;
}

void CanIoModules::read_io(hal::Tick /*now*/, const hal::AxisFeedbacks& /*axes*/,
                           hal::DigitalInputs& io) noexcept {
  io = hal::DigitalInputs{};  // each signal comes from the one module it is wired to
  hal::Tick oldest = n_ == 0 ? hal::kNeverTick : modules_[0]->inputs_refreshed();
  for (std::size_t k = 0; k < n_; ++k) {
    modules_[k]->read_wired(io);
    // kNeverTick (-1) is below every tick: one module never heard keeps the whole sample unseen.
    oldest = std::min(oldest, modules_[k]->inputs_refreshed());
  }
  io.refreshed = oldest;
}

void CanIoModules::read_analog(hal::Tick now, hal::AnalogInputs& analog) noexcept {
  if (load_cell_ == nullptr) {
    analog = hal::AnalogInputs{};  // no load cell fitted
    return;
  }
  load_cell_->read_analog(now, analog);
}

void CanIoModules::write_io(hal::Tick now, const hal::DigitalOutputs& io) noexcept {
  for (std::size_t k = 0; k < n_; ++k) modules_[k]->write_io(now, io);
}

}  // namespace loom::drivers

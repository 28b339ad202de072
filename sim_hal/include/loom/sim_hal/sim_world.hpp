// The simulated loom behind the HAL: three servo axes, two pistons with end sensors, the shuttle on its
// magnetic carrier with arrival sensors, the e-stop chain. Stepped in virtual time by the loop's own
// tick (write() integrates one period), so it runs as fast as the machine allows.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "loom/hal/hal.hpp"
#include "loom/sim_hal/scene.hpp"

namespace loom::sim_hal {

// One effect acting on an axis' commanded position each tick (servo lag, later inertia, friction...).
class AxisEffect {
 public:
  virtual ~AxisEffect() = default;
  // RT-safe. Turn the drive's commanded target into the new actual position after dt.
  virtual double step(double target, double actual, double dt) noexcept = 0;
};

struct SimAxis {
  hal::DriveState state = hal::DriveState::kSwitchOnDisabled;
  double position = 0.0;
  double velocity = 0.0;
  double target = 0.0;
  std::uint16_t fault_code = 0;
  std::vector<std::unique_ptr<AxisEffect>> effects;  // built once from the scene
};

class SimWorld final : public hal::AxisPort, public hal::IoPort {
 public:
  // Configure-time only: builds exactly the effects the scene names. Throws std::invalid_argument on an
  // unknown effect name (the firmware checks names earlier and reports file and line).
  SimWorld(const SimMachine& machine, const SceneSpec& scene);

  void read_axes(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) override;  // RT-safe
  void write_axes(hal::Tick now, const hal::AxisCommands& axes) override;                   // RT-safe
  void read_io(hal::Tick now, const hal::AxisFeedbacks& axes, hal::DigitalInputs& io) override;  // RT-safe
  void write_io(hal::Tick now, const hal::DigitalOutputs& io) override;                      // RT-safe

  // Test access.
  const SimAxis& axis(hal::Axis a) const { return axes_[hal::index(a)]; }
  double shuttle_x() const { return shuttle_x_; }
  std::size_t effect_count() const;

 private:
  void apply_injected_faults(hal::Tick now) noexcept;
  void step_axis(SimAxis& ax, const hal::AxisCommand& cmd) noexcept;

  SimMachine m_;
  SceneSpec scene_;
  std::array<SimAxis, hal::kAxisCount> axes_{};
  std::array<double, 2> piston_{0.0, 0.0};  // 0 retracted … 1 extended
  std::array<bool, 2> valve_{false, false};
  double shuttle_x_ = 0.0;
  bool estop_ok_ = true;
  std::size_t next_fault_ = 0;
};

}  // namespace loom::sim_hal

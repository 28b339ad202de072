// Simulated devices. Drive power states change in one tick (a real drive takes a few; the CAN drive
// node models that). Positions only follow targets in Operation Enabled.
#include "loom/sim_hal/sim_world.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "loom/sim_hal/effects.hpp"

namespace loom::sim_hal {

const std::vector<std::string>& known_effects() {
  static const std::vector<std::string> names{kEffectIdeal, kEffectServoLag};
  return names;
}

SimWorld::SimWorld(const SimMachine& machine, const SceneSpec& scene) : m_(machine), scene_(scene) {
  for (const std::string& e : scene_.effects) {
    if (e == kEffectIdeal) continue;  // ideal tracking is the absence of axis effects
    if (e == kEffectServoLag) {
      const ServoLag lag = scene_.servo_lag.value_or(ServoLag{});
      for (auto& ax : axes_) ax.effects.push_back(make_servo_lag(lag));
      continue;
    }
    throw std::invalid_argument("unknown simulation effect '" + e + "'");
  }
  std::sort(scene_.faults.begin(), scene_.faults.end(),
            [](const FaultInjection& a, const FaultInjection& b) { return a.at_s < b.at_s; });
}

std::size_t SimWorld::effect_count() const {
  std::size_t n = 0;
  for (const auto& ax : axes_) n += ax.effects.size();
  return n;
}

void SimWorld::apply_injected_faults(hal::Tick now) noexcept {
  const double t = static_cast<double>(now) * m_.period_s;
  while (next_fault_ < scene_.faults.size() && scene_.faults[next_fault_].at_s <= t) {
    const FaultInjection& f = scene_.faults[next_fault_++];
    if (f.kind == InjectedFault::kEStop) {
      estop_ok_ = false;
    } else {
      SimAxis& ax = axes_[hal::index(f.axis)];
      ax.state = hal::DriveState::kFault;
      ax.fault_code = f.code;
    }
  }
}

void SimWorld::read_axes(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) {
  apply_injected_faults(now);
  for (std::size_t i = 0; i < hal::kAxisCount; ++i) {
    const SimAxis& s = axes_[i];
    hal::AxisFeedback& fb = axes[i];
    fb.state = s.state;
    fb.position = s.position;
    fb.velocity = s.velocity;
    fb.effort = 0.0;
    fb.fault = s.state == hal::DriveState::kFault;
    fb.fault_code = s.fault_code;
    fb.following_error = false;
    fb.refreshed = now;
  }
  link = hal::LinkStatus{};
}

void SimWorld::step_axis(SimAxis& ax, const hal::AxisCommand& cmd) noexcept {
  using hal::AxisRequest;
  using hal::DriveState;
  if (ax.state == DriveState::kFault) {
    if (cmd.request == AxisRequest::kFaultReset) {
      ax.state = DriveState::kSwitchOnDisabled;
      ax.fault_code = 0;
    }
  } else {
    switch (cmd.request) {
      case AxisRequest::kDisable: ax.state = DriveState::kSwitchOnDisabled; break;
      case AxisRequest::kEnable:
        if (ax.state != DriveState::kQuickStopActive) ax.state = DriveState::kOperationEnabled;
        break;
      case AxisRequest::kQuickStop:
        if (ax.state == DriveState::kOperationEnabled) ax.state = DriveState::kQuickStopActive;
        break;
      case AxisRequest::kFaultReset: break;
    }
  }
  const double before = ax.position;
  if (ax.state == DriveState::kOperationEnabled) {
    ax.target = cmd.target_position;
    double actual = ax.target;
    for (auto& e : ax.effects) actual = e->step(ax.target, ax.position, m_.period_s);
    ax.position = actual;
  }
  ax.velocity = (ax.position - before) / m_.period_s;
}

void SimWorld::write_axes(hal::Tick, const hal::AxisCommands& axes) {
  for (std::size_t i = 0; i < hal::kAxisCount; ++i) step_axis(axes_[i], axes[i]);
}

void SimWorld::read_io(hal::Tick now, const hal::AxisFeedbacks& axes, hal::DigitalInputs& io) {
  // The shuttle rides the carrier on the helix shaft: one lead of travel per shaft turn. Taken from the
  // HAL's fresh helix feedback, so this I/O node also works beside real (CAN) drives.
  const double helix = axes[hal::index(hal::Axis::kHelix)].position;
  shuttle_x_ = helix * m_.helix_lead_m / (2.0 * 3.14159265358979323846);
  io.piston_a_extended = piston_[0] >= 1.0;
  io.piston_a_retracted = piston_[0] <= 0.0;
  io.piston_b_extended = piston_[1] >= 1.0;
  io.piston_b_retracted = piston_[1] <= 0.0;
  io.shuttle_at_left = shuttle_x_ <= m_.selvedge_sensor_window_m;
  io.shuttle_at_right = shuttle_x_ >= m_.width_m - m_.selvedge_sensor_window_m;
  io.estop_ok = estop_ok_;
  io.refreshed = now;
}

void SimWorld::write_io(hal::Tick, const hal::DigitalOutputs& io) {
  valve_ = {io.piston_a_extend, io.piston_b_extend};
  const double rate = m_.period_s / m_.piston_travel_s;  // fraction of stroke per tick
  for (std::size_t i = 0; i < 2; ++i) {
    piston_[i] = std::clamp(piston_[i] + (valve_[i] ? rate : -rate), 0.0, 1.0);
  }
}

}  // namespace loom::sim_hal

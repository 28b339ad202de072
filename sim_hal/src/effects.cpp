// Axis effects.
#include "loom/sim_hal/effects.hpp"

#include <cmath>

namespace loom::sim_hal {
namespace {

class ServoLagEffect final : public AxisEffect {
 public:
  explicit ServoLagEffect(const ServoLag& p) : tau_(p.tau_s) {}
  double step(double target, double actual, double dt) noexcept override {
    // The decay factor depends only on dt; cache it so a tick costs one multiply-add.
    if (dt != dt_) {
      dt_ = dt;
      alpha_ = tau_ > 0.0 ? 1.0 - std::exp(-dt / tau_) : 1.0;
    }
    return actual + alpha_ * (target - actual);
  }

 private:
  double tau_;
  double dt_ = -1.0;
  double alpha_ = 1.0;
};

}  // namespace

std::unique_ptr<AxisEffect> make_servo_lag(const ServoLag& p) { return std::make_unique<ServoLagEffect>(p); }

}  // namespace loom::sim_hal

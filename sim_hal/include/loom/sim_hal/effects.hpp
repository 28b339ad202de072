// Factories for the axis effects a scene can name. Each is built only when named.
#pragma once

#include <memory>

#include "loom/sim_hal/scene.hpp"
#include "loom/sim_hal/sim_world.hpp"

namespace loom::sim_hal {

// First-order lag: the drive's position loop closes with time constant tau. Exact discretisation
// (not Euler), so any tick period is stable.
std::unique_ptr<AxisEffect> make_servo_lag(const ServoLag& p);

// The beat-up crank as a rigid-body linkage behind a torque-limited position loop (see Inertia).
// `friction` may be null. Configure-time only (builds the tabulated forward model).
std::unique_ptr<AxisEffect> make_crank_inertia(const SimMachine& machine, const Inertia& p,
                                               const JointFriction* friction);

}  // namespace loom::sim_hal

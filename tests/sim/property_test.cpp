// Property-based safety test: random scenes (effects, parameters, seeds) with a random injected fault at
// a random time. Whatever happens, the simulated machine's TRUE state (not what the controller believes)
// must never show an unsafe motion:
//   - the carriage moving while the beater is in the warp,
//   - the helix shaft (a pick) moving while the shed is not open,
//   - a heald frame moving while the shuttle is in the shed,
// and once a fault is latched no target may move. "Moving" means more than 1 µm in a tick (0.5 mm/s): a
// servo's exponential settling tail (nanometres) is not motion that can catch a warp thread.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>

#include "loom/firmware/config.hpp"
#include "loom/firmware/machine.hpp"

using namespace loom;

namespace {

firmware::Scene random_scene(std::mt19937_64& rng, std::string& description) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  firmware::Scene s;
  s.spec.seed = rng();
  s.spec.effects = {"ideal"};
  std::ostringstream d;
  if (u(rng) < 0.5) {
    s.spec.effects.push_back("servo_lag");
    s.spec.servo_lag = sim_hal::ServoLag{0.001 + 0.007 * u(rng)};
    d << "servo_lag(" << s.spec.servo_lag->tau_s << ") ";
  }
  if (u(rng) < 0.5) {
    s.spec.effects.push_back("pneumatics");
    s.spec.pneumatics = sim_hal::Pneumatics{0.01 + 0.08 * u(rng), 0.1 + 0.5 * u(rng)};
    d << "pneumatics ";
  }
  if (u(rng) < 0.4) {
    s.spec.effects.push_back("sensor_noise");
    s.spec.sensor_noise = sim_hal::SensorNoise{0.01 * u(rng)};
    d << "noise(" << s.spec.sensor_noise->flip_probability << ") ";
  }
  if (u(rng) < 0.3) {
    s.spec.effects.push_back("shuttle_slip");
    s.spec.shuttle_slip = sim_hal::ShuttleSlip{10.0 + 15.0 * u(rng), 0.4, 4.0};
    d << "slip(" << s.spec.shuttle_slip->carrier_force_n << " N) ";
  }
  const int kind = static_cast<int>(u(rng) * 5);  // 4 = no fault
  if (kind < 4) {
    sim_hal::FaultInjection f;
    f.at_s = 16.0 * u(rng);
    f.kind = static_cast<sim_hal::InjectedFault>(kind);
    f.axis = static_cast<hal::Axis>(static_cast<int>(u(rng) * 3));
    f.piston = u(rng) < 0.5 ? 0 : 1;
    f.sensor = static_cast<sim_hal::Sensor>(static_cast<int>(u(rng) * 6));
    f.stuck_value = u(rng) < 0.5;
    s.spec.faults.push_back(f);
    d << "fault " << kind << " at " << f.at_s << " s";
  }
  description = d.str();
  return s;
}

constexpr double kMotionEpsilon = 1e-6;  // m or rad per tick
bool moved(double a, double b) { return std::abs(a - b) > kMotionEpsilon; }

bool shed_open(const std::array<double, 2>& p) {
  return (p[0] >= 1.0 && p[1] <= 0.0) || (p[0] <= 0.0 && p[1] >= 1.0);
}

}  // namespace

TEST(SafetyProperties, NoUnsafeMotionOverRandomScenesAndFaults) {
  constexpr int kRuns = 2000;
  std::mt19937_64 rng(20261121);
  const firmware::LoomConfig cfg = firmware::default_loom_config();
  const double window = cfg.machine.selvedge_sensor_window_m;
  int faulted = 0, completed = 0;
  for (int run = 0; run < kRuns; ++run) {
    std::string what;
    const firmware::Scene scene = random_scene(rng, what);
    firmware::MachineOptions opt;
    opt.telemetry = false;
    opt.rows = 2;
    firmware::Machine m(cfg, scene, opt, {});
    m.sequencer().request_start();
    const auto& sim = m.sim();
    double carriage = sim.axis(hal::Axis::kCarriage).position, helix = sim.axis(hal::Axis::kHelix).position;
    std::array<double, 2> pistons = sim.pistons();
    hal::HalOutputs at_fault{};
    bool fault_seen = false;
    hal::Tick t = 0;
    for (; t < 40000 && !(m.sequencer().finished() && t > 0); ++t) {
      const bool warp_before = sim.beater_in_warp();
      const bool shed_before = shed_open(pistons);
      const double x = sim.shuttle_x();
      const bool shuttle_in_shed = x > window && x < cfg.machine.width_m - window;
      m.loop().cycle(t);
      const double c2 = sim.axis(hal::Axis::kCarriage).position, h2 = sim.axis(hal::Axis::kHelix).position;
      const auto p2 = sim.pistons();
      ASSERT_FALSE(moved(c2, carriage) && warp_before && sim.beater_in_warp())
          << "run " << run << " (" << what << "): carriage moved " << (c2 - carriage) << " m in the warp at tick " << t;
      ASSERT_FALSE(moved(h2, helix) && !(shed_before && shed_open(p2)))
          << "run " << run << " (" << what << "): pick motion without an open shed at tick " << t;
      ASSERT_FALSE((moved(p2[0], pistons[0]) || moved(p2[1], pistons[1])) && shuttle_in_shed)
          << "run " << run << " (" << what << "): heald frame moved over the shuttle at tick " << t;
      if (m.sequencer().state() == sequencer::State::kFault) {
        if (!fault_seen) at_fault = m.loop().outputs();
        fault_seen = true;
        for (std::size_t k = 0; k < hal::kAxisCount; ++k) {
          ASSERT_EQ(m.loop().outputs().axes[k].target_position, at_fault.axes[k].target_position)
              << "run " << run << " (" << what << "): target moved after the fault";
        }
      }
      carriage = c2, helix = h2, pistons = p2;
    }
    faulted += fault_seen;
    completed += m.sequencer().state() == sequencer::State::kDone;
  }
  // The sample must exercise both outcomes, or it proves little.
  EXPECT_GT(faulted, kRuns / 4);
  EXPECT_GT(completed, kRuns / 10);
  std::printf("safety properties: %d runs, %d ended in a fault, %d completed\n", kRuns, faulted, completed);
}

// Two faults that meet so that a single switch reports exactly what the healthy machine would: the
// shuttle slips off its carrier and the arrival switch sticks on just as the carrier arrives; a piston
// seizes mid-stroke and its end switch sticks on just when the stroke would have ended. No timing or
// plausibility check can see either on a loom with single-channel sensors — these tests show the harm
// there (the campaign's true-state checks: a frame closes on the shuttle, a pick runs through a half-open
// shed) and that the default loom, with a second switch beside each safety sensor, stops first with
// sensor_discrepancy naming the sensor.
#include <gtest/gtest.h>

#include "campaign.hpp"
#include "loom/config/config.hpp"
#include "loom/config/scene_config.hpp"
#include "loom/firmware/machine.hpp"

using namespace loom;

namespace {
firmware::LoomConfig single_channel_loom() {
  return firmware::load_loom_config(std::string(LOOM_SOURCE_DIR) + "/tests/sim/single_channel_loom.toml");
}

// Found by loom-safety (seed 562967357, run 63292) on the single-channel loom: with 13 N of carrier
// force the shuttle slips a few millimetres out of the left sensor's reach, and the right arrival
// switch sticks on at 2.649 s, as the carrier reaches the right selvedge.
constexpr const char* kSlipAndStuckArrival = R"(seed = 6025581053597301030
effects = ["ideal", "shuttle_slip"]
[shuttle_slip]
carrier_force_n = 13.23918172347039
shuttle_mass_kg = 0.4
race_friction_m_s2 = 4
[[fault]]
kind = "stuck_sensor"
at_s = 2.6492631222300811
sensor = "shuttle_at_right"
value = true
)";
}  // namespace

TEST(DoubleFaults, SlipWithTheArrivalSwitchStuckAtArrivalNeedsTheSecondSwitch) {
  const firmware::Scene scene = firmware::parse_scene(kSlipAndStuckArrival, "slip_and_stuck_arrival.toml");
  const safety::RunOutcome single = safety::run_one(single_channel_loom(), scene.spec, 2);
  EXPECT_TRUE(single.violated) << "the single-channel loom was expected to be fooled; first fault "
                               << single.first_fault;
  const safety::RunOutcome dual = safety::run_one(firmware::default_loom_config(), scene.spec, 2);
  EXPECT_FALSE(dual.violated) << dual.what;
  EXPECT_EQ(dual.first_fault, "sensor_discrepancy");
  EXPECT_EQ(dual.fault_sensor, "shuttle_at_right");
}

TEST(DoubleFaults, APistonSeizedMidStrokeWithItsEndSwitchStuckOnNeedsTheSecondSwitch) {
  // Where the stroke is: a healthy run of the same loom finds the first shed change after the arming
  // shed test that extends piston A, the tick A passes mid-stroke and the tick it would reach its end.
  const firmware::LoomConfig cfg = firmware::default_loom_config();
  firmware::Scene ideal;
  ideal.spec.effects = {sim_hal::kEffectIdeal};
  hal::Tick mid = -1, end = -1;
  {
    firmware::MachineOptions opt;
    opt.telemetry = false;
    opt.rows = 2;
    firmware::Machine m(cfg, ideal, opt, {});
    m.sequencer().request_start();
    for (hal::Tick t = 0; t < 60000 && end < 0; ++t) {
      m.loop().cycle(t);
      const double a = m.sim().pistons()[0];
      if (mid < 0 && m.sequencer().state() == sequencer::State::kShed && a > 0.5 && a < 0.6) mid = t;
      if (mid >= 0 && a >= 1.0) end = t;
    }
  }
  ASSERT_GT(mid, 0);
  ASSERT_GT(end, mid);
  const double period = cfg.run.period_s;
  sim_hal::SceneSpec spec = ideal.spec;
  sim_hal::FaultInjection seize;
  seize.kind = sim_hal::InjectedFault::kStuckPiston;
  seize.piston = 0;
  seize.at_s = static_cast<double>(mid) * period;
  sim_hal::FaultInjection stuck;
  stuck.kind = sim_hal::InjectedFault::kStuckSensor;
  stuck.sensor = sim_hal::Sensor::kPistonAExtended;
  stuck.stuck_value = true;
  stuck.at_s = static_cast<double>(end) * period;
  spec.faults = {seize, stuck};
  const safety::RunOutcome single = safety::run_one(single_channel_loom(), spec, 2);
  EXPECT_TRUE(single.violated) << "the single-channel loom was expected to be fooled; first fault "
                               << single.first_fault;
  const safety::RunOutcome dual = safety::run_one(cfg, spec, 2);
  EXPECT_FALSE(dual.violated) << dual.what;
  EXPECT_EQ(dual.first_fault, "sensor_discrepancy");
  EXPECT_EQ(dual.fault_sensor, "piston_a_extended");
}

// Proves the RT tick allocates nothing after start-up: global operator new is replaced in this test
// executable (tests/support) and counts calls made on the loop's thread while ControlLoop::cycle runs, over a
// whole weaving run (> 10,000 ticks) with telemetry publishing through real LCM on another thread.
#include <gtest/gtest.h>

#include <string>

#include "alloc_counter.hpp"
#include "loom/config/config.hpp"
#include "loom/config/scene_config.hpp"
#include "loom/firmware/machine.hpp"

using namespace loom;

namespace {
std::size_t allocations_while_weaving(const firmware::Scene& scene, std::uint32_t rows, hal::Tick* ticks_out,
                                      firmware::LoomConfig cfg = firmware::default_loom_config(),
                                      sequencer::State end = sequencer::State::kDone) {
  cfg.telemetry.lcm_url = "udpm://239.255.76.67:7791?ttl=0";
  firmware::MachineOptions opt;
  opt.rows = rows;
  opt.lossless_telemetry = false;  // the real-time path: drop rather than wait
  firmware::Machine m(cfg, scene, opt, {});
  m.sequencer().request_start();
  hal::Tick t = 0;
  std::size_t total = 0;
  hal::Tick finished_at = -1;  // then 300 ticks more: a fault's diagnosis window, the drives' own reports
  for (; t < 200000; ++t) {
    if (m.sequencer().finished() && finished_at < 0) finished_at = t;
    if (finished_at >= 0 && t - finished_at > 300) break;
    test::reset_allocations();
    test::count_allocations(true);
    m.loop().cycle(t);
    test::count_allocations(false);
    total += test::allocations();
  }
  *ticks_out = t;
  EXPECT_EQ(m.sequencer().state(), end) << sequencer::fault_name(m.sequencer().first_fault());
  return total;
}
}  // namespace

TEST(TickAllocations, CounterSeesAnAllocation) {
  // The counter itself must be able to fail.
  test::reset_allocations();
  test::count_allocations(true);
  // A direct call: new-expressions may legally be elided by the optimiser, this may not.
  void* p = ::operator new(16);
  test::count_allocations(false);
  ::operator delete(p);
  EXPECT_EQ(test::allocations(), 1u);
}

TEST(TickAllocations, WeavingRunAllocatesNothingPerTick) {
  hal::Tick ticks = 0;
  EXPECT_EQ(allocations_while_weaving(firmware::default_scene(), 3, &ticks), 0u);
  EXPECT_GE(ticks, 10000);
}

TEST(TickAllocations, ServoLagSceneAllocatesNothingPerTick) {
  firmware::Scene scene = firmware::default_scene();
  scene.spec.effects = {"servo_lag"};
  scene.spec.servo_lag = sim_hal::ServoLag{0.004};
  hal::Tick ticks = 0;
  EXPECT_EQ(allocations_while_weaving(scene, 2, &ticks), 0u);
}

// The beat regulator at work (issue 31): warp_tension makes every beat's force differ, so the regulator
// learns from each measured beat and the sweep's clock changes the crank's speed between beats.
TEST(TickAllocations, RegulatedBeatsAllocateNothingPerTick) {
  const std::string scenes = std::string(LOOM_SOURCE_DIR) + "/sim_hal/scenes/";
  hal::Tick ticks = 0;
  EXPECT_EQ(allocations_while_weaving(firmware::load_scene(scenes + "warp_tension.toml"), 3, &ticks), 0u);
  EXPECT_GE(ticks, 10000);
}

// The ticks with the most to say: the sequencer's event list (faults latched and refined, the knotting
// heads' progress and requests of the weaver) forwarded to telemetry, and the drives' own fault reports.
TEST(TickAllocations, EventfulScenesAllocateNothingPerTick) {
  const std::string scenes = std::string(LOOM_SOURCE_DIR) + "/sim_hal/scenes/";
  hal::Tick ticks = 0;
  EXPECT_EQ(allocations_while_weaving(firmware::load_scene(scenes + "heartbeat_loss.toml"), 3, &ticks,
                                      firmware::default_loom_config(), sequencer::State::kFault),
            0u);
  EXPECT_EQ(allocations_while_weaving(firmware::load_scene(scenes + "knotting_faults.toml"), 2, &ticks,
                                      firmware::load_loom_config(std::string(LOOM_SOURCE_DIR) +
                                                                 "/firmware/config/knotting_loom.toml"),
                                      sequencer::State::kKnotting),  // no weaver here: the heads wait for one
            0u);
}

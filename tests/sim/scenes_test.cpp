// The shipped scenes, run in-process on the firmware's own machine assembly: each fault scene ends in
// a safe stop with the expected first fault (every axis quick-stopped and no target moving afterwards,
// counters kept); the default scene beats every point of the width with 80–100 N.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "loom/config/config.hpp"
#include "loom/firmware/machine.hpp"

using namespace loom;
using sequencer::Fault;
using sequencer::State;

namespace {
struct Outcome {
  bool power_cut = false;
  State state;
  Fault first_fault;
  sequencer::Counters counters;
  std::vector<sequencer::RowStats> rows;
  bool moved_after_fault = false;
};

enum class Sensing { kDualChannel, kSingleChannel };

// `period_ms` 0: the default loop period. kSingleChannel: the default loom without the safety sensors'
// second switches (io.<sensor>_2_bit = -1), so only the sequencer's plausibility checks stand guard.
Outcome run_scene(const std::string& name, std::uint32_t rows, double period_ms = 0.0,
                  Sensing sensing = Sensing::kDualChannel) {
  const firmware::Scene scene =
      firmware::load_scene(std::string(LOOM_SOURCE_DIR) + "/sim_hal/scenes/" + name + ".toml");
  firmware::MachineOptions opt;
  opt.telemetry = false;
  opt.rows = rows;
  firmware::LoomConfig cfg = firmware::default_loom_config();
  if (period_ms > 0.0) cfg.run.period_s = period_ms * 1e-3;
  if (sensing == Sensing::kSingleChannel) {
    for (auto& b : cfg.io.wiring.second) b.bit = -1;
  }
  if (period_ms > 0.0 || sensing == Sensing::kSingleChannel)
    firmware::rederive_and_check(cfg, "test variant");
  firmware::Machine m(cfg, scene, opt, {});
  Outcome o;
  m.sim().on_power_cut([](void* cut) { *static_cast<bool*>(cut) = true; }, &o.power_cut);
  m.sequencer().request_start();
  std::uint32_t seen = 0;
  hal::Tick t = 0;
  for (; t < 400000 && !m.sequencer().finished() && !o.power_cut; ++t) {
    m.loop().cycle(t);
    if (m.sequencer().counters().rows != seen) {
      seen = m.sequencer().counters().rows;
      o.rows.push_back(m.sequencer().last_row());
    }
  }
  o.state = m.sequencer().state();
  if (o.power_cut) {
    // The machine lost its power: whatever the controller (were it alive) commands, nothing moves.
    std::array<double, hal::kCoreAxisCount> at_cut{};
    for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k)
      at_cut[k] = m.sim().axis(static_cast<hal::CoreAxis>(k)).position;
    for (int i = 0; i < 500; ++i, ++t) {
      m.loop().cycle(t);
      for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k) {
        if (m.sim().axis(static_cast<hal::CoreAxis>(k)).position != at_cut[k]) o.moved_after_fault = true;
      }
    }
    return o;
  }
  // After the end: keep ticking; in a fault nothing may move any more.
  const hal::HalOutputs at_end = m.loop().outputs();
  for (int i = 0; i < 500; ++i, ++t) {
    m.loop().cycle(t);
    for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k) {
      if (m.loop().outputs().axes[k].target_position != at_end.axes[k].target_position)
        o.moved_after_fault = true;
      if (m.sequencer().state() == State::kFault &&
          m.loop().outputs().axes[k].request != hal::AxisRequest::kQuickStop) {
        o.moved_after_fault = true;
      }
    }
  }
  o.state = m.sequencer().state();
  o.first_fault = m.sequencer().first_fault();
  o.counters = m.sequencer().counters();
  return o;
}
}  // namespace

TEST(Scenes, DefaultSceneBeatsEveryPointOfTheWidthWithin80To100N) {
  const Outcome o = run_scene("default", 3);
  ASSERT_EQ(o.state, State::kDone) << sequencer::fault_name(o.first_fault);
  ASSERT_EQ(o.rows.size(), 3u);
  for (const auto& r : o.rows) {
    ASSERT_TRUE(r.force_measured);
    EXPECT_EQ(r.beats, 15);
    for (int k = 0; k < r.beats; ++k) {
      const auto& b = r.beat[static_cast<std::size_t>(k)];
      EXPECT_GE(b.peak_force_n, 80.0f) << "row " << r.row << " beat " << k;
      EXPECT_LE(b.peak_force_n, 100.0f) << "row " << r.row << " beat " << k;
    }
    // Beats cover the width: first at the left selvedge, last at width - beater width (or mirrored).
    const float first = r.beat[0].x_m, last = r.beat[static_cast<std::size_t>(r.beats - 1)].x_m;
    EXPECT_NEAR(std::min(first, last), 0.0, 1e-6);
    EXPECT_NEAR(std::max(first, last), 1.1, 1e-6);
  }
  EXPECT_LT(static_cast<double>(o.rows[0].total_ticks) * 0.002,
            300.0 / 20.0);  // ≥ 20× faster than weaving by hand
}

// The shuttle's follow checks compare sensor edges with the carrier's position; both are samples, so the
// windows must scale with the carrier's travel per tick. At loop periods from the default to the longest
// the config allows (shorter ones are refused by the CAN bus-load budget of the default machine, longer
// ones by the beat: at most 10 deg of crank per tick at the fastest beat the regulator may ask for, 9.44 ms
// for the default recipe), the default scene
// weaves without a false shuttle fault, and a slipping shuttle is still caught.
class LoopPeriods : public ::testing::TestWithParam<double> {};

TEST_P(LoopPeriods, ShuttleChecksHoldAtThisPeriod) {
  const Outcome ok = run_scene("default", 2, GetParam());
  EXPECT_EQ(ok.state, State::kDone) << GetParam() << " ms: " << sequencer::fault_name(ok.first_fault);
  EXPECT_EQ(ok.counters.rows, 2u);
  const Outcome slip = run_scene("shuttle_slip", 5, GetParam());
  EXPECT_EQ(slip.state, State::kFault) << GetParam() << " ms";
  EXPECT_TRUE(slip.first_fault == Fault::kShuttleSlipped || slip.first_fault == Fault::kShuttleNotArrived)
      << GetParam() << " ms: " << sequencer::fault_name(slip.first_fault);
  EXPECT_FALSE(slip.moved_after_fault);
}

INSTANTIATE_TEST_SUITE_P(AllowedRange, LoopPeriods, ::testing::Values(2.0, 5.0, 9.0, 9.4),
                         [](const auto& period) {
                           return std::to_string(static_cast<int>(period.param * 100)) + "0us";
                         });

// Each fault scene on the default loom (dual-channel safety sensors) and on the same loom with single-
// channel sensors: a stuck switch is a sensor_discrepancy with a second switch beside it, and is caught
// by the plausibility checks (its own named fault) without one.
struct FaultCase {
  const char* scene;
  Fault expected;
  Fault single_channel;
};

class FaultScenes : public ::testing::TestWithParam<FaultCase> {};

TEST_P(FaultScenes, EndInASafeStopWithTheExpectedFirstFault) {
  for (const Sensing sensing : {Sensing::kDualChannel, Sensing::kSingleChannel}) {
    const bool dual = sensing == Sensing::kDualChannel;
    const Outcome o = run_scene(GetParam().scene, 5, 0.0, sensing);
    const Fault expected = dual ? GetParam().expected : GetParam().single_channel;
    const char* loom = dual ? "dual-channel sensors" : "single-channel sensors";
    EXPECT_EQ(o.state, State::kFault) << loom;
    EXPECT_EQ(o.first_fault, expected) << loom << ": " << sequencer::fault_name(o.first_fault);
    EXPECT_FALSE(o.moved_after_fault) << loom;
    EXPECT_LT(o.counters.rows, 5u) << loom;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Shipped, FaultScenes,
    ::testing::Values(FaultCase{"drive_fault", Fault::kDriveFault, Fault::kDriveFault},
                      FaultCase{"stuck_piston", Fault::kShedNotReleased, Fault::kShedNotReleased},
                      FaultCase{"shuttle_slip", Fault::kShuttleSlipped, Fault::kShuttleSlipped},
                      FaultCase{"stuck_sensor", Fault::kSensorDiscrepancy, Fault::kShuttleLost},
                      FaultCase{"estop", Fault::kEStop, Fault::kEStop},
                      FaultCase{"stuck_end_sensor", Fault::kSensorDiscrepancy, Fault::kShedNotReleased},
                      FaultCase{"can_frame_loss", Fault::kStaleFeedback, Fault::kStaleFeedback},
                      FaultCase{"can_latency", Fault::kStaleFeedback, Fault::kStaleFeedback},
                      FaultCase{"bus_off", Fault::kLinkFault, Fault::kLinkFault},
                      FaultCase{"heartbeat_loss", Fault::kHeartbeatLost, Fault::kHeartbeatLost},
                      FaultCase{"emcy", Fault::kDriveEmcy, Fault::kDriveEmcy},
                      FaultCase{"intermittent_sensor", Fault::kSensorDiscrepancy, Fault::kShedSensorConflict},
                      FaultCase{"encoder_glitch", Fault::kEncoderJump, Fault::kEncoderJump},
                      FaultCase{"load_cell", Fault::kLoadCellFault, Fault::kLoadCellFault},
                      FaultCase{"air_loss", Fault::kAirLost, Fault::kAirLost},
                      FaultCase{"loop_stall", Fault::kLoopStall, Fault::kLoopStall}),
    [](const auto& param_info) { return std::string(param_info.param.scene); });

TEST(Scenes, SensorNoiseIsDebouncedAwayAndTheRunIsDeterministic) {
  const Outcome a = run_scene("sensor_noise", 2), b = run_scene("sensor_noise", 2);
  EXPECT_EQ(a.state, State::kDone) << sequencer::fault_name(a.first_fault);
  ASSERT_EQ(a.rows.size(), b.rows.size());
  for (std::size_t i = 0; i < a.rows.size(); ++i) EXPECT_EQ(a.rows[i].total_ticks, b.rows[i].total_ticks);
}

TEST(Scenes, RigidBodyCrankStillBeatsWithinTargetAndTracksItsServo) {
  // With the linkage's own dynamics behind a torque-limited servo the beat force is no longer the
  // kinematic m·a of the command: it must still land in 80–100 N, and no faults may arise.
  const Outcome o = run_scene("dynamics", 2);
  ASSERT_EQ(o.state, State::kDone) << sequencer::fault_name(o.first_fault);
  for (const auto& r : o.rows) {
    ASSERT_TRUE(r.force_measured);
    EXPECT_GE(r.force_min_n, 80.0);
    EXPECT_LE(r.force_max_n, 100.0);
  }
}

TEST(Scenes, PowerCutEndsTheRunAtItsTickWithNothingMovingAfterwards) {
  const Outcome o = run_scene("power_cut", 5);
  EXPECT_TRUE(o.power_cut);
  EXPECT_EQ(o.state, State::kPick);  // tick 800 is mid-pick of the first row
  EXPECT_FALSE(o.moved_after_fault);
}

TEST(Scenes, EveryShippedSceneParses) {
  for (const auto& e :
       std::filesystem::directory_iterator(std::string(LOOM_SOURCE_DIR) + "/sim_hal/scenes")) {
    EXPECT_NO_THROW(firmware::load_scene(e.path().string())) << e.path();
  }
}

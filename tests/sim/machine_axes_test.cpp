// A machine that grows: a loom with an axis beyond the core three weaves in simulation, holds and
// supervises the added axis like every other, and a fault on it stops the whole loom.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "loom/config/config.hpp"
#include "loom/firmware/machine.hpp"

using namespace loom;

namespace {
constexpr std::size_t kTakeUp = 3;  // slot of the added axis (after the core three)

firmware::LoomConfig four_axis_loom() {
  return firmware::load_loom_config(std::string(LOOM_SOURCE_DIR) + "/tests/sim/four_axis_loom.toml");
}

firmware::Scene scene_with(const std::string& faults) {
  return firmware::parse_scene("name = \"t\"\nseed = 1\neffects = [\"ideal\"]\n" + faults, "t.toml");
}

struct Outcome {
  sequencer::State state;
  sequencer::Fault fault;
  int fault_axis;
  std::uint32_t rows;
  bool take_up_enabled_while_weaving = false;
  double take_up_travel = 0.0;  // largest distance of the take-up axis from where it was armed
  bool every_axis_quick_stopped = false;
};

Outcome run(const firmware::LoomConfig& cfg, const firmware::Scene& scene, std::uint32_t rows) {
  firmware::MachineOptions opt;
  opt.telemetry = false;
  opt.rows = rows;
  firmware::Machine m(cfg, scene, opt, {});
  m.sequencer().request_start();
  Outcome r{};
  double armed_at = 0.0;
  bool armed = false;
  for (hal::Tick t = 0; t < 200000 && !m.sequencer().finished(); ++t) {
    m.loop().cycle(t);
    const hal::AxisFeedback& fb = m.loop().inputs().axes[kTakeUp];
    if (m.sequencer().state() == sequencer::State::kPick) {
      r.take_up_enabled_while_weaving = fb.state == hal::DriveState::kOperationEnabled;
      if (!armed) armed_at = fb.position, armed = true;
    }
    if (armed) r.take_up_travel = std::max(r.take_up_travel, std::abs(fb.position - armed_at));
  }
  r.state = m.sequencer().state();
  r.fault = m.sequencer().first_fault();
  r.fault_axis = m.sequencer().fault_axis();
  r.rows = m.sequencer().counters().rows;
  if (r.state == sequencer::State::kFault) {
    // One more tick: what the loop commands every axis while the fault is latched.
    m.loop().cycle(200001);
    r.every_axis_quick_stopped = true;
    for (std::size_t i = 0; i < cfg.axes.size(); ++i) {
      r.every_axis_quick_stopped =
          r.every_axis_quick_stopped && m.loop().outputs().axes[i].request == hal::AxisRequest::kQuickStop;
    }
  }
  return r;
}
}  // namespace

TEST(MachineAxes, AFourAxisLoomWeavesWithItsAddedAxisEnabledAndHeld) {
  const firmware::LoomConfig cfg = four_axis_loom();
  ASSERT_EQ(cfg.axes.size(), 4u);
  ASSERT_EQ(cfg.axes[kTakeUp].name, "take_up");
  const Outcome r = run(cfg, scene_with(""), 2);
  EXPECT_EQ(r.state, sequencer::State::kDone);
  EXPECT_EQ(r.rows, 2u);
  EXPECT_TRUE(r.take_up_enabled_while_weaving);
  EXPECT_LT(r.take_up_travel, 1e-12);  // nothing commands it yet: it holds where it was armed
}

TEST(MachineAxes, AFaultOnTheAddedAxisStopsTheWholeLoom) {
  const firmware::LoomConfig cfg = four_axis_loom();
  const Outcome r = run(
      cfg, scene_with("[[fault]]\nat_s = 3.0\nkind = \"drive_fault\"\naxis = \"take_up\"\ncode = 0x7500\n"),
      3);
  EXPECT_EQ(r.state, sequencer::State::kFault);
  EXPECT_EQ(r.fault, sequencer::Fault::kDriveFault);
  EXPECT_EQ(r.fault_axis, static_cast<int>(kTakeUp));
  EXPECT_TRUE(r.every_axis_quick_stopped);
  EXPECT_EQ(r.rows, 0u);
}

TEST(MachineAxes, AnEncoderJumpOnTheAddedAxisIsCaughtByItsOwnSpeedLimit) {
  const firmware::LoomConfig cfg = four_axis_loom();
  // 2 rad/s top speed: 0.05 rad in one 2 ms tick is 12x what the roller can do.
  const Outcome r = run(
      cfg, scene_with("[[fault]]\nat_s = 3.0\nkind = \"encoder_glitch\"\naxis = \"take_up\"\njump = 0.05\n"),
      3);
  EXPECT_EQ(r.fault, sequencer::Fault::kEncoderJump);
  EXPECT_EQ(r.fault_axis, static_cast<int>(kTakeUp));
}

TEST(MachineAxes, ASceneNamingAnAxisTheLoomLacksIsRefusedAtItsLine) {
  const firmware::Scene s = scene_with("[[fault]]\nat_s = 3.0\nkind = \"drive_fault\"\naxis = \"take_up\"\n");
  try {
    (void)firmware::check_scene_fits(s, firmware::default_loom_config());
    FAIL() << "accepted a fault on an axis the default loom does not have";
  } catch (const firmware::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("t.toml:4:1: fault[0].axis = \"take_up\": the loom"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("its axes: beat_crank, carriage, helix"), std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW((void)firmware::check_scene_fits(s, four_axis_loom()));
}

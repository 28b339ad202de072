// The simulated devices: an effect that is not named is not built; each effect does what its physics
// says (checked against closed forms where there is one); the machine state survives in its file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "loom/motion/angles.hpp"
#include "loom/sim_hal/sim_world.hpp"

using namespace loom;
using namespace loom::sim_hal;

namespace {
SceneSpec scene(std::vector<std::string> effects) {
  SceneSpec s;
  s.effects = std::move(effects);
  return s;
}

// Drives one axis to `target` every tick for `ticks` ticks with the drive enabled.
void drive(SimWorld& w, hal::CoreAxis axis, double target, int ticks, hal::Tick& now) {
  hal::AxisCommands cmd{};
  for (auto& c : cmd) c.request = hal::AxisRequest::kEnable;
  hal::AxisFeedbacks fb{};
  hal::LinkStatus link{};
  for (int i = 0; i < ticks; ++i, ++now) {
    w.read_axes(now, fb, link);
    for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k) cmd[k].target_position = fb[k].position;
    cmd[hal::index(axis)].target_position = target;
    w.write_axes(now, cmd);
  }
}
}  // namespace

TEST(SimWorld, UnnamedEffectsAreNotBuilt) {
  const SimMachine m;
  EXPECT_EQ(SimWorld(m, scene({"ideal"})).effect_count(), 0u);
  EXPECT_EQ(SimWorld(m, scene({"servo_lag"})).effect_count(), 3u);  // one per axis
  EXPECT_EQ(SimWorld(m, scene({"ideal", "pneumatics"})).effect_count(), 1u);
  EXPECT_EQ(SimWorld(m, scene({"inertia", "joint_friction"})).effect_count(), 2u);
  EXPECT_THROW(SimWorld(m, scene({"joint_friction"})), std::invalid_argument);
  EXPECT_THROW(SimWorld(m, scene({"warp_drive"})), std::invalid_argument);
}

TEST(SimWorld, ServoLagIsTheExactFirstOrderStepResponse) {
  SceneSpec s = scene({"servo_lag"});
  s.servo_lag = ServoLag{0.01};
  SimWorld w(SimMachine{}, s);
  hal::Tick now = 0;
  drive(w, hal::CoreAxis::kCarriage, 0.0, 1, now);  // enable
  drive(w, hal::CoreAxis::kCarriage, 0.1, 10, now);  // step of 0.1 m held 10 ticks = 20 ms = 2 τ
  EXPECT_NEAR(w.axis(hal::CoreAxis::kCarriage).position, 0.1 * (1.0 - std::exp(-2.0)), 1e-12);
}

TEST(SimWorld, PneumaticsDelayTheStrokeByFillAndBreakaway) {
  const SimMachine m;  // 0.25 s stroke at full pressure
  const auto ticks_to_extend = [&](const SceneSpec& s) {
    SimWorld w(m, s);
    hal::DigitalOutputs out{};
    out.piston_a_extend = true;
    hal::AxisFeedbacks fb{};
    hal::DigitalInputs in{};
    for (int t = 0; t < 2000; ++t) {
      w.write_io(t, out);
      w.read_io(t, fb, in);
      if (in.piston_a_extended) return t + 1;
    }
    return -1;
  };
  const int plain = ticks_to_extend(scene({"ideal"}));
  SceneSpec pneu = scene({"pneumatics"});
  pneu.pneumatics = Pneumatics{0.04, 0.3};
  const int filled = ticks_to_extend(pneu);
  EXPECT_EQ(plain, 125);  // 0.25 s / 2 ms
  // Breakaway: p = 1 − e^{−t/τ} reaches 0.3 after τ·ln(1/0.7) ≈ 14 ms, and the margin then slows it.
  EXPECT_GT(filled, plain + 7);
}

TEST(SimWorld, ShuttleSlipsOnlyAboveTheCouplingForce) {
  const auto pick = [](double force_n) {
    SceneSpec s = scene({"ideal", "shuttle_slip"});
    s.shuttle_slip = ShuttleSlip{force_n, 0.4, 4.0};
    SimWorld w(SimMachine{}, s);
    hal::AxisFeedbacks fb{};
    hal::DigitalInputs io{};
    // Carrier acceleration 50 m/s² (lead 0.1 m): needs 0.4 × 50 = 20 N of coupling.
    const double a_lin = 50.0, lead = 0.1, dt = 0.002;
    for (int t = 0; t < 100; ++t) {
      const double time = t * dt;
      fb[hal::index(hal::CoreAxis::kHelix)].position = 0.5 * a_lin * time * time / lead * motion::kTwoPi;
      w.read_io(t, fb, io);
    }
    return w.shuttle_coupled();
  };
  EXPECT_TRUE(pick(25.0));
  EXPECT_FALSE(pick(15.0));
}

TEST(SimWorld, SensorNoiseIsDeterministicForASeed) {
  const auto flips = [](std::uint64_t seed) {
    SceneSpec s = scene({"ideal", "sensor_noise"});
    s.seed = seed;
    s.sensor_noise = SensorNoise{0.05};
    SimWorld w(SimMachine{}, s);
    hal::AxisFeedbacks fb{};
    hal::DigitalInputs io{};
    std::vector<bool> left;
    for (int t = 0; t < 400; ++t) {
      w.read_io(t, fb, io);
      left.push_back(io.shuttle_at_left);
    }
    return left;
  };
  EXPECT_EQ(flips(3), flips(3));
  EXPECT_NE(flips(3), flips(4));
  const auto f = flips(3);
  const auto bounces = std::count(f.begin(), f.end(), false);
  EXPECT_GT(bounces, 5);   // p = 0.05 over 400 ticks: about 20
  EXPECT_LT(bounces, 45);
}

TEST(SimWorld, MachineStateSurvivesInItsFile) {
  const auto path = (std::filesystem::temp_directory_path() / "loom_sim_state_test.bin").string();
  std::filesystem::remove(path);
  hal::Tick now = 0;
  {
    SimStateFile file(path);
    SimWorld w(SimMachine{}, scene({"ideal"}));
    w.attach_state_file(file);
    drive(w, hal::CoreAxis::kHelix, 3.0, 5, now);
    hal::AxisFeedbacks fb{};
    hal::LinkStatus link{};
    hal::DigitalInputs io{};
    w.read_axes(now, fb, link);
    w.read_io(now, fb, io);  // the shuttle follows the helix as the I/O node sees it
    hal::DigitalOutputs out{};
    out.piston_b_extend = true;
    for (int t = 0; t < 200; ++t) w.write_io(t, out);
  }
  SimStateFile again(path);
  SimWorld w2(SimMachine{}, scene({"ideal"}));
  w2.attach_state_file(again);
  EXPECT_DOUBLE_EQ(w2.axis(hal::CoreAxis::kHelix).position, 3.0);
  EXPECT_DOUBLE_EQ(w2.pistons()[1], 1.0);
  EXPECT_NEAR(w2.shuttle_x(), 3.0 * 0.1 / motion::kTwoPi, 1e-15);
}

// beat_contact solves the linkage only inside a bracket of crank phases found at configure time. The
// bracket must hold every phase at which the exact solve (motion::BeatUp, not the simulator) puts the tip
// within the contact depth of the fell: swept finely over the whole warp window and around its ends.
TEST(SimWorld, BeatContactBracketHoldsEveryPhaseInContact) {
  const SimMachine m;
  const motion::BeatUp exact(m.beatup);
  const motion::WarpWindow& w = exact.warp();
  for (const double depth : {0.005, 1e-9, 0.02, 0.049, 0.2}) {
    SceneSpec s = scene({"beat_contact"});
    s.beat_contact = BeatContact{2.5, depth};
    const SimWorld world(m, s);
    const auto [from, to] = world.contact_bracket();
    ASSERT_LE(w.enter, from);
    ASSERT_LE(from, to);
    ASSERT_LE(to, w.exit);
    const auto check = [&](double phase) {  // (outside the warp window the simulator never solves)
      if (phase > w.enter && phase < w.exit && exact.at(phase).from_fell_m <= depth) {
        ASSERT_TRUE(phase >= from && phase <= to) << "depth " << depth << " phase " << phase;
      }
    };
    constexpr int kSweep = 200000;
    for (int i = 0; i <= kSweep; ++i) check(w.enter + (w.exit - w.enter) * i / kSweep);
    for (const double end : {from, to}) {
      for (int i = -2000; i <= 2000; ++i) check(end + i * 1e-9);
    }
    // At 5 mm of a 50 mm warp depth the bracket is a small part of the window (else it saves nothing).
    if (depth == 0.005) {
      EXPECT_LT(to - from, 0.5 * (w.exit - w.enter));
    }
    if (depth >= m.beatup.warp_depth_m) {
      EXPECT_TRUE(from == w.enter && to == w.exit);
    }
  }
}

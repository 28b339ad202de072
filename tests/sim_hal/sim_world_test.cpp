// The simulated devices: an effect that is not named is not built; each effect does what its physics
// says (checked against closed forms where there is one); the machine state survives in its file.
#include "loom/sim_hal/sim_world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "loom/motion/angles.hpp"

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
  EXPECT_EQ(SimWorld(m, scene({"ideal", "beat_contact"})).effect_count(), 1u);
  EXPECT_EQ(SimWorld(m, scene({"ideal", "beat_contact", "warp_tension"})).effect_count(), 2u);
  EXPECT_EQ(SimWorld(m, scene({"ideal", "beat_contact"})).warp_tension(), nullptr);
  EXPECT_THROW(SimWorld(m, scene({"ideal", "warp_tension"})),
               std::invalid_argument);  // it scales beat_contact's force
}

TEST(SimWorld, ServoLagIsTheExactFirstOrderStepResponse) {
  SceneSpec s = scene({"servo_lag"});
  s.servo_lag = ServoLag{0.01};
  SimWorld w(SimMachine{}, s);
  hal::Tick now = 0;
  drive(w, hal::CoreAxis::kCarriage, 0.0, 1, now);   // enable
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
  EXPECT_GT(bounces, 5);  // p = 0.05 over 400 ticks: about 20
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

namespace {
// The peak load-cell force of each crank turn, the crank turning at `omega` from park and the carriage
// stepping `pitch` once per turn while the beater is clear (at park).
std::vector<double> beat_peaks(const SceneSpec& s, double omega, double pitch, int turns) {
  const SimMachine m;
  SimWorld w(m, s);
  hal::AxisCommands cmd{};
  for (auto& c : cmd) c.request = hal::AxisRequest::kEnable;
  hal::AxisFeedbacks fb{};
  hal::LinkStatus link{};
  hal::DigitalInputs io{};
  hal::AnalogInputs analog{};
  const int per_turn = static_cast<int>(std::lround(motion::kTwoPi / (omega * m.period_s)));
  std::vector<double> peaks(static_cast<std::size_t>(turns), 0.0);
  for (hal::Tick t = 0; t < static_cast<hal::Tick>(per_turn) * turns; ++t) {
    const auto turn = static_cast<std::size_t>(t / per_turn);
    cmd[hal::index(hal::CoreAxis::kBeatCrank)].target_position = omega * m.period_s * static_cast<double>(t);
    cmd[hal::index(hal::CoreAxis::kCarriage)].target_position = pitch * static_cast<double>(turn);
    w.write_axes(t, cmd);
    w.read_axes(t, fb, link);
    w.read_io(t, fb, io);
    w.read_analog(t, analog);
    peaks[turn] = std::max(peaks[turn], analog.beat_force_n);
  }
  return peaks;
}
}  // namespace

// warp_tension scales each beat's contact force by the profile across the width where the comb beats (its
// middle: carriage + half the beater) and the drift over the carriage travel swept so far (a row per
// width − beater width), checked against the closed forms written out here.
TEST(SimWorld, WarpTensionScalesTheBeatByProfileAndDrift) {
  const SimMachine m;  // 1.2 m wide, 0.10 m comb: 1.1 m of travel per row
  const double pitch = 1.1 / 14.0, omega = 16.0;
  SceneSpec plain = scene({"ideal", "beat_contact"});
  SceneSpec taut = scene({"ideal", "beat_contact", "warp_tension"});
  taut.warp_tension = WarpTension{.centre_ratio = 0.8, .points = {}, .drift_per_row = 0.05, .noise = 0.0};
  const int turns = 29;  // two rows' worth of carriage travel (14 steps each), then one more beat
  const std::vector<double> f0 = beat_peaks(plain, omega, pitch, turns);
  const std::vector<double> f1 = beat_peaks(taut, omega, pitch, turns);
  for (int j = 0; j < turns; ++j) {
    ASSERT_GT(f0[static_cast<std::size_t>(j)], 50.0) << "turn " << j;  // every turn beats
    const double x = pitch * j;                                        // one-way: the carriage keeps going
    const double u = std::min(1.0, (x + 0.05) / 1.2);
    const double profile = 0.8 + 0.2 * ((2.0 * u - 1.0) * (2.0 * u - 1.0));  // 1 at the selvedges, 0.8 mid
    const double rows = x / 1.1;
    EXPECT_NEAR(f1[static_cast<std::size_t>(j)] / f0[static_cast<std::size_t>(j)],
                profile * (1.0 + 0.05 * rows), 1e-9)
        << "turn " << j;
  }
}

TEST(SimWorld, WarpTensionPointsAreLinearBetweenEquallySpacedPoints) {
  SimMachine m;
  WarpTension p{.centre_ratio = 1.0, .points = {1.1, 0.9, 1.0}, .drift_per_row = 0.0, .noise = 0.0};
  const WarpTensionModel model(p, m, 1);
  EXPECT_DOUBLE_EQ(model.profile(0.0), 1.1);
  EXPECT_DOUBLE_EQ(model.profile(0.25), 1.0);
  EXPECT_DOUBLE_EQ(model.profile(0.5), 0.9);
  EXPECT_DOUBLE_EQ(model.profile(0.75), 0.95);
  EXPECT_DOUBLE_EQ(model.profile(1.0), 1.0);
  EXPECT_DOUBLE_EQ(model.profile(2.0), 1.0);  // beyond a selvedge: the selvedge's
  p.points = {1.0};
  EXPECT_THROW(WarpTensionModel(p, m, 1), std::invalid_argument);
  m.beater_width_m = m.width_m;
  EXPECT_THROW(WarpTensionModel(WarpTension{}, m, 1), std::invalid_argument);
}

// Each beat draws its own variation once (a contact of several ticks keeps it): over many beats its mean
// is 1 and its standard deviation `noise`; the same seed replays it. Seed: LOOM_TEST_SEED (printed).
TEST(SimWorld, WarpTensionNoiseHasItsDeviationAndReplays) {
  const char* env = std::getenv("LOOM_TEST_SEED");
  const std::uint64_t seed = env ? std::stoull(env) : std::random_device{}();
  std::printf("seed %llu (LOOM_TEST_SEED)\n", static_cast<unsigned long long>(seed));
  const WarpTension p{.centre_ratio = 1.0, .points = {}, .drift_per_row = 0.0, .noise = 0.02};
  const SimMachine m;
  WarpTensionModel a(p, m, seed), b(p, m, seed);
  constexpr int kBeats = 20000;
  double sum = 0.0, sum2 = 0.0;
  for (int k = 0; k < kBeats; ++k) {
    const double f = a.factor(k, 0.0);
    ASSERT_EQ(a.factor(k, 0.0), f);  // the same contact: the same draw
    ASSERT_EQ(b.factor(k, 0.0), f);  // the same seed: the same beats
    sum += f;
    sum2 += f * f;
  }
  const double mean = sum / kBeats, sd = std::sqrt(sum2 / kBeats - mean * mean);
  // Five standard errors: the mean's is 0.02 / sqrt(20000) = 1.4e-4, the deviation's about 0.5 % of it.
  EXPECT_NEAR(mean, 1.0, 5 * 0.02 / std::sqrt(kBeats));
  EXPECT_NEAR(sd, 0.02, 5 * 0.02 / std::sqrt(2.0 * kBeats));
}

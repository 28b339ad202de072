// Referencing: a loom with incremental encoders powers up at arbitrary counts, homes its axes in the
// order the machine needs (the beat crank first, so the beater is clear of the warp before the carriage
// moves), and only then weaves; an axis that cannot be referenced never moves in production.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/firmware/machine.hpp"

using namespace loom;
using sequencer::Fault;
using sequencer::State;

namespace {
constexpr std::size_t kCrank = 0, kCarriage = 1;

firmware::LoomConfig incremental_loom() {
  return firmware::load_loom_config(std::string(LOOM_SOURCE_DIR) + "/tests/sim/incremental_loom.toml");
}

firmware::Scene scene(std::uint64_t seed, const std::string& extra = "") {
  return firmware::parse_scene(
      "name = \"t\"\nseed = " + std::to_string(seed) + "\neffects = [\"ideal\"]\n" + extra, "t.toml");
}

struct Trace {
  std::vector<State> states;      // each state once, in the order entered
  std::vector<int> homing_order;  // the axes asked to home, in order
  double first_crank_reading = 0.0, first_carriage_reading = 0.0;
  bool carriage_moved_while_beater_in_warp = false;
  bool anything_moved_before_referenced = false;
  State end;
  Fault fault;
  int fault_axis;
  std::uint32_t rows;
};

// `crank_at`, `carriage_at`: where the machine truly stands at power-up (away from its home switches,
// so the homing runs have to move).
Trace run(const firmware::LoomConfig& cfg, const firmware::Scene& s, std::uint32_t rows,
          double crank_at = 1.0, double carriage_at = 0.3) {
  firmware::MachineOptions opt;
  opt.telemetry = false;
  opt.rows = rows;
  firmware::Machine m(cfg, s, opt, {});
  hal::AxisFeedbacks start{};
  start[kCrank].position = crank_at;
  start[kCarriage].position = carriage_at;
  m.sim().set_initial_state(start, {0.0, 0.0});
  m.sequencer().request_start();
  Trace tr{};
  double carriage_truth = m.sim().axis(kCarriage).position;
  for (hal::Tick t = 0; t < 300000 && !m.sequencer().finished(); ++t) {
    m.loop().cycle(t);
    const State st = m.sequencer().state();
    if (tr.states.empty() || tr.states.back() != st) tr.states.push_back(st);
    const hal::HalInputs& in = m.loop().inputs();
    if (t == 0)
      tr.first_crank_reading = in.axes[kCrank].position,
      tr.first_carriage_reading = in.axes[kCarriage].position;
    for (std::size_t i = 0; i < cfg.axes.size(); ++i) {
      if (m.loop().outputs().axes[i].request == hal::AxisRequest::kHome &&
          (tr.homing_order.empty() || tr.homing_order.back() != static_cast<int>(i))) {
        tr.homing_order.push_back(static_cast<int>(i));
      }
    }
    // Ground truth: the carriage never moves while the true beater is in the warp.
    const double c = m.sim().axis(kCarriage).position;
    if (std::abs(c - carriage_truth) > 1e-9 && m.sim().beater_in_warp())
      tr.carriage_moved_while_beater_in_warp = true;
    carriage_truth = c;
    // No production state before every axis is referenced.
    const bool producing = st == State::kPositioning || st == State::kShedTest || st == State::kShed ||
                           st == State::kPick || st == State::kBeatSweep;
    if (producing && (!m.sim().axis(kCrank).referenced || !m.sim().axis(kCarriage).referenced)) {
      tr.anything_moved_before_referenced = true;
    }
  }
  tr.end = m.sequencer().state();
  tr.fault = m.sequencer().first_fault();
  tr.fault_axis = m.sequencer().fault_axis();
  tr.rows = m.sequencer().counters().rows;
  return tr;
}

std::uint64_t seed_of_this_run() {
  const std::uint64_t seed = static_cast<std::uint64_t>(::time(nullptr)) % 1000003;
  std::printf("referencing: power-up counts from seed %llu\n", static_cast<unsigned long long>(seed));
  return seed;
}
}  // namespace

TEST(Referencing, AnIncrementalLoomPowersUpAnywhereHomesInMachineOrderThenWeaves) {
  const firmware::LoomConfig cfg = incremental_loom();
  for (std::uint64_t seed : {std::uint64_t{1}, std::uint64_t{2}, seed_of_this_run()}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Trace tr = run(cfg, scene(seed), 2);
    // The drives powered up at arbitrary counts, far from the machine's coordinates.
    EXPECT_GT(std::abs(tr.first_crank_reading) + std::abs(tr.first_carriage_reading), 1e-3);
    ASSERT_EQ(tr.homing_order, (std::vector<int>{static_cast<int>(kCrank), static_cast<int>(kCarriage)}));
    ASSERT_GE(tr.states.size(), 4u);
    EXPECT_EQ(tr.states[0], State::kEnabling);
    EXPECT_EQ(tr.states[1], State::kHoming);
    EXPECT_EQ(tr.states[2], State::kPositioning);
    EXPECT_EQ(tr.end, State::kDone) << sequencer::fault_name(tr.fault);
    EXPECT_EQ(tr.rows, 2u);
    EXPECT_FALSE(tr.carriage_moved_while_beater_in_warp);
    EXPECT_FALSE(tr.anything_moved_before_referenced);
  }
}

// While one drive homes by itself the others are enabled and hold their targets: a reading of the helix that
// lies meanwhile (an encoder glitch within one tick's plausible step) turns nothing. Truth is the plant.
TEST(Referencing, TheDrivesThatDoNotHomeHoldWhatEverTheirReadingsSay) {
  const firmware::LoomConfig cfg = incremental_loom();
  constexpr std::size_t kHelix = 2;
  firmware::MachineOptions opt;
  opt.telemetry = false;
  opt.rows = 1;
  firmware::Machine m(cfg,
                      scene(3,
                            "[[fault]]\nkind = \"encoder_glitch\"\nat_s = 0.05\naxis = \"helix\"\n"
                            "jump = 0.3\nticks = 4\n"),
                      opt, {});
  hal::AxisFeedbacks start{};
  start[kCrank].position = 1.0;
  start[kCarriage].position = 0.3;
  m.sim().set_initial_state(start, {0.0, 0.0});
  m.sequencer().request_start();
  const double helix_at = m.sim().axis(kHelix).position;
  bool glitch_read_while_homing = false;
  for (hal::Tick t = 0; t < 2000; ++t) {
    m.loop().cycle(t);
    if (m.sequencer().state() != State::kHoming) continue;
    const double read = m.loop().inputs().axes[kHelix].position;
    glitch_read_while_homing = glitch_read_while_homing || std::abs(read - helix_at) > 0.29;
    ASSERT_EQ(m.sim().axis(kHelix).position, helix_at) << "tick " << t;
  }
  EXPECT_TRUE(glitch_read_while_homing)
      << "the glitch was not read while an axis homed: the test shows nothing";
}

TEST(Referencing, AnAbsoluteLoomNeverHomes) {
  const Trace tr = run(firmware::default_loom_config(), scene(1), 1);
  EXPECT_TRUE(tr.homing_order.empty());
  EXPECT_EQ(std::count(tr.states.begin(), tr.states.end(), State::kHoming), 0);
  EXPECT_EQ(tr.end, State::kDone);
}

TEST(Referencing, AHomingRunThatNeverFindsItsReferenceIsAFaultNamingTheAxis) {
  firmware::LoomConfig cfg = incremental_loom();
  cfg.axes[kCarriage].home_offset = 0.5;    // the switch 0.2 m away from where the carriage stands
  cfg.axes[kCarriage].homing_speed = 1e-4;  // 0.1 mm/s: it is not reached in time
  cfg.axes[kCarriage].homing_timeout_s = 0.5;
  firmware::rederive_and_check(cfg, "test");
  const Trace tr = run(cfg, scene(7), 1);
  EXPECT_EQ(tr.end, State::kFault);
  EXPECT_EQ(tr.fault, Fault::kHomingFailed);
  EXPECT_EQ(tr.fault_axis, static_cast<int>(kCarriage));
  EXPECT_EQ(tr.rows, 0u);
}

TEST(Referencing, ConfigRefusesWhatCannotBeHomedSafely) {
  const auto error = [](const std::string& body) -> std::string {
    try {
      (void)firmware::parse_loom_config("extends = \"default\"\n" + body, "loom.toml");
    } catch (const firmware::ConfigError& e) {
      return e.what();
    }
    return "";
  };
  const std::string homing =
      "referencing = \"homing\"\nhoming_method = 19\nhome_offset = 0\nhoming_speed = 1\n"
      "homing_accel = 10\nhoming_timeout_s = 5\n";
  EXPECT_NE(error("[axes.helix]\n" + homing).find("the helix cannot home"), std::string::npos);
  // The crank's home point inside the warp: the beater would rest in the warp.
  const std::string in_warp = error(
      "[axes.beat_crank]\nreferencing = \"homing\"\nhoming_method = 19\nhome_offset = 3.3\n"
      "homing_speed = 1\nhoming_accel = 10\nhoming_timeout_s = 5\n");
  EXPECT_NE(in_warp.find("axes.beat_crank.home_offset = 3.3: the beater is inside the warp"),
            std::string::npos)
      << in_warp;
  EXPECT_NE(error("[axes.carriage]\nreferencing = \"homing\"\nhoming_method = 19\n")
                .find("home_offset = (missing)"),
            std::string::npos);
  EXPECT_NE(error("[axes.carriage]\nhoming_speed = 1\n").find("only an axis with referencing = \"homing\""),
            std::string::npos);
  EXPECT_NE(
      error("[axes.carriage]\n" + std::string("referencing = \"homing\"\nhoming_method = 7\nhome_offset = 0\n"
                                              "homing_speed = 1\nhoming_accel = 10\nhoming_timeout_s = 5\n"))
          .find("supported CiA 402 methods"),
      std::string::npos);
}

// The unsafe runs reported against the simulated loom (issue "Safe by construction"), each replayed
// in-process: every one must now end in a safe stop with a named fault — or, where the machine's state
// proves what happened, in a correct pick — never a pick through a half-open shed or a beat without weft.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "loom/config/config.hpp"
#include "loom/firmware/machine.hpp"

using namespace loom;
using sequencer::Fault;
using sequencer::State;

namespace {
struct Outcome {
  State state = State::kIdle;
  Fault first_fault = Fault::kNone;
  sequencer::Counters counters{};
  bool helix_moved = false, crank_moved = false;
};

// Weave with `scene` from the machine state in `state_file` (if any), resuming `resume`; stop after
// `max_ticks`, or when `stop_when` says so.
template <class Stop>
Outcome weave(const firmware::LoomConfig& cfg, const firmware::Scene& scene, const std::string& state_file,
              sequencer::Counters resume, std::uint32_t rows, hal::Tick max_ticks, Stop stop_when) {
  firmware::MachineOptions opt;
  opt.telemetry = false;
  opt.rows = resume.rows + rows;
  opt.sim_state_path = state_file;
  firmware::Machine m(cfg, scene, opt, resume);
  m.sequencer().request_start();
  const double helix0 = m.sim().axis(hal::CoreAxis::kHelix).position,
               crank0 = m.sim().axis(hal::CoreAxis::kBeatCrank).position;
  Outcome r;
  for (hal::Tick t = 0; t < max_ticks && !m.sequencer().finished(); ++t) {
    m.loop().cycle(t);
    r.helix_moved = r.helix_moved || std::abs(m.sim().axis(hal::CoreAxis::kHelix).position - helix0) > 1e-6;
    r.crank_moved =
        r.crank_moved || std::abs(m.sim().axis(hal::CoreAxis::kBeatCrank).position - crank0) > 1e-3;
    if (stop_when(m.sequencer())) break;
  }
  r.state = m.sequencer().state();
  r.first_fault = m.sequencer().first_fault();
  r.counters = m.sequencer().counters();
  return r;
}
auto never = [](const sequencer::Sequencer&) { return false; };

std::string temp_file(const char* name) {
  const auto p = std::filesystem::temp_directory_path() /
                 (std::string("loom-repro-") + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove(p);
  return p.string();
}

firmware::Scene ideal() {
  firmware::Scene s;
  s.spec.effects = {"ideal"};
  return s;
}
}  // namespace

TEST(Reproductions, EndSensorStuckOnBeforeTheFrameArrivesStopsBeforeAnyPick) {
  // stuck_sensor piston_a_extended = true at 0.15 s: used to weave a row through a half-open shed, exit 0.
  const firmware::Scene scene = firmware::parse_scene(R"(effects = ["ideal"]
[[fault]]
at_s = 0.15
kind = "stuck_sensor"
sensor = "piston_a_extended"
value = true
)",
                                                      "stuck.toml");
  // With the default loom's second switch beside it, the stuck switch disagrees with its partner; on a
  // loom without second switches the shed monitor sees piston A never leave its retracted end.
  firmware::LoomConfig single = firmware::default_loom_config();
  for (auto& b : single.io.wiring.second) b.bit = -1;
  firmware::rederive_and_check(single, "single-channel variant");
  const struct {
    firmware::LoomConfig cfg;
    Fault expected;
  } looms[] = {{firmware::default_loom_config(), Fault::kSensorDiscrepancy},
               {single, Fault::kShedNotReleased}};
  for (const auto& loom : looms) {
    const Outcome r = weave(loom.cfg, scene, "", {}, 3, 100000, never);
    EXPECT_EQ(r.state, State::kFault);
    EXPECT_EQ(r.first_fault, loom.expected) << sequencer::fault_name(r.first_fault);
    EXPECT_FALSE(r.helix_moved);
    EXPECT_EQ(r.counters.picks, 0u);
  }
}

TEST(Reproductions, RestartWithResetCountersIsRefusedNotBeatenWithoutWeft) {
  // Phantom pick: one row woven with --sim-state, then a restart with the counters reset (or missing)
  // used to beat the next row with no weft (shed 0.00 s, pick 0.00 s) and exit 0.
  const std::string state = temp_file("phantom");
  const auto cfg = firmware::default_loom_config();
  const Outcome first = weave(cfg, ideal(), state, {}, 1, 100000, never);
  ASSERT_EQ(first.state, State::kDone) << sequencer::fault_name(first.first_fault);
  ASSERT_EQ(first.counters.rows, 1u);
  const Outcome again = weave(cfg, ideal(), state, {}, 1, 100000, never);
  EXPECT_EQ(again.state, State::kFault);
  EXPECT_EQ(again.first_fault, Fault::kShuttleSideMismatch) << sequencer::fault_name(again.first_fault);
  EXPECT_EQ(again.counters.rows, 0u);
  EXPECT_FALSE(again.helix_moved);
  EXPECT_FALSE(again.crank_moved);
  // With the true counters the same machine weaves the next row: a real pick, then the beat.
  const Outcome right = weave(cfg, ideal(), state, first.counters, 1, 100000, never);
  EXPECT_EQ(right.state, State::kDone) << sequencer::fault_name(right.first_fault);
  EXPECT_EQ(right.counters.rows, 2u);
  EXPECT_EQ(right.counters.picks, 2u);
  EXPECT_TRUE(right.helix_moved);
  std::filesystem::remove(state);
}

TEST(Reproductions, ImpossiblePicksInRowAreRefused) {
  // "picks_in_row": 99 used to skip straight to a beat sweep without weft.
  const Outcome r = weave(firmware::default_loom_config(), ideal(), "",
                          {.rows = 0, .picks = 99, .beats = 0, .picks_in_row = 99}, 1, 10000, never);
  EXPECT_EQ(r.state, State::kFault);
  EXPECT_EQ(r.first_fault, Fault::kCountersInconsistent) << sequencer::fault_name(r.first_fault);
  EXPECT_FALSE(r.crank_moved);
}

TEST(Reproductions, APickWhoseCountWasLostIsRecognisedFromTheMachine) {
  // The legitimate case the phantom pick hid behind: the power fails right after a pick completed, before
  // its count reached the file. The shed is still open for that pick, the carriage waits at the row's
  // start: the pick is counted, not repeated, and the row is beaten once.
  const std::string state = temp_file("lost-count");
  const auto cfg = firmware::default_loom_config();
  const Outcome cut = weave(cfg, ideal(), state, {}, 1, 100000,
                            [](const sequencer::Sequencer& s) { return s.state() == State::kBeatSweep; });
  ASSERT_EQ(cut.counters.picks, 1u);
  const Outcome resumed = weave(cfg, ideal(), state, {}, 1, 100000, never);
  EXPECT_EQ(resumed.state, State::kDone) << sequencer::fault_name(resumed.first_fault);
  EXPECT_EQ(resumed.counters.rows, 1u);
  EXPECT_EQ(resumed.counters.picks, 1u);
  EXPECT_FALSE(resumed.helix_moved);  // not picked again
  std::filesystem::remove(state);
}

TEST(Reproductions, RunawayCrankDynamicsAreANamedFaultNotAWovenRow) {
  // joint_friction.coulomb_nm = 1e6 in the dynamics scene: the crank went NaN and the run said
  // "woven 1 rows", exit 0.
  const firmware::Scene scene =
      firmware::parse_scene(R"(effects = ["inertia", "joint_friction", "pneumatics", "beat_contact"]
[joint_friction]
coulomb_nm = 1e6
)",
                            "dynamics.toml");
  const Outcome r = weave(firmware::default_loom_config(), scene, "", {}, 1, 100000, never);
  EXPECT_EQ(r.state, State::kFault);
  EXPECT_TRUE(r.first_fault == Fault::kNonFiniteFeedback || r.first_fault == Fault::kEncoderJump)
      << sequencer::fault_name(r.first_fault);
  EXPECT_EQ(r.counters.rows, 0u);
}

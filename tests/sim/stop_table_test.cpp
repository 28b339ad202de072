// Stop means stop, shown over every state the loom can be in × every stopping command (issue: a stop on a
// paused loom set it weaving again). Each case runs two identical simulated machines in lockstep — the
// baseline, which never gets the command, and the commanded one, which gets it through the operator policy
// (decide + apply, as the runner and the safety campaign apply commands) at the first tick of the state. The
// commanded machine may do what the baseline does (finishing a beat sweep, a knot cycle, a homing run), but
// from the first tick its outputs differ it must never set anything moving again (hal/motion_outputs.hpp:
// an enabled axis' target, a valve, a gripper closing, a cutter firing), and it must come to rest in the
// state the command asks for. The table documents what each stopping command means in each state.
#include <gtest/gtest.h>

#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/firmware/machine.hpp"
#include "loom/firmware/operator_policy.hpp"
#include "loom/hal/motion_outputs.hpp"
#include "loom/sequencer/operator_requests.hpp"

using namespace loom;
using firmware::Command;
using sequencer::State;

namespace {

const std::string kSim = std::string(LOOM_SOURCE_DIR) + "/tests/sim/";

enum class Stopping { kStopWeave, kStopServe, kPause, kExit, kStopNow };
const char* stopping_name(Stopping s) {
  switch (s) {
    case Stopping::kStopWeave:
      return "stop (weave: SIGTERM)";
    case Stopping::kStopServe:
      return "stop (serve: ctl, panel)";
    case Stopping::kPause:
      return "pause";
    case Stopping::kExit:
      return "exit (serve: SIGTERM)";
    case Stopping::kStopNow:
      return "stop now (second SIGTERM)";
  }
  return "?";
}
constexpr Stopping kAllStopping[] = {Stopping::kStopWeave, Stopping::kStopServe, Stopping::kPause,
                                     Stopping::kExit, Stopping::kStopNow};

// The states a stopping command may leave the loom in: done (stop), paused (pause), faulted (stop now, or any
// fault), or where it already stood.
bool rests_as_asked(Stopping c, State s) {
  switch (c) {
    case Stopping::kStopWeave:
    case Stopping::kStopServe:
      return s == State::kDone || s == State::kFault || s == State::kIdle;
    case Stopping::kPause:
      return s == State::kPaused || s == State::kDone || s == State::kFault || s == State::kIdle;
    case Stopping::kExit:
      return firmware::quiet(s);
    case Stopping::kStopNow:
      return s == State::kFault || s == State::kDone || s == State::kIdle;
  }
  return false;
}

// One machine as the runner would drive it in simulation: presses and the simulated weaver's answers through
// the operator policy, the counters "saved" a few ticks after each row (the row-boundary handshake).
struct Driven {
  firmware::Machine m;
  bool weaver_mode;
  hal::Tick waiting = 0;
  Driven(const firmware::LoomConfig& cfg, const firmware::Scene& scene, const firmware::MachineOptions& opt)
      : m(cfg, scene, opt, {}), weaver_mode(cfg.sequencer.knotting && m.knot_program() == nullptr) {
    m.sequencer().request_start();
  }
  void command(std::uint32_t cmds, bool held) {
    firmware::PolicyInputs in;
    in.commands = cmds;
    in.state = m.sequencer().state();
    in.held_session = held;
    in.estop_ok = m.loop().inputs().io.estop_ok;
    firmware::apply(firmware::decide(in), m.sequencer());
  }
  void tick(hal::Tick t) {
    m.loop().cycle(t);
    sequencer::Sequencer& seq = m.sequencer();
    sequencer::apply_presses(seq);
    if (seq.events().has(sequencer::EventKind::kWeaverRequest) &&
        seq.weaver_request().ask != sequencer::WeaverAsk::kNone) {
      firmware::Machine::simulated_weaver_sink(&m, seq.weaver_request());
    }
    // The weaver in weaver mode knots a row in 1 s; the reporter saves a row 20 ms after it ends.
    waiting = seq.state() == State::kAwaitKnotting ? waiting + 1 : 0;
    if (weaver_mode && waiting == 500) command(static_cast<std::uint32_t>(Command::kNext), false);
    if (seq.state() == State::kRowEnd && t - row_end_since(t) >= 10)
      seq.note_rows_saved(seq.counters().rows, false);
    seq.note_knots_saved(seq.counters().rows, seq.counters().knot.cycles_started);
  }
  hal::Tick row_end_since(hal::Tick t) {
    if (m.sequencer().state() != State::kRowEnd) row_end_at_ = -1;
    if (row_end_at_ < 0) row_end_at_ = t;
    return row_end_at_;
  }
  hal::Tick row_end_at_ = -1;
};

bool same_motion(const hal::HalOutputs& a, const hal::HalOutputs& b, std::size_t axes, int heads) {
  for (std::size_t i = 0; i < axes; ++i) {
    if (a.axes[i].request != b.axes[i].request || a.axes[i].target_position != b.axes[i].target_position)
      return false;
  }
  if (a.io.piston_a_extend != b.io.piston_a_extend || a.io.piston_b_extend != b.io.piston_b_extend)
    return false;
  for (int h = 0; h < heads; ++h) {
    const auto k = static_cast<std::size_t>(h);
    if (a.io.gripper_close[k] != b.io.gripper_close[k] || a.io.cutter[k] != b.io.cutter[k]) return false;
  }
  return true;
}

struct Case {
  std::string name;
  std::function<firmware::LoomConfig()> config;
  std::string scene;  // TOML ("" = the default scene)
  std::uint32_t rows = 3;
  bool await_row_saved = false;
  // A stopping command given to both machines first (the pause a stop then meets), at the first tick of...
  std::function<bool(firmware::Machine&)> prelude;
  Stopping prelude_command = Stopping::kPause;
  // ... then the command under test at the first tick this holds.
  std::function<bool(firmware::Machine&)> at;
};

std::function<bool(firmware::Machine&)> in_state(State s) {
  return [s](firmware::Machine& m) { return m.sequencer().state() == s; };
}

std::uint32_t bits_of(Stopping c) {
  switch (c) {
    case Stopping::kStopWeave:
    case Stopping::kStopServe:
      return static_cast<std::uint32_t>(Command::kStop);
    case Stopping::kPause:
      return static_cast<std::uint32_t>(Command::kPause);
    case Stopping::kExit:
      return static_cast<std::uint32_t>(Command::kExit);
    case Stopping::kStopNow:
      return 0;
  }
  return 0;
}

void give(Driven& d, Stopping c) {
  if (c == Stopping::kStopNow) {
    d.m.sequencer().request_stop_now();  // the runner's second signal
    return;
  }
  d.command(bits_of(c), c != Stopping::kStopWeave);
}

// Runs one case with one stopping command; "" when it holds, else what went wrong.
std::string run_case(const Case& k, Stopping c) {
  firmware::LoomConfig cfg = k.config();
  const firmware::Scene scene =
      k.scene.empty() ? firmware::default_scene() : firmware::parse_scene(k.scene, k.name + ".toml");
  firmware::MachineOptions opt;
  opt.telemetry = false;
  opt.rows = k.rows;
  opt.await_row_saved = k.await_row_saved;
  Driven a(cfg, scene, opt), b(cfg, scene, opt);
  const std::size_t axes = a.m.sequencer().axes().count;
  const int heads = a.m.knot_program() != nullptr ? a.m.knot_program()->heads() : 0;
  constexpr hal::Tick kReach = 400000, kAfter = 60000;  // 800 s to reach the state; 120 s after the command
  bool prelude_done = !k.prelude;
  hal::Tick t = 0, commanded_at = -1;
  for (; t < kReach && commanded_at < 0; ++t) {
    if (!prelude_done && k.prelude(a.m)) {
      give(a, k.prelude_command);
      give(b, k.prelude_command);
      prelude_done = true;
    }
    if (prelude_done && k.at(a.m)) {
      give(b, c);
      commanded_at = t;
      break;
    }
    a.tick(t);
    b.tick(t);
  }
  if (commanded_at < 0) return "the state was never reached";
  firmware::Machine& am = a.m;
  const State at_command = b.m.sequencer().state();
  const sequencer::Counters counters_at_command = b.m.sequencer().counters();
  hal::HalOutputs b_prev = b.m.loop().outputs();
  bool diverged = false;
  hal::Tick rest_since = -1;
  for (; t < commanded_at + kAfter; ++t) {
    a.tick(t);
    b.tick(t);
    const hal::HalOutputs& b_now = b.m.loop().outputs();
    if (!diverged && !same_motion(am.loop().outputs(), b_now, axes, heads)) diverged = true;
    if (diverged) {
      if (const hal::MotionChange mc = hal::motion_started(b_prev, b_now, axes, heads)) {
        return std::string(hal::motion_change_name(mc.what)) + " (index " + std::to_string(mc.index) +
               ") at tick " + std::to_string(t) + ", " + std::to_string(t - commanded_at) +
               " ticks after the command given in " + sequencer::state_name(at_command) + " (now " +
               sequencer::state_name(b.m.sequencer().state()) + ")";
      }
    }
    b_prev = b_now;
    const bool rested = rests_as_asked(c, b.m.sequencer().state());
    rest_since = rested ? (rest_since < 0 ? t : rest_since) : -1;
    if (rest_since >= 0 && t - rest_since > 500)
      break;  // standing for a second: it stays (checked that long)
  }
  if (rest_since < 0) {
    return std::string("did not come to rest within ") + std::to_string(kAfter) + " ticks (state " +
           sequencer::state_name(b.m.sequencer().state()) + ")";
  }
  // A stop of a loom that stood never finishes a row it had not finished.
  if (at_command == State::kPaused && (c == Stopping::kStopServe || c == Stopping::kStopWeave) &&
      b.m.sequencer().counters().rows != counters_at_command.rows) {
    return "a stop of the paused loom wove on to row " + std::to_string(b.m.sequencer().counters().rows);
  }
  return "";
}

firmware::LoomConfig default_loom() {
  return firmware::default_loom_config();
}
firmware::LoomConfig knotting_loom() {
  return firmware::load_loom_config(kSim + "knotting_sample_loom.toml");
}
firmware::LoomConfig homing_loom() {
  return firmware::load_loom_config(kSim + "incremental_loom.toml");
}
firmware::LoomConfig weaver_loom() {
  firmware::LoomConfig cfg = firmware::default_loom_config();
  cfg.sequencer.knotting = true;  // knotting.mode = "weaver": the loom waits for the weaver's row
  return cfg;
}
const std::string kKnotScene = "name = \"knots\"\nseed = 3\neffects = [\"ideal\", \"knotter\"]\n[knotter]\n";
const std::string kFaultScene =
    "name = \"emcy\"\nseed = 5\neffects = [\"ideal\"]\n[[fault]]\nat_s = 4.0\nkind = \"emcy\"\naxis = "
    "\"carriage\"\n"
    "code = 0x2310\n";

std::vector<Case> cases() {
  const auto first = [](State s) { return in_state(s); };
  const auto knot_cycle = [](int j) {
    return [j](firmware::Machine& m) {
      return m.sequencer().state() == State::kKnotting && m.sequencer().knot_cycle() == j;
    };
  };
  std::vector<Case> v;
  v.push_back({"idle", default_loom, "", 3, false, nullptr, Stopping::kPause,
               [](firmware::Machine&) { return true; }});
  for (const State s : {State::kEnabling, State::kPositioning, State::kShedTest, State::kShed, State::kPick,
                        State::kBeatSweep, State::kDone}) {
    v.push_back({sequencer::state_name(s), default_loom, "", s == State::kDone ? 1u : 3u, false, nullptr,
                 Stopping::kPause, first(s)});
  }
  v.push_back({"row_end", default_loom, "", 3, true, nullptr, Stopping::kPause, first(State::kRowEnd)});
  v.push_back({"paused at a row's end", default_loom, "", 3, false, first(State::kBeatSweep),
               Stopping::kPause, first(State::kPaused)});
  v.push_back(
      {"fault", default_loom, kFaultScene, 3, false, nullptr, Stopping::kPause, first(State::kFault)});
  v.push_back({"homing", homing_loom, "", 3, false, nullptr, Stopping::kPause, first(State::kHoming)});
  v.push_back({"await_knotting (weaver mode)", weaver_loom, "", 3, false, nullptr, Stopping::kPause,
               first(State::kAwaitKnotting)});
  v.push_back({"knotting, first cycle", knotting_loom, kKnotScene, 2, true, nullptr, Stopping::kPause,
               knot_cycle(0)});
  v.push_back(
      {"knotting, cycle 3", knotting_loom, kKnotScene, 2, true, nullptr, Stopping::kPause, knot_cycle(3)});
  v.push_back({"knotting, the heads waiting for the weaver", knotting_loom,
               kKnotScene + "miss_probability = 1.0\n", 2, true, nullptr, Stopping::kPause,
               [](firmware::Machine& m) {
                 return m.sequencer().weaver_request().ask == sequencer::WeaverAsk::kTieByHand;
               }});
  v.push_back({"paused between knot cycles", knotting_loom, kKnotScene, 2, true, knot_cycle(2),
               Stopping::kPause, first(State::kPaused)});
  v.push_back({"knotting loom, beat sweep", knotting_loom, kKnotScene, 2, true, nullptr, Stopping::kPause,
               first(State::kBeatSweep)});
  return v;
}

TEST(StopTable, NoStoppingCommandEverSetsTheLoomMovingInAnyState) {
  int failures = 0, ran = 0;
  for (const Case& k : cases()) {
    for (const Stopping c : kAllStopping) {
      const std::string why = run_case(k, c);
      ++ran;
      std::printf("  %-44s %-28s %s\n", k.name.c_str(), stopping_name(c),
                  why.empty() ? "holds" : why.c_str());
      if (!why.empty()) {
        ++failures;
        ADD_FAILURE() << k.name << " × " << stopping_name(c) << ": " << why;
      }
    }
  }
  EXPECT_EQ(failures, 0) << "of " << ran;
}

// The reproduction of the defect: paused mid-row by its operator, then `stop` — the loom stays where it is
// and ends in done, no row woven on.
TEST(StopTable, AStopOnAPausedLoomEndsInDoneWithNothingMoving) {
  Case k{"paused",
         default_loom,
         "",
         3,
         false,
         in_state(State::kPick),
         Stopping::kPause,
         in_state(State::kPaused)};
  EXPECT_EQ(run_case(k, Stopping::kStopServe), "");
}

}  // namespace

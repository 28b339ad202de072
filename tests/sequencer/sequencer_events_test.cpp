// The sequencer says what happened: step() lists this tick's events (Sequencer::events()), and nothing
// else has to compare polled state with the last tick's. Two rigs:
//  - ScriptedLoom: inputs written by the test, tick by tick (drives that follow their targets at once and
//    enable when asked, sensors set by hand): buttons (reported, made requests only by an owner), faults,
//    diagnosis, acknowledgement;
//  - the simulated loom (SimWorld): whole rows, where the list must agree with the counters it summarises
//    (one kPick per counted pick, one kRow per row, every beat once and in order) and with the pauses.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "loom/hal/hal.hpp"
#include "loom/sequencer/operator_requests.hpp"
#include "loom/sequencer/sequencer.hpp"
#include "loom/sim_hal/sim_world.hpp"

using namespace loom;
using sequencer::Button;
using sequencer::EventKind;
using sequencer::Fault;
using sequencer::State;
using sequencer::TickEvent;

namespace {

std::vector<EventKind> kinds(const sequencer::TickEvents& ev) {
  std::vector<EventKind> k;
  for (const TickEvent& e : ev) k.push_back(e.kind);
  return k;
}

// Inputs the test writes: every drive follows its target exactly and is enabled while asked to be, the
// frames rest retracted, the shuttle waits at the left selvedge, everything refreshed every tick.
struct ScriptedLoom {
  motion::ProfileSet profiles{motion::ProfileSpec{}};
  sequencer::SequencerConfig cfg{};
  std::unique_ptr<sequencer::Sequencer> seq;
  hal::HalInputs in{};
  hal::HalOutputs out{};
  hal::Tick now = 0;
  std::array<bool, hal::kMaxAxes> frozen{};  // an axis whose feedback stopped arriving

  ScriptedLoom() {
    seq = std::make_unique<sequencer::Sequencer>(profiles, cfg);
    in.io.estop_ok = true;
    in.io.piston_a_retracted = in.io.piston_b_retracted = true;
    in.io.shuttle_at_left = true;
  }
  // One tick; the returned list is the sequencer's for that tick.
  const sequencer::TickEvents& tick() {
    for (std::size_t i = 0; i < seq->axes().count; ++i) {
      hal::AxisFeedback& a = in.axes[i];
      if (frozen[i]) continue;
      a.position = out.axes[i].target_position;
      const bool enable = out.axes[i].request == hal::AxisRequest::kEnable;
      if (!a.fault)
        a.state = enable ? hal::DriveState::kOperationEnabled : hal::DriveState::kSwitchOnDisabled;
      a.refreshed = now;
    }
    in.io.refreshed = now;
    seq->step(now++, in, out);
    return seq->events();
  }
  // Ticks until `pred` holds after a tick (at most `limit` ticks).
  template <typename Pred>
  bool run_until(Pred pred, int limit = 10000) {
    for (int k = 0; k < limit; ++k) {
      tick();
      if (pred()) return true;
    }
    return false;
  }
};

}  // namespace

TEST(SequencerEvents, AnOrdinaryTickSaysNothing) {
  ScriptedLoom l;
  for (int k = 0; k < 100; ++k) EXPECT_TRUE(l.tick().empty()) << "tick " << k;
  EXPECT_EQ(l.seq->state(), State::kIdle);
  EXPECT_EQ(l.seq->events().began_in(), State::kIdle);
}

// The sequencer decodes and debounces the buttons and reports each press; it acts on none of them itself:
// a command means one thing whatever station gave it, and its owner makes the request
// (operator_requests.hpp).
TEST(SequencerEvents, APressIsOneEventOnceDebouncedAndTheSequencerDoesNotActOnIt) {
  ScriptedLoom l;
  for (int k = 0; k < 10; ++k) l.tick();
  l.in.io.button_start = true;
  int events = 0;
  hal::Tick pressed_at = -1;
  for (int k = 0; k < 20; ++k) {
    const sequencer::TickEvents& ev = l.tick();
    if (ev.empty()) continue;
    ++events;
    pressed_at = l.now - 1;
    ASSERT_EQ(kinds(ev), std::vector<EventKind>{EventKind::kButton});
    EXPECT_EQ(ev[0].button, Button::kStart);
    EXPECT_EQ(ev.began_in(), State::kIdle);
  }
  EXPECT_EQ(events, 1);  // held down: still one press
  EXPECT_EQ(pressed_at,
            10 + l.cfg.debounce_ticks - 1);  // pressed from tick 10: the debounce_ticks-th tick reading it
  // Start, pause, ack and the pedal pressed again and again with nobody to take them: reported, never acted
  // on.
  for (int press = 0; press < 3; ++press) {
    l.in.io.button_start = l.in.io.button_pause = l.in.io.button_ack = l.in.io.row_knotted = false;
    for (int k = 0; k < 10; ++k) l.tick();
    l.in.io.button_start = l.in.io.button_pause = l.in.io.button_ack = l.in.io.row_knotted = true;
    int presses = 0;
    for (int k = 0; k < 10; ++k) {
      for (const TickEvent& e : l.tick()) presses += e.kind == EventKind::kButton;
    }
    EXPECT_EQ(presses, 4);
  }
  for (int k = 0; k < 200; ++k) l.tick();
  EXPECT_EQ(l.seq->state(), State::kIdle);
  for (std::size_t i = 0; i < l.seq->axes().count; ++i)
    EXPECT_EQ(l.out.axes[i].request, hal::AxisRequest::kDisable);
}

// Through its owner a press acts in the step after the one that saw it, as a command between two steps does.
TEST(SequencerEvents, ThroughItsOwnerAStartPressStartsTheLoomInTheNextStep) {
  ScriptedLoom l;
  for (int k = 0; k < 10; ++k) l.tick();
  l.in.io.button_start = true;
  ASSERT_TRUE(l.run_until([&] { return l.seq->events().has(EventKind::kButton); }, 20));
  EXPECT_EQ(l.seq->state(), State::kIdle);  // seen, not acted on
  EXPECT_EQ(sequencer::request_of(Button::kStart, l.seq->events().began_in()),
            sequencer::OperatorRequest::kStart);
  sequencer::apply_presses(*l.seq);
  l.tick();
  EXPECT_EQ(l.seq->state(), State::kEnabling);
}

TEST(SequencerEvents, AStartWithTheEStopOpenLatchesTheFaultInTheStateItBeganIn) {
  ScriptedLoom l;
  l.tick();
  l.in.io.estop_ok = false;
  l.seq->request_start();
  const sequencer::TickEvents& ev = l.tick();
  ASSERT_EQ(kinds(ev), std::vector<EventKind>{EventKind::kFaultLatched});
  EXPECT_EQ(ev[0].fault, Fault::kEStop);
  EXPECT_EQ(ev[0].axis, -1);
  EXPECT_EQ(ev[0].sensor, -1);
  EXPECT_EQ(ev.began_in(), State::kIdle);
  EXPECT_EQ(l.seq->state(), State::kFault);
  for (int k = 0; k < 50; ++k) EXPECT_TRUE(l.tick().empty()) << "latched once, said once";
}

TEST(SequencerEvents, AStaleAxisIsLatchedThenRefinedToTheDriveThatFaulted) {
  ScriptedLoom l;
  l.seq->request_start();
  ASSERT_TRUE(l.run_until([&] { return l.seq->state() == State::kEnabling; }));
  const auto helix = hal::index(hal::CoreAxis::kHelix);
  l.frozen[helix] = true;  // its feedback stops arriving (and its drive never reports enabled)
  ASSERT_TRUE(l.run_until([&] { return !l.seq->events().empty(); }, 100));
  const sequencer::TickEvents& latched = l.seq->events();
  ASSERT_EQ(kinds(latched), std::vector<EventKind>{EventKind::kFaultLatched});
  EXPECT_EQ(latched[0].fault, Fault::kStaleFeedback);
  EXPECT_EQ(latched[0].axis, static_cast<int>(helix));
  EXPECT_EQ(latched.began_in(), State::kEnabling);
  // Within the diagnosis window the drive reports its fault: the root cause replaces the symptom, once.
  l.tick();
  EXPECT_TRUE(l.seq->events().empty());
  l.in.axes[helix].fault = true;
  l.in.axes[helix].state = hal::DriveState::kFault;
  l.in.axes[helix].fault_code = 0x7305;
  l.in.axes[helix].fault_kind = hal::FaultKind::kDrive;
  const sequencer::TickEvents& refined = l.tick();
  ASSERT_EQ(kinds(refined), std::vector<EventKind>{EventKind::kDiagnosisRefined});
  EXPECT_EQ(refined[0].fault, Fault::kDriveFault);
  EXPECT_EQ(refined[0].axis, static_cast<int>(helix));
  EXPECT_EQ(refined[0].detail, 0x7305);
  EXPECT_EQ(refined.began_in(), State::kFault);
  EXPECT_EQ(l.seq->stopped_by(), Fault::kStaleFeedback);
  for (int k = 0; k < 200; ++k) EXPECT_TRUE(l.tick().empty());
}

TEST(SequencerEvents, AnAckPressIsReportedAndAcknowledgesOnlyThroughItsOwner) {
  for (const bool owner : {false, true}) {
    SCOPED_TRACE(owner ? "the owner makes the request" : "nobody takes the press");
    ScriptedLoom l;
    l.seq->request_start();
    ASSERT_TRUE(l.run_until([&] { return l.seq->state() == State::kEnabling; }));
    l.seq->request_stop_now();
    const sequencer::TickEvents& stop = l.tick();
    ASSERT_EQ(kinds(stop), std::vector<EventKind>{EventKind::kFaultLatched});
    EXPECT_EQ(stop[0].fault, Fault::kStopRequested);
    for (int k = 0; k < 5; ++k) l.tick();
    l.in.io.button_ack = true;
    ASSERT_TRUE(l.run_until([&] { return !l.seq->events().empty(); }, 20));
    const sequencer::TickEvents& ack = l.seq->events();
    ASSERT_EQ(kinds(ack), std::vector<EventKind>{EventKind::kButton});
    EXPECT_EQ(ack[0].button, Button::kAck);
    EXPECT_EQ(ack.began_in(), State::kFault);
    EXPECT_EQ(l.seq->state(), State::kFault);  // seen, not acted on
    if (owner) sequencer::apply_presses(*l.seq);
    l.tick();
    EXPECT_EQ(l.seq->state(), owner ? State::kIdle : State::kFault);
    if (owner) {
      for (std::size_t i = 0; i < l.seq->axes().count; ++i) {
        EXPECT_EQ(l.out.axes[i].request, hal::AxisRequest::kFaultReset);
      }
    }
    for (int k = 0; k < 100; ++k) l.tick();
    EXPECT_EQ(l.seq->state(), owner ? State::kIdle : State::kFault);
  }
}

// An ack press whose debounced edge is seen in the tick the fault latched was pressed before the fault: the
// tick began in another state, so the press asks nothing, though the fault is latched when its owner looks.
TEST(SequencerEvents, AnAckPressSeenInTheTickTheFaultLatchedAcknowledgesNothing) {
  ScriptedLoom l;
  l.seq->request_start();
  ASSERT_TRUE(l.run_until([&] { return l.seq->state() == State::kEnabling; }));
  l.in.io.button_ack = true;
  for (int k = 0; k < l.cfg.debounce_ticks - 1; ++k) ASSERT_TRUE(l.tick().empty());
  const State arming = l.seq->state();
  ASSERT_NE(arming, State::kFault);
  l.seq->request_stop_now();  // latched in the tick that sees the press
  const sequencer::TickEvents& ev = l.tick();
  ASSERT_EQ(kinds(ev), (std::vector<EventKind>{EventKind::kFaultLatched, EventKind::kButton}));
  EXPECT_EQ(ev[1].button, Button::kAck);
  EXPECT_EQ(ev.began_in(), arming);
  EXPECT_EQ(l.seq->state(), State::kFault);
  EXPECT_EQ(sequencer::request_of(Button::kAck, ev.began_in()), sequencer::OperatorRequest::kNone);
  sequencer::apply_presses(*l.seq);
  for (int k = 0; k < 100; ++k) l.tick();
  EXPECT_EQ(l.seq->state(), State::kFault);
  EXPECT_EQ(l.seq->first_fault(), Fault::kStopRequested);
}

// The simulated loom weaves whole rows: the list must say exactly what the counters count.
TEST(SequencerEvents, OverWholeRowsTheListAgreesWithTheCountersAndThePauses) {
  motion::ProfileSet profiles{motion::ProfileSpec{}};
  sequencer::SequencerConfig cfg{};
  cfg.rows_to_weave = 3;
  cfg.picks_per_row = 2;
  sim_hal::SimWorld world(sim_hal::SimMachine{}, sim_hal::SceneSpec{});
  sequencer::Sequencer seq(profiles, cfg);
  hal::PortHal hal(world, world);
  hal::HalInputs in{};
  hal::HalOutputs out{};
  seq.request_start();
  sequencer::Counters was = seq.counters();
  State state_was = seq.state();
  std::uint32_t beats_said = 0, rows_said = 0, picks_said = 0, pauses = 0, resumes = 0;
  int next_beat = 0;
  bool paused_once = false;
  for (hal::Tick t = 0; t < 400000 && !seq.finished(); ++t) {
    if (!paused_once && seq.counters().picks == 1) {
      seq.request_pause();  // between the picks of row 1: holds before the next shed
      paused_once = true;
    }
    if (seq.state() == State::kPaused) seq.request_resume();
    hal.read(t, in);
    seq.step(t, in, out);
    hal.write(t, out);
    const sequencer::TickEvents& ev = seq.events();
    EXPECT_EQ(ev.began_in(), state_was);
    const sequencer::Counters& c = seq.counters();
    EXPECT_EQ(ev.has(EventKind::kRow), c.rows != was.rows) << "tick " << t;
    EXPECT_EQ(ev.has(EventKind::kPick), c.picks != was.picks) << "tick " << t;
    EXPECT_EQ(ev.has(EventKind::kPaused), state_was != State::kPaused && seq.state() == State::kPaused);
    EXPECT_EQ(ev.has(EventKind::kResumed), state_was == State::kPaused && seq.state() != State::kPaused);
    EXPECT_FALSE(ev.has(EventKind::kFaultLatched)) << sequencer::fault_name(seq.first_fault());
    for (const TickEvent& e : ev) {
      if (e.kind == EventKind::kBeat) {
        // Every beat once, in order, of the row being woven (counted at the fell, said once out of the warp).
        EXPECT_EQ(e.beat.row, c.rows + (ev.has(EventKind::kRow) ? 0u : 1u));
        EXPECT_EQ(e.beat.index, next_beat);
        ++next_beat;
        ++beats_said;
      }
      if (e.kind == EventKind::kRow) {
        ++rows_said;
        EXPECT_EQ(next_beat, profiles.beats_per_row());
        EXPECT_EQ(seq.last_row().row, c.rows);
        next_beat = 0;
      }
      picks_said += e.kind == EventKind::kPick ? 1u : 0u;
      pauses += e.kind == EventKind::kPaused ? 1u : 0u;
      resumes += e.kind == EventKind::kResumed ? 1u : 0u;
    }
    was = c;
    state_was = seq.state();
  }
  ASSERT_EQ(seq.state(), State::kDone) << sequencer::fault_name(seq.first_fault());
  EXPECT_EQ(rows_said, 3u);
  EXPECT_EQ(picks_said, 6u);
  EXPECT_EQ(beats_said, seq.counters().beats);
  EXPECT_EQ(pauses, 1u);
  EXPECT_EQ(resumes, 1u);
  EXPECT_EQ(seq.events().lost(), 0u);
}

TEST(SequencerEvents, TheListIsBoundedAndCountsWhatDidNotFit) {
  sequencer::TickEvents ev;
  ev.clear(State::kIdle);
  for (std::size_t k = 0; k < sequencer::TickEvents::kCapacity + 3; ++k) ev.add(EventKind::kPick);
  EXPECT_EQ(ev.size(), sequencer::TickEvents::kCapacity);
  EXPECT_EQ(ev.lost(), 3u);
  ev.clear(State::kShed);
  EXPECT_TRUE(ev.empty());
  EXPECT_EQ(ev.began_in(), State::kShed);
}

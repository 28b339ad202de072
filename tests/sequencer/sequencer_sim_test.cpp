// The sequencer driving the simulated loom in virtual time: rows complete with the planned beats, the
// carriage covers the width, interlocks never trip, and injected faults stop motion with counters kept.
#include <gtest/gtest.h>

#include <cmath>

#include "loom/hal/hal.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/profile_set.hpp"
#include "loom/motion/profile_slot.hpp"
#include "loom/sequencer/operator_requests.hpp"
#include "loom/sequencer/sequencer.hpp"
#include "loom/sim_hal/sim_world.hpp"

using namespace loom;
using sequencer::Fault;
using sequencer::State;

namespace {
struct Rig {
  motion::ProfileSet profiles{motion::ProfileSpec{}};
  sequencer::SequencerConfig cfg{};
  sim_hal::SimMachine machine{};
  sim_hal::SceneSpec scene{};
  std::unique_ptr<sim_hal::SimWorld> world;
  std::unique_ptr<sequencer::Sequencer> seq;
  hal::HalInputs in{};
  hal::HalOutputs out{};
  hal::Tick now = 0;

  void build(std::uint32_t rows) {
    cfg.rows_to_weave = rows;
    world = std::make_unique<sim_hal::SimWorld>(machine, scene);
    seq = std::make_unique<sequencer::Sequencer>(profiles, cfg);
    seq->request_start();
  }
  // Runs until finished or max ticks; calls `each` after every tick.
  template <class F>
  void run(hal::Tick max_ticks, F&& each) {
    hal::PortHal hal(*world, *world);
    for (; now < max_ticks && !seq->finished(); ++now) {
      hal.read(now, in);
      seq->step(now, in, out);
      hal.write(now, out);
      each();
    }
  }
};
}  // namespace

TEST(SequencerSim, WeavesThreeRowsWithEveryBeatAndFullCarriageTravel) {
  Rig r;
  r.build(3);
  double carriage_min = 1e9, carriage_max = -1e9;
  std::uint32_t rows_seen = 0;
  r.run(200000, [&] {
    const double x = r.world->axis(hal::CoreAxis::kCarriage).position;
    carriage_min = std::min(carriage_min, x);
    carriage_max = std::max(carriage_max, x);
    if (r.seq->counters().rows != rows_seen) {
      rows_seen = r.seq->counters().rows;
      const auto& row = r.seq->last_row();
      EXPECT_EQ(row.beats, r.profiles.beats_per_row());
      EXPECT_GT(row.shed_ticks, 0);
      EXPECT_GT(row.pick_ticks, 0);
      EXPECT_GT(row.beat_ticks, 0);
    }
  });
  ASSERT_EQ(r.seq->state(), State::kDone) << sequencer::fault_name(r.seq->first_fault());
  EXPECT_EQ(r.seq->counters().rows, 3u);
  EXPECT_EQ(r.seq->counters().picks, 3u);
  EXPECT_EQ(r.seq->counters().beats, 3u * static_cast<std::uint32_t>(r.profiles.beats_per_row()));
  EXPECT_NEAR(carriage_min, 0.0, 1e-12);
  EXPECT_NEAR(carriage_max, r.profiles.carriage_travel_m(), 1e-12);
  // Three picks alternate: left→right, right→left, left→right.
  EXPECT_TRUE(r.world->shuttle_x() > 1.19);
}

TEST(SequencerSim, ServoLagStillWeavesWithoutInterlockTrips) {
  Rig r;
  r.scene.effects = {"servo_lag"};
  r.scene.servo_lag = sim_hal::ServoLag{0.004};
  r.build(2);
  r.run(200000, [] {});
  EXPECT_EQ(r.seq->state(), State::kDone) << sequencer::fault_name(r.seq->first_fault());
  EXPECT_EQ(r.seq->counters().rows, 2u);
}

TEST(SequencerSim, DriveFaultStopsEveryAxisAndKeepsCounters) {
  Rig r;
  r.scene.faults.push_back({.at_s = 12.0,
                            .kind = sim_hal::InjectedFault::kDriveFault,
                            .axis_name = "carriage",
                            .axis = hal::index(hal::CoreAxis::kCarriage),
                            .code = 0x8611});
  r.build(5);
  r.run(200000, [] {});
  ASSERT_EQ(r.seq->state(), State::kFault);
  EXPECT_EQ(r.seq->first_fault(), Fault::kDriveFault);
  EXPECT_EQ(r.seq->fault_axis(), static_cast<int>(hal::CoreAxis::kCarriage));
  EXPECT_EQ(r.seq->fault_detail(), 0x8611);
  const auto counters = r.seq->counters();
  EXPECT_GE(counters.rows, 1u);
  // After the fault: every axis is asked to quick-stop and no target moves any more.
  const hal::HalOutputs at_fault = r.out;
  for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k)
    EXPECT_EQ(at_fault.axes[k].request, hal::AxisRequest::kQuickStop);
  hal::PortHal hal(*r.world, *r.world);
  for (int i = 0; i < 1000; ++i, ++r.now) {
    hal.read(r.now, r.in);
    r.seq->step(r.now, r.in, r.out);
    hal.write(r.now, r.out);
    for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k)
      EXPECT_EQ(r.out.axes[k].target_position, at_fault.axes[k].target_position);
  }
  EXPECT_EQ(r.seq->counters().rows, counters.rows);
  EXPECT_EQ(r.seq->first_fault(), Fault::kDriveFault);  // first fault stays latched
}

// The e-stop chain opens mid-row: latched in the tick the input says so, with the reaction the fault table
// documents — every axis asked to quick-stop, the valves holding their state (a frame never closes onto a
// stopped shuttle), the red lamp on, no cutter — and nothing commanded moves afterwards.
TEST(SequencerSim, EStopMidRowIsLatchedAndStopsEverything) {
  Rig r;
  r.scene.faults.push_back({.at_s = 3.0, .kind = sim_hal::InjectedFault::kEStop});
  r.build(2);
  hal::HalOutputs before{}, at_fault{};
  bool seen = false;
  hal::Tick latched_at = -1;
  r.run(200000, [&] {
    if (!seen && r.seq->first_fault() != Fault::kNone) {
      seen = true;
      at_fault = r.out;
      latched_at = r.now;
      EXPECT_FALSE(r.in.io.estop_ok) << "latched before the chain opened";
    }
    if (!seen) before = r.out;
  });
  ASSERT_TRUE(seen);
  EXPECT_EQ(r.seq->first_fault(), Fault::kEStop);
  EXPECT_EQ(r.seq->state(), State::kFault);
  EXPECT_GT(latched_at, 0);
  for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k) {
    EXPECT_EQ(at_fault.axes[k].request, hal::AxisRequest::kQuickStop) << "axis " << k;
  }
  EXPECT_EQ(at_fault.io.piston_a_extend, before.io.piston_a_extend);
  EXPECT_EQ(at_fault.io.piston_b_extend, before.io.piston_b_extend);
  EXPECT_TRUE(at_fault.io.lamp_red);
  EXPECT_FALSE(at_fault.io.lamp_green);
  EXPECT_EQ(at_fault.io.cutter, decltype(at_fault.io.cutter){});
  // The loop goes on with the chain still open: the targets stay where the fault left them, the valves too.
  hal::PortHal hal(*r.world, *r.world);
  for (int i = 0; i < 1000; ++i, ++r.now) {
    hal.read(r.now, r.in);
    r.seq->step(r.now, r.in, r.out);
    hal.write(r.now, r.out);
    for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k) {
      ASSERT_EQ(r.out.axes[k].target_position, at_fault.axes[k].target_position)
          << "axis " << k << ", tick " << i;
      ASSERT_EQ(r.out.axes[k].request, hal::AxisRequest::kQuickStop) << "axis " << k << ", tick " << i;
    }
    ASSERT_EQ(r.out.io.piston_a_extend, at_fault.io.piston_a_extend);
    ASSERT_EQ(r.out.io.piston_b_extend, at_fault.io.piston_b_extend);
  }
  EXPECT_EQ(r.seq->first_fault(), Fault::kEStop);
}

TEST(SequencerSim, EveryBeatHappensAtFullCrankSpeed) {
  Rig r;
  r.build(1);
  const double fell = r.profiles.beatup().warp().fell;
  int beats = 0;
  double prev_phase = 0.0;
  double prev_pos = r.world->axis(hal::CoreAxis::kBeatCrank).position;
  r.run(200000, [&] {
    const double pos = r.world->axis(hal::CoreAxis::kBeatCrank).position;
    const double phase = motion::wrap_two_pi(pos);
    if (r.seq->state() == State::kBeatSweep && prev_phase < fell && phase >= fell && pos > prev_pos) {
      ++beats;
      EXPECT_NEAR((pos - prev_pos) / r.cfg.period_s, r.profiles.spec().crank.velocity, 1e-6);
    }
    prev_phase = phase;
    prev_pos = pos;
  });
  EXPECT_EQ(beats, r.profiles.beats_per_row());
}

TEST(SequencerSim, NeverSeenFeedbackIsNotStaleRightAfterArming) {
  // On a freshly started bus the first PDOs arrive a few cycles after the first SYNC.
  Rig r;
  r.build(1);
  hal::PortHal hal(*r.world, *r.world);
  for (; r.now < 5; ++r.now) {
    hal.read(r.now, r.in);
    for (auto& a : r.in.axes) a.refreshed = hal::kNeverTick;
    r.seq->step(r.now, r.in, r.out);
    hal.write(r.now, r.out);
  }
  EXPECT_NE(r.seq->state(), State::kFault) << sequencer::fault_name(r.seq->first_fault());
  r.run(200000, [] {});
  EXPECT_EQ(r.seq->state(), State::kDone);
}

TEST(SequencerSim, DeadDriveStopsOnStaleFeedbackAndIsReportedAsHeartbeatLoss) {
  Rig r;
  r.cfg.diagnosis_window_s = 0.3;
  r.build(3);
  hal::PortHal hal(*r.world, *r.world);
  const hal::Tick dead_at = 4000, heartbeat_seen_at = dead_at + 120;  // 240 ms later at 2 ms
  hal::AxisFeedbacks frozen{};
  for (; r.now < dead_at + 400; ++r.now) {
    hal.read(r.now, r.in);
    if (r.now == dead_at) frozen = r.in.axes;
    if (r.now >= dead_at) r.in.axes = frozen;  // no more PDOs from any drive
    if (r.now >= heartbeat_seen_at) {
      r.in.axes[hal::index(hal::CoreAxis::kHelix)].fault = true;
      r.in.axes[hal::index(hal::CoreAxis::kHelix)].fault_code = 0x8130;
      r.in.axes[hal::index(hal::CoreAxis::kHelix)].fault_kind = hal::FaultKind::kNodeLost;
    }
    r.seq->step(r.now, r.in, r.out);
    hal.write(r.now, r.out);
    if (r.now == heartbeat_seen_at - 1) {
      ASSERT_EQ(r.seq->state(), State::kFault);
      EXPECT_EQ(r.seq->first_fault(), Fault::kStaleFeedback);  // motion already stopped
    }
  }
  EXPECT_EQ(r.seq->first_fault(), Fault::kHeartbeatLost);
  EXPECT_EQ(r.seq->stopped_by(), Fault::kStaleFeedback);
  EXPECT_EQ(r.seq->fault_axis(), static_cast<int>(hal::CoreAxis::kHelix));
}

TEST(SequencerSim, RootCauseOutsideTheWindowDoesNotRewriteHistory) {
  Rig r;
  r.cfg.diagnosis_window_s = 0.1;
  r.build(3);
  hal::PortHal hal(*r.world, *r.world);
  hal::AxisFeedbacks frozen{};
  for (; r.now < 5000; ++r.now) {
    hal.read(r.now, r.in);
    if (r.now == 4000) frozen = r.in.axes;
    if (r.now >= 4000) r.in.axes = frozen;
    if (r.now >= 4200) r.in.axes[0].fault = true;  // 400 ms later: too late to be the cause
    r.seq->step(r.now, r.in, r.out);
    hal.write(r.now, r.out);
  }
  EXPECT_EQ(r.seq->first_fault(), Fault::kStaleFeedback);
}

TEST(SequencerSim, PauseHoldsAtTheNextSafePointAndResumeContinues) {
  Rig r;
  r.build(3);
  r.run(1000, [] {});  // into the first pick
  r.seq->request_pause();
  r.run(200000, [&] {
    if (r.seq->state() == State::kPaused) r.now = 200000;  // stop the run loop once paused
  });
  ASSERT_EQ(r.seq->state(), State::kPaused);
  EXPECT_EQ(r.seq->counters().rows, 1u);  // the row in progress was finished first
  // Paused: nothing moves.
  const hal::HalOutputs held = r.out;
  hal::PortHal hal(*r.world, *r.world);
  for (int i = 0; i < 500; ++i, ++r.now) {
    hal.read(r.now, r.in);
    r.seq->step(r.now, r.in, r.out);
    hal.write(r.now, r.out);
    for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k)
      EXPECT_EQ(r.out.axes[k].target_position, held.axes[k].target_position);
  }
  r.seq->request_resume();
  r.run(r.now + 200000, [] {});
  EXPECT_EQ(r.seq->state(), State::kDone);
  EXPECT_EQ(r.seq->counters().rows, 3u);
  EXPECT_EQ(r.seq->counters().picks, 3u);
}

TEST(SequencerSim, TwoPicksPerRowAlternateTheShedAndTheShuttle) {
  Rig r;
  r.cfg.picks_per_row = 2;
  r.build(2);
  r.run(200000, [] {});
  ASSERT_EQ(r.seq->state(), State::kDone) << sequencer::fault_name(r.seq->first_fault());
  EXPECT_EQ(r.seq->counters().picks, 4u);
  EXPECT_LT(r.world->shuttle_x(), 0.01);  // four picks: back at the left selvedge
}

TEST(SequencerSim, NewRecipeIsAdoptedAtTheNextRowBoundaryWithoutStopping) {
  motion::ProfileSlot slot(std::make_unique<const motion::ProfileSet>(motion::ProfileSpec{}));
  sequencer::SequencerConfig cfg;
  cfg.rows_to_weave = 3;
  sim_hal::SimWorld world(sim_hal::SimMachine{}, sim_hal::SceneSpec{});
  sequencer::Sequencer seq(slot, cfg);
  seq.request_start();
  hal::PortHal hal(world, world);
  hal::HalInputs in{};
  hal::HalOutputs out{};
  std::vector<int> beats;
  std::uint32_t rows = 0;
  bool published = false;
  for (hal::Tick t = 0; t < 300000 && !seq.finished(); ++t) {
    hal.read(t, in);
    seq.step(t, in, out);
    hal.write(t, out);
    if (!published && seq.state() == State::kBeatSweep) {
      // During row 1's beat sweep: a recipe beating every position twice. Row 1 must finish as planned.
      motion::ProfileSpec twice;
      twice.beats_per_position = 2;
      slot.publish(std::make_unique<const motion::ProfileSet>(twice));
      published = true;
    }
    if (seq.counters().rows != rows) {
      rows = seq.counters().rows;
      beats.push_back(seq.last_row().beats);
    }
    if (t % 1000 == 0) slot.collect();
  }
  ASSERT_EQ(seq.state(), State::kDone) << sequencer::fault_name(seq.first_fault());
  EXPECT_EQ(beats, (std::vector<int>{15, 30, 30}));
  EXPECT_EQ(seq.recipe_changes(), 1u);
  EXPECT_EQ(seq.profiles().beats_per_row(), 30);
}

// The row-boundary handshake (a counters file is kept): the sequencer parks at each row end until the
// reporter confirms the row on disk; nothing moves meanwhile; a failed save and a save never confirmed
// are the fault counters_not_saved at that safe point, with the counters kept.
TEST(SequencerSim, EachRowWaitsUntilTheOneBeforeIsOnDisk) {
  Rig r;
  r.cfg.await_row_saved = true;
  r.build(2);
  hal::Tick row_end_at = -1;  // when row 1 ended
  hal::HalOutputs parked{};
  bool moved_while_waiting = false, waiting = false;
  r.run(200000, [&] {
    if (r.seq->state() != State::kRowEnd) {
      waiting = false;
      return;
    }
    if (!waiting) {  // just parked at a boundary
      waiting = true;
      parked = r.out;
      if (row_end_at < 0) row_end_at = r.now;
    }
    for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k) {
      moved_while_waiting =
          moved_while_waiting || r.out.axes[k].target_position != parked.axes[k].target_position;
    }
    // The reporter confirms row 1 one second (500 ticks) after it ended.
    if (r.now - row_end_at == 500) r.seq->note_rows_saved(1, false);
    if (r.seq->counters().rows == 2) r.seq->note_rows_saved(2, false);
  });
  ASSERT_EQ(r.seq->state(), State::kDone) << sequencer::fault_name(r.seq->first_fault());
  EXPECT_EQ(r.seq->counters().rows, 2u);
  EXPECT_FALSE(moved_while_waiting);
  ASSERT_GE(row_end_at, 0);
  // Row 2 (started only after the confirmation) ended at least 500 ticks plus its own length after row 1.
  EXPECT_GE(r.now - row_end_at, 500 + r.seq->last_row().total_ticks);
}

TEST(SequencerSim, AFailedRowSaveStopsAtTheBoundaryWithCountersNotSaved) {
  Rig r;
  r.cfg.await_row_saved = true;
  r.build(3);
  r.run(200000, [&] {
    if (r.seq->state() == State::kRowEnd) r.seq->note_rows_saved(0, true);
  });
  EXPECT_EQ(r.seq->state(), State::kFault);
  EXPECT_EQ(r.seq->first_fault(), Fault::kCountersNotSaved);
  EXPECT_EQ(r.seq->counters().rows, 1u);
  EXPECT_EQ(r.seq->counters().picks, 1u);
}

TEST(SequencerSim, ASaveNeverConfirmedTimesOutWithCountersNotSaved) {
  Rig r;
  r.cfg.await_row_saved = true;
  r.cfg.row_save_timeout_s = 0.5;
  r.build(3);
  hal::Tick row_end_at = -1;
  r.run(200000, [&] {
    if (r.seq->state() == State::kRowEnd && row_end_at < 0) row_end_at = r.now;
  });
  EXPECT_EQ(r.seq->first_fault(), Fault::kCountersNotSaved);
  EXPECT_EQ(r.seq->counters().rows, 1u);
  EXPECT_NEAR(static_cast<double>(r.seq->fault_tick() - row_end_at) * r.cfg.period_s, 0.5,
              2.0 * r.cfg.period_s);
}

// Knotting mode: before every new row the loom parks and waits for the weaver's "row knotted" — the
// pedal input (debounced, on its rising edge) or request_row_knotted() — and records how long it waited.
TEST(SequencerSim, KnottingModeWaitsBeforeEveryRowForTheWeaver) {
  Rig r;
  r.cfg.knotting = true;
  r.build(2);
  hal::PortHal hal(*r.world, *r.world);
  hal::Tick waiting_since = -1;
  int waits = 0, pedal_ticks = 0;
  bool moved_while_waiting = false;
  hal::HalOutputs parked{};
  for (; r.now < 200000 && !r.seq->finished(); ++r.now) {
    hal.read(r.now, r.in);
    // The weaver presses the pedal 300 ticks into each wait and holds it for 20 ticks (the simulated
    // world has no pedal: the input is set here on every tick).
    r.in.io.row_knotted = waiting_since >= 0 && r.now - waiting_since >= 300 && pedal_ticks < 20;
    if (r.in.io.row_knotted) ++pedal_ticks;
    r.seq->step(r.now, r.in, r.out);
    sequencer::apply_presses(*r.seq);  // the owner: the pedal's press becomes request_row_knotted()
    hal.write(r.now, r.out);
    if (r.seq->state() == State::kAwaitKnotting) {
      if (waiting_since < 0) {
        waiting_since = r.now;
        parked = r.out;
        pedal_ticks = 0;
        ++waits;
      }
      for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k) {
        moved_while_waiting =
            moved_while_waiting || r.out.axes[k].target_position != parked.axes[k].target_position;
      }
      EXPECT_TRUE(r.out.io.lamp_amber);
    } else if (pedal_ticks >= 20) {
      waiting_since = -1;  // the pedal released: the next wait is a new one
    }
  }
  ASSERT_EQ(r.seq->state(), State::kDone) << sequencer::fault_name(r.seq->first_fault()) << " waits " << waits
                                          << " rows " << r.seq->counters().rows;
  EXPECT_EQ(waits, 2);  // before row 1 and before row 2
  EXPECT_FALSE(moved_while_waiting);
  // Recorded with the row: the pedal's debounce (3 ticks) after 300 ticks, give or take a tick.
  EXPECT_NEAR(static_cast<double>(r.seq->last_row().knotting_ticks), 300.0 + r.cfg.debounce_ticks, 2.0);
}

// The pedal is reported like any button and acted on by nobody but the owner: without one the wait goes on.
TEST(SequencerSim, ThePedalAloneDoesNotEndTheKnottingWait) {
  Rig r;
  r.cfg.knotting = true;
  r.build(2);
  hal::PortHal hal(*r.world, *r.world);
  int presses = 0;
  hal::Tick waiting_since = -1;
  for (; r.now < 20000 && !r.seq->finished(); ++r.now) {
    hal.read(r.now, r.in);
    // Pressed for 20 ticks, 300 and 600 ticks into the wait: two presses.
    const hal::Tick into = waiting_since < 0 ? -1 : r.now - waiting_since;
    r.in.io.row_knotted = (into >= 300 && into < 320) || (into >= 600 && into < 620);
    r.seq->step(r.now, r.in, r.out);
    hal.write(r.now, r.out);
    for (const sequencer::TickEvent& e : r.seq->events()) {
      presses += e.kind == sequencer::EventKind::kButton && e.button == sequencer::Button::kRowKnotted;
    }
    if (r.seq->state() == State::kAwaitKnotting && waiting_since < 0) waiting_since = r.now;
  }
  ASSERT_GE(waiting_since, 0) << sequencer::fault_name(r.seq->first_fault());
  EXPECT_EQ(presses, 2);
  EXPECT_EQ(r.seq->state(), State::kAwaitKnotting);
  EXPECT_EQ(r.seq->counters().rows, 0u);
}

TEST(SequencerSim, KnottingWaitEndsOnRequestAndAStopThereIsDone) {
  Rig r;
  r.cfg.knotting = true;
  r.build(3);
  int knots = 0;
  r.run(200000, [&] {
    if (r.seq->state() != State::kAwaitKnotting) return;
    if (r.seq->counters().rows < 1) {
      r.seq->request_row_knotted();
      ++knots;
    } else {
      r.seq->request_stop();  // waiting before row 2: a stop ends the session here
    }
  });
  EXPECT_EQ(r.seq->state(), State::kDone);
  EXPECT_EQ(r.seq->counters().rows, 1u);
  EXPECT_EQ(knots, 1);
}

// Feedback the sequencer must not believe (NaN, EMCY on an enabled drive, a vanished load cell), the
// operator's requests (stop now, acknowledge, buttons) and the stack light, on the simulated loom.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "loom/hal/hal.hpp"
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
  sim_hal::SceneSpec scene{};
  std::unique_ptr<sim_hal::SimWorld> world;
  std::unique_ptr<sequencer::Sequencer> seq;
  hal::HalInputs in{};
  hal::HalOutputs out{};
  hal::Tick now = 0;
  std::function<void(hal::Tick, hal::HalInputs&)> tamper = [](hal::Tick, hal::HalInputs&) {};

  void build(std::uint32_t rows, bool start = true) {
    cfg.rows_to_weave = rows;
    world = std::make_unique<sim_hal::SimWorld>(sim_hal::SimMachine{}, scene);
    seq = std::make_unique<sequencer::Sequencer>(profiles, cfg);
    if (start) seq->request_start();
  }
  // Runs `ticks` ticks or until `until` says stop.
  void run(
      hal::Tick ticks, const std::function<bool()>& until = [] { return false; }) {
    hal::PortHal hal(*world, *world);
    for (const hal::Tick end = now + ticks; now < end; ++now) {
      hal.read(now, in);
      tamper(now, in);
      seq->step(now, in, out);
      sequencer::apply_presses(*seq);  // the owner: the I/O module's presses become requests
      hal.write(now, out);
      if (until()) {
        ++now;
        return;
      }
    }
  }
};
}  // namespace

TEST(SequencerFaults, NonFiniteAxisFeedbackIsAFaultOnThatAxis) {
  Rig r;
  r.tamper = [](hal::Tick t, hal::HalInputs& in) {
    if (t >= 3000)
      in.axes[hal::index(hal::CoreAxis::kCarriage)].velocity = std::numeric_limits<double>::quiet_NaN();
  };
  r.build(3);
  r.run(5000);
  EXPECT_EQ(r.seq->first_fault(), Fault::kNonFiniteFeedback);
  EXPECT_EQ(r.seq->fault_axis(), static_cast<int>(hal::CoreAxis::kCarriage));
  EXPECT_EQ(r.seq->fault_tick(), 3000);
}

TEST(SequencerFaults, EmcyFromAnEnabledDriveStopsInTheSameTick) {
  Rig r;
  r.tamper = [](hal::Tick t, hal::HalInputs& in) {
    if (t >= 3000) {
      in.axes[hal::index(hal::CoreAxis::kHelix)].fault_code = 0x2310;
      in.axes[hal::index(hal::CoreAxis::kHelix)].fault_kind = hal::FaultKind::kEmcy;
    }
  };
  r.build(3);
  r.run(5000);
  EXPECT_EQ(r.seq->first_fault(), Fault::kDriveEmcy);
  EXPECT_EQ(r.seq->fault_detail(), 0x2310);
  EXPECT_EQ(r.seq->fault_tick(), 3000);
  for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k)
    EXPECT_EQ(r.out.axes[k].request, hal::AxisRequest::kQuickStop);
}

TEST(SequencerFaults, ALoadCellThatVanishesOrReadsNaNIsAFault) {
  for (const bool nan : {false, true}) {
    Rig r;
    r.scene.effects = {"ideal", "beat_contact"};
    r.tamper = [nan](hal::Tick t, hal::HalInputs& in) {
      if (t < 3000) return;
      if (nan) {
        in.analog.beat_force_n = std::numeric_limits<double>::quiet_NaN();
      } else {
        in.analog.beat_force_valid = false;
      }
    };
    r.build(3);
    r.run(5000);
    EXPECT_EQ(r.seq->first_fault(), Fault::kLoadCellFault) << "nan " << nan;
  }
}

TEST(SequencerFaults, StopNowStopsAtOnceKeepsTheCountersAndAcknowledgeRearms) {
  Rig r;
  r.build(3);
  r.run(1000);  // mid first row
  const sequencer::Counters before = r.seq->counters();
  r.seq->request_stop_now();
  r.run(1);
  EXPECT_EQ(r.seq->state(), State::kFault);
  EXPECT_EQ(r.seq->first_fault(), Fault::kStopRequested);
  EXPECT_EQ(r.seq->counters().picks, before.picks);
  EXPECT_TRUE(r.out.io.lamp_red);
  EXPECT_FALSE(r.out.io.lamp_green);
  r.run(100);
  EXPECT_EQ(r.seq->state(), State::kFault);  // latched until acknowledged
  r.seq->request_acknowledge();
  r.run(1);
  EXPECT_EQ(r.seq->state(), State::kIdle);
  EXPECT_EQ(r.seq->first_fault(), Fault::kNone);
  for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k)
    EXPECT_EQ(r.out.axes[k].request, hal::AxisRequest::kFaultReset);
  EXPECT_TRUE(r.out.io.lamp_amber);
  r.seq->request_start();
  r.run(200000, [&] { return r.seq->finished(); });
  EXPECT_EQ(r.seq->state(), State::kDone) << sequencer::fault_name(r.seq->first_fault());
  EXPECT_EQ(r.seq->counters().rows, 3u);
  EXPECT_EQ(r.seq->counters().picks, 3u);  // the pick cut by the stop was finished, not repeated
}

TEST(SequencerFaults, ButtonsAreDebouncedEdgesAndAButtonHeldAtPowerOnIsNoPress) {
  Rig r;
  bool start = true, pause = false;
  r.tamper = [&](hal::Tick, hal::HalInputs& in) {
    in.io.button_start = start;
    in.io.button_pause = pause;
  };
  r.build(2, /*start=*/false);
  r.run(50);
  EXPECT_EQ(r.seq->state(), State::kIdle);  // held since power-on: not a press
  EXPECT_TRUE(r.out.io.lamp_amber);
  start = false;
  r.run(10);
  start = true;
  r.run(2);  // shorter than the debounce: contact bounce, not a press
  start = false;
  r.run(10);
  EXPECT_EQ(r.seq->state(), State::kIdle);
  start = true;
  r.run(10);
  start = false;
  EXPECT_NE(r.seq->state(), State::kIdle);
  r.run(100);
  EXPECT_TRUE(r.out.io.lamp_green);
  pause = true;
  r.run(10);
  pause = false;
  r.run(200000, [&] { return r.seq->state() == State::kPaused; });
  EXPECT_EQ(r.seq->state(), State::kPaused);
  EXPECT_TRUE(r.out.io.lamp_amber);
  start = true;  // start also resumes
  r.run(10);
  start = false;
  r.run(200000, [&] { return r.seq->finished(); });
  EXPECT_EQ(r.seq->state(), State::kDone) << sequencer::fault_name(r.seq->first_fault());
  EXPECT_EQ(r.seq->counters().rows, 2u);
}

// Issue 22: an acknowledgement given before a fault acknowledged it (the drives got "disable voltage"
// while moving, no red lamp, no fault). From both sources — the I/O module's button and a command — an
// ack before the fault is discarded: the e-stop that follows is latched, quick-stops, lights red and stays
// latched; an ack while the chain is still open is refused; only a press after the chain closed re-arms.
TEST(SequencerFaults, AnAcknowledgementBeforeTheFaultIsDiscardedAndOneWhileTheChainIsOpenRefused) {
  for (const bool by_button : {true, false}) {
    SCOPED_TRACE(by_button ? "ack button" : "request_acknowledge");
    Rig r;
    bool ack = false, chain_open = false;
    r.tamper = [&](hal::Tick, hal::HalInputs& in) {
      in.io.button_ack = ack;
      if (chain_open) in.io.estop_ok = false;
    };
    const auto press = [&] {
      if (by_button) {
        ack = true;
        r.run(150);  // 0.3 s at 2 ms
        ack = false;
        r.run(10);
      } else {
        r.seq->request_acknowledge();
        r.run(1);
      }
    };
    r.build(3);
    r.run(1500);
    ASSERT_NE(r.seq->state(), State::kFault) << sequencer::fault_name(r.seq->first_fault());
    ASSERT_NE(r.seq->state(), State::kIdle);
    press();  // while weaving, no fault: not an acknowledgement
    EXPECT_NE(r.seq->state(), State::kFault);
    r.run(800);  // 1.6 s later the e-stop chain opens
    chain_open = true;
    r.run(1);
    EXPECT_EQ(r.seq->state(), State::kFault);
    EXPECT_EQ(r.seq->first_fault(), Fault::kEStop);
    for (std::size_t k = 0; k < hal::kCoreAxisCount; ++k)
      EXPECT_EQ(r.out.axes[k].request, hal::AxisRequest::kQuickStop);
    r.run(300);
    EXPECT_EQ(r.seq->state(), State::kFault) << "the stale acknowledgement was taken";
    EXPECT_TRUE(r.out.io.lamp_red);
    EXPECT_FALSE(r.out.io.lamp_amber);
    press();  // the chain is still open: refused, still latched
    EXPECT_EQ(r.seq->state(), State::kFault);
    EXPECT_EQ(r.seq->first_fault(), Fault::kEStop);
    chain_open = false;
    r.run(50);
    EXPECT_EQ(r.seq->state(), State::kFault);  // closing the chain acknowledges nothing
    press();
    EXPECT_EQ(r.seq->state(), State::kIdle);
    EXPECT_EQ(r.seq->first_fault(), Fault::kNone);
  }
}

TEST(SequencerFaults, BeatsPerRowBeyondCapacityAreRefusedAtConfiguration) {
  motion::ProfileSpec wide;
  wide.width_m = 3.0;
  wide.beats_per_position = 8;
  const motion::ProfileSet p(wide);
  ASSERT_GT(p.beats_per_row(), sequencer::kMaxBeatsPerRow);
  const std::string why = sequencer::validate(sequencer::SequencerConfig{}, p);
  EXPECT_NE(why.find("recipe.beats_per_position"), std::string::npos) << why;
  EXPECT_THROW(sequencer::Sequencer(p, sequencer::SequencerConfig{}), std::invalid_argument);
  sequencer::SequencerConfig nan_park;
  nan_park.crank_park_position_rad = std::nan("");
  EXPECT_NE(sequencer::validate(nan_park, motion::ProfileSet(motion::ProfileSpec{})), "");
}

// ---- Debouncing (debounce.hpp) ------------------------------------------------------------------

TEST(Debouncer, AChangeCountsOnlyWhileItLastsAndStartsOverWhenTheInputGoesBack) {
  sequencer::Debouncer<2> d(3);
  d.update({false, true});  // the first update adopts the inputs as they are
  EXPECT_FALSE(d[0]);
  EXPECT_TRUE(d[1]);
  // Input 0 reads on for two ticks, off for one, on for two: never three in a row, never adopted.
  const bool seq[] = {true, true, false, true, true};
  for (bool raw : seq) {
    d.update({raw, true});
    EXPECT_FALSE(d[0]);
  }
  d.update({true, true});  // the third tick on in a row
  EXPECT_TRUE(d[0]);
  EXPECT_TRUE(d[1]) << "the other input never changed";
  // Unchanged inputs for many ticks change nothing, and a later change again needs three ticks.
  for (int i = 0; i < 10; ++i) d.update({true, true});
  d.update({true, false});
  d.update({true, false});
  EXPECT_TRUE(d[1]);
  d.update({true, false});
  EXPECT_FALSE(d[1]);
}

// ---- Dual-channel safety sensors (dual_channel.hpp) ----------------------------------------------

TEST(DualChannelSensors, ASensorIsOnOnlyWhileBothChannelsSayOnWhereASecondIsWired) {
  sequencer::DualChannelSensors d({true, true, true, true, false, true}, 10);
  const auto v = d.agreed({true, true, false, false, true, true}, {true, false, true, false, false, false});
  EXPECT_TRUE(v[0]);   // both on
  EXPECT_FALSE(v[1]);  // second off: not confirmed
  EXPECT_FALSE(v[2]);  // first off: not confirmed, whatever the second says
  EXPECT_FALSE(v[3]);
  EXPECT_TRUE(v[4]);  // no second channel: the first alone
  EXPECT_FALSE(v[5]);
}

TEST(DualChannelSensors, EveryPictureOfBothChannelsAgreesSensorBySensor) {
  // All 2^18 combinations of wiring and the two channels' six sensors, against the rule written out
  // per sensor: on only while the first says on and, where a second is wired, the second too.
  using Channels = sequencer::DualChannelSensors::Channels;
  const auto picture = [](unsigned bits) {
    Channels c{};
    for (std::size_t i = 0; i < c.size(); ++i) c[i] = (bits >> i) & 1U;
    return c;
  };
  for (unsigned w = 0; w < 64; ++w) {
    const Channels wired = picture(w);
    const sequencer::DualChannelSensors d(wired, 3);
    for (unsigned f = 0; f < 64; ++f) {
      for (unsigned s = 0; s < 64; ++s) {
        const Channels first = picture(f), second = picture(s);
        const Channels v = d.agreed(first, second);
        for (std::size_t i = 0; i < v.size(); ++i) {
          const bool expected = wired[i] ? (first[i] && second[i]) : first[i];
          ASSERT_EQ(v[i], expected) << "wired " << w << " first " << f << " second " << s << " sensor " << i;
        }
      }
    }
  }
}

TEST(DualChannelSensors, ADisagreementIsAFaultOnlyOnceItLastsTheDiscrepancyTime) {
  sequencer::DualChannelSensors d({true, true, true, true, true, false}, 4);
  const sequencer::DualChannelSensors::Channels first{false, false, false, false, true, true};
  sequencer::DualChannelSensors::Channels second{false, false, false, false, false, false};
  for (int i = 0; i < 3; ++i) {
    d.track(first, second);
    EXPECT_EQ(d.discrepant(), -1) << "tick " << i;
  }
  d.track(first, {false, false, false, false, true, false});  // the channels agree again: the count restarts
  for (int i = 0; i < 3; ++i) d.track(first, second);
  EXPECT_EQ(d.discrepant(), -1);
  d.track(first, second);
  EXPECT_EQ(d.discrepant(), static_cast<int>(hal::SafetySensor::kShuttleAtLeft));
  // Sensor 5 has no second channel: its "disagreement" is never counted.
  sequencer::DualChannelSensors unwired({false, false, false, false, false, false}, 1);
  for (int i = 0; i < 5; ++i) unwired.track(first, second);
  EXPECT_EQ(unwired.discrepant(), -1);
}

namespace {
// The rig with second switches on all six safety sensors, in the simulator and the sequencer.
void fit_second_channels(Rig& r, sim_hal::SimMachine& m) {
  r.cfg.second_channel.fill(true);
  m.second_channel.fill(true);
}
void build_dual(Rig& r, std::uint32_t rows) {
  sim_hal::SimMachine m;
  fit_second_channels(r, m);
  r.cfg.rows_to_weave = rows;
  r.world = std::make_unique<sim_hal::SimWorld>(m, r.scene);
  r.seq = std::make_unique<sequencer::Sequencer>(r.profiles, r.cfg);
  r.seq->request_start();
}
}  // namespace

TEST(SequencerFaults, HealthySecondChannelsAgreeAndTheLoomWeavesEvenWithBounce) {
  Rig r;
  r.scene.effects = {sim_hal::kEffectIdeal, sim_hal::kEffectSensorNoise};
  r.scene.sensor_noise = sim_hal::SensorNoise{0.01};
  build_dual(r, 2);
  r.run(60000, [&] { return r.seq->finished(); });
  EXPECT_EQ(r.seq->state(), State::kDone) << sequencer::fault_name(r.seq->first_fault());
  EXPECT_EQ(r.seq->counters().rows, 2u);
}

TEST(SequencerFaults, AFirstChannelThatSaysArrivedAloneConfirmsNothingAndIsADiscrepancy) {
  // The arrival switch at the right (first channel) claims the shuttle from the first tick of the first
  // pick on, while the shuttle is still at the left and the second switch says so: no pick may be
  // counted on its word, and the disagreement is the fault sensor_discrepancy naming shuttle_at_right.
  Rig r;
  hal::Tick lies_from = -1;
  r.tamper = [&](hal::Tick t, hal::HalInputs& in) {
    if (lies_from < 0 && r.seq && r.seq->state() == State::kPick) lies_from = t;
    if (lies_from >= 0) in.io.shuttle_at_right = true;
  };
  build_dual(r, 2);
  r.run(20000, [&] { return r.seq->state() == State::kFault; });
  ASSERT_GE(lies_from, 0) << "the loom never reached its first pick";
  EXPECT_EQ(r.seq->first_fault(), Fault::kSensorDiscrepancy) << sequencer::fault_name(r.seq->first_fault());
  EXPECT_EQ(r.seq->fault_sensor(), static_cast<int>(hal::SafetySensor::kShuttleAtRight));
  EXPECT_EQ(r.seq->counters().picks, 0u);
  // Debounce (3 ticks) + discrepancy time (20 ms = 10 ticks at 2 ms): found within 13 ticks.
  EXPECT_GE(r.seq->fault_tick(), lies_from);
  EXPECT_LE(r.seq->fault_tick(), lies_from + 13);
}

TEST(SequencerFaults, ASecondChannelThatNeverSwitchesIsFoundAtTheFirstStroke) {
  // The second switch of piston A's extended end is dead (reads off for ever): the first stroke that
  // extends A shows the two channels apart, and the shed is never confirmed on the first alone.
  Rig r;
  r.tamper = [](hal::Tick, hal::HalInputs& in) {
    in.io.second_channel[static_cast<std::size_t>(hal::SafetySensor::kPistonAExtended)] = false;
  };
  build_dual(r, 2);
  r.run(20000, [&] { return r.seq->state() == State::kFault; });
  EXPECT_EQ(r.seq->first_fault(), Fault::kSensorDiscrepancy) << sequencer::fault_name(r.seq->first_fault());
  EXPECT_EQ(r.seq->fault_sensor(), static_cast<int>(hal::SafetySensor::kPistonAExtended));
  EXPECT_EQ(r.seq->counters().picks, 0u);
}

// validate()'s refusals carry their field (the config maps it to its key, never reading the message).
TEST(SequencerFaults, ConfigurationRefusalsCarryTheirField) {
  const motion::ProfileSet p{motion::ProfileSpec{}};
  EXPECT_FALSE(sequencer::find_fault(sequencer::SequencerConfig{}, p).has_value());
  const auto expect = [&](const sequencer::SequencerConfig& c, sequencer::SequencerField field,
                          const char* names) {
    const std::optional<sequencer::SequencerFault> f = sequencer::find_fault(c, p);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->field, field) << f->message;
    EXPECT_EQ(f->message, sequencer::validate(c, p));
    EXPECT_NE(f->message.find(names), std::string::npos) << f->message;
  };
  sequencer::SequencerConfig c;
  c.period_s = 0.0;
  expect(c, sequencer::SequencerField::kPeriod, "timing.period_ms");
  c = {};
  c.sensor_discrepancy_s = c.period_s / 2;
  expect(c, sequencer::SequencerField::kSensorDiscrepancy, "timing.sensor_discrepancy_ms");
  c = {};
  c.helix_left_position_rad = 2e6;
  expect(c, sequencer::SequencerField::kHelixLeftPosition, "helix.left_position_rad");
  c = {};
  c.row_save_timeout_s = std::numeric_limits<double>::infinity();
  expect(c, sequencer::SequencerField::kRowSaveTimeout, "timing.row_save_timeout_s");
  c = {};
  c.debounce_ticks = 0;
  expect(c, sequencer::SequencerField::kDebounceTicks, "timing.debounce_ticks");
}

// A reading that lies while the drives enable (an encoder glitch within the plausible step, so no fault)
// must not become motion: a drive enables on the target of its tick, and the frames are closed. Found by
// the safety campaign (seed 110157238, run 53251: the helix turned 0.069 rad with its lag, at tick 1).
TEST(SequencerFaults, AReadingThatLiesWhileTheDrivesEnableMovesNothing) {
  Rig r;
  sim_hal::FaultInjection glitch;
  glitch.kind = sim_hal::InjectedFault::kEncoderGlitch;
  glitch.axis = hal::index(hal::CoreAxis::kHelix);
  glitch.axis_name = "helix";
  glitch.at_s = 0.5 * r.cfg.period_s;  // read from tick 1 on, when the loom starts enabling
  glitch.jump = 0.3;                   // rad: within one tick's plausible step of the helix
  glitch.ticks = 4;
  r.scene.faults.push_back(glitch);
  r.build(1);
  const std::size_t helix = hal::index(hal::CoreAxis::kHelix);
  const double at_rest = r.world->axis(helix).position;
  bool glitch_read = false;
  for (int t = 0; t < 10; ++t) {
    r.run(1);
    glitch_read = glitch_read || std::abs(r.in.axes[helix].position - at_rest) > 0.29;
    EXPECT_EQ(r.world->axis(helix).position, at_rest)
        << "tick " << t << ", state " << sequencer::state_name(r.seq->state());
  }
  EXPECT_TRUE(glitch_read) << "the glitch was never read: the test shows nothing";
}

// The runner's real-time pacing against an injected fake clock: deadlines stay on the period grid, an
// overrun is counted and re-phased (never caught up in a burst), N consecutive overruns latch
// loop_overrun (a safe stop), and the wake-up latency and tick cost it reports are the ones the clock
// and the HAL were scripted to produce. The loop is the real one: sim HAL, real sequencer.
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/firmware/control_loop.hpp"
#include "loom/firmware/run_summary.hpp"
#include "loom/firmware/runner.hpp"
#include "loom/sim_hal/sim_world.hpp"

using namespace loom;
using firmware::RunOptions;
using firmware::RunResult;

namespace {

constexpr std::int64_t kPeriodNs = 2'000'000;

// Time moves only when the loop sleeps (to the deadline plus a scripted wake-up latency) or when the
// HAL "works" (the scripted cost of a tick). Only the loop thread touches it while the loop runs.
class FakeClock final : public firmware::LoopClock {
 public:
  std::int64_t now_ns() noexcept override { return now_; }
  void sleep_until(std::int64_t d) noexcept override {
    sleeps.push_back(d);
    now_before_sleep.push_back(now_);
    if (d > now_) now_ = d;
    now_ += wake_latency_ns;
  }
  void advance(std::int64_t ns) noexcept { now_ += ns; }
  std::int64_t now_ = 1'000'000'000;
  std::int64_t wake_latency_ns = 0;
  std::vector<std::int64_t> sleeps, now_before_sleep;
};

// The simulated HAL, plus a scripted cost per tick charged to the fake clock inside cycle().
class SlowHal final : public hal::Hal {
 public:
  SlowHal(hal::Hal& inner, FakeClock& clock) : inner_(inner), clock_(clock) {}
  void read(hal::Tick now, hal::HalInputs& in) noexcept override {
    const auto i = static_cast<std::size_t>(now);
    clock_.advance(i < cost_ns.size() ? cost_ns[i] : default_cost_ns);
    inner_.read(now, in);
    if (script) script(now);
    in.io.button_start = start_pressed;  // the I/O module's buttons, held as scripted
    in.io.button_pause = pause_pressed;
    in.io.button_ack = ack_pressed;
    in.io.row_knotted = knotted_pressed;  // the weaver's pedal
    if (recovery) {                       // a CAN link's recovery state, as the CAN ports report it
      in.link.recovery = *recovery;
      in.link.silent_node = silent_node;
    }
  }
  void write(hal::Tick now, const hal::HalOutputs& out) noexcept override { inner_.write(now, out); }
  std::vector<std::int64_t> cost_ns;
  std::int64_t default_cost_ns = 10'000;
  std::optional<hal::LinkRecovery> recovery;
  std::uint8_t silent_node = 0;
  bool start_pressed = false, pause_pressed = false, ack_pressed = false, knotted_pressed = false;
  std::function<void(hal::Tick)> script;  // called with each tick before its buttons are read

 private:
  hal::Hal& inner_;
  FakeClock& clock_;
};

struct Rig {
  Rig() {
    cfg = firmware::default_loom_config();
    profiles = std::make_unique<motion::ProfileSet>(cfg.profile);
    seq = std::make_unique<sequencer::Sequencer>(*profiles, cfg.sequencer);
    sim = std::make_unique<sim_hal::SimWorld>(cfg.machine, firmware::default_scene().spec);
    port = std::make_unique<hal::PortHal>(*sim, *sim);
    slow = std::make_unique<SlowHal>(*port, clock);
    loop = std::make_unique<firmware::ControlLoop>(*slow, *seq, nullptr, cfg.timing.period_ns, false);
  }
  RunResult run(hal::Tick ticks, std::uint32_t overrun_stop_after = 0) {
    RunOptions o;
    o.period_s = cfg.sequencer.period_s;
    o.realtime = true;
    o.fifo_priority = 0;  // the fake clock never sleeps: a SCHED_FIFO spin here would starve the machine
    o.max_ticks = ticks;
    o.clock = &clock;
    o.overrun_stop_after = overrun_stop_after;
    seq->request_start();
    return firmware::run_loop(*loop, *seq, o, [](const firmware::RunEvent&) {});
  }
  firmware::LoomConfig cfg;
  FakeClock clock;
  std::unique_ptr<motion::ProfileSet> profiles;
  std::unique_ptr<sequencer::Sequencer> seq;
  std::unique_ptr<sim_hal::SimWorld> sim;
  std::unique_ptr<hal::PortHal> port;
  std::unique_ptr<SlowHal> slow;
  std::unique_ptr<firmware::ControlLoop> loop;
};

}  // namespace

TEST(RunnerClock, DeadlinesFollowThePeriodGridWithoutOverruns) {
  Rig r;
  ASSERT_EQ(r.cfg.sequencer.period_s, 0.002);
  const std::int64_t t0 = r.clock.now_;
  const RunResult res = r.run(500);
  EXPECT_EQ(res.overruns, 0u);
  ASSERT_EQ(r.clock.sleeps.size(), 500u);
  for (std::size_t i = 0; i < r.clock.sleeps.size(); ++i) {
    ASSERT_EQ(r.clock.sleeps[i], t0 + static_cast<std::int64_t>(i + 1) * kPeriodNs) << "tick " << i;
  }
}

TEST(RunnerClock, AnOverrunIsCountedAndRephasedOntoTheGridWithoutABurst) {
  Rig r;
  const std::int64_t t0 = r.clock.now_;
  r.slow->cost_ns.assign(20, 10'000);
  r.slow->cost_ns[10] = 5 * kPeriodNs + 300'000;  // tick 10 takes 5.15 periods
  const RunResult res = r.run(20);
  EXPECT_EQ(res.overruns, 1u);
  EXPECT_EQ(res.max_consecutive_overruns, 1u);
  EXPECT_FALSE(res.overrun_stop);
  ASSERT_EQ(r.clock.sleeps.size(), 20u);
  // Ticks 0..10 slept to deadlines 1..11 periods; tick 10 woke at 11 periods and ran until 16.15.
  // The next deadline is the first grid point after that (17 periods), not 12 (a burst of catch-ups).
  EXPECT_EQ(r.clock.sleeps[10], t0 + 11 * kPeriodNs);
  EXPECT_EQ(r.clock.sleeps[11], t0 + 17 * kPeriodNs);
  for (std::size_t i = 1; i < r.clock.sleeps.size(); ++i) {
    EXPECT_EQ((r.clock.sleeps[i] - t0) % kPeriodNs, 0) << "deadline off the grid at tick " << i;
    EXPECT_GT(r.clock.sleeps[i], r.clock.now_before_sleep[i]) << "a deadline already past at tick " << i;
  }
}

TEST(RunnerClock, ConsecutiveOverrunsLatchLoopOverrunAsASafeStop) {
  Rig r;
  r.slow->cost_ns.assign(200, 10'000);
  for (int i = 50; i < 55; ++i) r.slow->cost_ns[static_cast<std::size_t>(i)] = kPeriodNs + 500'000;
  const RunResult res = r.run(200, 5);
  EXPECT_TRUE(res.overrun_stop);
  EXPECT_EQ(res.max_consecutive_overruns, 5u);
  EXPECT_EQ(r.seq->state(), sequencer::State::kFault);
  EXPECT_EQ(r.seq->first_fault(), sequencer::Fault::kLoopOverrun);
}

TEST(RunnerClock, OverrunsThatAreNotConsecutiveDoNotStop) {
  Rig r;
  r.slow->cost_ns.assign(200, 10'000);
  // Four in a row, one good tick, four in a row: never five consecutive.
  for (int i : {50, 51, 52, 53, 55, 56, 57, 58})
    r.slow->cost_ns[static_cast<std::size_t>(i)] = kPeriodNs + 500'000;
  const RunResult res = r.run(200, 5);
  EXPECT_EQ(res.overruns, 8u);
  EXPECT_EQ(res.max_consecutive_overruns, 4u);
  EXPECT_FALSE(res.overrun_stop);
  EXPECT_NE(r.seq->state(), sequencer::State::kFault);
}

TEST(RunnerClock, ReportsTheScriptedWakeLatencyAndTickCost) {
  Rig r;
  r.clock.wake_latency_ns = 7'000;
  r.slow->cost_ns.assign(1000, 20'000);
  r.slow->cost_ns[500] = 900'000;  // one slow tick: the maximum, not the median
  const RunResult res = r.run(1000);
  // The histogram reports the middle of a bucket 1/32 wide: within 3 % of the true value.
  EXPECT_NEAR(static_cast<double>(res.wake_latency_p50_ns), 7'000.0, 7'000.0 / 32);
  EXPECT_NEAR(static_cast<double>(res.wake_latency_p99_ns), 7'000.0, 7'000.0 / 32);
  EXPECT_EQ(res.wake_latency_max_ns, 7'000);
  EXPECT_NEAR(static_cast<double>(res.median_tick_cost_ns), 20'000.0, 20'000.0 / 32);
  EXPECT_EQ(res.max_tick_cost_ns, 900'000);
  EXPECT_EQ(res.overruns, 0u);
  EXPECT_EQ(r.loop->stats().max_wake_latency_ns, 7'000);
}

// The summary tells the tick's own cost and the virtual-time telemetry wait apart, both in µs.
TEST(RunnerClock, SummaryReportsTickCostAndTelemetryWaitApart) {
  firmware::RunResult r;
  r.ticks = 3000;
  r.median_tick_cost_ns = 4'100;
  r.p999_tick_cost_ns = 12'300;
  r.max_tick_cost_ns = 40'200;
  r.telemetry_wait_ticks = 1'203;
  r.telemetry_wait_total_ns = 512'300'000;
  r.telemetry_wait_max_ns = 6'356'992;
  r.telemetry_wait_yields = 18'056;
  const std::string text = firmware::describe_run(r, RunOptions{});
  EXPECT_NE(
      text.find("tick cost (the tick's own work) median 4.1 \u00b5s, p99.9 12.3 \u00b5s, max 40.2 \u00b5s"),
      std::string::npos)
      << text;
  EXPECT_NE(text.find("telemetry wait"), std::string::npos) << text;
  EXPECT_NE(text.find("1203 ticks, total 512300.0 \u00b5s, max 6357.0 \u00b5s, 18056 yields"),
            std::string::npos)
      << text;
  // No wait: nothing about it.
  r.telemetry_wait_ticks = 0;
  EXPECT_EQ(firmware::describe_run(r, RunOptions{}).find("telemetry wait"), std::string::npos);
}

TEST(RunnerClock, FallingBehindThePaceIsReportedHonestly) {
  Rig r;
  r.slow->default_cost_ns = 3 * kPeriodNs;  // every tick takes three periods
  RunOptions o;
  o.period_s = 0.002;
  o.realtime = true;
  o.fifo_priority = 0;
  o.max_ticks = 100;
  o.clock = &r.clock;
  r.seq->request_start();
  const RunResult res = firmware::run_loop(*r.loop, *r.seq, o, [](const firmware::RunEvent&) {});
  EXPECT_TRUE(res.fell_behind);
  EXPECT_NEAR(res.achieved_ratio, 1.0 / 4.0, 0.05);  // 3 periods of work, re-phased to the 4th
  const std::string text = firmware::describe_run(res, o);
  EXPECT_NE(text.find("could not keep up"), std::string::npos) << text;
  EXPECT_NE(text.find("0.25x real time"), std::string::npos) << text;
}

// ---- operator commands through the OperatorLink (virtual time: same handling, no thread) ----
namespace {
RunResult run_virtual(Rig& r, hal::Tick ticks, firmware::OperatorLink& link, bool hold = true) {
  RunOptions o;
  o.period_s = r.cfg.sequencer.period_s;
  o.max_ticks = ticks;
  o.clock = &r.clock;
  o.link = &link;
  o.hold_when_finished = hold;
  return firmware::run_loop(*r.loop, *r.seq, o, [](const firmware::RunEvent&) {});
}
}  // namespace

TEST(RunnerCommands, NothingMovesUntilStartAndStatusIsPublished) {
  Rig r;  // note: Rig::run() would request a start; here only the link may
  firmware::OperatorLink link;
  run_virtual(r, 200, link);
  EXPECT_EQ(r.seq->state(), sequencer::State::kIdle);
  EXPECT_EQ(link.state.load(), static_cast<std::uint8_t>(sequencer::State::kIdle));
  EXPECT_EQ(link.tick.load(), 199);
  link.post(firmware::Command::kStart);
  run_virtual(r, 50, link);
  EXPECT_NE(r.seq->state(), sequencer::State::kIdle);
  EXPECT_EQ(link.pending.load(), 0u) << "a command was left pending";
}

TEST(RunnerCommands, StopWhileIdleDoesNotCutTheNextStartShort) {
  Rig r;
  r.slow->default_cost_ns = 0;
  firmware::OperatorLink link;
  link.post(firmware::Command::kStop);
  run_virtual(r, 10, link);
  link.post(firmware::Command::kStart);
  // Weave until the first row is done and a little more: rows_to_weave is 0 (until stopped), so the
  // loom must be weaving its second row, not done.
  RunOptions o;
  o.period_s = r.cfg.sequencer.period_s;
  o.clock = &r.clock;
  o.link = &link;
  o.hold_when_finished = true;
  o.max_ticks = 6000;  // 12 s: the first row (about 7.6 s) done, the second under way
  ASSERT_EQ(r.seq->counters().rows, 0u);
  firmware::run_loop(*r.loop, *r.seq, o, [](const firmware::RunEvent&) {});
  EXPECT_GE(r.seq->counters().rows, 1u);
  EXPECT_NE(r.seq->state(), sequencer::State::kDone);
  EXPECT_NE(r.seq->state(), sequencer::State::kFault) << sequencer::fault_name(r.seq->first_fault());
}

TEST(RunnerCommands, AckOfALatchedFaultEndsTheSessionForReArming) {
  Rig r;
  firmware::OperatorLink link;
  r.seq->request_safe_stop(sequencer::Fault::kLoopOverrun);
  link.post(firmware::Command::kAck);  // while not faulted yet: ignored
  run_virtual(r, 10, link);
  ASSERT_EQ(r.seq->state(), sequencer::State::kFault);
  EXPECT_EQ(link.first_fault.load(), static_cast<std::uint8_t>(sequencer::Fault::kLoopOverrun));
  link.post(firmware::Command::kAck);
  const RunResult res = run_virtual(r, 1000, link);
  EXPECT_EQ(res.end, RunResult::End::kAckRequested);
  EXPECT_EQ(res.ticks, 0);
}

TEST(RunnerCommands, AckIsRefusedWhileALostNodeIsSilentOrTheBusIsOff) {
  Rig r;
  firmware::OperatorLink link;
  r.seq->request_safe_stop(sequencer::Fault::kLoopOverrun);
  run_virtual(r, 10, link);
  ASSERT_EQ(r.seq->state(), sequencer::State::kFault);
  for (const auto rec : {hal::LinkRecovery::kNodeSilent, hal::LinkRecovery::kBusOff}) {
    r.slow->recovery = rec;
    r.slow->silent_node = 3;
    run_virtual(r, 2, link);  // the loop judges an acknowledgement by the inputs it last read
    link.post(firmware::Command::kAck);
    const RunResult res = run_virtual(r, 100, link);
    EXPECT_EQ(res.end, RunResult::End::kMaxTicks) << hal::link_recovery_name(rec);
    EXPECT_EQ(res.acks_refused, 1u);
    EXPECT_NE(firmware::describe_run(res, RunOptions{})
                  .find("acknowledgements refused while the link could not be re-armed 1"),
              std::string::npos);
    EXPECT_EQ(link.link_recovery.load(), static_cast<std::uint8_t>(rec));
    EXPECT_EQ(link.silent_node.load(), 3);
    EXPECT_EQ(r.seq->state(), sequencer::State::kFault);
  }
  r.slow->recovery = hal::LinkRecovery::kReady;  // the node is heard again: re-arming can reconfigure it
  run_virtual(r, 2, link);
  link.post(firmware::Command::kAck);
  EXPECT_EQ(run_virtual(r, 100, link).end, RunResult::End::kAckRequested);
}

TEST(RunnerCommands, ExitWhileIdleLeavesAtOnce) {
  Rig r;
  firmware::OperatorLink link;
  link.post(firmware::Command::kExit);
  const RunResult res = run_virtual(r, 1000, link);
  EXPECT_EQ(res.end, RunResult::End::kExitRequested);
  EXPECT_LE(res.ticks, 1);
}

TEST(RunnerCommands, ARunStoppedByASymptomWaitsOutTheDiagnosisWindowBeforeEnding) {
  // weave ends a finished run after its grace ticks — but not while a symptom (here an interlock trip)
  // stopped the machine and the root cause (a lost heartbeat arrives up to the heartbeat time later on
  // CAN) may still replace it: the run would otherwise report the symptom as the first fault.
  Rig r;
  firmware::OperatorLink link;
  r.seq->request_safe_stop(sequencer::Fault::kCarriageInWarp);
  RunOptions o;
  o.period_s = r.cfg.sequencer.period_s;
  o.max_ticks = 10'000;
  o.clock = &r.clock;
  o.link = &link;
  o.grace_ticks = 5;
  const RunResult res = firmware::run_loop(*r.loop, *r.seq, o, [](const firmware::RunEvent&) {});
  ASSERT_EQ(r.seq->first_fault(), sequencer::Fault::kCarriageInWarp);
  const auto window = static_cast<hal::Tick>(std::ceil(r.cfg.sequencer.diagnosis_window_s / o.period_s));
  EXPECT_GE(res.ticks, r.seq->fault_tick() + window) << "ended inside the diagnosis window";
  EXPECT_LE(res.ticks, r.seq->fault_tick() + window + 10);
  // A root cause (not a symptom) ends after the grace ticks alone.
  Rig r2;
  r2.seq->request_safe_stop(sequencer::Fault::kLoopOverrun);
  const RunResult res2 = firmware::run_loop(*r2.loop, *r2.seq, o, [](const firmware::RunEvent&) {});
  EXPECT_LE(res2.ticks, r2.seq->fault_tick() + 10);
}

// The buttons are decoded once, by the sequencer (debounced, one event per press, acted on by nobody there);
// the runner turns its presses into commands and audits each in the state the press was seen in — the state
// it was judged in, not the state at the end of that tick (a fault latched in it does not make a stale ack
// press count, and its verdict says so).
TEST(RunnerButtons, APressIsAuditedOnceInTheStateItWasSeenIn) {
  Rig r;
  r.slow->default_cost_ns = 0;
  firmware::OperatorLink link;
  std::vector<firmware::RunEvent> presses;
  RunOptions o;
  o.period_s = r.cfg.sequencer.period_s;
  o.clock = &r.clock;
  o.link = &link;
  o.audit_buttons = true;
  o.hold_when_finished = true;
  o.max_ticks = 40;
  const auto run = [&] {
    return firmware::run_loop(*r.loop, *r.seq, o, [&](const firmware::RunEvent& e) {
      if (e.kind == firmware::RunEvent::Kind::kButton) presses.push_back(e);
    });
  };
  run();  // idle, nothing pressed
  ASSERT_TRUE(presses.empty());
  r.slow->start_pressed = true;  // held down for the whole run: one press
  run();
  ASSERT_EQ(presses.size(), 1u);
  EXPECT_EQ(presses[0].button, firmware::Command::kStart);
  EXPECT_EQ(presses[0].state, sequencer::State::kIdle);
  EXPECT_NE(r.seq->state(), sequencer::State::kIdle);
  r.slow->start_pressed = false;
  // An ack press on a latched fault ends the session for re-arming: the fault stays latched in this
  // sequencer (the service re-arms from the measured positions).
  r.seq->request_safe_stop(sequencer::Fault::kLoopOverrun);
  run();
  ASSERT_EQ(r.seq->state(), sequencer::State::kFault);
  presses.clear();
  r.slow->ack_pressed = true;
  const RunResult res = run();
  EXPECT_EQ(res.end, RunResult::End::kAckRequested);
  ASSERT_EQ(presses.size(), 1u);
  EXPECT_EQ(presses[0].button, firmware::Command::kAck);
  EXPECT_EQ(presses[0].state, sequencer::State::kFault);
  EXPECT_EQ(r.seq->state(), sequencer::State::kFault);
  EXPECT_EQ(r.seq->first_fault(), sequencer::Fault::kLoopOverrun);
}

// The weaver's pedal is a command like the buttons (`next`): audited once per press, in the state it was
// seen in, when the run audits presses; a run that does not (weave) emits nothing for it.
TEST(RunnerButtons, ThePedalIsAuditedAsNext) {
  for (const bool audit : {true, false}) {
    Rig r;
    r.slow->default_cost_ns = 0;
    std::vector<firmware::RunEvent> presses;
    RunOptions o;
    o.period_s = r.cfg.sequencer.period_s;
    o.clock = &r.clock;
    o.audit_buttons = audit;
    o.max_ticks = 40;
    // Released first (a pedal held since power-on is no press), then held to the end: one press.
    r.slow->script = [&r](hal::Tick now) { r.slow->knotted_pressed = now >= 10; };
    firmware::run_loop(*r.loop, *r.seq, o, [&](const firmware::RunEvent& e) {
      if (e.kind == firmware::RunEvent::Kind::kButton) presses.push_back(e);
    });
    ASSERT_EQ(presses.size(), audit ? 1u : 0u);
    if (!audit) continue;
    EXPECT_EQ(presses[0].button, firmware::Command::kNext);
    EXPECT_EQ(presses[0].state, sequencer::State::kIdle);
  }
}

// A pause press reaches the sequencer the way a pause command does, in a weave as in the service: weave's
// SIGUSR1/SIGUSR2 flag acts on a change only, so it no longer cancels the press at the next tick.
TEST(RunnerButtons, InAWeaveAPressStartsPausesResumesAndAcknowledgesThroughTheRunner) {
  Rig r;
  r.slow->default_cost_ns = 0;
  const std::atomic<bool> pause_flag{false};  // as loomctl weave passes it (SIGUSR1 pauses, SIGUSR2 resumes)
  const hal::Tick d = r.cfg.sequencer.debounce_ticks;
  hal::Tick started = -1, paused = -1, resumed = -1, faulted = -1, acked = -1;
  const auto hold = [&](bool& button, hal::Tick now, hal::Tick from) {
    button = now >= from && now < from + 20;
  };
  r.slow->script = [&](hal::Tick now) {
    const sequencer::State s = r.seq->state();
    hold(r.slow->start_pressed, now, 10);
    if (started < 0 && s != sequencer::State::kIdle) started = now;
    hold(r.slow->pause_pressed, now, 1500);  // weaving row 1: holds at the next safe point
    if (paused < 0 && s == sequencer::State::kPaused) paused = now;
    if (paused >= 0) hold(r.slow->start_pressed, now, paused + 100);  // start also resumes
    if (paused >= 0 && resumed < 0 && s != sequencer::State::kPaused) resumed = now;
    if (resumed >= 0 && faulted < 0) {
      r.seq->request_safe_stop(sequencer::Fault::kLoopOverrun);
      faulted = now;
    }
    if (faulted >= 0) hold(r.slow->ack_pressed, now, faulted + 10);
    if (faulted >= 0 && acked < 0 && s == sequencer::State::kIdle) acked = now;
  };
  RunOptions o;
  o.period_s = r.cfg.sequencer.period_s;
  o.clock = &r.clock;
  o.pause_flag = &pause_flag;
  o.max_ticks = 60'000;
  const RunResult res = firmware::run_loop(*r.loop, *r.seq, o, [](const firmware::RunEvent&) {});
  // Each press acts in the step after the one that saw it (debounce_ticks after it went down).
  EXPECT_EQ(started, 10 + d + 1);
  ASSERT_GT(paused, 1500 + d) << "the pause press was lost";
  EXPECT_EQ(resumed, paused + 100 + d + 1);
  ASSERT_GT(faulted, 0);
  EXPECT_EQ(acked, faulted + 10 + d + 1);
  EXPECT_EQ(r.seq->state(), sequencer::State::kIdle);
  EXPECT_EQ(res.end, RunResult::End::kFinished);  // weave's run ends after the fault's grace ticks
}

// The service's runner: each press audited once, in the state it was seen in, and acting through the same
// commands as the socket's — a pause press pauses, an ack press on a latched fault ends the session for
// re-arming. An ack press seen in the tick the fault latched was pressed before it: no re-arming.
TEST(RunnerButtons, InTheServiceAnAckPressSeenInTheTickTheFaultLatchedDoesNotReArm) {
  Rig r;
  r.slow->default_cost_ns = 0;
  firmware::OperatorLink link;
  std::vector<firmware::RunEvent> presses;
  const hal::Tick d = r.cfg.sequencer.debounce_ticks;
  hal::Tick paused = -1;
  r.slow->script = [&](hal::Tick now) {
    r.slow->start_pressed = now >= 10 && now < 30;
    r.slow->pause_pressed = now >= 1500 && now < 1520;
    if (paused < 0 && r.seq->state() == sequencer::State::kPaused) paused = now;
    // Pressed at `paused + 100`; the fault latches in the tick whose debounce sees the press.
    r.slow->ack_pressed = paused >= 0 && now >= paused + 100 && now < paused + 120;
    if (paused >= 0 && now == paused + 100 + d - 1) r.seq->request_safe_stop(sequencer::Fault::kLoopOverrun);
  };
  RunOptions o;
  o.period_s = r.cfg.sequencer.period_s;
  o.clock = &r.clock;
  o.link = &link;
  o.audit_buttons = true;
  o.hold_when_finished = true;
  o.max_ticks = 20'000;
  const auto on_event = [&](const firmware::RunEvent& e) {
    if (e.kind == firmware::RunEvent::Kind::kButton) presses.push_back(e);
  };
  RunResult res = firmware::run_loop(*r.loop, *r.seq, o, on_event);
  ASSERT_GT(paused, 0) << "the pause press was lost";
  EXPECT_EQ(res.end, RunResult::End::kMaxTicks) << "the ack pressed before the fault re-armed";
  ASSERT_EQ(r.seq->state(), sequencer::State::kFault);
  EXPECT_EQ(r.seq->first_fault(), sequencer::Fault::kLoopOverrun);
  ASSERT_EQ(presses.size(), 3u);
  EXPECT_EQ(presses[0].button, firmware::Command::kStart);
  EXPECT_EQ(presses[0].state, sequencer::State::kIdle);
  EXPECT_EQ(presses[1].button, firmware::Command::kPause);
  EXPECT_EQ(presses[2].button, firmware::Command::kAck);
  EXPECT_EQ(presses[2].state, sequencer::State::kPaused);  // audited in the state it was judged in
  // Pressed again, after the fault: the session ends for re-arming.
  presses.clear();
  r.slow->script = [&](hal::Tick now) { r.slow->ack_pressed = now >= 10 && now < 30; };
  o.max_ticks = 200;
  res = firmware::run_loop(*r.loop, *r.seq, o, on_event);
  EXPECT_EQ(res.end, RunResult::End::kAckRequested);
  EXPECT_EQ(res.ticks, 10 + d);  // the tick after the one that saw the press
  ASSERT_EQ(presses.size(), 1u);
  EXPECT_EQ(presses[0].state, sequencer::State::kFault);
}

// The control loop on its own (as loomctl commission drives it while the technician works every button by
// hand) acts on no press: only an owner makes requests of them, and commissioning makes none.
TEST(ControlLoopButtons, TheLoopAloneActsOnNoPress) {
  Rig r;
  for (hal::Tick t = 0; t < 400; ++t) {
    r.slow->start_pressed = (t / 50) % 2 == 1;  // pressed and released four times
    r.slow->ack_pressed = r.slow->start_pressed;
    r.loop->cycle(t);
    ASSERT_EQ(r.seq->state(), sequencer::State::kIdle) << "tick " << t;
    for (std::size_t i = 0; i < r.seq->axes().count; ++i) {
      ASSERT_EQ(r.loop->outputs().axes[i].request, hal::AxisRequest::kDisable) << "tick " << t;
    }
  }
}

// serve's job queue against a start (OperatorLink::queue_gate): a change of the armed job that came first
// keeps the loom from starting it in this session (the start re-arms from the changed queue); a start that
// came first keeps the queue from changing that job under it.
TEST(RunnerCommands, AStartAfterTheArmedJobChangedReArmsInsteadOfStartingIt) {
  Rig r;
  firmware::OperatorLink link;
  ASSERT_TRUE(link.close_for_queue_change());
  link.post(firmware::Command::kRearm);
  link.post(firmware::Command::kStart);
  const RunResult res = run_virtual(r, 100, link);
  EXPECT_EQ(res.end, RunResult::End::kStartRequested);
  EXPECT_EQ(r.seq->state(), sequencer::State::kIdle);
  // A start alone, the gate closed by a change whose rearm was not taken yet: the same.
  Rig r2;
  firmware::OperatorLink link2;
  ASSERT_TRUE(link2.close_for_queue_change());
  link2.post(firmware::Command::kStart);
  EXPECT_EQ(run_virtual(r2, 100, link2).end, RunResult::End::kStartRequested);
  EXPECT_EQ(r2.seq->state(), sequencer::State::kIdle);
}

TEST(RunnerCommands, AStartedJobIsNotChangedUnderTheLoomAndARearmWhileWeavingIsNothing) {
  Rig r;
  firmware::OperatorLink link;
  link.post(firmware::Command::kStart);
  run_virtual(r, 20, link);
  ASSERT_NE(r.seq->state(), sequencer::State::kIdle);
  EXPECT_EQ(link.queue_gate.load(), firmware::OperatorLink::kGateStarted);
  EXPECT_FALSE(link.close_for_queue_change());
  link.post(firmware::Command::kRearm);
  EXPECT_EQ(run_virtual(r, 100, link).end, RunResult::End::kMaxTicks);  // the session weaves on
  EXPECT_NE(r.seq->state(), sequencer::State::kFault);
}

TEST(RunnerCommands, ARearmEndsAStandingSessionWithoutMotion) {
  Rig r;
  firmware::OperatorLink link;
  link.post(firmware::Command::kRearm);
  const RunResult res = run_virtual(r, 100, link);
  EXPECT_EQ(res.end, RunResult::End::kRearmRequested);
  EXPECT_EQ(r.seq->state(), sequencer::State::kIdle);
  EXPECT_EQ(link.queue_gate.load(), firmware::OperatorLink::kGateOpen);
}

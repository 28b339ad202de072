// The run's summary (firmware/src/run_summary.cpp), word for word: the line an operator, the README's
// examples and scripts (tests/bench/sim_speed.sh, tests/board/latency_vs_cyclictest.sh) read, for a run
// that never ticked, a fast virtual-time run with every count, and a real-time run that fell behind.
#include "loom/firmware/run_summary.hpp"

#include <gtest/gtest.h>
#include <sched.h>

#include <string>

namespace {

using loom::firmware::describe_run;
using loom::firmware::RunOptions;
using loom::firmware::RunResult;

// No tick ran (a refused start): zero everything, the ratio printed as 0.00, no optional part.
TEST(RunSummary, ARunWithNoTicksSaysZerosAndNothingElse) {
  EXPECT_EQ(
      describe_run(RunResult{}, RunOptions{}),
      "loop: 0 ticks (0.00 s machine time) in 0.000 s wall (0.00x real time); tick cost (the tick's own "
      "work) median 0.0 \u00b5s, p99.9 0.0 \u00b5s, max 0.0 \u00b5s; overruns 0");
}

// Virtual time, 77x: the ratio loses its decimals from 10x on; the telemetry wait, dropped events and
// refused acknowledgements each appear only when counted.
TEST(RunSummary, AFastVirtualRunGivesEveryCountItHas) {
  RunResult r;
  r.ticks = 12'180;  // 24.36 s of machine time at 2 ms
  r.wall_s = 0.316;
  r.achieved_ratio = 24.36 / 0.316;  // 77.09
  r.median_tick_cost_ns = 400;
  r.p999_tick_cost_ns = 6'500;
  r.max_tick_cost_ns = 18'400;
  r.telemetry_wait_ticks = 44;
  r.telemetry_wait_total_ns = 308'636'900;
  r.telemetry_wait_max_ns = 11'804'500;
  r.telemetry_wait_yields = 182;
  r.events_dropped = 3;
  r.acks_refused = 2;
  r.acks_refused_unsaved = 1;
  EXPECT_EQ(
      describe_run(r, RunOptions{}),
      "loop: 12180 ticks (24.36 s machine time) in 0.316 s wall (77x real time); tick cost (the tick's own "
      "work) median 0.4 \u00b5s, p99.9 6.5 \u00b5s, max 18.4 \u00b5s; overruns 0; telemetry wait (virtual "
      "time: the loop waited between ticks for the LCM publisher to free ring space, not part of the "
      "tick) 44 ticks, total 308636.9 \u00b5s, max 11804.5 \u00b5s, 182 yields; run events dropped 3; "
      "acknowledgements refused while the link could not be re-armed 2; acknowledgements refused while "
      "the counters could not be saved 1");
  // Exactly 10x is printed without decimals, just under it with two.
  r = RunResult{};
  r.achieved_ratio = 10.0;
  EXPECT_NE(describe_run(r, RunOptions{}).find("(10x real time)"), std::string::npos);
  r.achieved_ratio = 9.5;
  EXPECT_NE(describe_run(r, RunOptions{}).find("(9.50x real time)"), std::string::npos);
}

// Real time: the wake-up latency and the loop thread's policy, then one line per warning.
TEST(RunSummary, ARealTimeRunThatFellBehindWarnsOnLinesOfTheirOwn) {
  RunOptions o;
  o.realtime = true;
  o.pace = 1000.0;  // a 2 ms period asked in 2 µs
  o.overrun_stop_after = 5;
  RunResult r;
  r.ticks = 100;
  r.wall_s = 0.8;
  r.achieved_ratio = 0.25;
  r.median_tick_cost_ns = 20'000;
  r.p999_tick_cost_ns = 900'000;
  r.max_tick_cost_ns = 900'000;
  r.overruns = 7;
  r.wake_latency_p50_ns = 5'000;
  r.wake_latency_p99_ns = 7'000;
  r.wake_latency_max_ns = 7'000;
  r.loop_policy = SCHED_OTHER;
  r.fifo_refused = true;
  r.fell_behind = true;
  r.overrun_stop = true;
  EXPECT_EQ(
      describe_run(r, o),
      "loop: 100 ticks (0.20 s machine time) in 0.800 s wall (0.25x real time); tick cost (the tick's own "
      "work) median 20.0 \u00b5s, p99.9 900.0 \u00b5s, max 900.0 \u00b5s; overruns 7; wake-up latency p50 "
      "5000 ns, p99 7000 ns, max 7000 ns; loop thread SCHED_OTHER\n"
      "loomctl: WARNING: SCHED_FIFO was refused; the loop ran at SCHED_OTHER\n"
      "loomctl: WARNING: could not keep up: asked for 1000x real time, achieved 0.25x (7 overruns; a tick "
      "period of 2000 ns is shorter than the loop can hold)\n"
      "loomctl: the loop overran 5 deadlines in a row: safe stop (loop_overrun)");
  // Granted SCHED_FIFO: its priority is named.
  r = RunResult{};
  r.loop_policy = SCHED_FIFO;
  r.loop_priority = 80;
  const std::string text = describe_run(r, o);
  EXPECT_EQ(text.substr(text.find("; wake-up")),
            "; wake-up latency p50 0 ns, p99 0 ns, max 0 ns; loop thread SCHED_FIFO 80");
}

}  // namespace

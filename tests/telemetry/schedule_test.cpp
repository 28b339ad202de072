// Decimation rules: each channel once per interval of ticks (counted from independent closed forms),
// intervals measured in ticks so dropped snapshots do not stretch them, and STATUS on every change of
// state, counter or fault however long the heartbeat interval.
#include "loom/telemetry/schedule.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "synthetic_loom.hpp"

namespace {

using namespace loom::telemetry;
namespace sequencer = loom::sequencer;
using test_support::script_snapshot;
using test_support::WeaveScript;

Snapshot steady(std::int64_t tick) {
  Snapshot s;
  s.tick = tick;
  s.state = test_support::byte_of(sequencer::State::kBeatSweep);
  return s;
}

TEST(Schedule, SteadySnapshotsGoOutOncePerInterval) {
  for (const std::int64_t n : {1, 3, 10, 64}) {
    ChannelSchedule sched(
        {.status_every_n_ticks = n, .axes_every_n_ticks = n + 1, .rt_every_n_ticks = 2 * n});
    std::int64_t status = 0, axes = 0, rt = 0;
    constexpr std::int64_t kTicks = 1000;
    for (std::int64_t t = 0; t < kTicks; ++t) {
      const ChannelSet c = sched.decide(steady(t));
      // With contiguous ticks from 0, "due" must coincide with the tick being a multiple of n.
      EXPECT_EQ(c.status, t % n == 0) << "n=" << n << " t=" << t;
      EXPECT_EQ(c.axes, t % (n + 1) == 0);
      EXPECT_EQ(c.rt, t % (2 * n) == 0);
      status += c.status;
      axes += c.axes;
      rt += c.rt;
    }
    EXPECT_EQ(status, (kTicks + n - 1) / n);
    EXPECT_EQ(axes, (kTicks + n) / (n + 1));
    EXPECT_EQ(rt, (kTicks + 2 * n - 1) / (2 * n));
  }
}

TEST(Schedule, IntervalsAreTicksNotSnapshots) {
  // Every third tick arrives (the others were dropped): AXES every 10 ticks must go out at the first
  // arriving tick at least 10 after the last one — 0, 12, 24, ... — not every 10th snapshot.
  ChannelSchedule sched({.status_every_n_ticks = 1000, .axes_every_n_ticks = 10, .rt_every_n_ticks = 1000});
  std::vector<std::int64_t> sent;
  for (std::int64_t t = 0; t < 100; t += 3) {
    if (sched.decide(steady(t)).axes) sent.push_back(t);
  }
  EXPECT_EQ(sent, (std::vector<std::int64_t>{0, 12, 24, 36, 48, 60, 72, 84, 96}));
}

TEST(Schedule, EveryStatusChangeGoesOutEvenWithALongHeartbeat) {
  WeaveScript w;
  w.fault_at_tick = 3 * w.row_ticks() + 40;
  ChannelSchedule sched({.status_every_n_ticks = 100'000, .axes_every_n_ticks = 7, .rt_every_n_ticks = 50});
  const std::int64_t ticks = w.fault_at_tick + 200;
  Snapshot prev;
  std::int64_t changes = 0, sent = 0;
  for (std::int64_t t = 0; t < ticks; ++t) {
    const Snapshot s = script_snapshot(w, t);
    const bool changed = t == 0 || s.state != prev.state || s.row != prev.row || s.pick != prev.pick ||
                         s.beat != prev.beat || s.first_fault != prev.first_fault ||
                         s.first_fault_code != prev.first_fault_code;
    const bool status = sched.decide(s).status;
    EXPECT_EQ(status, changed) << "t=" << t;
    changes += changed;
    sent += status;
    prev = s;
  }
  // Per row at least: entering shed, pick, beat (with the pick counted), each of the first B-1 beats,
  // and row_done (with the last beat) — B + 3 distinct change ticks.
  EXPECT_GE(changes, 3 * (w.beats_per_row + 3));
  EXPECT_EQ(sent, changes);
}

TEST(Schedule, ChangeRestartsTheHeartbeat) {
  ChannelSchedule sched({.status_every_n_ticks = 10, .axes_every_n_ticks = 10, .rt_every_n_ticks = 10});
  std::vector<std::int64_t> sent;
  for (std::int64_t t = 0; t < 40; ++t) {
    Snapshot s = steady(t);
    s.row = t >= 15 ? 1 : 0;  // one change at tick 15
    if (sched.decide(s).status) sent.push_back(t);
  }
  EXPECT_EQ(sent, (std::vector<std::int64_t>{0, 10, 15, 25, 35}));
}

TEST(Schedule, ANewFaultIsAChangeAtOnce) {
  ChannelSchedule sched({.status_every_n_ticks = 1000, .axes_every_n_ticks = 1000, .rt_every_n_ticks = 1000});
  ASSERT_TRUE(sched.decide(steady(0)).status);
  EXPECT_FALSE(sched.decide(steady(1)).status);
  Snapshot b = steady(2);
  b.first_fault = test_support::byte_of(sequencer::Fault::kEStop);
  EXPECT_TRUE(sched.decide(b).status);
}

TEST(Schedule, TickGoingBackwardsRestartsEveryChannel) {
  ChannelSchedule sched({.status_every_n_ticks = 100, .axes_every_n_ticks = 100, .rt_every_n_ticks = 100});
  for (std::int64_t t = 0; t < 50; ++t) sched.decide(steady(t));
  const ChannelSet c = sched.decide(steady(0));
  EXPECT_TRUE(c.status && c.axes && c.rt);
}

TEST(Schedule, IntervalsBelowOneAreRefusedByName) {
  EXPECT_EQ(decimation_error({}), "");
  EXPECT_NE(decimation_error({.status_every_n_ticks = 0}).find("status_every_n_ticks = 0"),
            std::string::npos);
  EXPECT_NE(decimation_error({.axes_every_n_ticks = -3}).find("axes_every_n_ticks = -3"), std::string::npos);
  EXPECT_NE(decimation_error({.rt_every_n_ticks = 0}).find("rt_every_n_ticks"), std::string::npos);
}

}  // namespace

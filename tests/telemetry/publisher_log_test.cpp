// The real Publisher writing through LCM's file:// provider, read back with lcm::LogFile: decimated
// message counts per channel, every STATUS change of a weaving run in order, stop() draining the
// ring, drop counting, and configuration errors that name the bad value.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <tuple>

#include "log_reader.hpp"
#include "loom/telemetry/telemetry.hpp"
#include "synthetic_loom.hpp"
#include "test_dir.hpp"

namespace {

using namespace loom::telemetry;
namespace sequencer = loom::sequencer;
namespace fs = std::filesystem;

class PublisherLog : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = loom::test::fresh_test_dir("telemetry"); }
  void TearDown() override { fs::remove_all(dir_); }
  std::string log_path() const { return (dir_ / "run.lcmlog").string(); }
  PublisherConfig config(const Decimation& d) const {
    PublisherConfig c;
    c.lcm_url = "file://" + log_path() + "?mode=w";
    c.loom_id = "T1";
    c.decimation = d;
    c.idle_sleep = std::chrono::microseconds(100);
    c.max_messages_per_s = 0.0;  // a file takes any burst; pacing has its own test
    return c;
  }
  fs::path dir_;
};

Snapshot steady(std::int64_t tick) {
  Snapshot s;
  s.tick = tick;
  s.period_ns = 1'000'000;
  s.state = test_support::byte_of(sequencer::State::kBeatSweep);
  return s;
}

TEST_F(PublisherLog, DecimatedCountsMatchTheIntervals) {
  constexpr std::int64_t kTicks = 10'007;  // not a multiple of any interval
  const Decimation d{.status_every_n_ticks = 100, .axes_every_n_ticks = 7, .rt_every_n_ticks = 1000};
  {
    Telemetry tel(config(d));
    tel.start();
    for (std::int64_t t = 0; t < kTicks; ++t) ASSERT_TRUE(tel.push_waiting(steady(t)));
    tel.stop();
    const PublisherStats st = tel.stats();
    EXPECT_EQ(st.snapshots, static_cast<std::uint64_t>(kTicks));
    EXPECT_EQ(st.publish_errors, 0u);
    EXPECT_EQ(tel.dropped(), 0u);
  }
  const auto log = test_support::read_log(log_path(), "LOOM.T1");
  ASSERT_EQ(log.decode_errors, 0);
  EXPECT_TRUE(log.other_channels.empty());
  // IDENTITY: at least the first STATUS carries who publishes (then at most once a second).
  ASSERT_FALSE(log.identity.empty());
  EXPECT_EQ(log.identity.front().loom_id, "T1");
  EXPECT_EQ(log.identity.front().pid, static_cast<std::int32_t>(::getpid()));
  EXPECT_FALSE(log.identity.front().host.empty());
  EXPECT_NE(log.identity.front().instance, 0);
  // Ticks 0..K-1, one message per whole interval started: ceil(K / n).
  const auto ceil_div = [](std::int64_t a, std::int64_t b) { return (a + b - 1) / b; };
  EXPECT_EQ(static_cast<std::int64_t>(log.status.size()), ceil_div(kTicks, 100));
  EXPECT_EQ(static_cast<std::int64_t>(log.axes.size()), ceil_div(kTicks, 7));
  EXPECT_EQ(static_cast<std::int64_t>(log.rt.size()), ceil_div(kTicks, 1000));
  for (const auto& m : log.axes) EXPECT_EQ(m.tick % 7, 0);
  EXPECT_DOUBLE_EQ(log.status.back().time_s, 10'000 * 1e-3);
}

TEST_F(PublisherLog, WeavingRunShowsEveryStatusChangeInOrder) {
  test_support::WeaveScript w;
  w.fault_at_tick = 3 * w.row_ticks() + 25;  // during row 4's pick
  const std::int64_t ticks = w.fault_at_tick + 100;
  // Heartbeat far longer than the run: every STATUS message must come from a change.
  const Decimation d{.status_every_n_ticks = 1'000'000, .axes_every_n_ticks = 10, .rt_every_n_ticks = 100};
  {
    Telemetry tel(config(d));
    tel.start();
    for (std::int64_t t = 0; t < ticks; ++t)
      ASSERT_TRUE(tel.push_waiting(test_support::script_snapshot(w, t)));
    tel.stop();
  }
  const auto log = test_support::read_log(log_path(), "LOOM.T1");
  ASSERT_EQ(log.decode_errors, 0);

  // Independent truth: the script's own sequence of distinct (state, row, pick, beat, fault) values.
  using Key = std::tuple<std::string, std::int64_t, std::int64_t, std::int64_t, std::string, int>;
  std::vector<Key> want;
  for (std::int64_t t = 0; t < ticks; ++t) {
    const Snapshot s = test_support::script_snapshot(w, t);
    const Key k{sequencer::state_name(static_cast<sequencer::State>(s.state)),
                s.row,
                s.pick,
                s.beat,
                s.first_fault != 0 ? sequencer::fault_name(static_cast<sequencer::Fault>(s.first_fault)) : "",
                s.first_fault_code};
    if (want.empty() || want.back() != k) want.push_back(k);
  }
  std::vector<Key> got;
  for (const auto& m : log.status) {
    got.emplace_back(m.state, m.rows_done, m.pick, m.beat, m.first_fault, m.first_fault_code);
  }
  EXPECT_EQ(got, want);
  ASSERT_FALSE(log.status.empty());
  EXPECT_EQ(log.status.back().rows_done, 3);
  EXPECT_EQ(log.status.back().row, 4);  // the row the fault stopped
  EXPECT_EQ(log.status.back().state, "fault");
  EXPECT_EQ(log.status.back().first_fault, "estop");
}

TEST_F(PublisherLog, StopDrainsWhatTheRingHolds) {
  const Decimation d{.status_every_n_ticks = 1, .axes_every_n_ticks = 1, .rt_every_n_ticks = 1};
  {
    Telemetry tel(config(d));
    // Not started yet: fill the ring to the brim, then overflow it by three.
    for (std::size_t t = 0; t < kSnapshotRingCapacity; ++t) {
      ASSERT_TRUE(tel.push(steady(static_cast<std::int64_t>(t))));
    }
    for (int i = 0; i < 3; ++i) EXPECT_FALSE(tel.push(steady(-1)));
    EXPECT_EQ(tel.dropped(), 3u);
    EXPECT_FALSE(tel.push_waiting(steady(-1))) << "no publisher running: must not wait forever";
    EXPECT_EQ(tel.dropped(), 4u);
    tel.start();
    tel.stop();
    EXPECT_EQ(tel.stats().snapshots, kSnapshotRingCapacity);
    EXPECT_EQ(tel.stats().status, kSnapshotRingCapacity);
  }  // closes the log
  const auto log = test_support::read_log(log_path(), "LOOM.T1");
  ASSERT_EQ(log.status.size(), kSnapshotRingCapacity);
  EXPECT_EQ(log.status.back().tick, static_cast<std::int64_t>(kSnapshotRingCapacity) - 1);
  EXPECT_EQ(log.rt.back().dropped_snapshots, 4);
}

TEST_F(PublisherLog, PacingSpacesMessagesAtTheConfiguredRate) {
  // 2000 messages/s and 200 messages (every tick on one channel): the first goes at once, each later
  // one waits its 0.5 ms turn, so the run cannot take less than 199 gaps.
  constexpr int kMessages = 200;
  constexpr double kRate = 2000.0;
  PublisherConfig c =
      config({.status_every_n_ticks = 1, .axes_every_n_ticks = 1'000'000, .rt_every_n_ticks = 1'000'000});
  c.max_messages_per_s = kRate;
  Telemetry tel(c);
  for (int t = 0; t < kMessages; ++t) ASSERT_TRUE(tel.push(steady(t)));
  // AXES and RT also go out once, on tick 0: count every message actually sent.
  const auto t0 = std::chrono::steady_clock::now();
  tel.start();
  tel.stop();
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto st = tel.stats();
  const double sent = static_cast<double>(st.status + st.axes + st.rt);
  EXPECT_EQ(st.status, static_cast<std::uint64_t>(kMessages));
  EXPECT_GE(elapsed_s, (sent - 1.0) / kRate);
  EXPECT_LT(elapsed_s, 5.0 * sent / kRate) << "pacing far slower than asked";
}

TEST_F(PublisherLog, BadUrlIsRefusedWithTheUrlInTheMessage) {
  for (const std::string& url : {std::string("bogus://nowhere"),
                                 "file://" + (dir_ / "no_such_dir" / "x.lcmlog").string() + "?mode=w"}) {
    PublisherConfig c = config({});
    c.lcm_url = url;
    try {
      Telemetry tel(c);
      ADD_FAILURE() << "accepted " << url;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("'" + url + "'"), std::string::npos) << e.what();
    }
  }
}

TEST_F(PublisherLog, BadConfigFieldsAreNamed) {
  const auto message = [&](PublisherConfig c) -> std::string {
    try {
      Telemetry tel(c);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  PublisherConfig c = config({});
  c.loom_id = "hall 3";
  EXPECT_NE(message(c).find("'hall 3'"), std::string::npos);
  c = config({.status_every_n_ticks = 0});
  EXPECT_NE(message(c).find("status_every_n_ticks = 0"), std::string::npos);
  c = config({});
  c.channel_prefix = "A..B";
  EXPECT_NE(message(c).find("'A..B'"), std::string::npos);
  c = config({});
  c.batch = 0;
  EXPECT_NE(message(c).find("batch"), std::string::npos);
  c = config({});
  c.max_messages_per_s = -1.0;
  EXPECT_NE(message(c).find("max_messages_per_s = -1"), std::string::npos);
}

}  // namespace

// Snapshot → LCM message mapping: every field lands where the .lcm file says, names are cut at the
// array end when unterminated, and each message survives LCM's own encode/decode unchanged.
#include "loom/telemetry/encode.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "synthetic_loom.hpp"

namespace {

using namespace loom::telemetry;

Snapshot sample() {
  Snapshot s;
  s.tick = 123'456;
  s.period_ns = 2'000'000;
  test_support::set_name(s.state, "beat");
  test_support::set_name(s.first_fault, "heartbeat_lost");
  s.first_fault_code = 0x8130;
  s.row = 7;
  s.pick = 8;
  s.beat = 29;
  s.crank_phase_rad = 1.25;
  s.beater_angle_rad = -0.3;
  s.beat_force_n = 91.5;
  for (std::size_t i = 0; i < s.axes.size(); ++i) {
    const double k = static_cast<double>(i + 1);
    s.axes[i] = {.position = 1.0 * k,
                 .velocity = 2.0 * k,
                 .target = 3.0 * k,
                 .following_error = 4.0 * k,
                 .effort = 5.0 * k,
                 .drive_state = static_cast<std::uint8_t>(loom::hal::DriveState::kFault),
                 .request = static_cast<std::uint8_t>(loom::hal::AxisRequest::kQuickStop)};
  }
  s.outputs = 0b10;
  s.inputs = 0b1000101;
  s.overruns = 3;
  s.tick_cost_ns = 41'000;
  s.max_tick_cost_ns = 97'000;
  return s;
}

template <typename M>
M round_trip(const M& m) {
  std::vector<unsigned char> buf(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  M out;
  EXPECT_EQ(out.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  return out;
}

TEST(Encode, StatusCarriesStateCountersAndFault) {
  const auto m = round_trip(to_status(sample(), "L7", 42));
  EXPECT_EQ(m.utime, 42);
  EXPECT_EQ(m.loom_id, "L7");
  EXPECT_EQ(m.tick, 123'456);
  EXPECT_DOUBLE_EQ(m.time_s, 123'456 * 0.002);
  EXPECT_EQ(m.period_ns, 2'000'000);
  EXPECT_EQ(m.state, "beat");
  EXPECT_EQ(m.row, 7);
  EXPECT_EQ(m.pick, 8);
  EXPECT_EQ(m.beat, 29);
  EXPECT_EQ(m.first_fault, "heartbeat_lost");
  EXPECT_EQ(m.first_fault_code, 0x8130);
  EXPECT_EQ(m.outputs, 0b10);
  EXPECT_EQ(m.inputs, 0b1000101);
}

TEST(Encode, AxesCarryEveryAxisWithNames) {
  const auto m = round_trip(to_axes(sample(), "L7", 42));
  EXPECT_EQ(m.tick, 123'456);
  EXPECT_DOUBLE_EQ(m.crank_phase_rad, 1.25);
  EXPECT_DOUBLE_EQ(m.beater_angle_rad, -0.3);
  EXPECT_DOUBLE_EQ(m.beat_force_n, 91.5);
  ASSERT_EQ(m.num_axes, 3);
  ASSERT_EQ(m.axes.size(), 3u);
  EXPECT_EQ(m.axes[0].name, "beat_crank");
  EXPECT_EQ(m.axes[1].name, "carriage");
  EXPECT_EQ(m.axes[2].name, "helix");
  for (std::size_t i = 0; i < 3; ++i) {
    const double k = static_cast<double>(i + 1);
    EXPECT_DOUBLE_EQ(m.axes[i].position, 1.0 * k);
    EXPECT_DOUBLE_EQ(m.axes[i].velocity, 2.0 * k);
    EXPECT_DOUBLE_EQ(m.axes[i].target, 3.0 * k);
    EXPECT_DOUBLE_EQ(m.axes[i].following_error, 4.0 * k);
    EXPECT_DOUBLE_EQ(m.axes[i].effort, 5.0 * k);
    EXPECT_EQ(m.axes[i].drive_state, "fault");
    EXPECT_EQ(m.axes[i].drive_state_code, static_cast<int>(loom::hal::DriveState::kFault));
    EXPECT_EQ(m.axes[i].request, static_cast<int>(loom::hal::AxisRequest::kQuickStop));
  }
}

TEST(Encode, RtTakesDropsAndBacklogFromTheRing) {
  const auto m = round_trip(to_rt_stats(sample(), "L7", 42, 11, 5));
  EXPECT_EQ(m.period_ns, 2'000'000);
  EXPECT_EQ(m.overruns, 3);
  EXPECT_EQ(m.tick_cost_ns, 41'000);
  EXPECT_EQ(m.max_tick_cost_ns, 97'000);
  EXPECT_EQ(m.dropped_snapshots, 11);
  EXPECT_EQ(m.backlog, 5);
  // Counters beyond int64 saturate instead of wrapping negative.
  EXPECT_EQ(to_rt_stats(sample(), "L7", 0, ~0ull, 0).dropped_snapshots, INT64_MAX);
}

TEST(Encode, UnterminatedNamesStopAtTheArrayEnd) {
  Snapshot s = sample();
  std::memset(s.state.data(), 'S', s.state.size());
  std::memset(s.first_fault.data(), 'F', s.first_fault.size());
  const auto m = to_status(s, "L7", 0);
  EXPECT_EQ(m.state, std::string(s.state.size(), 'S'));
  EXPECT_EQ(m.first_fault, std::string(s.first_fault.size(), 'F'));
}

}  // namespace

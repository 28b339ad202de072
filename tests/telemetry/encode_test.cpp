// Snapshot → LCM message mapping: every field lands where the .lcm file says, names are cut at the
// array end when unterminated, and each message survives LCM's own encode/decode unchanged.
#include "loom/telemetry/encode.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "synthetic_loom.hpp"

namespace {

using namespace loom::telemetry;
namespace sequencer = loom::sequencer;

Snapshot sample() {
  Snapshot s;
  s.tick = 123'456;
  s.period_ns = 2'000'000;
  s.state = test_support::byte_of(sequencer::State::kBeatSweep);
  s.first_fault = test_support::byte_of(sequencer::Fault::kHeartbeatLost);
  s.first_fault_code = 0x8130;
  s.row = 7;
  s.row_in_progress = 8;
  s.rows_target = 20;
  s.fault_axis = 1;
  s.fault_device_code = 0x8611;
  s.fault_tick = 100'000;
  s.stopped_by = test_support::byte_of(sequencer::Fault::kStaleFeedback);
  s.pick = 8;
  s.beat = 29;
  s.crank_phase_rad = 1.25;
  s.beater_angle_rad = -0.3;
  s.beat_force_n = 91.5;
  s.beat_force_valid = true;
  s.can_tx_dropped = 6;
  s.can_rx_errors = 9;
  s.wake_latency_p99_ns = 12'000;
  s.axis_count = 3;  // the default loom's axes (names from the core layout)
  for (std::size_t i = 0; i < s.axis_count; ++i) {
    const double k = static_cast<double>(i + 1);
    s.axes[i] = {.position = 1.0 * k,
                 .velocity = 2.0 * k,
                 .target = 3.0 * k,
                 .following_error = 4.0 * k,
                 .effort = 5.0 * k,
                 .following_error_limit = 6.0 * k,
                 .fault_code = static_cast<std::uint16_t>(0x8600 + i),
                 .drive_state = static_cast<std::uint8_t>(loom::hal::DriveState::kFault),
                 .request = static_cast<std::uint8_t>(loom::hal::AxisRequest::kQuickStop)};
  }
  s.outputs = 0b10;
  s.inputs = 0b1000101;
  s.inputs_2 = 0b100001;
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
  EXPECT_EQ(m.state, "beat_sweep");
  EXPECT_EQ(m.row, 8);  // the row in progress
  EXPECT_EQ(m.rows_done, 7);
  EXPECT_EQ(m.rows_target, 20);
  EXPECT_EQ(m.pick, 8);
  EXPECT_EQ(m.beat, 29);
  EXPECT_EQ(m.first_fault, "heartbeat_lost");
  EXPECT_EQ(m.first_fault_code, 0x8130);
  EXPECT_EQ(m.fault_axis, "carriage");
  EXPECT_EQ(m.fault_device_code, 0x8611);
  EXPECT_EQ(m.fault_text, "a CAN node stopped sending heartbeats");  // from the fault table
  EXPECT_DOUBLE_EQ(m.fault_time_s, 200.0);
  EXPECT_EQ(m.stopped_by, "stale_feedback");
  EXPECT_EQ(m.outputs, 0b10);
  EXPECT_EQ(m.inputs, 0b1000101);
  EXPECT_EQ(m.inputs_2, 0b100001);
}

TEST(Encode, AxesCarryEveryAxisWithNames) {
  const auto m = round_trip(to_axes(sample(), "L7", 42));
  EXPECT_EQ(m.tick, 123'456);
  EXPECT_DOUBLE_EQ(m.crank_phase_rad, 1.25);
  EXPECT_DOUBLE_EQ(m.beater_angle_rad, -0.3);
  EXPECT_DOUBLE_EQ(m.beat_force_n, 91.5);
  EXPECT_TRUE(m.beat_force_valid);
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
    EXPECT_DOUBLE_EQ(m.axes[i].following_error_limit, 6.0 * k);
    EXPECT_EQ(m.axes[i].fault_code, static_cast<int>(0x8600 + i));
    EXPECT_EQ(m.axes[i].drive_state, "fault");
    EXPECT_EQ(m.axes[i].drive_state_code, static_cast<int>(loom::hal::DriveState::kFault));
    EXPECT_EQ(m.axes[i].request, static_cast<int>(loom::hal::AxisRequest::kQuickStop));
  }
}

// Issue 22: the panel and the monitor showed "SI" for the axes a machine adds. Each axis carries its unit,
// decided from its role in one place (hal::axis_unit): the carriage is linear (m), every other axis —
// the core shafts, knotters, selectors, auxiliaries — rotary (rad).
TEST(Encode, EveryAxisCarriesItsUnitFromItsDescription) {
  loom::hal::AxisLayout layout = loom::hal::AxisLayout::core();
  ASSERT_TRUE(layout.add("knotter_1", loom::hal::AxisRole::kKnotter));
  ASSERT_TRUE(layout.add("selector_1", loom::hal::AxisRole::kSelector));
  ASSERT_TRUE(layout.add("take_up", loom::hal::AxisRole::kAuxiliary));
  Snapshot s = sample();
  s.axis_count = static_cast<std::uint8_t>(layout.count);
  const auto m = round_trip(to_axes(s, "L7", 42, layout));
  ASSERT_EQ(m.axes.size(), 6u);
  const char* want[] = {"rad", "m", "rad", "rad", "rad", "rad"};
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(m.axes[i].unit, want[i]) << m.axes[i].name;
  EXPECT_EQ(m.axes[3].name, "knotter_1");
}

TEST(Encode, RtTakesDropsAndBacklogFromTheRing) {
  const auto m = round_trip(to_rt_stats(sample(), "L7", 42, 11, 5));
  EXPECT_EQ(m.period_ns, 2'000'000);
  EXPECT_EQ(m.overruns, 3);
  EXPECT_EQ(m.tick_cost_ns, 41'000);
  EXPECT_EQ(m.max_tick_cost_ns, 97'000);
  EXPECT_EQ(m.dropped_snapshots, 11);
  EXPECT_EQ(m.backlog, 5);
  EXPECT_EQ(m.can_tx_dropped, 6);
  EXPECT_EQ(m.can_rx_errors, 9);
  EXPECT_EQ(m.wake_latency_p99_ns, 12'000);
  EXPECT_EQ(round_trip(to_rt_stats(sample(), "L7", 42, 0, 0, 4)).dropped_events, 4);
  // Counters beyond int64 saturate instead of wrapping negative.
  EXPECT_EQ(to_rt_stats(sample(), "L7", 0, ~0ull, 0).dropped_snapshots, INT64_MAX);
}

TEST(Encode, NoFaultMeansNoFaultDetails) {
  Snapshot s = sample();
  s.first_fault = s.stopped_by = 0;
  s.first_fault_code = 0;
  const auto m = to_status(s, "L7", 0);
  EXPECT_EQ(m.fault_axis, "");
  EXPECT_EQ(m.fault_device_code, 0);
  EXPECT_EQ(m.fault_text, "");
}

TEST(Encode, UnmeasuredForceIsZero) {
  Snapshot s = sample();
  s.beat_force_valid = false;
  EXPECT_EQ(to_axes(s, "L7", 0).beat_force_n, 0.0);
  EXPECT_FALSE(to_axes(s, "L7", 0).beat_force_valid);
}

Event event(Event::Kind k) {
  Event e;
  e.kind = k;
  e.tick = 5000;
  e.period_ns = 2'000'000;
  e.row = 3;
  e.rows_done = 2;
  e.pick = 3;
  e.beat = 33;
  e.beats_per_row = 15;
  e.band_min_n = 80.0;
  e.band_max_n = 100.0;
  return e;
}

TEST(Encode, BeatEvent) {
  Event e = event(Event::Kind::kBeat);
  e.beat_index = 4;
  e.x_m = 0.25f;
  e.peak_force_n = 89.5f;
  e.force_measured = true;
  e.in_band = true;
  const auto m = round_trip(to_beat(e, "L7", 9));
  EXPECT_EQ(m.loom_id, "L7");
  EXPECT_EQ(m.tick, 5000);
  EXPECT_DOUBLE_EQ(m.time_s, 10.0);
  EXPECT_EQ(m.row, 3);
  EXPECT_EQ(m.index, 4);
  EXPECT_EQ(m.beats_per_row, 15);
  EXPECT_DOUBLE_EQ(m.x_m, 0.25);
  EXPECT_DOUBLE_EQ(m.peak_force_n, 89.5);
  EXPECT_TRUE(m.force_measured);
  EXPECT_TRUE(m.in_band);
  EXPECT_DOUBLE_EQ(m.band_min_n, 80.0);
  EXPECT_DOUBLE_EQ(m.band_max_n, 100.0);
}

TEST(Encode, FaultEventNamesAxisCodeAndText) {
  Event e = event(Event::Kind::kFault);
  e.fault_kind = Event::FaultKind::kFirst;
  e.fault = 2;  // the fault table's third entry: drive_fault
  e.axis = 1;
  e.device_code = 0x8611;
  e.state = test_support::byte_of(sequencer::State::kBeatSweep);
  const auto m = round_trip(to_fault(e, "L7", 9));
  EXPECT_EQ(m.kind, "first");
  EXPECT_EQ(m.name, "drive_fault");
  EXPECT_EQ(m.code, 0x1002);
  EXPECT_EQ(m.text, "a servo drive reported a fault");
  EXPECT_EQ(m.axis, "carriage");
  EXPECT_EQ(m.device_code, 0x8611);
  EXPECT_EQ(m.state, "beat_sweep");
  EXPECT_EQ(m.row, 3);
  EXPECT_EQ(m.rows_done, 2);
  EXPECT_EQ(m.beat, 33);
  e.axis = -1;
  e.fault_kind = Event::FaultKind::kDevice;
  EXPECT_EQ(to_fault(e, "L7", 9).axis, "");
  EXPECT_EQ(to_fault(e, "L7", 9).kind, "device");
}

TEST(Encode, ASensorDiscrepancyNamesItsSensorInTheText) {
  Event e = event(Event::Kind::kFault);
  e.fault = 31;  // the fault table's entry sensor_discrepancy
  e.sensor = static_cast<std::int8_t>(loom::hal::SafetySensor::kShuttleAtRight);
  const auto m = round_trip(to_fault(e, "L7", 9));
  EXPECT_EQ(m.name, "sensor_discrepancy");
  EXPECT_EQ(
      m.text,
      "the two channels of a safety sensor disagree (a stuck switch or a wiring fault): shuttle_at_right");
  Snapshot s = sample();
  s.first_fault = test_support::byte_of(sequencer::Fault::kSensorDiscrepancy);
  s.fault_sensor = static_cast<std::int8_t>(loom::hal::SafetySensor::kPistonBExtended);
  EXPECT_EQ(
      round_trip(to_status(s, "L7", 9)).fault_text,
      "the two channels of a safety sensor disagree (a stuck switch or a wiring fault): piston_b_extended");
}

TEST(Encode, RowEventSplitsTimeInSeconds) {
  Event e = event(Event::Kind::kRow);
  e.row = 2;
  e.row_ticks = 3770;
  e.shed_ticks = 160;
  e.pick_ticks = 646;
  e.beat_ticks = 2964;
  e.beats = 15;
  e.carriage_steps = 14;
  e.beats_in_band = 14;
  e.force_measured = true;
  e.force_min_n = 79.0;
  e.force_mean_n = 89.0;
  e.force_max_n = 91.0;
  const auto m = round_trip(to_row(e, "L7", 9));
  EXPECT_EQ(m.row, 2);
  EXPECT_DOUBLE_EQ(m.row_s, 7.54);
  EXPECT_DOUBLE_EQ(m.shed_s, 0.32);
  EXPECT_DOUBLE_EQ(m.pick_s, 1.292);
  EXPECT_DOUBLE_EQ(m.beat_s, 5.928);
  EXPECT_EQ(m.beats, 15);
  EXPECT_EQ(m.carriage_steps, 14);
  EXPECT_EQ(m.beats_in_band, 14);
  EXPECT_DOUBLE_EQ(m.force_min_n, 79.0);
  EXPECT_DOUBLE_EQ(m.force_max_n, 91.0);
}

// The ring carries enums; a byte outside them (a corrupted slot) is named "?", never read past a table.
TEST(Encode, AStateOrFaultOutsideTheEnumsIsNamedQuestionMark) {
  Snapshot s = sample();
  s.state = 0xEE;
  s.first_fault = s.stopped_by = 0xEE;
  const auto m = to_status(s, "L7", 0);
  EXPECT_EQ(m.state, "?");
  EXPECT_EQ(m.first_fault, "?");
  EXPECT_EQ(m.stopped_by, "?");
}

// copy_in_use (snapshot.hpp): what the loop puts into a ring slot. Every field arrives; of the axes only
// the machine's, so a slot's other axis entries keep what they held (value-initialised: zero).
TEST(Snapshot, CopyInUseCopiesEveryFieldAndOnlyTheMachinesAxes) {
  Snapshot from;
  from.tick = 123456;
  from.period_ns = 2'000'000;
  from.state = test_support::byte_of(sequencer::State::kBeatSweep);
  from.first_fault = test_support::byte_of(sequencer::Fault::kDriveFault);
  from.stopped_by = test_support::byte_of(sequencer::Fault::kEStop);
  from.first_fault_code = 7;
  from.row = 11, from.pick = 22, from.beat = 33, from.row_in_progress = 12, from.rows_target = 40;
  from.crank_phase_rad = 1.25, from.beater_angle_rad = -0.5, from.beat_force_n = 91.0,
  from.beat_force_valid = true;
  from.axis_count = 3;
  for (std::size_t i = 0; i < from.axes.size(); ++i) {
    from.axes[i].position = 1.0 + static_cast<double>(i);
    from.axes[i].fault_code = static_cast<std::uint16_t>(100 + i);
  }
  from.outputs = 3, from.inputs = 0x55, from.inputs_2 = 0x2a;
  from.overruns = 4, from.tick_cost_ns = 5, from.max_tick_cost_ns = 6;
  from.wake_latency_p50_ns = 7, from.wake_latency_p99_ns = 8, from.wake_latency_max_ns = 9;
  from.telemetry_dropped = 10, from.can_tx_dropped = 11, from.can_rx_errors = 12;

  Snapshot to{};
  copy_in_use(to, from);
  EXPECT_EQ(to.tick, 123456);
  EXPECT_EQ(to.period_ns, 2'000'000);
  EXPECT_EQ(to.state, from.state);
  EXPECT_EQ(to.first_fault, from.first_fault);
  EXPECT_EQ(to.stopped_by, from.stopped_by);
  EXPECT_EQ(to.first_fault_code, 7);
  EXPECT_EQ(to.row, 11u);
  EXPECT_EQ(to.pick, 22u);
  EXPECT_EQ(to.beat, 33u);
  EXPECT_EQ(to.row_in_progress, 12u);
  EXPECT_EQ(to.rows_target, 40u);
  EXPECT_EQ(to.crank_phase_rad, 1.25);
  EXPECT_EQ(to.beater_angle_rad, -0.5);
  EXPECT_EQ(to.beat_force_n, 91.0);
  EXPECT_TRUE(to.beat_force_valid);
  EXPECT_EQ(to.axis_count, 3);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(to.axes[i].position, 1.0 + static_cast<double>(i)) << "axis " << i;
    EXPECT_EQ(to.axes[i].fault_code, 100 + i) << "axis " << i;
  }
  for (std::size_t i = 3; i < to.axes.size(); ++i) {
    EXPECT_EQ(to.axes[i].position, 0.0) << "axis " << i << " is not the machine's: not copied";
    EXPECT_EQ(to.axes[i].fault_code, 0) << "axis " << i;
  }
  EXPECT_EQ(to.outputs, 3);
  EXPECT_EQ(to.inputs, 0x55);
  EXPECT_EQ(to.inputs_2, 0x2a);
  EXPECT_EQ(to.overruns, 4u);
  EXPECT_EQ(to.tick_cost_ns, 5);
  EXPECT_EQ(to.max_tick_cost_ns, 6);
  EXPECT_EQ(to.wake_latency_p50_ns, 7);
  EXPECT_EQ(to.wake_latency_p99_ns, 8);
  EXPECT_EQ(to.wake_latency_max_ns, 9);
  EXPECT_EQ(to.telemetry_dropped, 10u);
  EXPECT_EQ(to.can_tx_dropped, 11u);
  EXPECT_EQ(to.can_rx_errors, 12u);
}

}  // namespace

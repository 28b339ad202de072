// loom-monitor's line format: the fields technicians and scripts parse, in order, one line per
// message, with hostile text unable to break the space-separated layout.
#include "lines.hpp"

#include <gtest/gtest.h>

#include "synthetic_loom.hpp"

namespace {

using namespace loom::monitor;

loomlcm::status_t status() {
  loomlcm::status_t m{};
  m.loom_id = "hall-3";
  m.tick = 1500;
  m.time_s = 3.0;
  m.state = "pick";
  m.row = 13;
  m.rows_done = 12;
  m.pick = 13;
  m.beat = 48;
  m.first_fault = "";
  m.first_fault_code = 0;
  return m;
}

TEST(MonitorLines, StatusLineHasTheDocumentedFields) {
  EXPECT_EQ(status_line(status()),
            "loom=hall-3 tick=1500 t=3.000s state=pick row=13 done=12 pick=13 beat=48 fault=none "
            "fault_code=0x0000");
  auto m = status();
  m.first_fault = "drive_fault";
  m.first_fault_code = 0x1002;
  m.fault_axis = "carriage";
  m.fault_device_code = 0x8611;
  m.fault_text = "a servo drive reported a fault";
  EXPECT_EQ(status_line(m),
            "loom=hall-3 tick=1500 t=3.000s state=pick row=13 done=12 pick=13 beat=48 fault=drive_fault "
            "fault_code=0x1002 axis=carriage device_code=0x8611 text=\"a servo drive reported a fault\"");
}

TEST(MonitorLines, HostileTextCannotSplitTheLine) {
  auto m = status();
  m.state = "a b\nrow=999";
  m.loom_id = "";
  const std::string line = status_line(m);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_NE(line.find("loom=- "), std::string::npos);
  EXPECT_NE(line.find("state=a?b?row=999 row=13 "), std::string::npos);
}

TEST(MonitorLines, AxesLineListsEachAxis) {
  loomlcm::axes_t m{};
  m.loom_id = "L";
  m.tick = 10;
  m.time_s = 0.02;
  m.crank_phase_rad = 1.5;
  m.beater_angle_rad = 0.25;
  m.beat_force_n = 88.0;
  m.num_axes = 2;
  m.axes.resize(2);
  m.axes[0].name = "beat_crank";
  m.axes[0].position = 12.5;
  m.axes[0].drive_state = "operation_enabled";
  m.axes[0].unit = "rad";
  m.axes[1].name = "carriage";
  m.axes[1].unit = "m";
  m.axes[1].position = 0.75;
  m.axes[1].following_error = 0.001;
  m.axes[1].drive_state = "fault";
  m.axes[1].following_error_limit = 0.002;
  m.axes[1].fault_code = 0x8611;
  EXPECT_EQ(axes_line(m),
            "axes loom=L tick=10 t=0.020s crank_phase=1.5000rad beater=0.2500rad force=88.0N"
            " | beat_crank pos=12.5 vel=0 tgt=0 ferr=0 lim=0 eff=0 drive=operation_enabled unit=rad"
            " | carriage pos=0.75 vel=0 tgt=0 ferr=0.001 lim=0.002 eff=0 drive=fault unit=m code=0x8611");
}

TEST(MonitorLines, RtLineInMicroseconds) {
  loomlcm::rt_stats_t m{};
  m.loom_id = "L";
  m.tick = 500;
  m.time_s = 1.0;
  m.overruns = 2;
  m.tick_cost_ns = 12'300;
  m.max_tick_cost_ns = 45'000;
  m.dropped_snapshots = 4;
  m.backlog = 1;
  m.dropped_events = 0;
  m.can_tx_dropped = 3;
  m.wake_latency_max_ns = 250'000;
  EXPECT_EQ(rt_line(m),
            "rt loom=L tick=500 t=1.000s overruns=2 tick_cost_us=12.3 max_tick_cost_us=45.0 wake_p50_us=0.0 "
            "wake_p99_us=0.0 wake_max_us=250.0 dropped=4 dropped_events=0 backlog=1 can_tx_dropped=3 "
            "can_rx_errors=0");
}

loomlcm::beat_t beat(int row, int index, double force, bool in_band) {
  loomlcm::beat_t m{};
  m.loom_id = "L";
  m.time_s = 2.5;
  m.row = row;
  m.index = static_cast<std::int16_t>(index);
  m.beats_per_row = 15;
  m.x_m = 0.0786;
  m.peak_force_n = force;
  m.force_measured = 1;
  m.in_band = in_band ? 1 : 0;
  m.band_min_n = 80;
  m.band_max_n = 100;
  return m;
}

TEST(MonitorLines, BeatFaultAndRowLines) {
  EXPECT_EQ(beat_line(beat(1, 1, 89.46, true)),
            "beat loom=L t=2.500s row=1 index=1 x=0.0786m force=89.5N in_band=yes");
  loomlcm::fault_t f{};
  f.loom_id = "L";
  f.time_s = 12.0;
  f.kind = "first";
  f.name = "drive_fault";
  f.code = 0x1002;
  f.text = "a servo drive reported a fault";
  f.axis = "carriage";
  f.device_code = 0x8611;
  f.state = "beat_sweep";
  f.row = 2;
  f.pick = 2;
  f.beat = 20;
  EXPECT_EQ(fault_line(f),
            "fault loom=L t=12.000s kind=first name=drive_fault code=0x1002 axis=carriage device_code=0x8611 "
            "state=beat_sweep row=2 pick=2 beat=20 text=\"a servo drive reported a fault\"");
  EventView v;
  EXPECT_EQ(
      v.on_fault(f).at(0),
      "L t=12.000s FAULT drive_fault (0x1002) axis carriage device code 0x8611: a servo drive reported a "
      "fault [first; in beat_sweep, row 2, picks 2, beats 20]");
  loomlcm::row_t r{};
  r.loom_id = "L";
  r.time_s = 7.564;
  r.row = 1;
  r.row_s = 7.56;
  r.shed_s = 0.33;
  r.pick_s = 1.29;
  r.beat_s = 5.93;
  r.beats = 15;
  r.carriage_steps = 14;
  r.force_measured = 1;
  r.force_min_n = 89.3;
  r.force_mean_n = 89.5;
  r.force_max_n = 89.7;
  r.beats_in_band = 15;
  EXPECT_EQ(row_line(r),
            "row loom=L t=7.564s row=1 time=7.56s shed=0.33s pick=1.29s beat=5.93s beats=15 steps=14 "
            "force_min=89.3N force_mean=89.5N force_max=89.7N in_band=15/15 knotting=0.00s");
  EXPECT_EQ(
      v.on_row(r).at(0),
      "L t=7.564s row 1 done in 7.56 s (shed 0.33, pick 1.29, beat 5.93 s), 15 beats, force min/mean/max "
      "89.3/89.5/89.7 N, 15/15 in band");
  r.knotting_s = 212.4;  // knotting mode: the weaver's time before the row
  EXPECT_EQ(
      v.on_row(r).at(0),
      "L t=7.564s row 1 done in 7.56 s (shed 0.33, pick 1.29, beat 5.93 s), 15 beats, force min/mean/max "
      "89.3/89.5/89.7 N, 15/15 in band, knotted in 212.4 s before it");
}

TEST(MonitorLines, EventViewSaysBandAndKeepsStatusSparse) {
  EventView v(1.0);
  EXPECT_EQ(v.on_beat(beat(2, 0, 75.0, false)).at(0),
            "L t=2.500s beat  row 2 #1/15 at x=0.079 m: 75.0 N BELOW band 80-100 N");
  EXPECT_EQ(v.on_beat(beat(2, 1, 89.0, true)).at(0),
            "L t=2.500s beat  row 2 #2/15 at x=0.079 m: 89.0 N in band 80-100 N");
  // A state change is always a line; the same state again only once per second of loop time.
  auto m = status();
  m.loom_id = "L";
  m.rows_target = 20;
  std::size_t lines = 0;
  for (int i = 0; i < 100; ++i) {  // 100 STATUS at 20 ms: 2 s of loop time
    m.time_s = 3.0 + 0.02 * i;
    lines += v.on_status(m).size();
  }
  EXPECT_EQ(lines, 2u);  // the change into "pick", then one compact status a second later
  m.state = "beat_sweep";
  const auto out = v.on_status(m);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], "L t=4.980s state pick -> beat_sweep, row 13/20");
}

}  // namespace

TEST(MonitorLines, DesignShowsTheRowToKnotAsRunsOnceEachRow) {
  const auto d = loom::telemetry::test_support::design_message("L", {{0, 0, 0, 0, 0}, {1, 1, 0, 0, 1}});
  EXPECT_EQ(loom::monitor::design_line(d),
            "design loom=L name=rug.csv next_row=2/6 repeat=1 rows_done=1 width=5 knots=Bx2 Rx2 Bx1");
  loom::monitor::EventView v;
  EXPECT_EQ(v.on_design(d).at(0), "L knot row 2/6 of rug.csv: Bx2 Rx2 Bx1");
  EXPECT_TRUE(v.on_design(d).empty());  // the once-a-second repeat of the same row prints nothing
}

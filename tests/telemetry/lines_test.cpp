// loom-monitor's line format: the fields technicians and scripts parse, in order, one line per
// message, with hostile text unable to break the space-separated layout.
#include "lines.hpp"

#include <gtest/gtest.h>

namespace {

using namespace loom::monitor;

loomlcm::status_t status() {
  loomlcm::status_t m{};
  m.loom_id = "hall-3";
  m.tick = 1500;
  m.time_s = 3.0;
  m.state = "pick";
  m.row = 12;
  m.pick = 13;
  m.beat = 48;
  m.first_fault = "";
  m.first_fault_code = 0;
  return m;
}

TEST(MonitorLines, StatusLineHasTheDocumentedFields) {
  EXPECT_EQ(status_line(status()),
            "loom=hall-3 tick=1500 t=3.000s state=pick row=12 pick=13 beat=48 fault=none fault_code=0");
  auto m = status();
  m.first_fault = "estop";
  m.first_fault_code = 4097;
  EXPECT_EQ(status_line(m),
            "loom=hall-3 tick=1500 t=3.000s state=pick row=12 pick=13 beat=48 fault=estop fault_code=4097");
}

TEST(MonitorLines, HostileTextCannotSplitTheLine) {
  auto m = status();
  m.state = "a b\nrow=999";
  m.loom_id = "";
  const std::string line = status_line(m);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_NE(line.find("loom=- "), std::string::npos);
  EXPECT_NE(line.find("state=a?b?row=999 row=12 "), std::string::npos);
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
  m.axes[1].name = "carriage";
  m.axes[1].position = 0.75;
  m.axes[1].following_error = 0.001;
  m.axes[1].drive_state = "fault";
  EXPECT_EQ(axes_line(m),
            "axes loom=L tick=10 t=0.020s crank_phase=1.5000rad beater=0.2500rad force=88.0N"
            " | beat_crank pos=12.5 vel=0 tgt=0 ferr=0 eff=0 drive=operation_enabled"
            " | carriage pos=0.75 vel=0 tgt=0 ferr=0.001 eff=0 drive=fault");
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
  EXPECT_EQ(rt_line(m),
            "rt loom=L tick=500 t=1.000s overruns=2 tick_cost_us=12.3 max_tick_cost_us=45.0 dropped=4 "
            "backlog=1");
}

}  // namespace

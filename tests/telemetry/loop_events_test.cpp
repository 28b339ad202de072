// The loop's events as a technician receives them: a whole simulated run through the real control
// loop, publisher and LCM (into a log through LCM's file provider), read back and checked against the
// sequencer's own counts — every beat exactly once (BEAT is an event, never decimated), a ROW per row,
// STATUS naming the row in progress, and a drive fault reported with axis, device code and text.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <set>

#include "log_reader.hpp"
#include "loom/config/config.hpp"
#include "loom/firmware/machine.hpp"

using namespace loom;

namespace {

struct WovenRun {
  telemetry::test_support::LoggedMessages log;
  sequencer::Counters counters;
  sequencer::State state = sequencer::State::kIdle;
};

WovenRun weave(const firmware::Scene& scene, std::uint32_t rows, const std::string& name) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("loom_loop_events_" + name + "_" + std::to_string(::getpid()) + ".lcmlog"))
                               .string();
  std::filesystem::remove(path);
  WovenRun out;
  {
    firmware::LoomConfig cfg = firmware::default_loom_config();
    cfg.loom_id = "ev";
    cfg.telemetry.lcm_url = "file://" + path + "?mode=w";
    firmware::MachineOptions opt;
    opt.rows = rows;
    firmware::Machine m(cfg, scene, opt, {});
    m.sequencer().request_start();
    hal::Tick t = 0;
    hal::Tick finished = -1;
    for (; t < 400000; ++t) {
      m.loop().cycle(t);
      if (m.sequencer().finished() && finished < 0) finished = t;
      if (finished >= 0 && t - finished > 100) break;
    }
    m.telemetry()->stop();
    out.counters = m.sequencer().counters();
    out.state = m.sequencer().state();
  }  // the machine (and its LCM file) closes here
  out.log = telemetry::test_support::read_log(path, "LOOM.ev");
  std::filesystem::remove(path);
  return out;
}

}  // namespace

TEST(LoopEvents, EveryBeatOfATwoRowRunIsOneBeatMessage) {
  const WovenRun r = weave(firmware::default_scene(), 2, "clean");
  ASSERT_EQ(r.log.decode_errors, 0);
  ASSERT_EQ(r.state, sequencer::State::kDone);
  // The default loom beats 15 times per row: 30 beats, each exactly once, in order.
  ASSERT_EQ(r.counters.beats, 30u);
  ASSERT_EQ(r.log.beat.size(), 30u);
  std::set<std::pair<int, int>> seen;
  for (std::size_t i = 0; i < r.log.beat.size(); ++i) {
    const auto& b = r.log.beat[i];
    EXPECT_EQ(b.row, static_cast<int>(i / 15) + 1);
    EXPECT_EQ(b.index, static_cast<int>(i % 15));
    EXPECT_EQ(b.beats_per_row, 15);
    EXPECT_TRUE(b.force_measured);
    EXPECT_TRUE(b.in_band) << "beat " << i << ": " << b.peak_force_n << " N";
    EXPECT_GE(b.peak_force_n, 80.0);
    EXPECT_LE(b.peak_force_n, 100.0);
    EXPECT_DOUBLE_EQ(b.band_min_n, 80.0);
    EXPECT_DOUBLE_EQ(b.band_max_n, 100.0);
    if (i > 0) {
      EXPECT_GT(b.tick, r.log.beat[i - 1].tick);
    }
    seen.emplace(b.row, b.index);
  }
  EXPECT_EQ(seen.size(), 30u);
  // The carriage sweeps the width: row 1 left to right, row 2 back.
  EXPECT_LT(r.log.beat[0].x_m, r.log.beat[14].x_m);
  EXPECT_GT(r.log.beat[15].x_m, r.log.beat[29].x_m);

  ASSERT_EQ(r.log.row.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    const auto& row = r.log.row[static_cast<std::size_t>(i)];
    EXPECT_EQ(row.row, i + 1);
    EXPECT_EQ(row.beats, 15);
    EXPECT_EQ(row.beats_in_band, 15);
    // Row 1 also holds the shed test every arming starts with (the frames stroked to learn them).
    EXPECT_GE(row.row_s, row.shed_s + row.pick_s + row.beat_s - 0.01);
    if (i > 0) {
      EXPECT_NEAR(row.row_s, row.shed_s + row.pick_s + row.beat_s, 0.1);
    }
    EXPECT_GE(row.force_min_n, 80.0);
    EXPECT_LE(row.force_max_n, 100.0);
  }
  EXPECT_TRUE(r.log.fault.empty());

  // STATUS: the row in progress is 1 while row 1 is woven, 2 during row 2, 2 once done.
  bool saw_row1_beating = false, saw_row2_beating = false;
  for (const auto& s : r.log.status) {
    if (s.state == "beat_sweep" && s.rows_done == 0) {
      EXPECT_EQ(s.row, 1);
      saw_row1_beating = true;
    }
    if (s.state == "beat_sweep" && s.rows_done == 1) {
      EXPECT_EQ(s.row, 2);
      saw_row2_beating = true;
    }
    EXPECT_EQ(s.rows_target, 2);
    EXPECT_EQ(s.beats_per_row, 15);
  }
  EXPECT_TRUE(saw_row1_beating);
  EXPECT_TRUE(saw_row2_beating);
  ASSERT_FALSE(r.log.status.empty());
  EXPECT_EQ(r.log.status.back().state, "done");
  EXPECT_EQ(r.log.status.back().row, 2);
  // AXES carries the load cell's force now: some sample sees the beater on the fell.
  bool force_seen = false;
  for (const auto& a : r.log.axes) force_seen = force_seen || (a.beat_force_valid && a.beat_force_n > 0.0);
  EXPECT_TRUE(force_seen);
}

TEST(LoopEvents, DriveFaultIsReportedWithAxisDeviceCodeAndText) {
  firmware::Scene scene =
      firmware::load_scene(std::string(LOOM_SOURCE_DIR) + "/sim_hal/scenes/drive_fault.toml");
  const WovenRun r = weave(scene, 3, "fault");
  ASSERT_EQ(r.log.decode_errors, 0);
  ASSERT_EQ(r.state, sequencer::State::kFault);
  ASSERT_GE(r.log.fault.size(), 1u);
  const auto& f = r.log.fault.front();
  EXPECT_EQ(f.kind, "first");
  EXPECT_EQ(f.name, "drive_fault");
  EXPECT_EQ(f.code, 0x1002);
  EXPECT_EQ(f.axis, "carriage");
  EXPECT_EQ(f.device_code, 0x8611);
  EXPECT_EQ(f.text, "a servo drive reported a fault");
  EXPECT_NE(f.state, "fault");  // the state the loom was in when it happened
  EXPECT_EQ(f.row, static_cast<int>(r.counters.rows) + 1);
  EXPECT_NEAR(f.time_s, 12.0, 0.01);
  // One report per fault: the drive that latched the first fault is not reported again as a device.
  for (std::size_t i = 1; i < r.log.fault.size(); ++i) {
    EXPECT_NE(r.log.fault[i].axis, "carriage");
  }
  const auto& s = r.log.status.back();
  EXPECT_EQ(s.state, "fault");
  EXPECT_EQ(s.first_fault, "drive_fault");
  EXPECT_EQ(s.first_fault_code, 0x1002);
  EXPECT_EQ(s.fault_axis, "carriage");
  EXPECT_EQ(s.fault_device_code, 0x8611);
  EXPECT_EQ(s.fault_text, "a servo drive reported a fault");
  EXPECT_NEAR(s.fault_time_s, 12.0, 0.01);
  EXPECT_EQ(s.row, static_cast<int>(r.counters.rows) + 1);
}

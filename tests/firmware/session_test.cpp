// firmware::Session and its parts: the command line's HAL choice, the production record (counters and
// the loop's handshake), the fault as every report names it, and the session's steps — build (input
// errors and hardware errors map to their exit codes), run (the run's line said, the telemetry stopped),
// and tick (the tick count goes on across calls, as one run would have it).
#include "loom/firmware/session.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace loom;
using firmware::ConfigError;
using firmware::ProductionRecord;
using firmware::Session;
using firmware::SessionError;
using firmware::SessionOptions;
using firmware::Severity;

struct TempDir {
  std::filesystem::path path;
  TempDir() {
    char name[] = "/tmp/loom_session_XXXXXX";
    path = mkdtemp(name);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string file(const char* n) const { return (path / n).string(); }
};

std::string refusal(const std::string& hal, const std::string& iface, const std::string& io,
                    double pace = 1.0) {
  try {
    (void)SessionOptions::from_command_line(hal, iface, io, pace);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(SessionOptions, TheCommandLinesContradictionsAreRefusedWithTheirWords) {
  EXPECT_EQ(refusal("socketcan", "", ""), "--hal socketcan needs --iface NAME");
  EXPECT_EQ(refusal("sim", "can0", ""),
            "--iface can0 needs --hal socketcan (without it the simulated loom would run)");
  EXPECT_EQ(refusal("socketcan", "can0", "", 2.5),
            "--pace = 2.5: simulation only (a loom runs at its own pace)");
  EXPECT_EQ(refusal("sim", "", "wireless"), "--io wireless: want can or simulated");
  EXPECT_EQ(refusal("fpga", "", ""), "--hal fpga: want sim or socketcan");
  EXPECT_EQ(refusal("sim", "", "", 3.0), "");  // a simulation may run faster than real time
}

TEST(SessionOptions, WhatTheyChoose) {
  const SessionOptions hw = SessionOptions::from_command_line("socketcan", "can0,can1", "simulated");
  EXPECT_TRUE(hw.hardware());
  EXPECT_TRUE(hw.paced());  // hardware always runs at the machine's pace
  EXPECT_EQ(hw.iface, "can0,can1");
  ASSERT_TRUE(hw.io.has_value());
  EXPECT_EQ(*hw.io, firmware::IoKind::kSimulated);
  const SessionOptions sim = SessionOptions::from_command_line("sim", "", "");
  EXPECT_FALSE(sim.hardware());
  EXPECT_FALSE(sim.paced());
  EXPECT_FALSE(sim.io.has_value());
}

TEST(ProductionRecord, WithoutAFileNothingIsKeptAndEverythingStartsAtZero) {
  ProductionRecord record("", firmware::default_loom_config());
  EXPECT_FALSE(record.kept());
  EXPECT_EQ(record.row_saves(), nullptr);
  EXPECT_EQ(record.load().rows, 0u);
  EXPECT_NO_THROW(record.save(sequencer::Counters{.rows = 4, .picks = 4, .beats = 60, .picks_in_row = 0}));
}

TEST(ProductionRecord, CountersThatAreNotThisLoomsAreRefusedNamingTheFileAndField) {
  const TempDir dir;
  const std::string path = dir.file("counters.json");
  const firmware::LoomConfig cfg = firmware::default_loom_config();
  ProductionRecord record(path, cfg);
  const std::uint32_t too_many = cfg.recipe.picks_per_row + 1;
  // Written by the store itself, so only the picks in the row are wrong.
  state::CounterStore(path).save({.rows = 1, .picks = 9, .beats = 15, .picks_in_row = too_many});
  try {
    (void)record.load();
    FAIL() << "counters with more picks in the row than the recipe has were taken";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path + ": picks_in_row = " + std::to_string(too_many)), std::string::npos) << what;
    EXPECT_NE(what.find("not this loom's"), std::string::npos) << what;
  }
}

TEST(ProductionRecord, ASaveTellsTheLoopWhatIsOnDiskAndAFailedOneThatItFailed) {
  const TempDir dir;
  const std::string path = dir.file("counters.json");
  ProductionRecord record(path, firmware::default_loom_config());
  ASSERT_TRUE(record.kept());
  record.begin_session({.rows = 2, .picks = 2, .beats = 30, .picks_in_row = 0});
  ASSERT_NE(record.row_saves(), nullptr);
  EXPECT_EQ(record.row_saves()->rows_on_disk.load(), 2u);
  sequencer::Counters c{.rows = 3, .picks = 3, .beats = 45, .picks_in_row = 0};
  c.knot.cycles_started = 7;
  record.save(c);
  EXPECT_EQ(record.row_saves()->rows_on_disk.load(), 3u);
  EXPECT_EQ(record.row_saves()->knots_on_disk.load(), (std::uint64_t{3} << 32) | 7u);
  EXPECT_EQ(record.load().rows, 3u);  // and it is on disk
  // The folder taken away: the next save fails, the loop learns it and the caller gets the reason.
  std::filesystem::remove_all(dir.path);
  c.rows = 4;
  EXPECT_ANY_THROW(record.save(c));
  EXPECT_TRUE(record.row_saves()->last_save_failed.load());
  EXPECT_EQ(record.row_saves()->rows_on_disk.load(), 3u);  // never claims a row it could not keep
  // A loom that must count and cannot refuses to arm.
  try {
    record.prove_writable(c);
    FAIL() << "an unwritable counters file was taken";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("counters file cannot be written, refusing to arm"),
              std::string::npos);
  }
}

TEST(FaultReport, TheTextNamesTheSensorAndWhatMotionStoppedOn) {
  firmware::FaultReport f;
  f.fault = sequencer::Fault::kSensorDiscrepancy;
  f.sensor = 0;
  f.stopped_by = sequencer::Fault::kSensorDiscrepancy;
  const std::string base = sequencer::fault_text(sequencer::Fault::kSensorDiscrepancy);
  const std::string sensor = hal::safety_sensor_name(static_cast<hal::SafetySensor>(0));
  EXPECT_EQ(f.text(), base + ": " + sensor);
  EXPECT_EQ(f.stopped_note(), "");
  f.fault = sequencer::Fault::kDriveFault;
  f.sensor = -1;
  EXPECT_EQ(f.stopped_note(), "(motion stopped on sensor_discrepancy)");
  EXPECT_EQ(f.text(), std::string(sequencer::fault_text(sequencer::Fault::kDriveFault)) +
                          " (motion stopped on sensor_discrepancy)");
  EXPECT_EQ(f.code(), sequencer::fault_code(sequencer::Fault::kDriveFault));
}

// What a session said, for the tests to read.
struct Heard {
  std::vector<std::pair<Severity, std::string>> lines;
  firmware::Say say() {
    return [this](Severity s, const std::string& t) { lines.emplace_back(s, t); };
  }
};

firmware::MachineOptions quiet_machine(std::uint32_t rows) {
  firmware::MachineOptions mo;
  mo.telemetry = false;
  mo.rows = rows;
  return mo;
}

TEST(Session, HardwareThatCannotBeBroughtUpIsNotArmedAndBadInputIsBadInput) {
  Heard heard;
  {
    Session s(SessionOptions::from_command_line("socketcan", "loomtest9", "simulated"), heard.say());
    try {
      s.build(firmware::default_loom_config(), firmware::default_scene(), quiet_machine(1), {});
      FAIL() << "a missing CAN interface was armed";
    } catch (const SessionError& e) {
      EXPECT_EQ(e.exit_code(), firmware::kExitNotArmed) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("cannot arm: ", 0), 0u) << e.what();
    }
  }
  {
    // Real drives beside simulated I/O that only the config asks for: refused before any bus is opened.
    firmware::LoomConfig cfg = firmware::default_loom_config();
    cfg.io.kind = firmware::IoKind::kSimulated;
    Session s(SessionOptions::from_command_line("socketcan", "loomtest9", ""), heard.say());
    try {
      s.build(cfg, firmware::default_scene(), quiet_machine(1), {});
      FAIL() << "simulated I/O beside real drives was armed without --io simulated";
    } catch (const SessionError& e) {
      EXPECT_EQ(e.exit_code(), firmware::kExitBadInput) << e.what();
    }
  }
}

TEST(Session, RunsARowAndSaysTheRunsLine) {
  Heard heard;
  Session s(SessionOptions::from_command_line("sim", "", ""), heard.say());
  firmware::Machine& m =
      s.build(firmware::default_loom_config(), firmware::default_scene(), quiet_machine(1), {});
  m.sequencer().request_start();
  int rows = 0;
  const firmware::RunResult res = s.run(s.run_options(nullptr), [&rows](const firmware::RunEvent& e) {
    if (e.kind == firmware::RunEvent::Kind::kRowDone) ++rows;
  });
  EXPECT_EQ(res.end, firmware::RunResult::End::kFinished);
  EXPECT_EQ(rows, 1);
  EXPECT_FALSE(s.fault().has_value());
  ASSERT_EQ(heard.lines.size(), 1u);  // one line, nothing to warn about
  EXPECT_EQ(heard.lines[0].first, Severity::kInfo);
  EXPECT_EQ(heard.lines[0].second.rfind("loop: ", 0), 0u) << heard.lines[0].second;
}

TEST(Session, TheOptionsEveryCommandSharesComeFromTheConfigAndTheHal) {
  Heard heard;
  firmware::LoomConfig cfg = firmware::default_loom_config();
  SessionOptions so = SessionOptions::from_command_line("sim", "", "", 4.0);
  so.realtime = true;
  Session s(so, heard.say());
  s.build(cfg, firmware::default_scene(), quiet_machine(1), {});
  const TempDir dir;
  ProductionRecord record(dir.file("counters.json"), cfg);
  const firmware::RunOptions ro = s.run_options(&record);
  EXPECT_EQ(ro.period_s, cfg.sequencer.period_s);
  EXPECT_TRUE(ro.realtime);
  EXPECT_EQ(ro.pace, 4.0);
  EXPECT_FALSE(ro.require_fifo);         // a simulation asks for SCHED_FIFO, never insists
  EXPECT_EQ(ro.overrun_stop_after, 0u);  // a paced simulator that falls behind endangers nothing
  EXPECT_EQ(ro.row_saves, record.row_saves());
}

// The loop's inputs after `first` and then `second` ticks of one session (a started sequencer moves).
std::vector<double> positions_after(hal::Tick first, hal::Tick second) {
  Heard heard;
  Session s(SessionOptions::from_command_line("sim", "", ""), heard.say());
  firmware::Machine& m =
      s.build(firmware::default_loom_config(), firmware::default_scene(), quiet_machine(1), {});
  m.sequencer().request_start();
  s.tick(first);
  s.tick(second);
  std::vector<double> p;
  for (std::size_t i = 0; i < m.sequencer().axes().count; ++i)
    p.push_back(m.loop().inputs().axes[i].position);
  return p;
}

TEST(Session, TicksGoOnAcrossCallsAsOneRunWouldHaveThem) {
  // Ticks restarting at 0 on each call would replay the first second of motion instead of going on.
  const std::vector<double> one_run = positions_after(1500, 0);
  const std::vector<double> two_calls = positions_after(500, 1000);
  ASSERT_EQ(one_run.size(), two_calls.size());
  for (std::size_t i = 0; i < one_run.size(); ++i) EXPECT_EQ(one_run[i], two_calls[i]) << "axis " << i;
  // And the machine did move in that time (the comparison is not of two machines at rest).
  EXPECT_NE(positions_after(1500, 0), positions_after(10, 0));
}

}  // namespace

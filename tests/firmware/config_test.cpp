// Config and CLI input errors: one line naming file, line, column, field and value; exit 2; nothing
// started. Also the embedded defaults parse and the shipped scenes load.
#include "loom/config/config.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli_run.hpp"
#include "config_error.hpp"
#include "loom/motion/profile_set.hpp"

using namespace loom::firmware;

namespace {

using loom::test::CliRun;
using loom::test::config_error;
CliRun run_loomctl(const std::string& args) {
  return loom::test::run_command(std::string(LOOMCTL_PATH) + " " + args);
}
std::string write_temp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path.string();
}
}  // namespace

TEST(Config, EmbeddedDefaultsParse) {
  const LoomConfig c = default_loom_config();
  EXPECT_EQ(c.loom_id, "loom1");
  EXPECT_DOUBLE_EQ(c.profile.beatup.bar.crank, 0.058);
  EXPECT_DOUBLE_EQ(c.sequencer.period_s, 0.002);
  const Scene s = default_scene();
  EXPECT_EQ(s.spec.effects, (std::vector<std::string>{"servo_lag", "pneumatics", "beat_contact"}));
  EXPECT_TRUE(s.spec.servo_lag && s.spec.pneumatics && s.spec.beat_contact);
  EXPECT_FALSE(s.spec.shuttle_slip || s.spec.sensor_noise);
}

TEST(Config, ShippedScenesLoad) {
  for (const char* name : {"default", "ideal", "servo_lag", "drive_fault", "estop", "stuck_piston",
                           "shuttle_slip", "stuck_sensor", "sensor_noise", "dynamics"}) {
    const Scene s = load_scene(std::string(LOOM_SOURCE_DIR) + "/sim_hal/scenes/" + name + ".toml");
    EXPECT_EQ(s.spec.name, name);
  }
}

TEST(Config, OutOfRangeValueNamesFileLineColumnFieldAndValue) {
  const std::string e =
      config_error("extends = \"default\"\n[loom]\nwidth_m = 1.2\n\n[beatup]\ncrank_m = -0.058\n");
  EXPECT_EQ(e, "loom.toml:6:11: beatup.crank_m = -0.058: must be in [0.005, 2]");
}

TEST(Config, WrongTypeAndUnknownKeyAndBadEnum) {
  EXPECT_EQ(config_error("extends = \"default\"\n[helix]\nlead_m = \"ten\"\n"),
            "loom.toml:3:10: helix.lead_m = \"ten\": expected a number");
  EXPECT_EQ(config_error("extends = \"default\"\n[helix]\nleed_m = 0.1\n"),
            "loom.toml:3:10: helix.leed_m = 0.1: unknown field");
  EXPECT_NE(config_error("extends = \"default\"\n[beatup]\nbranch = \"up\"\n")
                .find("beatup.branch = \"up\": must be one of"),
            std::string::npos);
}

TEST(Config, SyntaxErrorHasLineAndColumn) {
  const std::string e = config_error("[loom]\nwidth_m = = 3\n");
  EXPECT_EQ(e.rfind("loom.toml:2:", 0), 0u) << e;
}

TEST(Config, InfeasibleMotionIsRefusedWithTheLimits) {
  // A crank so slow to accelerate that it cannot reach speed before the first beat.
  const std::string e =
      config_error("extends = \"default\"\n[recipe]\ncrank_speed_rad_s = 15.5\ncrank_accel_rad_s2 = 5.0\n");
  EXPECT_NE(e.find("cannot reach 15.5 rad/s before the first beat"), std::string::npos) << e;
}

TEST(Config, HeartbeatTimeoutMustDetectLossWithinThreePeriods) {
  EXPECT_NE(config_error("extends = \"default\"\n[can]\nheartbeat_ms = 100\nheartbeat_timeout_ms = 400\n")
                .find("loom.toml:4:24: can.heartbeat_timeout_ms = 400: the CAN master refuses it"),
            std::string::npos);
}

TEST(Config, SceneRejectsUnknownEffectsAndOrphanParameters) {
  EXPECT_NE(std::string([] {
              try {
                (void)parse_scene("effects = [\"ideal\", \"warp_drive\"]\n", "s.toml");
              } catch (const ConfigError& e) {
                return std::string(e.what());
              }
              return std::string();
            }())
                .find("s.toml:1:"),
            std::string::npos);
  EXPECT_THROW((void)parse_scene("effects = [\"ideal\"]\n[servo_lag]\ntau_s = 0.01\n", "s.toml"),
               ConfigError);
}

TEST(LoomctlCli, BadConfigValueIsOneLineAndExit2) {
  const std::string path = write_temp("loom_bad.toml", "extends = \"default\"\n[loom]\nwidth_m = 99\n");
  const CliRun r = run_loomctl("weave --no-telemetry --config " + path);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.output, "loomctl: " + path + ":3:11: loom.width_m = 99: must be in [0.2, 10]\n");
}

TEST(LoomctlCli, BadArgumentsExit2) {
  EXPECT_EQ(run_loomctl("weave --rows 0").exit_code, 2);
  EXPECT_EQ(run_loomctl("weave --hal can").exit_code, 2);
  EXPECT_EQ(run_loomctl("weave --hal socketcan").exit_code, 2);
  EXPECT_EQ(run_loomctl("weave --period-ms 100 --no-telemetry").exit_code, 2);
  EXPECT_EQ(run_loomctl("fly").exit_code, 2);
}

TEST(LoomctlCli, WeavesThreeRowsAndPrintsRowSummaries) {
  const CliRun r = run_loomctl("weave --rows 3 --no-telemetry");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  for (const char* row : {"row 1/3:", "row 2/3:", "row 3/3:"})
    EXPECT_NE(r.output.find(row), std::string::npos);
  EXPECT_NE(r.output.find("15 beats, 14 carriage steps"), std::string::npos) << r.output;
}

TEST(LoomctlCli, FaultSceneExits3AndKeepsCounters) {
  const std::string counters = (std::filesystem::temp_directory_path() / "loom_fault_counters.json").string();
  std::filesystem::remove(counters);
  const CliRun r = run_loomctl("weave --rows 5 --no-telemetry --counters " + counters + " --scene " +
                               std::string(LOOM_SOURCE_DIR) + "/sim_hal/scenes/drive_fault.toml");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("FAULT drive_fault"), std::string::npos) << r.output;
  std::ifstream f(counters);
  std::string body((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  EXPECT_NE(body.find("\"rows\":1"), std::string::npos) << body;
}

TEST(LoomctlCli, ResumesFromSavedCounters) {
  // A fresh simulated machine has its shuttle at the left, which only an even pick count agrees with
  // (odd counts against it are refused as shuttle_side_mismatch: see tests/sim/reproductions_test.cpp).
  const std::string counters =
      write_temp("loom_resume_counters.json", "{\"rows\":6,\"picks\":6,\"beats\":90,\"picks_in_row\":0}\n");
  const CliRun r = run_loomctl("weave --rows 1 --no-telemetry --counters " + counters);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("row 7/7:"), std::string::npos) << r.output;
  std::ifstream f(counters);
  std::string body((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  EXPECT_EQ(body, "{\"rows\":7,\"picks\":7,\"beats\":105,\"picks_in_row\":0}\n");
}

TEST(Config, BeatForceTargetSetsTheCrankSpeedAndExcludesAFixedSpeed) {
  const LoomConfig c = default_loom_config();
  EXPECT_DOUBLE_EQ(c.beat_force_target_n, 90.0);
  EXPECT_NEAR(c.profile.crank.velocity, 16.06, 0.01);  // the beat-up's inverse dynamics for 90 N
  const LoomConfig slow =
      parse_loom_config("extends = \"default\"\n[recipe]\nbeat_force_target_n = 80.0\n", "loom.toml");
  // The beater force is inertial: speed scales with the square root of the force.
  EXPECT_NEAR(slow.profile.crank.velocity / c.profile.crank.velocity, std::sqrt(80.0 / 90.0), 1e-9);
  const LoomConfig fixed =
      parse_loom_config("extends = \"default\"\n[recipe]\ncrank_speed_rad_s = 15.5\n", "loom.toml");
  EXPECT_DOUBLE_EQ(fixed.profile.crank.velocity, 15.5);
  EXPECT_EQ(fixed.beat_force_target_n, 0.0);
  EXPECT_NE(
      config_error("extends = \"default\"\n[recipe]\ncrank_speed_rad_s = 15.5\nbeat_force_target_n = 90.0\n")
          .find("not both"),
      std::string::npos);
}

TEST(Config, BeatsPerPositionMultipliesTheBeatsOfARow) {
  const LoomConfig c =
      parse_loom_config("extends = \"default\"\n[recipe]\nbeats_per_position = 3\n", "loom.toml");
  const loom::motion::ProfileSet p(c.profile);
  EXPECT_EQ(p.beats_per_row(), 45);
  EXPECT_EQ(p.cam().steps(), 14);
  EXPECT_EQ(config_error("extends = \"default\"\n[recipe]\nbeats_per_position = 0\n"),
            "loom.toml:3:22: recipe.beats_per_position = 0: must be in [1, 16]");
}

// The loop period must resolve the beat: the load cell is read once per tick and a beat's contact with
// the fell lasts only a few ticks, so at most 10 deg of crank per tick at the beat (at 20 ms the default
// recipe's beats came out down to 78.8 N, under the 80 N band) — at the fastest beat the loom may run: the
// beat regulator may beat up to its bound (x1.15) above the recipe's speed. Default recipe: 16.06 rad/s at
// the beat, 18.47 rad/s at the fastest, so 9.4 ms (9.95 deg) is the longest representable period (0x60C2:
// value·10^index) still accepted; 10 ms, accepted before the regulator, is refused.
TEST(Config, LoopPeriodMustResolveTheBeat) {
  const std::string head = "extends = \"default\"\n[timing]\n";
  EXPECT_EQ(config_error(head + "period_ms = 9.4\n"), "");
  const std::string e = config_error(head + "period_ms = 9.5\n");
  EXPECT_EQ(
      e.rfind("loom.toml:3:13: timing.period_ms = 9.5: the crank turns 10.1 deg per tick at the fastest "
              "beat (18.47 rad/s, the beat regulator's bound x1.15 on the recipe's speed); at most 10 deg "
              "per tick, i.e. period_ms <= 9.44 for this recipe",
              0),
      0u)
      << e;
  EXPECT_NE(config_error(head + "period_ms = 10\n"), "");
  const std::string e20 = config_error(head + "period_ms = 20\n");
  EXPECT_EQ(
      e20.rfind(
          "loom.toml:3:13: timing.period_ms = 20: the crank turns 21.2 deg per tick at the fastest beat", 0),
      0u)
      << e20;
  EXPECT_NE(e20.find("the load cell, read once per tick, can miss its peak"), std::string::npos) << e20;
  // A slower crank allows a longer period: 12.5 rad/s (14.37 at the fastest beat) turns 9.9 deg in 12 ms.
  EXPECT_EQ(
      config_error("extends = \"default\"\n[recipe]\ncrank_speed_rad_s = 12.5\n[timing]\nperiod_ms = 12\n"),
      "");
  EXPECT_NE(
      config_error("extends = \"default\"\n[recipe]\ncrank_speed_rad_s = 12.5\n[timing]\nperiod_ms = 15\n")
          .find("timing.period_ms = 15: the crank turns 12.4 deg per tick at the fastest beat (14.37 rad/s"),
      std::string::npos);
}

TEST(Config, LoopPeriodFromTheCommandLineIsCheckedToo) {
  LoomConfig c = default_loom_config();
  c.run.period_s = 0.0094;
  EXPECT_NO_THROW(rederive_and_check(c, "--period-ms 9.4"));
  c.run.period_s = 0.02;
  try {
    rederive_and_check(c, "--period-ms 20");
    ADD_FAILURE() << "20 ms accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(
                  "--period-ms 20: with it, timing.period_ms = 20: the crank turns 21.2 deg", 0),
              0u)
        << e.what();
  }
}

TEST(LoomctlCli, CoarseLoopPeriodIsRefusedByCheckAndWeave) {
  const CliRun w = run_loomctl("weave --rows 1 --no-telemetry --period-ms 20");
  EXPECT_EQ(w.exit_code, 2) << w.output;
  EXPECT_NE(w.output.find("timing.period_ms = 20: the crank turns 21.2 deg per tick at the fastest beat"),
            std::string::npos)
      << w.output;
  const std::string path =
      write_temp("loom_period20.toml", "extends = \"default\"\n[timing]\nperiod_ms = 20\n");
  const CliRun c = run_loomctl("check --config " + path);
  EXPECT_EQ(c.exit_code, 2) << c.output;
  EXPECT_NE(c.output.find(
                path + ":3:13: timing.period_ms = 20: the crank turns 21.2 deg per tick at the fastest beat"),
            std::string::npos)
      << c.output;
  EXPECT_EQ(run_loomctl("weave --rows 1 --no-telemetry --period-ms 9").exit_code, 0);
}

// One default, not two: the embedded default TOML and a default-constructed LoomConfig must say the same
// thing, or code that builds a LoomConfig without parsing (tests, tools) runs a different machine.
TEST(Config, StructDefaultsAgreeWithTheEmbeddedDefaultToml) {
  const LoomConfig parsed = default_loom_config();
  const LoomConfig built;
  // Every machine, CAN, I/O, timing and telemetry key, compared as loomctl prints them.
  EXPECT_EQ(restart_only_changes(built, parsed), "");
  ASSERT_EQ(built.axes.size(), 3u);
  EXPECT_DOUBLE_EQ(built.axes[1].counts_per_unit(),
                   52428800.0);  // 2^20 counts per 20 mm, as the drives assume
  EXPECT_DOUBLE_EQ(built.axes[1].counts_per_unit(), loom::drivers::kDefaultCountsPerM);
  EXPECT_DOUBLE_EQ(built.axes[0].counts_per_unit(), loom::drivers::kDefaultCountsPerRad);
  // The recipe's numeric keys (restart_only_changes leaves the recipe out).
  const Recipe& a = built.recipe;
  const Recipe& b = parsed.recipe;
  EXPECT_DOUBLE_EQ(a.beat_force_target_n, b.beat_force_target_n);
  EXPECT_DOUBLE_EQ(a.crank_speed_rad_s, b.crank_speed_rad_s);
  EXPECT_DOUBLE_EQ(a.crank_accel_rad_s2, b.crank_accel_rad_s2);
  EXPECT_DOUBLE_EQ(a.crank_jerk_rad_s3, b.crank_jerk_rad_s3);
  EXPECT_EQ(a.picks_per_row, b.picks_per_row);
  EXPECT_EQ(a.beats_per_position, b.beats_per_position);
  EXPECT_DOUBLE_EQ(a.overlap_m, b.overlap_m);
  EXPECT_DOUBLE_EQ(a.cam_margin_rad, b.cam_margin_rad);
  EXPECT_DOUBLE_EQ(a.beat_force_min_n, b.beat_force_min_n);
  EXPECT_DOUBLE_EQ(a.beat_force_max_n, b.beat_force_max_n);
  EXPECT_EQ(a.crank_law.kind, b.crank_law.kind);
  EXPECT_DOUBLE_EQ(a.crank_law.ellipse_e, b.crank_law.ellipse_e);
  EXPECT_EQ(a.crank_law.ellipse_lobes, b.crank_law.ellipse_lobes);
  EXPECT_DOUBLE_EQ(a.crank_law.ellipse_phi02_rad, b.crank_law.ellipse_phi02_rad);
  EXPECT_EQ(a.table_size, b.table_size);
  EXPECT_EQ(a.table_interp, b.table_interp);
  EXPECT_EQ(a.table_precision, b.table_precision);
  EXPECT_DOUBLE_EQ(a.max_table_error_rad, b.max_table_error_rad);
  EXPECT_EQ(built.loom_id, parsed.loom_id);
}

// The safety sensors' second switches are wiring like any other input: a bit already used is refused at
// the second switch's own key; -1 leaves that sensor single-channel; the discrepancy time is a time.
TEST(Config, SecondSwitchesAreWiredInputsAndDeriveTheSequencersDualChannels) {
  const LoomConfig dual = parse_loom_config("extends = \"default\"\n", "loom.toml");
  for (bool wired : dual.sequencer.second_channel) EXPECT_TRUE(wired);
  for (bool fitted : dual.machine.second_channel) EXPECT_TRUE(fitted);
  EXPECT_DOUBLE_EQ(dual.sequencer.sensor_discrepancy_s, 0.02);
  const LoomConfig single =
      parse_loom_config("extends = \"default\"\n[io]\nshuttle_at_left_2_bit = -1\n", "loom.toml");
  EXPECT_FALSE(
      single.sequencer.second_channel[static_cast<std::size_t>(loom::hal::SafetySensor::kShuttleAtLeft)]);
  EXPECT_FALSE(
      single.machine.second_channel[static_cast<std::size_t>(loom::hal::SafetySensor::kShuttleAtLeft)]);
  EXPECT_TRUE(
      single.sequencer.second_channel[static_cast<std::size_t>(loom::hal::SafetySensor::kShuttleAtRight)]);
  const std::string e = config_error("extends = \"default\"\n[io]\nshuttle_at_right_2_bit = 5\n");
  EXPECT_EQ(e.rfind("loom.toml:3:26: io.shuttle_at_right_2_bit = 5: the I/O module refuses it: ", 0), 0u)
      << e;
  EXPECT_NE(e.find("already used by io.inputs.shuttle_at_right"), std::string::npos) << e;
  EXPECT_EQ(config_error("extends = \"default\"\n[io]\npiston_a_extended_2_bit = 64\n"),
            "loom.toml:3:27: io.piston_a_extended_2_bit = 64: must be in [-1, 63]");
  EXPECT_EQ(config_error("extends = \"default\"\n[timing]\nsensor_discrepancy_ms = 0\n"),
            "loom.toml:3:25: timing.sensor_discrepancy_ms = 0: must be in [1, 1000]");
}

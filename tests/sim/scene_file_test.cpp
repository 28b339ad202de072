// Scene files are read as strictly as loom configs: every refusal names file:line:col, key and value;
// a scene written by scene_to_toml (loom-safety's violation files) reads back to the same scene.
#include <gtest/gtest.h>

#include <string>

#include "loom/config/config.hpp"
#include "loom/config/scene_config.hpp"

using namespace loom;

namespace {
// The ConfigError message for `text`, or "" when it parses.
std::string error_of(const std::string& text) {
  try {
    firmware::parse_scene(text, "s.toml");
  } catch (const firmware::ConfigError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(SceneFile, NonFiniteOrNegativeTimesAreRefusedAtTheirLine) {
  EXPECT_EQ(error_of("effects = [\"ideal\"]\n[[fault]]\nkind = \"estop\"\nat_s = nan\n"),
            "s.toml:4:8: fault[0].at_s = nan: must be a finite number in [0, 1e+07]");
  EXPECT_NE(error_of("effects = [\"ideal\"]\n[[fault]]\nkind = \"estop\"\nat_s = inf\n"), "");
  EXPECT_NE(error_of("effects = [\"ideal\"]\n[[fault]]\nkind = \"estop\"\nat_s = -1.0\n"), "");
}

TEST(SceneFile, AnEmptyFaultIsRefusedNotADriveFaultAtZero) {
  const std::string e = error_of("effects = [\"ideal\"]\n[[fault]]\n");
  EXPECT_NE(e.find("s.toml:2:1: fault[0].kind = (missing)"), std::string::npos) << e;
}

TEST(SceneFile, EachKindNeedsItsFieldsAndTakesNoOthers) {
  EXPECT_NE(error_of("effects = [\"ideal\"]\n[[fault]]\nkind = \"stuck_sensor\"\nat_s = 1.0\nsensor = "
                     "\"shuttle_at_left\"\n")
                .find("fault[0].value = (missing)"),
            std::string::npos);
  EXPECT_NE(error_of("effects = [\"ideal\"]\n[[fault]]\nkind = \"estop\"\nat_s = 1.0\naxis = \"helix\"\n")
                .find("s.toml:5:8: fault[0].axis = \"helix\": not used by a estop fault"),
            std::string::npos);
  EXPECT_NE(error_of("effects = [\"ideal\"]\n[[fault]]\nkind = \"power_cut\"\nat_s = 1.0\n").find("at_tick"),
            std::string::npos);
  EXPECT_NE(
      error_of("effects = [\"ideal\"]\n[[fault]]\nkind = \"load_cell_failure\"\nat_s = 1.0\nmode = \"nan\"\n")
          .find("beat_contact"),
      std::string::npos);
  EXPECT_NE(
      error_of("effects = [\"ideal\"]\n[[fault]]\nkind = \"emcy\"\nat_s = 1.0\naxis = \"helix\"\ncode = 0\n")
          .find("fault[0].code = 0"),
      std::string::npos);
  EXPECT_NE(error_of("effects = [\"ideal\"]\n[[fault]]\nkind = \"warp_break\"\nat_s = 1.0\n")
                .find("must be one of"),
            std::string::npos);
}

TEST(SceneFile, DuplicatesAreRefused) {
  EXPECT_NE(error_of("effects = [\"ideal\", \"servo_lag\", \"servo_lag\"]\n").find("named twice"),
            std::string::npos);
  EXPECT_NE(error_of("effects = [\"ideal\"]\n[[fault]]\nkind = \"estop\"\nat_s = 1.0\n[[fault]]\nkind = "
                     "\"estop\"\nat_s = 1.0\n")
                .find("s.toml:5:1: fault[1]"),
            std::string::npos);
  EXPECT_NE(error_of("effects = []\n"), "");
}

TEST(SceneFile, EveryFaultKindRoundTripsThroughTheWriter) {
  sim_hal::SceneSpec s;
  s.name = "round \"trip\"";
  s.seed = 42;
  s.effects = {"ideal", "servo_lag", "beat_contact"};
  s.servo_lag = sim_hal::ServoLag{0.0031};
  s.beat_contact = sim_hal::BeatContact{2.4, 0.004};
  for (int k = 0; k < sim_hal::kInjectedFaultCount; ++k) {
    sim_hal::FaultInjection f;
    f.kind = static_cast<sim_hal::InjectedFault>(k);
    f.at_s = 0.1 * k + 1.0 / 3.0;
    f.at_tick = 1234;
    f.axis_name = "helix";
    f.axis = hal::index(hal::CoreAxis::kHelix);
    f.code = 0x2310;
    f.sensor = sim_hal::Sensor::kPistonBExtended;
    f.stuck_value = true;
    f.duration_s = 0.25;
    f.probability = 0.5;
    f.latency_s = 0.01;
    f.jump = -0.125;
    f.ticks = 7;
    f.load_cell = sim_hal::LoadCellMode::kLost;
    s.faults.push_back(f);
  }
  const std::string text = firmware::scene_to_toml(s);
  const firmware::Scene back = firmware::parse_scene(text, "written.toml");
  EXPECT_EQ(firmware::scene_to_toml(back.spec), text);
  ASSERT_EQ(back.spec.faults.size(), s.faults.size());
  EXPECT_EQ(back.spec.faults[0].at_s, s.faults[0].at_s);  // 17 digits: exact
  EXPECT_EQ(back.spec.name, s.name);
}

// Knotting heads are simulated only where the simulator is the loom's I/O: there a scene must name the
// effect "knotter"; with a real I/O module carrying the heads' signals (over CAN) it need not.
TEST(SceneFile, HeadsNeedTheKnotterEffectOnlyWhenTheirIoIsSimulated) {
  firmware::LoomConfig heads = firmware::default_loom_config();
  heads.knotting.mode = sequencer::KnottingMode::kHeads;
  const firmware::Scene plain = firmware::parse_scene("effects = [\"ideal\"]\n", "s.toml");
  EXPECT_THROW((void)firmware::check_scene_fits(plain, heads, true), firmware::ConfigError);
  EXPECT_NO_THROW((void)firmware::check_scene_fits(plain, heads, false));
  const firmware::Scene knotter = firmware::parse_scene("effects = [\"ideal\", \"knotter\"]\n", "s.toml");
  EXPECT_NO_THROW((void)firmware::check_scene_fits(knotter, heads, true));
}

TEST(SceneFile, AFaultInASecondSwitchTheLoomDoesNotHaveIsRefusedAtTheFault) {
  const firmware::Scene scene = firmware::parse_scene(
      "effects = [\"ideal\"]\n[[fault]]\nkind = \"stuck_sensor\"\nat_s = 1.0\nsensor = "
      "\"shuttle_at_right_2\"\nvalue = true\n",
      "s.toml");
  EXPECT_NO_THROW(firmware::check_scene_fits(scene, firmware::default_loom_config()));
  firmware::LoomConfig single = firmware::default_loom_config();
  single.io.wiring.second[static_cast<std::size_t>(hal::SafetySensor::kShuttleAtRight)].bit = -1;
  firmware::rederive_and_check(single, "test");
  try {
    firmware::check_scene_fits(scene, single);
    FAIL() << "a fault in a switch the loom does not have was accepted";
  } catch (const firmware::ConfigError& e) {
    EXPECT_EQ(
        std::string(e.what()).rfind("s.toml:2:1: fault[0].sensor = \"shuttle_at_right_2\": the loom", 0), 0u)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("io.shuttle_at_right_2_bit = -1"), std::string::npos) << e.what();
  }
}

// warp_tension: its numbers are range-checked at their line, it needs beat_contact, `points` and
// `centre_ratio` exclude each other, and both forms round-trip through the writer.
TEST(SceneFile, WarpTensionIsCheckedAtItsLineAndRoundTrips) {
  const std::string effects = "effects = [\"ideal\", \"beat_contact\", \"warp_tension\"]\n[warp_tension]\n";
  EXPECT_EQ(error_of(effects + "noise = 0.5\n"), "s.toml:3:9: warp_tension.noise = 0.5: must be in [0, 0.2]");
  EXPECT_EQ(error_of(effects + "drift_per_row = nan\n"),
            "s.toml:3:17: warp_tension.drift_per_row = nan: must be finite");
  EXPECT_EQ(error_of(effects + "points = [1.0]\n"),
            "s.toml:3:10: warp_tension.points = [...]: expected 2..64 relative tensions, equally spaced from "
            "the left "
            "selvedge to the right");
  EXPECT_EQ(error_of(effects + "points = [1.0, -2.0]\n"),
            "s.toml:3:16: warp_tension.points = -2: each relative tension must be a number in [0.05, 5]");
  EXPECT_NE(error_of(effects + "points = [1.0, 0.9]\ncentre_ratio = 0.9\n").find("not both"),
            std::string::npos);
  EXPECT_NE(error_of(effects + "tilt = 1\n").find("warp_tension.tilt"), std::string::npos);  // unknown key
  EXPECT_NE(error_of("effects = [\"ideal\", \"warp_tension\"]\n").find("name \"beat_contact\" too"),
            std::string::npos);
  EXPECT_NE(error_of("effects = [\"ideal\", \"beat_contact\"]\n[warp_tension]\nnoise = 0.1\n")
                .find("parameters given for an effect the scene does not name"),
            std::string::npos);
  for (const bool with_points : {false, true}) {
    sim_hal::SceneSpec s;
    s.effects = {"ideal", "beat_contact", "warp_tension"};
    s.beat_contact = sim_hal::BeatContact{};
    s.warp_tension =
        sim_hal::WarpTension{.centre_ratio = 0.8125, .points = {}, .drift_per_row = -0.0015, .noise = 0.03};
    if (with_points) s.warp_tension->points = {1.1, 0.875, 1.0};
    const std::string text = firmware::scene_to_toml(s);
    const firmware::Scene back = firmware::parse_scene(text, "written.toml");
    EXPECT_EQ(firmware::scene_to_toml(back.spec), text);
    ASSERT_TRUE(back.spec.warp_tension.has_value());
    EXPECT_EQ(back.spec.warp_tension->points, s.warp_tension->points);
    EXPECT_EQ(back.spec.warp_tension->drift_per_row, -0.0015);
  }
}

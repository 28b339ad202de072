// The servo drives of the machine description: a drive described once, as it is sold ([drives.<model>]),
// named by its axes; the limits the profiles use derived from it; a limit above what it delivers refused
// at its line; today's knotting head (a micro servo asked for 60 rad/s) refused and the shipped one
// (a 100 W AC servo behind a 10:1 planetary) accepted, its knot cycle planned under its torque-speed line.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "config_error.hpp"
#include "loom/config/config.hpp"
#include "loom/motion/knot_cycle.hpp"
#include "text_file.hpp"

using namespace loom::firmware;

namespace {

using loom::test::read_text_file;

using loom::test::config_error;

const std::string kConfigDir = std::string(LOOM_SOURCE_DIR) + "/firmware/config";

// The shipped knotting loom's text with every `from` line replaced by `to`.
std::string shipped_with(const std::string& from, const std::string& to) {
  std::string s = read_text_file(kConfigDir + "/knotting_loom.toml");
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
  return s;
}

const std::string kKnotterDrive =
    "drive = \"servo_100w_10to1\"    # the default loom's [drives] table: 62.8 rad/s no-load at the "
    "linkage's "
    "crank";

// An MG90S-class micro servo as the old head described it, its output facts as sold (no gearbox to name:
// the gear train is inside): 0.1 s/60° at no load = 100 rpm, 0.18 N m stall, a third of it continuous,
// 1.7e-5 kg m² at the output.
const std::string kMicroServo =
    "\n[drives.micro_servo]\nmotor_speed_rpm = 100\nrated_torque_nm = 0.06\npeak_torque_nm = 0.18\n"
    "rotor_inertia_kg_m2 = 1.7e-5\n";

}  // namespace

TEST(ServoDrives, TodaysHeadIsRefused) {
  // As it was written: the servo's torque as a [knotting] key beside a 60 rad/s knotter axis.
  const std::string old_text = shipped_with(kKnotterDrive, "max_speed = 60.0");
  std::string with_old_key = old_text;
  with_old_key.replace(with_old_key.find("[knotting]\n"), 11,
                       "[knotting]\nservo_torque_nm = 0.06        # micro servo: a third of its stall\n");
  const std::string e1 = config_error(with_old_key, kConfigDir + "/today.toml");
  EXPECT_NE(e1.find("knotting.servo_torque_nm = 0.06: moved: this fact is drives.<model>.rated_torque_nm"),
            std::string::npos)
      << e1;
  // Described as a drive, the same head asks for more speed than the servo has.
  const std::string e2 =
      config_error(shipped_with(kKnotterDrive, "drive = \"micro_servo\"\nmax_speed = 60.0") + kMicroServo,
                   kConfigDir + "/today.toml");
  EXPECT_NE(e2.find("today.toml:21:13: axes.knotter_1.max_speed = 60 rad/s: exceeds the drive's 10.5 rad/s "
                    "at the output (drives.micro_servo: 100 rpm / gear_ratio 1)"),
            std::string::npos)
      << e2;
  // At what it can do, the micro servo's knot cycle takes 0.86 s (the torque-speed line binds).
  const LoomConfig c = parse_loom_config(shipped_with(kKnotterDrive, "drive = \"micro_servo\"") + kMicroServo,
                                         kConfigDir + "/today.toml");
  EXPECT_NEAR(c.knot_cycle.no_load_speed_rad_s, 100 * 2 * M_PI / 60, 1e-12);
  const loom::motion::KnotCycle kc = loom::motion::KnotCycle::build(c.knot_cycle);
  // ≥ the dwells and the travel at 10.47 rad/s with no acceleration time
  EXPECT_GT(kc.duration_s(), 0.856);
}

TEST(ServoDrives, TheShippedHeadIsAcceptedAndItsCycleRidesTheLine) {
  const LoomConfig c = load_loom_config(kConfigDir + "/knotting_loom.toml");
  // The knot cycle's servo is the drive's output: 6000 rpm / 10, 0.95 N m × 10 × 0.95, (0.051 + 0.03) kg
  // cm² × 10².
  EXPECT_NEAR(c.knot_cycle.no_load_speed_rad_s, 6000 * 2 * M_PI / 60 / 10, 1e-12);
  EXPECT_NEAR(c.knot_cycle.peak_torque_nm, 9.025, 1e-12);
  EXPECT_NEAR(c.knot_cycle.continuous_torque_nm, 3.04, 1e-12);
  EXPECT_NEAR(c.knot_cycle.rotor_inertia_kg_m2, 8.1e-4, 1e-15);
  EXPECT_EQ(c.knot_cycle.max_speed_rad_s, 0.0);  // no cap: the line alone
  // Derived limits: the knotters' top speed is the drive's; the selectors keep their lower max_speed.
  for (const AxisSpec& a : c.axes) {
    if (a.role == loom::hal::AxisRole::kKnotter) {
      EXPECT_NEAR(a.max_speed, 62.83185307, 1e-8) << a.name;
    } else if (a.role == loom::hal::AxisRole::kSelector) {
      EXPECT_EQ(a.max_speed, 20.0) << a.name;
    }
  }
  const loom::motion::KnotCycle kc = loom::motion::KnotCycle::build(c.knot_cycle);
  for (const auto& seg : kc.report().segments) {
    if (seg.distance_rad != 0.0) {
      EXPECT_EQ(seg.bound, loom::motion::KnotLimit::kTorqueSpeedLine) << seg.name;
    }
  }
  EXPECT_NEAR(kc.duration_s(), 0.459, 0.001);
  EXPECT_LT(kc.report().rms_torque_nm, c.knot_cycle.continuous_torque_nm);
}

// One fact in one place: the motion library's seed spec carries the shipped drive too; the two are equal.
TEST(ServoDrives, TheDefaultFilesDriveIsTheMotionLibrarysShippedOne) {
  const LoomConfig c = default_loom_config();
  // The knotters' drive among the core axes' (the default loom describes one per axis class).
  const DriveModel* knotter = nullptr;
  for (const DriveModel& m : c.drives) {
    if (m.name == "servo_100w_10to1") knotter = &m;
  }
  ASSERT_NE(knotter, nullptr);
  const loom::motion::ServoDrive a = knotter->drive, b = loom::motion::shipped_knotter_drive();
  EXPECT_DOUBLE_EQ(a.motor_speed_rad_s, b.motor_speed_rad_s);
  EXPECT_DOUBLE_EQ(a.motor_rated_torque_nm, b.motor_rated_torque_nm);
  EXPECT_DOUBLE_EQ(a.motor_peak_torque_nm, b.motor_peak_torque_nm);
  EXPECT_DOUBLE_EQ(a.rotor_inertia_kg_m2, b.rotor_inertia_kg_m2);
  EXPECT_DOUBLE_EQ(a.gear_ratio, b.gear_ratio);
  EXPECT_DOUBLE_EQ(a.gear_inertia_kg_m2, b.gear_inertia_kg_m2);
  EXPECT_DOUBLE_EQ(a.gear_efficiency, b.gear_efficiency);
}

TEST(ServoDrives, ACapBelowTheDriveIsHonouredAndCruises) {
  const LoomConfig c =
      parse_loom_config(shipped_with(kKnotterDrive, "drive = \"servo_100w_10to1\"\nmax_speed = 30.0"),
                        kConfigDir + "/capped.toml");
  EXPECT_EQ(c.knot_cycle.max_speed_rad_s, 30.0);
  const loom::motion::KnotCycle kc = loom::motion::KnotCycle::build(c.knot_cycle);
  EXPECT_EQ(kc.report().segments[5].bound, loom::motion::KnotLimit::kSpeedCap);
  EXPECT_LE(kc.report().peak_speed_rad_s, 30.0 * (1 + 1e-12));
}

TEST(ServoDrives, RefusalsNameTheLine) {
  // A knotting servo with heads must name its drive.
  const std::string none =
      config_error(shipped_with(kKnotterDrive, "max_speed = 30.0"), kConfigDir + "/n.toml");
  EXPECT_NE(none.find("n.toml:16:8: axes.knotter_1.role = \"knotter\": a knotting servo names its drive"),
            std::string::npos)
      << none;
  // A drive no table describes.
  const std::string unknown =
      config_error(shipped_with(kKnotterDrive, "drive = \"servo_200w\""), kConfigDir + "/u.toml");
  EXPECT_NE(unknown.find("axes.knotter_1.drive = \"servo_200w\": no [drives.servo_200w] table (the file "
                         "describes servo_100w_10to1, servo_200w_5to1, servo_400w_10to1, servo_400w_belt)"),
            std::string::npos)
      << unknown;
  // A data sheet whose rated torque exceeds its peak; a missing fact; a fact out of range.
  EXPECT_NE(
      config_error("extends = \"default\"\n[drives.x]\nmotor_speed_rpm = 3000\nrated_torque_nm = 1\n"
                   "peak_torque_nm = 0.5\nrotor_inertia_kg_m2 = 1e-5\n")
          .find("loom.toml:4:19: drives.x.rated_torque_nm = 1: the rated (continuous) torque 1 N m exceeds "
                "the peak torque 0.5 N m"),
      std::string::npos);
  EXPECT_NE(config_error("extends = \"default\"\n[drives.x]\nmotor_speed_rpm = 3000\n")
                .find("drives.x.rated_torque_nm = (missing): missing: a fact of the drive's data sheet"),
            std::string::npos);
  EXPECT_NE(config_error("extends = \"default\"\n[drives.servo_100w_10to1]\ngear_efficiency = 1.2\n")
                .find("loom.toml:3:19: drives.servo_100w_10to1.gear_efficiency = 1.2: must be in (0, 1]"),
            std::string::npos);
  // The knot cycle's torque refusals blame the knotting servo's drive: a cycle whose rms torque is over the
  // continuous rating.
  const std::string weak = config_error(read_text_file(kConfigDir + "/knotting_loom.toml") +
                                            "\n[drives.servo_100w_10to1]\nrated_torque_nm = 0.05\n",
                                        kConfigDir + "/w.toml");
  EXPECT_NE(weak.find("axes.knotter_1.drive = \"servo_100w_10to1\": the knotting servo's drive: knot cycle: "
                      "continuous_torque_nm = 0.475"),
            std::string::npos)
      << weak;
}

// The core axes (beat crank, carriage, helix) described by their drives as sold: the shipped loom names
// one for each and its motion fits them; the figures at the axis follow the closed forms (output shaft:
// speed / ratio, torque x ratio x efficiency, inertia x ratio^2; the carriage through its screw lead:
// rpm / 60 x lead, 2 pi x torque x efficiency / lead, inertia x (2 pi / lead)^2); a loom file asking more
// than its drive gives is refused at the key that asks (else at the line naming the drive), the drive named.
#include "loom/config/core_drives.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "config_error.hpp"
#include "loom/config/config.hpp"
#include "loom/motion/profile_set.hpp"

using namespace loom::firmware;
using loom::test::config_error;

namespace {

const CoreDriveFit* fit_of(const std::vector<CoreDriveFit>& fits, const std::string& axis) {
  for (const CoreDriveFit& f : fits) {
    if (f.axis == axis) return &f;
  }
  return nullptr;
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST(CoreDrives, TheShippedLoomNamesADriveForEachCoreAxisAndFitsIt) {
  const LoomConfig c = default_loom_config();
  const loom::motion::ProfileSet set(c.profile);
  const std::vector<CoreDriveFit> fits = core_drive_fits(c, set);
  ASSERT_EQ(fits.size(), 3u);
  const CoreDriveFit* crank = fit_of(fits, "beat_crank");
  const CoreDriveFit* carriage = fit_of(fits, "carriage");
  const CoreDriveFit* helix = fit_of(fits, "helix");
  ASSERT_TRUE(crank && carriage && helix);
  EXPECT_EQ(crank->model, "servo_400w_10to1");
  EXPECT_EQ(carriage->model, "servo_400w_screw");
  EXPECT_EQ(helix->model, "servo_200w_5to1");
  const double rpm = 2.0 * M_PI / 60.0;
  // The crank: a 400 W servo (6000 rpm, 3.8 N m peak, 1.27 N m rated, 0.27 + 0.07 kg cm^2) behind 10:1 at 95
  // %.
  EXPECT_NEAR(crank->at.top_speed, 6000 * rpm / 10, 1e-12);
  EXPECT_NEAR(crank->at.peak_effort, 3.8 * 10 * 0.95, 1e-12);
  EXPECT_NEAR(crank->at.rated_effort, 1.27 * 10 * 0.95, 1e-12);
  EXPECT_NEAR(crank->at.inertia, 0.34e-4 * 100, 1e-15);
  // The carriage: the same motor straight on the 10 mm screw (0.66 kg cm^2, 90 %): 1.0 m/s, 2149 N.
  EXPECT_NEAR(carriage->at.top_speed, 6000.0 / 60.0 * 0.010, 1e-12);
  EXPECT_NEAR(carriage->at.peak_effort, 2 * M_PI * 3.8 * 0.90 / 0.010, 1e-9);
  EXPECT_NEAR(carriage->at.rated_effort, 2 * M_PI * 1.27 * 0.90 / 0.010, 1e-9);
  EXPECT_NEAR(carriage->at.inertia, 0.93e-4 * std::pow(2 * M_PI / 0.010, 2), 1e-9);
  // The helix: a 200 W servo (1.91 N m peak, 0.14 + 0.07 kg cm^2) behind 5:1 at 95 %; the shuttle's
  // 0.40 kg on the 0.10 m lead adds m (lead / 2 pi)^2.
  EXPECT_NEAR(helix->at.top_speed, 6000 * rpm / 5, 1e-12);
  EXPECT_NEAR(helix->at.peak_effort, 1.91 * 5 * 0.95, 1e-12);
  EXPECT_NEAR(helix->at.inertia, 0.21e-4 * 25, 1e-15);
  EXPECT_NEAR(helix->load_inertia, 0.40 * std::pow(0.10 / (2 * M_PI), 2), 1e-15);
  // What the shipped motion asks: the crank's fastest beat is its force-derived speed x the regulator's
  // 1.15 (constant law); the carriage's and helix' limits as the file states them.
  EXPECT_NEAR(crank->need_speed, c.profile.crank.velocity * 1.15, 1e-12);
  EXPECT_EQ(carriage->need_speed, 1.0);
  EXPECT_EQ(helix->need_speed, 60.0);
  EXPECT_EQ(helix->need_accel, 3000.0);
  for (const CoreDriveFit& f : fits) {
    EXPECT_LE(f.need_speed, f.at.top_speed * (1 + 1e-12)) << f.axis;
    EXPECT_LT(f.need_effort(), f.at.peak_effort) << f.axis;
  }
}

TEST(CoreDrives, ACrankAskingMoreThanItsDriveIsRefusedAtItsSpeed) {
  // A 40:1 gearbox: 15.7 rad/s at the crank; 15.5 rad/s x the regulator's 1.15 = 17.8 rad/s.
  const std::string e = config_error(
      "extends = \"default\"\n[drives.servo_400w_10to1]\ngear_ratio = 40.0\n[recipe]\ncrank_speed_rad_s = "
      "15.5\n");
  EXPECT_TRUE(
      has(e,
          "loom.toml:5:21: recipe.crank_speed_rad_s = 15.5: needs 17.8 rad/s (the crank at 15.5 rad/s "
          "x the beat regulator's top scale 1.15); the drive servo_400w_10to1 (axes.beat_crank.drive) "
          "gives 15.7 rad/s at the output (6000 rpm / gear_ratio 40)"))
      << e;
  // At 13.5 rad/s (x1.15 = 15.5) it fits.
  EXPECT_EQ(config_error("extends = \"default\"\n[drives.servo_400w_10to1]\ngear_ratio = 40.0\n[recipe]\n"
                         "crank_speed_rad_s = 13.5\n"),
            "");
}

TEST(CoreDrives, ACarriageOnASlowerDriveIsRefusedAtTheLineNamingIt) {
  // A 3000 rpm motor on the 10 mm lead: 0.5 m/s against the carriage's 1.0 m/s.
  const std::string e = config_error(
      "extends = \"default\"\n[drives.slow_400w]\nmotor_speed_rpm = 3000\nrated_torque_nm = 1.27\n"
      "peak_torque_nm = 3.8\nrotor_inertia_kg_m2 = 0.27e-4\n[axes.carriage]\ndrive = \"slow_400w\"\n");
  EXPECT_TRUE(has(e,
                  "loom.toml:8:9: axes.carriage.drive = \"slow_400w\": needs 1 m/s (the carriage's re-arm "
                  "moves cruise at it; its cam steps peak at 0.758 m/s)"))
      << e;
  EXPECT_TRUE(has(e,
                  "the drive slow_400w (axes.carriage.drive) gives 0.5 m/s at the output (3000 rpm / "
                  "gear_ratio 1 x lead 0.01 m)"))
      << e;
  // Its rotor alone at 60 m/s^2: (0.27 + 0.66) kg cm^2 x (2 pi / 10 mm)^2 = 36.7 kg, 2203 N > 2149 N.
  const std::string f = config_error("extends = \"default\"\n[carriage]\nmax_accel_m_s2 = 60.0\n");
  EXPECT_TRUE(has(f,
                  "loom.toml:3:18: carriage.max_accel_m_s2 = 60: needs 2.2e+03 N to accelerate the drive's "
                  "own rotor and gears alone; the drive servo_400w_screw (axes.carriage.drive) gives "
                  "2.15e+03 N at the output"))
      << f;
}

TEST(CoreDrives, AHelixAskingMoreThanItsDriveIsRefusedAtItsSpeed) {
  const std::string e = config_error("extends = \"default\"\n[helix]\nmax_speed_rad_s = 130.0\n");
  EXPECT_TRUE(
      has(e, "loom.toml:3:19: helix.max_speed_rad_s = 130: needs 130 rad/s (the pick peaks at 130 rad/s)"))
      << e;
  EXPECT_TRUE(has(e,
                  "the drive servo_200w_5to1 (axes.helix.drive) gives 126 rad/s at the output (6000 rpm / "
                  "gear_ratio 5)"))
      << e;
  EXPECT_EQ(config_error("extends = \"default\"\n[helix]\nmax_speed_rad_s = 120.0\n"), "");
}

TEST(CoreDrives, ACompleteFileMayLeaveTheCoreDrivesOut) {
  // Without a drive the core axes' limits stand as their keys say (no check to make).
  LoomConfig c = default_loom_config();
  for (AxisSpec& a : c.axes) a.drive.clear();
  const loom::motion::ProfileSet set(c.profile);
  EXPECT_TRUE(core_drive_fits(c, set).empty());
}

TEST(CoreDrives, ARederivedConfigIsCheckedToo) {
  // A config changed in code (as a recipe swap is re-derived): the crank's drive geared down to 40:1
  // gives 15.7 rad/s; the default beat force asks 16.1 rad/s x 1.15 = 18.5 rad/s.
  LoomConfig c = default_loom_config();
  for (DriveModel& m : c.drives) {
    if (m.name == "servo_400w_10to1") m.drive.gear_ratio = 40.0;
  }
  try {
    rederive_and_check(c, "test");
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_TRUE(has(what, "needs 18.5 rad/s")) << what;
    EXPECT_TRUE(has(what, "the drive servo_400w_10to1 (axes.beat_crank.drive) gives 15.7 rad/s")) << what;
  }
}

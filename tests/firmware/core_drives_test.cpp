// The core axes (beat crank, carriage, helix) described by their drives as sold: the shipped loom names
// one for each and its motion fits them; the figures at the axis follow the closed forms (output shaft:
// speed / ratio, torque x ratio x efficiency, inertia x ratio^2; the carriage through its lead, travel
// per motor turn: rpm / 60 x lead, 2 pi x torque x efficiency / lead, inertia x (2 pi / lead)^2). What an
// axis needs at its top speed (accelerating what it moves, carrying its mechanism's load) must be under
// the drive's torque-speed line there; a loom file asking more than its drive gives is refused at the key
// that asks (else at the line naming the drive), the drive named.
#include "loom/config/core_drives.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "config_error.hpp"
#include "loom/config/config.hpp"
#include "loom/motion/dynamics.hpp"
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
  EXPECT_EQ(carriage->model, "servo_400w_belt");
  EXPECT_EQ(helix->model, "servo_200w_5to1");
  const double rpm = 2.0 * M_PI / 60.0;
  // The crank: a 400 W servo (6000 rpm, 3.8 N m peak, 1.27 N m rated, 0.27 + 0.07 kg cm^2) behind 10:1 at 95
  // %.
  EXPECT_NEAR(crank->at.top_speed, 6000 * rpm / 10, 1e-12);
  EXPECT_NEAR(crank->at.peak_effort, 3.8 * 10 * 0.95, 1e-12);
  EXPECT_NEAR(crank->at.rated_effort, 1.27 * 10 * 0.95, 1e-12);
  EXPECT_NEAR(crank->at.inertia, 0.34e-4 * 100, 1e-15);
  // The carriage: the same motor behind 5:1 on a 100 mm belt pulley, 20 mm a motor turn (0.073 kg cm^2,
  // 0.95 x 0.98): 2.0 m/s, 1110 N, and the 20 kg carriage besides the rotor's 3.39 kg.
  EXPECT_NEAR(carriage->at.top_speed, 6000.0 / 60.0 * 0.020, 1e-12);
  EXPECT_NEAR(carriage->at.peak_effort, 2 * M_PI * 3.8 * 0.93 / 0.020, 1e-9);
  EXPECT_NEAR(carriage->at.rated_effort, 2 * M_PI * 1.27 * 0.93 / 0.020, 1e-9);
  EXPECT_NEAR(carriage->at.inertia, 0.343e-4 * std::pow(2 * M_PI / 0.020, 2), 1e-9);
  EXPECT_EQ(carriage->load_inertia, 20.0);
  // At 1.0 m/s, half its no-load speed, the line gives half the peak; the carriage and the rotor at
  // 20 m/s^2 take 468 N of its 555 N.
  EXPECT_NEAR(carriage->line_effort(), 0.5 * carriage->at.peak_effort, 1e-9);
  EXPECT_NEAR(carriage->need_effort(), (carriage->at.inertia + 20.0) * 20.0, 1e-9);
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
    EXPECT_LT(f.need_speed, f.at.top_speed) << f.axis;
    EXPECT_LT(f.need_effort(), f.line_effort()) << f.axis;
    EXPECT_LE(f.load_rms_effort, f.at.rated_effort) << f.axis;
  }
}

// The crank's load is the beat-up linkage's torque at constant speed. Checked against the reduced model
// (M(theta) from the kinematic coefficients, not the 9x9 pin-force solve the fit uses): at constant speed
// the crank torque is 1/2 M'(theta) w^2 + dV/dtheta, its peak over a turn and its rms the fit's.
TEST(CoreDrives, TheCranksLinkageLoadIsTheReducedModelsTorqueAtItsTopSpeed) {
  const LoomConfig c = default_loom_config();
  const loom::motion::ProfileSet set(c.profile);
  const std::vector<CoreDriveFit> fits = core_drive_fits(c, set);
  const CoreDriveFit* crank = fit_of(fits, "beat_crank");
  ASSERT_TRUE(crank);
  const auto& m = c.machine_spec;
  const loom::motion::BeatUpDynamics dyn(m.beatup, loom::motion::beatup_masses(m.beatup, m.beater_mass_kg));
  const double w = crank->need_speed;
  double peak = 0.0, sum_sq = 0.0;
  constexpr int kSamples = 3600;
  for (int i = 0; i < kSamples; ++i) {
    const loom::motion::ReducedTerms r = dyn.reduced(2.0 * M_PI * i / kSamples);
    const double torque = 0.5 * r.dinertia_kg_m2_rad * w * w + r.gravity_torque_nm;
    peak = std::max(peak, std::abs(torque));
    sum_sq += torque * torque;
  }
  EXPECT_NEAR(crank->load_effort, peak, 0.005 * peak);  // 360 samples against 3600: within 0.5 %
  EXPECT_NEAR(crank->load_rms_effort, std::sqrt(sum_sq / kSamples), 0.005 * peak);
  EXPECT_GT(crank->load_effort, 1.0);  // the default beat's linkage is not a rounding error (10.6 N m)
  EXPECT_NEAR(crank->need_effort(), crank->at.inertia * crank->need_accel + crank->load_effort, 1e-12);
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
  // At 13.5 rad/s (x1.15 = 15.5, under the 15.7) the speed is there but not the torque: at 99 % of its
  // no-load speed the line gives 1.7 N m, and the rotor at 400 rad/s^2 and the linkage need 29.7.
  EXPECT_TRUE(
      has(config_error("extends = \"default\"\n[drives.servo_400w_10to1]\ngear_ratio = 40.0\n"
                       "[recipe]\ncrank_speed_rad_s = 13.5\n"),
          "loom.toml:5:21: recipe.crank_speed_rad_s = 13.5: needs 29.7 N m at 15.5 rad/s (the drive's "
          "own rotor and gears at 400 rad/s^2: 21.8 N m; the linkage 7.9 N m (its peak over a turn at "
          "that speed)); the drive servo_400w_10to1 (axes.beat_crank.drive) gives 1.68 N m there (its "
          "torque-speed line: 144 N m at standstill, 0 at its no-load 15.7 rad/s)"));
  // At 9 rad/s (x1.15 = 10.4) it fits.
  EXPECT_EQ(config_error("extends = \"default\"\n[drives.servo_400w_10to1]\ngear_ratio = 40.0\n[recipe]\n"
                         "crank_speed_rad_s = 9.0\n"),
            "");
}

TEST(CoreDrives, ACarriageOnASlowerDriveIsRefusedAtTheLineNamingIt) {
  // A 1500 rpm motor on the 20 mm lead: 0.5 m/s against the carriage's 1.0 m/s.
  const std::string e = config_error(
      "extends = \"default\"\n[drives.slow_400w]\nmotor_speed_rpm = 1500\nrated_torque_nm = 1.27\n"
      "peak_torque_nm = 3.8\nrotor_inertia_kg_m2 = 0.27e-4\n[axes.carriage]\ndrive = \"slow_400w\"\n");
  EXPECT_TRUE(has(e,
                  "loom.toml:8:9: axes.carriage.drive = \"slow_400w\": needs 1 m/s (the carriage's re-arm "
                  "moves cruise at it; its cam steps peak at 0.758 m/s)"))
      << e;
  EXPECT_TRUE(has(e,
                  "the drive slow_400w (axes.carriage.drive) gives 0.5 m/s at the output (1500 rpm / "
                  "gear_ratio 1 x lead 0.02 m)"))
      << e;
  // At 60 m/s^2 the carriage and the rotor ((20 + 3.39) kg) need 1403 N at 1.0 m/s; the line gives 555 N.
  const std::string f = config_error("extends = \"default\"\n[carriage]\nmax_accel_m_s2 = 60.0\n");
  EXPECT_TRUE(has(f,
                  "loom.toml:3:18: carriage.max_accel_m_s2 = 60: needs 1.4e+03 N at 1 m/s (the drive's own "
                  "rotor and gears and the carriage's 20 kg (carriage.mass_kg) at 60 m/s^2: 1.4e+03 N); the "
                  "drive servo_400w_belt (axes.carriage.drive) gives 555 N there (its torque-speed line: "
                  "1.11e+03 N at standstill, 0 at its no-load 2 m/s)"))
      << f;
  // So is a heavier carriage, at its key.
  EXPECT_TRUE(has(config_error("extends = \"default\"\n[carriage]\nmass_kg = 30.0\n"),
                  "loom.toml:3:11: carriage.mass_kg = 30: needs 668 N at 1 m/s"));
}

// The carriage as it was shipped before: the motor straight on a 10 mm-lead ball screw reaches 1.0 m/s
// only at its no-load speed, where its torque-speed line leaves nothing to move the carriage with.
TEST(CoreDrives, ACarriageAtItsDrivesNoLoadSpeedIsRefused) {
  const std::string e = config_error(
      "extends = \"default\"\n[drives.screw_400w]\nmotor_speed_rpm = 6000\nrated_torque_nm = 1.27\n"
      "peak_torque_nm = 3.8\nrotor_inertia_kg_m2 = 0.27e-4\ngear_ratio = 1.0\ngear_inertia_kg_m2 = 0.66e-4\n"
      "gear_efficiency = 0.90\n[axes.carriage]\ndrive = \"screw_400w\"\nlead_m = 0.010\n");
  EXPECT_TRUE(has(e, "axes.carriage.drive = \"screw_400w\": needs 1.13e+03 N at 1 m/s")) << e;
  EXPECT_TRUE(
      has(e, "gives 0 N there (its torque-speed line: 2.15e+03 N at standstill, 0 at its no-load 1 m/s)"))
      << e;
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
  // At 120 rad/s (95 % of it) the line leaves 0.41 N m, and the pick's 3000 rad/s^2 needs 1.88.
  EXPECT_TRUE(has(config_error("extends = \"default\"\n[helix]\nmax_speed_rad_s = 120.0\n"),
                  "needs 1.88 N m at 120 rad/s (the drive's own rotor and gears and the shuttle at 3e+03 "
                  "rad/s^2: 1.88 N m); the drive servo_200w_5to1 (axes.helix.drive) gives 0.409 N m there"));
  EXPECT_EQ(config_error("extends = \"default\"\n[helix]\nmax_speed_rad_s = 90.0\n"), "");
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

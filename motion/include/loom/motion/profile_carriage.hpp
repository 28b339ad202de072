// What one carriage step costs the carriage drive: the cam steps one pitch inside the beater's clear
// window, so its peak speed, acceleration and jerk follow from the window, the pitch and the crank's
// speed through the crank law. A step that would break a limit is a configuration error that names
// the limits and the fastest crank speed that fits — never a profile that silently breaks them.
#pragma once

#include "loom/motion/carriage_cam.hpp"
#include "loom/motion/profile_crank.hpp"

namespace loom::motion {

struct CarriageLimits {
  double speed_m_s = 1.0;
  double accel_m_s2 = 20.0;
  double jerk_m_s3 = 2000.0;
};

struct CarriagePeaks {
  double speed_m_s = 0.0;
  double accel_m_s2 = 0.0;
  double jerk_m_s3 = 0.0;
  double step_time_s = 0.0;            // time the crank spends in the step window
  double max_crank_speed_rad_s = 0.0;  // fastest master (cruise) speed at which every limit holds
};

// Configure-time only. Peaks of a carriage step with the master at a constant `master_speed_rad_s`
// (the steps happen at cruise speed; the run-up check keeps them there). Exact maxima for the
// constant law; for the elliptic law the maxima of 8192 samples per turn plus the constant law's
// peak points (relative shortfall below 1e-5).
CarriagePeaks carriage_step_peaks(const CarriageCam& cam, const CrankLaw& law, double master_speed_rad_s,
                                  const CarriageLimits& limits);

// Configure-time only. The peaks, or MotionError(kInvalidInput) when a step breaks a limit; the message
// names the step, the window, the needed peaks, the limits (config keys) and the fastest crank speed.
CarriagePeaks check_carriage_step(const CarriageCam& cam, const CrankLaw& law, double master_speed_rad_s,
                                  const CarriageLimits& limits);

}  // namespace loom::motion

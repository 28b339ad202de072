// The drive's envelope and the move under it against independent truth: the output facts of a geared
// servo by hand arithmetic, the torque–speed line's four quadrants, and the move's time against the
// bang-bang solution integrated by RK4 in the phase plane (drive on the line until the braking distance
// closes the move), its samples against finite differences and the envelope.
#include "loom/motion/servo_envelope.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "loom/motion/errors.hpp"

namespace {

using loom::motion::EnvelopeLimits;
using loom::motion::EnvelopeMove;
using loom::motion::MotionError;
using loom::motion::ServoDrive;
using loom::motion::TorqueSpeedLine;

TEST(ServoDrive, OutputFactsThroughTheGearbox) {
  ServoDrive d;
  d.motor_speed_rad_s = 6000 * 2 * M_PI / 60;  // 628.3 rad/s
  d.motor_rated_torque_nm = 0.32;
  d.motor_peak_torque_nm = 0.95;
  d.rotor_inertia_kg_m2 = 0.051e-4;
  d.gear_ratio = 10;
  d.gear_inertia_kg_m2 = 0.03e-4;
  d.gear_efficiency = 0.95;
  EXPECT_NEAR(d.output_speed_rad_s(), 62.83185, 1e-5);
  EXPECT_NEAR(d.output_peak_torque_nm(), 9.025, 1e-12);
  EXPECT_NEAR(d.output_rated_torque_nm(), 3.04, 1e-12);
  EXPECT_NEAR(d.output_inertia_kg_m2(), 8.1e-4, 1e-15);
  EXPECT_NO_THROW(validate(d, "test"));
  d.motor_rated_torque_nm = 1.0;  // above the peak
  EXPECT_THROW(validate(d, "test"), MotionError);
  d.motor_rated_torque_nm = 0.32;
  d.gear_efficiency = 1.1;
  EXPECT_THROW(validate(d, "test"), MotionError);
}

TEST(TorqueSpeedLine, FourQuadrants) {
  const TorqueSpeedLine l{10.0, 2.0};
  EXPECT_DOUBLE_EQ(l.available_nm(0.0, 1.0), 2.0);
  EXPECT_DOUBLE_EQ(l.available_nm(5.0, 1.0), 1.0);    // driving: halfway down the line
  EXPECT_DOUBLE_EQ(l.available_nm(-5.0, -1.0), 1.0);  // the same, the other way
  EXPECT_DOUBLE_EQ(l.available_nm(5.0, -1.0), 2.0);   // braking: the peak caps the line
  EXPECT_DOUBLE_EQ(l.available_nm(12.0, 1.0), 0.0);   // beyond no-load: nothing to drive with
}

// RK4 on dω/dt = a0 (1 − ω/ω∞) until θ + ω²/2b reaches d; the switch interpolated between steps.
double bang_bang(double d, double a0, double w_inf, double b) {
  const double dt = 1e-7;
  double th = 0, w = 0, t = 0, f = -d, tp = 0, wp = 0, fp = -d;
  const auto acc = [&](double ww) { return a0 * (1 - ww / w_inf); };
  while (f < 0) {
    tp = t, wp = w, fp = f;
    const double k1 = acc(w), k2 = acc(w + 0.5 * dt * k1), k3 = acc(w + 0.5 * dt * k2), k4 = acc(w + dt * k3);
    th += dt * (w + 2 * (w + 0.5 * dt * k1) + 2 * (w + 0.5 * dt * k2) + (w + dt * k3)) / 6;
    w += dt * (k1 + 2 * k2 + 2 * k3 + k4) / 6;
    t += dt;
    f = th + w * w / (2 * b) - d;
  }
  const double u = -fp / (f - fp);
  return tp + u * dt + (wp + u * (w - wp)) / b;
}

TEST(EnvelopeMove, TimeIsTheBangBangSolution) {
  const TorqueSpeedLine line{62.8, 9.0};
  const EnvelopeLimits lim = EnvelopeMove::limits_for(line, 8.1e-4, 0.0, 1.0, 0.0);
  EXPECT_NEAR(lim.stall_accel, 9.0 / 8.1e-4, 1e-9);
  EXPECT_NEAR(lim.asymptote_speed, 62.8, 1e-12);
  for (double d : {1e-3, 0.05, 0.4, 2.65, -2.65, 10.0}) {
    const EnvelopeMove m = EnvelopeMove::plan(d, lim);
    EXPECT_NEAR(m.duration(), bang_bang(std::fabs(d), lim.stall_accel, lim.asymptote_speed, lim.brake_decel),
                2e-8 + 1e-7 * m.duration())
        << d;
    EXPECT_FALSE(m.cruises());
    EXPECT_NEAR(m.at(m.duration()).position, d, 1e-15);
  }
}

TEST(EnvelopeMove, SamplesAreConsistentAndWithinTheLine) {
  const TorqueSpeedLine line{62.8, 9.0};
  const double J = 8.1e-4, load = 0.3;
  for (double cap : {0.0, 20.0}) {
    const EnvelopeLimits lim = EnvelopeMove::limits_for(line, J, load, 1.0, cap);
    const EnvelopeMove m = EnvelopeMove::plan(-2.65, lim);
    EXPECT_EQ(m.cruises(), cap > 0.0);
    const double T = m.duration(), h = 1e-6;
    for (int k = 1; k < 5000; ++k) {
      const double t = T * k / 5000.0;
      const auto s = m.at(t), p = m.at(t + h), q = m.at(t - h);
      EXPECT_NEAR((p.position - q.position) / (2 * h), s.velocity, 1e-4 * 62.8) << t;
      // Any load torque up to `load`, either way: within the line.
      for (double l : {-load, load}) {
        const double tau = J * s.acceleration + l;
        EXPECT_LE(std::fabs(tau), line.available_nm(s.velocity, tau < 0 ? -1.0 : 1.0) * (1 + 1e-12) + 1e-12)
            << t;
      }
      if (cap > 0.0) {
        EXPECT_LE(std::fabs(s.velocity), cap * (1 + 1e-12));
      }
    }
  }
  // A load that takes the whole torque leaves nothing to move with.
  EXPECT_THROW(EnvelopeMove::limits_for(line, J, 9.0, 1.0, 0.0), MotionError);
}

}  // namespace

// Needle six-bar inverse dynamics. Accelerations of the centres come from the rigid-body motion of
// each link (not from 002's hand-expanded eqns 20–36), and every body's equations are written as
// Σ forces = m a_G and Σ moments about G = I α, so the two systems share one sign convention.
#include "loom/motion/design/dynamics_needle.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

// Coefficients of r × F on (Fx, Fy), scaled.
template <int N>
void put_arm(Eigen::Matrix<double, N, N>& a, int row, int col, const Eigen::Vector2d& r, double s) {
  a(row, col) = -r.y() * s;
  a(row, col + 1) = r.x() * s;
}

template <int N>
Eigen::Matrix<double, N, 1> solve_checked(const Eigen::Matrix<double, N, N>& a,
                                          const Eigen::Matrix<double, N, 1>& b, const char* which,
                                          double theta1) {
  const Eigen::PartialPivLU<Eigen::Matrix<double, N, N>> lu(a);
  const Eigen::Matrix<double, N, N> inv = lu.inverse();
  const double rcond =
      1.0 / (a.cwiseAbs().colwise().sum().maxCoeff() * inv.cwiseAbs().colwise().sum().maxCoeff());
  if (!(rcond > kSingularRcond)) {
    std::ostringstream os;
    os << "needle six-bar: force system " << which << " is singular at theta1 = " << deg(theta1)
       << " deg (reciprocal condition " << rcond << ")";
    throw MotionError(ErrorCode::kSingular, os.str());
  }
  const Eigen::Matrix<double, N, 1> x = lu.solve(b);
  if (!x.allFinite()) {
    throw MotionError(ErrorCode::kSingular,
                      std::string("needle six-bar: force system ") + which + " gave non-finite forces");
  }
  return x;
}

void check_inputs(const NeedleMasses& m, const NeedleLoads& l) {
  for (std::size_t i = 0; i < 6; ++i) {
    if (!(m.mass_kg[i] >= 0.0) || !std::isfinite(m.mass_kg[i]) || !(m.inertia_kg_m2[i] >= 0.0) ||
        !std::isfinite(m.inertia_kg_m2[i])) {
      std::ostringstream os;
      os << "needle six-bar: l" << i + 1 << " mass " << m.mass_kg[i] << " kg, inertia " << m.inertia_kg_m2[i]
         << " kg m^2: must be finite and >= 0";
      throw MotionError(ErrorCode::kInvalidInput, os.str());
    }
  }
  if (!(l.friction_n >= 0.0) || !std::isfinite(l.friction_n) || !l.gravity_m_s2.allFinite()) {
    std::ostringstream os;
    os << "needle six-bar: friction " << l.friction_n << " N must be finite and >= 0, gravity finite";
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
}

// The backing's vertical force on the needle bar: against its motion (needle_v > 0 is the needle going
// down, so the backing pushes up); zero at the instant the needle stands still.
double backing_friction(const NeedleState& s, const NeedleLoads& l) {
  return s.needle_v_m_s > 0.0 ? l.friction_n : s.needle_v_m_s < 0.0 ? -l.friction_n : 0.0;
}

}  // namespace

NeedleMasses needle_table1_masses() {
  NeedleMasses m;
  m.mass_kg = {3.07, 3.79, 2.96, 1.74, 0.36, 1.47};
  m.inertia_kg_m2 = {4.34e-3, 26.99e-3, 10.77e-3, 6.69e-3, 0.91e-3, 19.15e-3};
  return m;
}

std::array<BodyMotion, 6> needle_motion(const NeedleLinkage& linkage, const NeedleState& s) {
  const NeedleDims& d = linkage.dims();
  std::array<BodyMotion, 6> b;
  const auto rotating = [](BodyMotion& m, double th, double w, double a) {
    m.angle_rad = th;
    m.omega_rad_s = w;
    m.alpha_rad_s2 = a;
  };
  // A point carried by a link rotating about a moving origin: v = v_o + ω×r, a = a_o + α×r − ω²r.
  const auto carry = [](const BodyMotion& from, const Eigen::Vector2d& local, BodyMotion& to) {
    to.origin_m = from.point(local);
    to.origin_vel_m_s = from.velocity(local);
    to.origin_acc_m_s2 = from.acceleration(local);
  };
  rotating(b[0], s.theta1_rad, s.omega1_rad_s, s.alpha1_rad_s2);
  rotating(b[1], s.theta2_rad, s.omega2_rad_s, s.alpha2_rad_s2);
  carry(b[0], {d.l1_m, 0.0}, b[1]);
  rotating(b[2], s.theta3_rad, s.omega3_rad_s, s.alpha3_rad_s2);
  b[2].origin_m = {d.x1_m, d.h1_m};
  rotating(b[3], s.theta4_rad, s.omega4_rad_s, s.alpha4_rad_s2);
  b[3].origin_m = {d.x1_m, d.h1_m};
  rotating(b[4], s.theta5_rad, s.omega5_rad_s, s.alpha5_rad_s2);
  carry(b[3], {d.l4_m, 0.0}, b[4]);
  rotating(b[5], 0.0, 0.0, 0.0);
  carry(b[4], {d.l5_m, 0.0}, b[5]);
  return b;
}

std::array<PlanarInertia, 6> needle_bodies(const NeedleLinkage& linkage, const NeedleMasses& m) {
  const NeedleDims& d = linkage.dims();
  const std::array<double, 5> len{d.l1_m, d.l2_m, d.l3_m, d.l4_m, d.l5_m};
  std::array<PlanarInertia, 6> b;
  for (std::size_t i = 0; i < 5; ++i) b[i] = {m.mass_kg[i], {0.5 * len[i], 0.0}, m.inertia_kg_m2[i]};
  b[5] = {m.mass_kg[5], {0.0, -0.5 * d.l6_m}, m.inertia_kg_m2[5]};
  return b;
}

NeedleSystems needle_systems(const NeedleLinkage& linkage, const NeedleMasses& m, const NeedleState& s,
                             const NeedleLoads& loads) {
  check_inputs(m, loads);
  const NeedleDims& d = linkage.dims();
  const std::array<BodyMotion, 6> mo = needle_motion(linkage, s);
  const std::array<PlanarInertia, 6> body = needle_bodies(linkage, m);
  std::array<Eigen::Vector2d, 6> g, acc;
  for (std::size_t i = 0; i < 6; ++i) {
    g[i] = mo[i].point(body[i].centre_m);
    acc[i] = mo[i].acceleration(body[i].centre_m);
  }
  const Eigen::Vector2d o(0.0, 0.0);
  const Eigen::Vector2d a = mo[1].origin_m;
  const Eigen::Vector2d b = mo[2].point({d.l3_m, 0.0});
  const Eigen::Vector2d c = mo[2].origin_m;
  const Eigen::Vector2d dp = mo[4].origin_m;
  const Eigen::Vector2d e = mo[5].origin_m;
  const Eigen::Vector2d grav = loads.gravity_m_s2;
  NeedleSystems sys;
  sys.length_scale_m = std::max({d.l1_m, d.l2_m, d.l3_m, d.l4_m, d.l5_m, d.l6_m, std::hypot(d.x1_m, d.h1_m)});
  const double k = 1.0 / sys.length_scale_m;
  const auto newton = [&](std::size_t i) { return Eigen::Vector2d(m.mass_kg[i] * (acc[i] - grav)); };
  const auto euler = [&](std::size_t i) { return m.inertia_kg_m2[i] * mo[i].alpha_rad_s2 * k; };

  // ---- C·y = D: l4, l5, l6. y = (F_C4, F_54, F_65, N, M_r/L) ------------------------------------
  Eigen::Matrix<double, 8, 8>& C = sys.C;
  Eigen::Matrix<double, 8, 1>& D = sys.D;
  C.setZero();
  // l4: F_C4 + F_54 = m a − m g; (C−G)×F_C4 + (D−G)×F_54 + M_r = I α.
  C(0, 0) = 1;
  C(0, 2) = 1;
  C(1, 1) = 1;
  C(1, 3) = 1;
  put_arm<8>(C, 2, 0, c - g[3], k);
  put_arm<8>(C, 2, 2, dp - g[3], k);
  C(2, 7) = 1;
  // l5: −F_54 + F_65 = m a − m g; (D−G)×(−F_54) + (E−G)×F_65 = I α.
  C(3, 2) = -1;
  C(3, 4) = 1;
  C(4, 3) = -1;
  C(4, 5) = 1;
  put_arm<8>(C, 5, 2, -(dp - g[4]), k);
  put_arm<8>(C, 5, 4, e - g[4], k);
  // l6 (translation only; the guide takes its moment): −F_65 + (N, friction) = m a − m g.
  C(6, 4) = -1;
  C(6, 6) = 1;
  C(7, 5) = -1;
  const double fric = backing_friction(s, loads);
  const Eigen::Vector2d f4 = newton(3), f5 = newton(4), f6 = newton(5);
  D << f4.x(), f4.y(), euler(3), f5.x(), f5.y(), euler(4), f6.x(), f6.y() - fric;

  // ---- A·x = B: l1, l2, l3. x = (F_21, F_O1, F_32, F_C3, M_b/L); M_r comes from C·y = D ----------
  Eigen::Matrix<double, 9, 9>& A = sys.A;
  Eigen::Matrix<double, 9, 1>& B = sys.B;
  A.setZero();
  // l1: F_21 + F_O1 = m a − m g; (A−G)×F_21 + (O−G)×F_O1 + M_b = I α.
  A(0, 0) = 1;
  A(0, 2) = 1;
  A(1, 1) = 1;
  A(1, 3) = 1;
  put_arm<9>(A, 2, 0, a - g[0], k);
  put_arm<9>(A, 2, 2, o - g[0], k);
  A(2, 8) = 1;
  // l2: −F_21 + F_32 = m a − m g; (A−G)×(−F_21) + (B−G)×F_32 = I α.
  A(3, 0) = -1;
  A(3, 4) = 1;
  A(4, 1) = -1;
  A(4, 5) = 1;
  put_arm<9>(A, 5, 0, -(a - g[1]), k);
  put_arm<9>(A, 5, 4, b - g[1], k);
  // l3: −F_32 + F_C3 = m a − m g; (B−G)×(−F_32) + (C−G)×F_C3 − M_r = I α.
  A(6, 4) = -1;
  A(6, 6) = 1;
  A(7, 5) = -1;
  A(7, 7) = 1;
  put_arm<9>(A, 8, 4, -(b - g[2]), k);
  put_arm<9>(A, 8, 6, c - g[2], k);
  const Eigen::Vector2d f1 = newton(0), f2 = newton(1), f3 = newton(2);
  B << f1.x(), f1.y(), euler(0), f2.x(), f2.y(), euler(1), f3.x(), f3.y(),
      euler(2);  // + M_r/L added on solve
  return sys;
}

NeedleForces needle_inverse_dynamics(const NeedleLinkage& linkage, const NeedleMasses& m,
                                     const NeedleState& s, const NeedleLoads& loads) {
  NeedleSystems sys = needle_systems(linkage, m, s, loads);
  const Eigen::Matrix<double, 8, 1> y = solve_checked<8>(sys.C, sys.D, "C F = D", s.theta1_rad);
  sys.B(8) += y(7);  // l3 receives −M_r: moved to the right-hand side it adds M_r/L
  const Eigen::Matrix<double, 9, 1> x = solve_checked<9>(sys.A, sys.B, "A F = B", s.theta1_rad);
  const double L = sys.length_scale_m;
  NeedleForces f;
  f.state = s;
  f.friction_n = backing_friction(s, loads);
  f.pin_c4_n = y.segment<2>(0);
  f.pin_d_n = y.segment<2>(2);
  f.pin_e_n = y.segment<2>(4);
  f.guide_n = y(6);
  f.weld_torque_nm = y(7) * L;
  f.pin_a_n = x.segment<2>(0);
  f.pin_o_n = x.segment<2>(2);
  f.pin_b_n = x.segment<2>(4);
  f.pin_c3_n = x.segment<2>(6);
  f.balancing_torque_nm = x(8) * L;
  return f;
}

std::vector<NeedleForces> needle_dynamics_sweep(const NeedleLinkage& linkage, const NeedleMasses& m,
                                                int samples, double omega1, const NeedleLoads& loads) {
  const std::vector<NeedleState> states = needle_sweep(linkage, samples, omega1);
  std::vector<NeedleForces> out;
  out.reserve(states.size());
  for (const NeedleState& s : states) out.push_back(needle_inverse_dynamics(linkage, m, s, loads));
  return out;
}

}  // namespace loom::motion

// Three-precision-point synthesis by the λ method (seed 001), done right: the report's worked example
// flips the signs of M2, M3 and misreads a point, so its λ and lengths are wrong. Every real root
// is kept, and each is polished by Newton on the loop equations so closure holds to rounding.
#include "loom/motion/design/three_point.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

Vector2d unit(double angle) {
  return {std::cos(angle), std::sin(angle)};
}

// The vector from the fixed pivot O1 = a0·u(θ0) to the moving pivot O2 = P_i − a2·u(θ2_i); its
// length must be a1 at every precision point.
Vector2d free_link(const PrecisionPoint& pt, double theta0, double a0, double a2) {
  return Vector2d(pt.x, pt.y) - a2 * unit(pt.theta2_rad) - a0 * unit(theta0);
}

void check_input(const std::array<PrecisionPoint, 3>& points, double theta0) {
  if (!std::isfinite(theta0)) {
    throw MotionError(ErrorCode::kInvalidInput, "three-point synthesis: theta0 must be finite");
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const PrecisionPoint& p = points[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.theta2_rad)) {
      std::ostringstream msg;
      msg << "three-point synthesis: precision point " << i + 1 << " (x, y, theta2) must be finite";
      throw MotionError(ErrorCode::kInvalidInput, msg.str());
    }
  }
}

// Newton on E_i = |r_i|² − a1² over (a0, a1, a2); a few steps take the closed form to rounding.
void polish(const std::array<PrecisionPoint, 3>& points, double theta0, ThreePointSolution& s) {
  const Vector2d u0 = unit(theta0);
  Vector3d x(s.a0, s.a1, s.a2);
  auto residual = [&](const Vector3d& v) {
    Vector3d e;
    for (int i = 0; i < 3; ++i) {
      const Vector2d r = free_link(points[static_cast<std::size_t>(i)], theta0, v(0), v(2));
      e(i) = r.squaredNorm() - v(1) * v(1);
    }
    return e;
  };
  Vector3d e = residual(x);
  for (int it = 0; it < 6; ++it) {
    Matrix3d J;
    for (int i = 0; i < 3; ++i) {
      const PrecisionPoint& pt = points[static_cast<std::size_t>(i)];
      const Vector2d r = free_link(pt, theta0, x(0), x(2));
      J(i, 0) = -2.0 * r.dot(u0);
      J(i, 1) = -2.0 * x(1);
      J(i, 2) = -2.0 * r.dot(unit(pt.theta2_rad));
    }
    const Vector3d step = J.fullPivLu().solve(-e);
    if (!step.allFinite()) break;
    const Vector3d trial = x + step;
    const Vector3d e_trial = residual(trial);
    if (!(e_trial.cwiseAbs().maxCoeff() < e.cwiseAbs().maxCoeff())) break;
    x = trial;
    e = e_trial;
  }
  s.a0 = x(0);
  s.a1 = std::fabs(x(1));
  s.a2 = x(2);
}

void measure_closure(const std::array<PrecisionPoint, 3>& points, double theta0, ThreePointSolution& s) {
  s.closure_residual = 0.0;
  for (std::size_t i = 0; i < 3; ++i) {
    const Vector2d r = free_link(points[i], theta0, s.a0, s.a2);
    s.theta1_rad[i] = std::atan2(r.y(), r.x());
    const Vector2d end =
        s.a0 * unit(theta0) + s.a1 * unit(s.theta1_rad[i]) + s.a2 * unit(points[i].theta2_rad);
    s.closure_residual = std::max(s.closure_residual, (end - Vector2d(points[i].x, points[i].y)).norm());
  }
}

}  // namespace

ThreePointResult three_point_synthesis(const std::array<PrecisionPoint, 3>& points, double theta0_rad) {
  check_input(points, theta0_rad);
  const Vector2d u0 = unit(theta0_rad);

  // Loop equation i divided by a0·a2:  P1 + P2·2(ρ·u0) + P3·2(ρ·u2) − λ·ρ² = 2cos(θ2 − θ0)
  // with P1 = (a1² − a0² − a2²)/(a0a2), P2 = 1/a2, P3 = 1/a0, λ = P2·P3.
  Matrix3d A;
  Vector3d F;
  Vector3d rho2;
  for (int i = 0; i < 3; ++i) {
    const PrecisionPoint& pt = points[static_cast<std::size_t>(i)];
    const Vector2d rho(pt.x, pt.y);
    A(i, 0) = 1.0;
    A(i, 1) = 2.0 * rho.dot(u0);
    A(i, 2) = 2.0 * rho.dot(unit(pt.theta2_rad));
    F(i) = 2.0 * std::cos(pt.theta2_rad - theta0_rad);
    rho2(i) = rho.squaredNorm();
  }
  // Columns carry lengths; equilibrate them so the singularity test is scale-free.
  Vector3d scale = A.cwiseAbs().colwise().maxCoeff().transpose();
  for (int j = 0; j < 3; ++j) {
    if (!(scale(j) > 0.0)) {
      throw MotionError(ErrorCode::kSingular,
                        "three-point synthesis: the precision points leave the linear system "
                        "singular (a coefficient column is zero)");
    }
  }
  const Matrix3d As = A * scale.cwiseInverse().asDiagonal();
  const Eigen::FullPivLU<Matrix3d> lu(As);
  // Full pivoting orders |U_ii| decreasingly: their ratio measures closeness to singularity, and
  // is exactly 0 for a rank-deficient system (Eigen's rcond() estimate is not reliable there).
  const double pivot_ratio = std::fabs(lu.matrixLU()(2, 2)) / std::fabs(lu.matrixLU()(0, 0));
  if (!(pivot_ratio > 1e-13) || !(lu.rcond() > 1e-13)) {
    std::ostringstream msg;
    msg << "three-point synthesis: the precision points leave the linear system singular "
           "(pivot ratio "
        << pivot_ratio << "); choose three distinct, independent points";
    throw MotionError(ErrorCode::kSingular, msg.str());
  }
  const Vector3d l = scale.cwiseInverse().asDiagonal() * lu.solve(F);
  const Vector3d M = scale.cwiseInverse().asDiagonal() * lu.solve(rho2);

  // (l2 + λM2)(l3 + λM3) = λ
  const double p = M(1) * M(2);
  const double q = l(1) * M(2) + l(2) * M(1) - 1.0;
  const double r = l(1) * l(2);

  ThreePointResult out;
  std::vector<double> roots;
  if (p == 0.0) {
    if (q != 0.0) {
      roots.push_back(-r / q);
    } else if (r == 0.0) {
      throw MotionError(ErrorCode::kSingular,
                        "three-point synthesis: every lambda satisfies the quadratic (p = q = r = 0)");
    }
  } else {
    double disc = q * q - 4.0 * p * r;
    const double rounding = 8.0 * std::numeric_limits<double>::epsilon() * (q * q + 4.0 * std::fabs(p * r));
    if (disc < 0.0 && disc >= -rounding) disc = 0.0;  // a double root rounded below zero
    if (disc < 0.0) {
      out.complex_roots = 2;
    } else {
      // Stable pair: the root with |q| + √Δ in the numerator, the other from the product r/p.
      const double t = -0.5 * (q + std::copysign(std::sqrt(disc), q));
      if (t != 0.0) {
        roots.push_back(t / p);
        if (disc > 0.0) roots.push_back(r / t);
      } else {
        roots.push_back(0.0);
      }
    }
  }

  for (double lambda : roots) {
    const Vector3d P = l + lambda * M;
    if (!(lambda != 0.0) || !(P(1) != 0.0) || !(P(2) != 0.0) || !std::isfinite(lambda)) {
      ++out.rejected_roots;
      continue;
    }
    ThreePointSolution s;
    s.lambda = lambda;
    s.a0 = 1.0 / P(2);
    s.a2 = 1.0 / P(1);
    const double a1_sq = P(0) * s.a0 * s.a2 + s.a0 * s.a0 + s.a2 * s.a2;
    if (!(a1_sq > 0.0) || !std::isfinite(a1_sq)) {
      ++out.rejected_roots;
      continue;
    }
    s.a1 = std::sqrt(a1_sq);
    polish(points, theta0_rad, s);
    measure_closure(points, theta0_rad, s);
    out.solutions.push_back(s);
  }
  std::sort(out.solutions.begin(), out.solutions.end(),
            [](const ThreePointSolution& x, const ThreePointSolution& y) { return x.lambda > y.lambda; });
  return out;
}

}  // namespace loom::motion

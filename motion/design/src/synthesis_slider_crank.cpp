// Söylemez's slider-crank synthesis (thesis 000 §4.5.1, eqs. 4.10–4.24), rewritten in half-angle
// form: with k = cos(φ/2), s = sin(φ/2) every quantity is a product or quotient of terms that do not
// cancel, so b → ∞ as φ → π and μ_min → 0 as φ → π/2 are both computed to full relative accuracy.
#include <cmath>
#include <sstream>

#include "checks.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/synthesis.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

// Half-angle terms of the crank rotation, taken from the exact differences π − φ and φ − π/2
// (Sterbenz: both subtractions are exact for π/2 ≤ φ ≤ π).
struct HalfAngles {
  double k;      // cos(φ/2)
  double s;      // sin(φ/2)
  double sin_g;  // sin(φ − π/2) = −cos φ
  double sin_phi;
};

// The rotation checked against [90°, 180°) — the upper end on the exact supplement π − φ, so that a φ given
// in degrees a hair below 180° is designed, not refused as 180°.
CrankRotation checked_phi(CrankRotation phi) {
  if (!std::isfinite(phi.phi_rad) || !std::isfinite(phi.supplement_rad)) {
    throw MotionError(ErrorCode::kInvalidInput, "slider-crank synthesis: phi must be finite");
  }
  if (std::fabs(phi.phi_rad - 0.5 * kPi) <= kSynthesisSnap_rad) return CrankRotation{0.5 * kPi, 0.5 * kPi};
  if (phi.phi_rad < 0.5 * kPi || phi.supplement_rad <= kSynthesisSnap_rad) {
    std::ostringstream msg;
    msg << "slider-crank synthesis: phi = " << deg(phi.phi_rad) << " deg is outside [90, 180) deg";
    if (std::fabs(phi.supplement_rad) <= kSynthesisSnap_rad) {
      msg << " (phi = 180 deg needs an infinitely long coupler)";
    } else if (phi.supplement_rad < 0.0) {
      msg << " (give the short-side rotation 360 - phi)";
    }
    throw MotionError(ErrorCode::kInvalidInput, msg.str());
  }
  return phi;
}

// From the supplement ε = π − φ (exact when φ came in degrees) and g = φ − π/2 (exact: Sterbenz).
HalfAngles half_angles(CrankRotation phi) {
  const double eps = phi.supplement_rad;
  const double g = phi.phi_rad - 0.5 * kPi;
  HalfAngles h{};
  h.k = std::sin(0.5 * eps);
  h.s = std::cos(0.5 * eps);
  h.sin_g = std::sin(g);
  h.sin_phi = std::sin(eps);
  return h;
}

void check_stroke(double stroke) {
  detail::require_positive_length("slider-crank synthesis", "stroke", stroke, "");
}

// Shared tail of both entry points. one_minus_lambda2 and k2_minus_lambda_s2 are passed in because
// for λ_opt they have cancellation-free closed forms the generic differences would lose.
SliderCrankDesign assemble(double stroke, double phi_rad, const HalfAngles& h, double lambda, double lambda2,
                           double one_minus_lambda2, double k2_minus_lambda_s2, bool at_bound) {
  const double D = h.k * h.k + lambda2 * h.s * h.s;  // cos²(φ/2) + λ² sin²(φ/2), eq. 4.11
  const double b_unit = 0.5 / std::sqrt(D);
  const double c_unit = one_minus_lambda2 * h.s * h.k / (2.0 * D);  // eq. 4.10

  SliderCrankDesign d;
  d.stroke = stroke;
  d.phi_rad = phi_rad;
  d.lambda = lambda;
  d.mechanism.coupler = stroke * b_unit;
  d.mechanism.crank = stroke * lambda * b_unit;
  d.mechanism.offset = stroke * c_unit;

  // 1 − cos μ_min = 1 − λ − c/b = (1 − λ)·G, G = (k² − λs²)² / (D·(1 + b(1+λ) sin φ)).
  const double one_minus_lambda = one_minus_lambda2 / (1.0 + lambda);
  const double G =
      k2_minus_lambda_s2 * k2_minus_lambda_s2 / (D * (1.0 + b_unit * (1.0 + lambda) * h.sin_phi));
  const double one_minus_cos = std::fmax(0.0, one_minus_lambda * G);
  d.mu_min_rad = 2.0 * std::asin(std::fmin(1.0, std::sqrt(0.5 * one_minus_cos)));
  if (at_bound) {
    d.flags |= kDesignChangePoint;
    d.mu_min_rad = 0.0;
  }
  return d;
}

}  // namespace

LambdaBounds soylemez_lambda_bounds(CrankRotation phi_rad) {
  const HalfAngles h = half_angles(checked_phi(phi_rad));
  LambdaBounds lb;
  lb.lower = (h.k * h.k) / (h.s * h.s);
  lb.upper = 1.0;
  return lb;
}

double soylemez_lambda_opt(CrankRotation phi_rad) {
  const HalfAngles h = half_angles(checked_phi(phi_rad));
  const double w = std::sqrt(4.0 + h.k * h.k);
  // λ² = (√(5 + 4t²) − 1)/(2t²) with t = s/k, multiplied through by k² and rationalised.
  return std::sqrt(2.0 * h.k / (h.s * h.s * (w + h.k)));
}

SliderCrankDesign soylemez_slider_crank(double stroke, CrankRotation phi_rad) {
  check_stroke(stroke);
  const CrankRotation phi = checked_phi(phi_rad);
  const HalfAngles h = half_angles(phi);
  const double k = h.k;
  const double s = h.s;
  const double w = std::sqrt(4.0 + k * k);
  const double lambda2 = 2.0 * k / (s * s * (w + k));
  // 1 − λ² and k⁴ − λ²s⁴ both carry the factor cos φ = −sin g; the rest is positive on [π/2, π).
  const double one_minus_lambda2 = 2.0 * h.sin_g / (s * s * (1.0 + s * s + k * w));
  const double lambda = std::sqrt(lambda2);
  const double k4_minus = -4.0 * k * h.sin_g / ((w + k) * (k * k * k * w + 2.0 * s * s - k * k * k * k));
  const double k2_minus_lambda_s2 = k4_minus / (k * k + lambda * s * s);
  // At φ = π/2 the optimum is λ = 1 = both bounds: a = b, c = 0, μ_min = 0.
  const bool at_bound = !(one_minus_lambda2 > 0.0);
  return assemble(stroke, phi.phi_rad, h, at_bound ? 1.0 : lambda, at_bound ? 1.0 : lambda2,
                  at_bound ? 0.0 : one_minus_lambda2, k2_minus_lambda_s2, at_bound);
}

SliderCrankDesign soylemez_slider_crank(double stroke, CrankRotation phi_rad, double lambda) {
  check_stroke(stroke);
  const CrankRotation phi = checked_phi(phi_rad);
  const HalfAngles h = half_angles(phi);
  if (!std::isfinite(lambda)) {
    throw MotionError(ErrorCode::kInvalidInput, "slider-crank synthesis: lambda must be finite");
  }
  const double lower = (h.k * h.k) / (h.s * h.s);
  constexpr double kLambdaSnap = 1e-14;
  bool at_bound = false;
  double lam = lambda;
  if (std::fabs(lam - lower) <= kLambdaSnap) {
    lam = lower;
    at_bound = true;
  } else if (std::fabs(lam - 1.0) <= kLambdaSnap) {
    lam = 1.0;
    at_bound = true;
  } else if (lam < lower || lam > 1.0) {
    std::ostringstream msg;
    msg.precision(10);
    msg << "slider-crank synthesis: lambda = " << lambda << " is outside its bounds [" << lower
        << ", 1] for phi = " << deg(phi.phi_rad) << " deg (1/tan^2(phi/2) <= lambda <= 1)";
    throw MotionError(ErrorCode::kOutOfBounds, msg.str());
  }
  const double one_minus_lambda2 = (1.0 - lam) * (1.0 + lam);
  const double k2_minus_lambda_s2 = h.k * h.k - lam * h.s * h.s;
  return assemble(stroke, phi.phi_rad, h, lam, lam * lam, one_minus_lambda2, k2_minus_lambda_s2, at_bound);
}

LambdaBounds soylemez_lambda_bounds(double phi_rad) {
  return soylemez_lambda_bounds(CrankRotation::radians(phi_rad));
}
double soylemez_lambda_opt(double phi_rad) {
  return soylemez_lambda_opt(CrankRotation::radians(phi_rad));
}
SliderCrankDesign soylemez_slider_crank(double stroke, double phi_rad) {
  return soylemez_slider_crank(stroke, CrankRotation::radians(phi_rad));
}
SliderCrankDesign soylemez_slider_crank(double stroke, double phi_rad, double lambda) {
  return soylemez_slider_crank(stroke, CrankRotation::radians(phi_rad), lambda);
}

}  // namespace loom::motion

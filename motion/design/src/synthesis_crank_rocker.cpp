// Khare–Dave crank-rocker synthesis (thesis 000 §4.5.2, eqs. 4.25–4.43) for every case of φ.
// Derived afresh from the dead-centre loop B_f − B0 = R(ψ)(B_e − B0) with B_e = (a+b)·u(β) and
// B_f = −(b−a)·u(β+φ): with δ = (π−φ)/2, γ = β−δ, h = δ+ψ/2 this gives a = sin(ψ/2)·sin γ / cos h and
// b = sin(ψ/2)·cos γ / sin h (the thesis' eq. 4.27 rewritten so that φ = 180° and the bounds are exact).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include "checks.hpp"
#include "geometry.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/synthesis.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

// ---------------------------------------------------------------------------------------------
// Input checks and the case split.

struct Problem {
  double psi;
  double phi;         // snapped to π or π + ψ when within kSynthesisSnap_rad
  double supplement;  // π − φ to full relative precision (snapped with φ)
  CrankRockerCase design_case;
  double lower;
  double upper;
};

std::string describe(double psi, double phi) {
  std::ostringstream s;
  s << "psi = " << deg(psi) << " deg, phi = " << deg(phi) << " deg";
  return s.str();
}

Problem classify(double psi, const CrankRotation& rotation) {
  const double phi = rotation.phi_rad;
  const double sup = rotation.supplement_rad;
  if (!std::isfinite(psi) || !(psi > 0.0) || !(psi < kPi)) {
    std::ostringstream msg;
    msg << "crank-rocker synthesis: psi = " << deg(psi) << " deg must lie in (0, 180) deg";
    throw MotionError(ErrorCode::kInvalidInput, msg.str());
  }
  if (!std::isfinite(phi) || !std::isfinite(sup)) {
    throw MotionError(ErrorCode::kInvalidInput, "crank-rocker synthesis: phi must be finite");
  }
  const double phi_min = 0.5 * kPi + 0.5 * psi;
  const double phi_max = 1.5 * kPi + 0.5 * psi;
  if (!(phi > phi_min + kSynthesisSnap_rad) || !(phi < phi_max - kSynthesisSnap_rad)) {
    std::ostringstream msg;
    msg << "crank-rocker synthesis: no crank-rocker has " << describe(psi, phi)
        << ": phi must lie in (90 + psi/2, 270 + psi/2) = (" << deg(phi_min) << ", " << deg(phi_max)
        << ") deg";
    throw MotionError(ErrorCode::kInvalidInput, msg.str());
  }
  Problem p{psi, phi, sup, CrankRockerCase::kPhi180, 0.0, 0.5 * kPi - 0.5 * psi};
  const double beta_rocker_limit = 0.5 * kPi - 0.5 * psi;  // coupler as short as the crank
  if (std::fabs(sup + psi) <= kSynthesisSnap_rad) {
    p.phi = kPi + psi;
    p.supplement = -psi;
    p.design_case = CrankRockerCase::kPhi180PlusPsi;
    p.lower = p.upper = beta_rocker_limit;
  } else if (std::fabs(sup) <= kSynthesisSnap_rad) {
    p.phi = kPi;
    p.supplement = 0.0;
    p.design_case = CrankRockerCase::kPhi180;
    p.lower = 0.0;
    p.upper = beta_rocker_limit;
  } else if (sup > 0.0) {
    p.design_case = CrankRockerCase::kPhiBelow180;
    p.lower = sup;
    p.upper = beta_rocker_limit;
  } else if (sup + psi > 0.0) {
    p.design_case = CrankRockerCase::kPhiAbove180;
    p.lower = 0.0;
    p.upper = beta_rocker_limit;
  } else {
    p.design_case = CrankRockerCase::kPhiBeyond180PlusPsi;
    p.lower = beta_rocker_limit;
    p.upper = kTwoPi - phi;
  }
  return p;
}

void check_ground(double ground) {
  detail::require_positive_length("crank-rocker synthesis", "ground", ground, "");
}

// ---------------------------------------------------------------------------------------------
// Transmission angle.

// Extremes of the coupler–rocker angle occur with the crank along the ground line (|AB0| = d ∓ a).
double mu_min_of(double a, double b, double c, double d) {
  const double near = detail::triangle_angle(std::fabs(d - a), b, c);
  const double far = detail::triangle_angle(d + a, b, c);
  return std::fmin(near, kPi - far);
}

// ---------------------------------------------------------------------------------------------
// Designs (unit ground, scaled at the end).

struct UnitLinkage {
  double a, b, c;
  double extended_reach;  // |A0 B_e| = a + b
  double folded_reach;    // |A0 B_f| = b − a
};

UnitLinkage general_linkage(const Problem& p, double beta) {
  const double sp = std::sin(0.5 * p.psi);
  const double delta = 0.5 * p.supplement;
  const double h = delta + 0.5 * p.psi;
  const double gamma = beta - delta;
  UnitLinkage u{};
  u.a = sp * std::sin(gamma) / std::cos(h);
  u.b = sp * std::cos(gamma) / std::sin(h);
  u.extended_reach = u.a + u.b;
  // b − a = 2 sin(ψ/2) cos(β + ψ/2) / sin(2h): exact zero at the upper bound, no cancellation.
  u.folded_reach = 2.0 * sp * std::sin((0.5 * kPi - 0.5 * p.psi) - beta) / std::sin(2.0 * h);
  const double half_beta = std::sin(0.5 * beta);
  const double r = u.extended_reach;
  u.c = std::sqrt((r - 1.0) * (r - 1.0) + 4.0 * r * half_beta * half_beta);  // law of cosines
  return u;
}

// φ = π + ψ: a = sin(ψ/2) is fixed and the coupler b (> a) picks the member of the family.
UnitLinkage special_linkage(const Problem& p, double coupler) {
  UnitLinkage u{};
  u.a = std::sin(0.5 * p.psi);
  u.b = coupler;
  u.c = std::sqrt((1.0 - u.a) * (1.0 + u.a) + coupler * coupler);
  u.extended_reach = u.a + u.b;
  u.folded_reach = u.b - u.a;
  return u;
}

CrankRockerDesign finish(const Problem& p, double beta, const UnitLinkage& u, double ground, unsigned flags) {
  CrankRockerDesign d;
  d.crank = ground * u.a;
  d.coupler = ground * u.b;
  d.rocker = ground * u.c;
  d.ground = ground;
  d.psi_rad = p.psi;
  d.phi_rad = p.phi;
  d.beta_rad = beta;
  d.design_case = p.design_case;
  d.flags = flags;
  d.mu_min_rad = (flags & kDesignChangePoint) ? 0.0 : mu_min_of(u.a, u.b, u.c, 1.0);
  d.crank_extended_rad = wrap_two_pi(beta);
  d.crank_folded_rad = wrap_two_pi(beta + p.phi);
  const double ex = u.extended_reach * std::cos(beta);
  const double ey = u.extended_reach * std::sin(beta);
  const double fx = -u.folded_reach * std::cos(beta + p.phi);
  const double fy = -u.folded_reach * std::sin(beta + p.phi);
  d.rocker_extended_rad = wrap_two_pi(std::atan2(ey, ex - 1.0));
  d.rocker_folded_rad = wrap_two_pi(std::atan2(fy, fx - 1.0));
  return d;
}

// Unit-ground μ_min for β strictly inside the bounds (used by the optimiser; no flags, no throw).
double mu_min_at(const Problem& p, double beta) {
  const UnitLinkage u = general_linkage(p, beta);
  return mu_min_of(u.a, u.b, u.c, 1.0);
}

[[noreturn]] void throw_beta_out_of_bounds(const Problem& p, double beta) {
  std::ostringstream msg;
  msg << "crank-rocker synthesis: beta = " << deg(beta) << " deg is outside its bounds [" << deg(p.lower)
      << ", " << deg(p.upper) << "] deg for " << describe(p.psi, p.phi) << " ("
      << crank_rocker_case_name(p.design_case) << ")";
  throw MotionError(ErrorCode::kOutOfBounds, msg.str());
}

CrankRockerDesign design_for_beta(const Problem& p, double beta, double ground) {
  if (!std::isfinite(beta)) {
    throw MotionError(ErrorCode::kInvalidInput, "crank-rocker synthesis: beta must be finite");
  }
  unsigned flags = 0;
  double b = beta;
  if (std::fabs(b - p.lower) <= kSynthesisSnap_rad) {
    b = p.lower;
  } else if (std::fabs(b - p.upper) <= kSynthesisSnap_rad) {
    b = p.upper;
  } else if (b < p.lower || b > p.upper) {
    throw_beta_out_of_bounds(p, beta);
  }
  if (p.design_case == CrankRockerCase::kPhi180PlusPsi) {
    // Thesis case III (eqs. 4.36–4.39): the member with a 90° transmission angle when the crank
    // points away from B0; it also maximises μ_min over the family (checked by the tests).
    const double a = std::sin(0.5 * p.psi);
    return finish(p, b, special_linkage(p, std::sqrt(a * (1.0 + a))), ground, 0);
  }
  if (p.design_case == CrankRockerCase::kPhi180 && b == 0.0) {
    // The centric family's lower bound: a = c = 0 (eq. 4.41), the coupler lies on the ground. The
    // thesis prints μ_min = ∞ (eq. 4.43 read as 0/0); from inside, μ_min → 90° − ψ/2.
    std::ostringstream msg;
    msg << "crank-rocker synthesis: beta = 0 deg at phi = 180 deg is the null crank (a = c = 0, b = ground): "
           "not a mechanism; mu_min -> "
        << 90.0 - 0.5 * deg(p.psi) << " deg as beta -> 0 (choose beta in (0, " << deg(p.upper)
        << "] deg) for psi = " << deg(p.psi) << " deg";
    throw MotionError(ErrorCode::kOutOfBounds, msg.str());
  }
  if (b == p.lower || b == p.upper) flags |= kDesignChangePoint;
  if (std::fabs(p.supplement + p.psi) <= kNearSpecialCase_rad) flags |= kDesignNearSpecialCase;
  return finish(p, b, general_linkage(p, b), ground, flags);
}

}  // namespace

const char* crank_rocker_case_name(CrankRockerCase c) {
  switch (c) {
    case CrankRockerCase::kPhiBelow180:
      return "phi < 180";
    case CrankRockerCase::kPhi180:
      return "phi = 180";
    case CrankRockerCase::kPhiAbove180:
      return "180 < phi < 180 + psi";
    case CrankRockerCase::kPhi180PlusPsi:
      return "phi = 180 + psi";
    case CrankRockerCase::kPhiBeyond180PlusPsi:
      return "phi > 180 + psi";
  }
  return "?";
}

CrankRotation CrankRotation::degrees(double phi_deg) {
  return {rad(phi_deg), rad(180.0 - phi_deg)};
}
CrankRotation CrankRotation::radians(double phi_rad) {
  return {phi_rad, kPi - phi_rad};
}

std::optional<CrankRotation> CrankRotation::decimal_degrees(std::string_view text) {
  const std::size_t point = text.find('.');
  if (text.empty() || text.size() > 60 || text == ".") return std::nullopt;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (i != point && (text[i] < '0' || text[i] > '9')) return std::nullopt;
  }
  // Both numbers as digit strings with the same number of fraction digits, then |180 − φ| by schoolbook
  // subtraction (the larger minus the smaller), its sign kept aside.
  const std::string_view whole = point == std::string_view::npos ? text : text.substr(0, point);
  const std::string_view frac = point == std::string_view::npos ? std::string_view{} : text.substr(point + 1);
  std::string phi = std::string(whole) + std::string(frac);
  std::string ref = "180" + std::string(frac.size(), '0');
  const std::size_t width = std::max(phi.size(), ref.size());
  phi.insert(0, width - phi.size(), '0');
  ref.insert(0, width - ref.size(), '0');
  const bool negative = phi > ref;  // same width: the digit strings compare as the numbers
  const std::string& big = negative ? phi : ref;
  const std::string& small = negative ? ref : phi;
  std::string diff(width, '0');
  int borrow = 0;
  for (std::size_t i = width; i-- > 0;) {
    int d = (big[i] - '0') - (small[i] - '0') - borrow;
    borrow = d < 0 ? 1 : 0;
    diff[i] = static_cast<char>('0' + d + 10 * borrow);
  }
  diff.insert(diff.size() - frac.size(), ".");
  const double supplement_deg = std::strtod(diff.c_str(), nullptr);  // correctly rounded, once
  const double phi_deg = std::strtod(std::string(text).c_str(), nullptr);
  return CrankRotation{rad(phi_deg), rad(negative ? -supplement_deg : supplement_deg)};
}

BetaBounds khare_dave_beta_bounds(double psi_rad, double phi_rad) {
  return khare_dave_beta_bounds(psi_rad, CrankRotation::radians(phi_rad));
}
CrankRockerDesign khare_dave_crank_rocker(double psi_rad, double phi_rad, double beta_rad, double ground) {
  return khare_dave_crank_rocker(psi_rad, CrankRotation::radians(phi_rad), beta_rad, ground);
}
CrankRockerDesign khare_dave_best_beta(double psi_rad, double phi_rad, double ground) {
  return khare_dave_best_beta(psi_rad, CrankRotation::radians(phi_rad), ground);
}
CrankRockerDesign khare_dave_for_ratio(double psi_rad, double phi_rad, double lambda, double ground) {
  return khare_dave_for_ratio(psi_rad, CrankRotation::radians(phi_rad), lambda, ground);
}

BetaBounds khare_dave_beta_bounds(double psi_rad, const CrankRotation& phi_rad) {
  const Problem p = classify(psi_rad, phi_rad);
  return BetaBounds{p.lower, p.upper, p.design_case};
}

CrankRockerDesign khare_dave_crank_rocker(double psi_rad, const CrankRotation& phi_rad, double beta_rad,
                                          double ground) {
  check_ground(ground);
  return design_for_beta(classify(psi_rad, phi_rad), beta_rad, ground);
}

CrankRockerDesign khare_dave_best_beta(double psi_rad, const CrankRotation& phi_rad, double ground) {
  check_ground(ground);
  const Problem p = classify(psi_rad, phi_rad);
  if (p.design_case == CrankRockerCase::kPhi180PlusPsi) return design_for_beta(p, p.lower, ground);
  if (p.design_case == CrankRockerCase::kPhi180) {
    std::ostringstream msg;
    msg << "crank-rocker synthesis: for phi = 180 deg mu_min = acos(sin(psi/2)/cos(beta)) rises "
           "monotonically towards "
        << 90.0 - 0.5 * deg(p.psi)
        << " deg as beta -> 0, where the crank vanishes: no best beta exists; choose beta in ("
        << deg(p.lower) << ", " << deg(p.upper) << "] deg or a crank/coupler ratio";
    throw MotionError(ErrorCode::kOutOfBounds, msg.str());
  }
  // μ_min is 0 at both bounds and positive inside: bracket the maximum on a grid, then golden
  // section (μ_min is the minimum of two smooth branches, so the peak may be a kink).
  constexpr int kGrid = 256;
  const double span = p.upper - p.lower;
  int best = 1;
  double best_mu = -1.0;
  for (int i = 1; i < kGrid; ++i) {
    const double m = mu_min_at(p, p.lower + span * i / kGrid);
    if (m > best_mu) {
      best_mu = m;
      best = i;
    }
  }
  double lo = p.lower + span * (best - 1) / kGrid;
  double hi = p.lower + span * (best + 1) / kGrid;
  const double inv_phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - inv_phi * (hi - lo);
  double x2 = lo + inv_phi * (hi - lo);
  double f1 = mu_min_at(p, x1);
  double f2 = mu_min_at(p, x2);
  for (int it = 0; it < 200 && hi - lo > 1e-13; ++it) {
    if (f1 < f2) {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + inv_phi * (hi - lo);
      f2 = mu_min_at(p, x2);
    } else {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - inv_phi * (hi - lo);
      f1 = mu_min_at(p, x1);
    }
  }
  return design_for_beta(p, 0.5 * (lo + hi), ground);
}

CrankRockerDesign khare_dave_for_ratio(double psi_rad, const CrankRotation& phi_rad, double lambda,
                                       double ground) {
  check_ground(ground);
  const Problem p = classify(psi_rad, phi_rad);
  if (!std::isfinite(lambda) || !(lambda > 0.0)) {
    std::ostringstream msg;
    msg << "crank-rocker synthesis: lambda = a/b = " << lambda << " must be finite and > 0";
    throw MotionError(ErrorCode::kInvalidInput, msg.str());
  }
  if (p.design_case == CrankRockerCase::kPhi180PlusPsi) {
    // b = a/λ; a crank-rocker needs b > a (λ < 1), λ = 1 is the change point b = a.
    if (lambda > 1.0 + 1e-14) {
      std::ostringstream msg;
      msg << "crank-rocker synthesis: lambda = " << lambda << " is outside its bounds (0, 1] for "
          << describe(p.psi, p.phi) << " (phi = 180 + psi)";
      throw MotionError(ErrorCode::kOutOfBounds, msg.str());
    }
    const bool change_point = lambda >= 1.0 - 1e-14;
    const double a = std::sin(0.5 * p.psi);
    return finish(p, p.lower, special_linkage(p, change_point ? a : a / lambda), ground,
                  change_point ? kDesignChangePoint : 0u);
  }
  // a/b = tan γ · tan h is monotonic in β; γ lies in (0, π/2) when h > 0 and in (π/2, π) when h < 0.
  const double delta = 0.5 * p.supplement;
  const double h = delta + 0.5 * p.psi;
  const double gamma = std::atan2(lambda * std::cos(h), std::sin(h));
  const double beta = gamma + delta;
  if (beta < p.lower - kSynthesisSnap_rad || beta > p.upper + kSynthesisSnap_rad) {
    const UnitLinkage lo = general_linkage(p, p.lower);
    const UnitLinkage hi = general_linkage(p, p.upper);
    std::ostringstream msg;
    msg << "crank-rocker synthesis: lambda = a/b = " << lambda << " is outside its bounds ["
        << std::min(lo.a / lo.b, hi.a / hi.b) << ", " << std::max(lo.a / lo.b, hi.a / hi.b) << "] for "
        << describe(p.psi, p.phi);
    throw MotionError(ErrorCode::kOutOfBounds, msg.str());
  }
  return design_for_beta(p, std::clamp(beta, p.lower, p.upper), ground);
}

}  // namespace loom::motion

// Dimensional synthesis of the beat-up linkage from the thesis (000 §4.5): Söylemez's slider-crank
// with optimum transmission angle for a stroke and crank rotation φ, and Khare–Dave's crank-rocker for
// a swing ψ, crank rotation φ and extended-dead-centre crank angle β, in every case of φ.
// All functions are configure-time only: they throw MotionError for impossible input, never NaN.
#pragma once

#include <optional>
#include <string_view>

#include "loom/motion/slider_crank.hpp"

namespace loom::motion {

// ---------------------------------------------------------------------------------------------
// Degenerate designs are returned and flagged (bits of `flags`), not thrown.
inline constexpr unsigned kDesignChangePoint = 1u << 0;  // design variable at a bound: links can
                                                         // lie collinear (Grashof equality), μ_min = 0
inline constexpr unsigned kDesignNearSpecialCase = 1u
                                                   << 2;  // φ within kNearSpecialCase_rad of 180° + ψ
                                                          // (but not on it): b and c grow like 1/|φ − 180° −
                                                          // ψ| towards a path-dependent limit that is not the
                                                          // case-III linkage; the design is ill-conditioned

// φ closer than this to 180° + ψ (and farther than kSynthesisSnap_rad) is flagged kDesignNearSpecialCase:
// there b ≈ sin(ψ/2)·cos γ / |h| exceeds ~1e4 ground lengths and its digits follow φ's last digits.
inline constexpr double kNearSpecialCase_rad = 1e-4 * 3.14159265358979323846 / 180.0;

// Angles closer than this to a special value (φ = 180°, φ = 180° + ψ, a β or λ bound) are taken as
// that value: degree→radian conversion and one subtraction leave a few ulps of π (~1e-15 rad).
inline constexpr double kSynthesisSnap_rad = 1e-14;

// ---------------------------------------------------------------------------------------------
// Söylemez slider-crank. φ is the crank rotation between the dead centres on the short side
// (90° ≤ φ < 180°); in slider_crank.hpp's frame it is the counter-clockwise travel folded → extended,
// with the offset e = c ≥ 0. λ = a/b.

struct SliderCrankDesign {
  SliderCrank mechanism;  // a, b, c in the stroke's unit
  double stroke = 0.0;
  double phi_rad = 0.0;
  double lambda = 0.0;      // a / b
  double mu_min_rad = 0.0;  // minimum transmission angle, acos((a + c) / b)
  unsigned flags = 0;
};

// The crank rotation φ together with its supplement π − φ, each to full relative precision. Near
// φ = 180° the designs depend on π − φ, which `π − φ_rad` gets only to ulp(π)/|π − φ| (9.5e-9 relative at
// 179.999999°, 1 % at 180° − 1e-12°); from degrees the supplement is exact (Sterbenz) before conversion.
struct CrankRotation {
  double phi_rad = 0.0;                          // φ
  double supplement_rad = 0.0;                   // π − φ
  static CrankRotation degrees(double phi_deg);  // supplement from 180 − φ_deg, converted after
  static CrankRotation radians(double phi_rad);  // supplement from π − φ_rad (as accurate as φ_rad is)
  // φ as a person writes it ("179.999999999999"): the supplement is 180 − φ subtracted exactly in decimal,
  // then rounded once, so it is the written value's to full relative precision — `degrees` can only have
  // the double nearest the text, whose 180 − φ is off by up to ulp(180)/2 (0.14 % at 180° − 1e-12°).
  // nullopt unless the text is plain decimal: digits, at most one '.', at most 60 characters (no sign,
  // exponent, nan or inf: those go through `degrees`).
  static std::optional<CrankRotation> decimal_degrees(std::string_view phi_deg);
};

struct LambdaBounds {
  double lower = 0.0;  // 1 / tan²(φ/2): the folded dead centre puts the coupler across the line
  double upper = 1.0;  // a = b: the folded dead centre puts the slider on the crank pivot
};

// configure-time only. Feasible λ for crank rotation φ; both ends are change points (μ_min = 0).
// Throws kInvalidInput unless π/2 ≤ φ < π.
LambdaBounds soylemez_lambda_bounds(double phi_rad);
LambdaBounds soylemez_lambda_bounds(CrankRotation phi);

// configure-time only. λ maximising μ_min (the root Q₁ of the thesis' cubic, eq. 4.24), written in
// half-angle form so it stays accurate as φ → π. Throws kInvalidInput unless π/2 ≤ φ < π.
double soylemez_lambda_opt(double phi_rad);
double soylemez_lambda_opt(CrankRotation phi);

// configure-time only. Optimum design (λ = λ_opt) for a stroke > 0 and π/2 ≤ φ < π. b grows like
// stroke / √(2(π − φ)) as φ → π and stays finite and accurate; φ = π exactly is kInvalidInput. The design
// depends on π − φ: give φ as a CrankRotation (from degrees) to keep it to full relative precision near
// 180° (the radian overloads lose ulp(π)/(π − φ) of it).
SliderCrankDesign soylemez_slider_crank(double stroke, double phi_rad);
SliderCrankDesign soylemez_slider_crank(double stroke, CrankRotation phi);

// configure-time only. Design for a given λ in soylemez_lambda_bounds(φ): kOutOfBounds outside
// (message names the bounds), flagged kDesignChangePoint at either bound.
SliderCrankDesign soylemez_slider_crank(double stroke, double phi_rad, double lambda);
SliderCrankDesign soylemez_slider_crank(double stroke, CrankRotation phi, double lambda);

// ---------------------------------------------------------------------------------------------
// Khare–Dave crank-rocker. Frame: crank pivot A0 at the origin, rocker pivot B0 at (ground, 0);
// the crank turns counter-clockwise through φ from the extended dead centre (crank at angle β,
// coupler B above the ground line) to the folded one while the rocker swings through ψ.

enum class CrankRockerCase {
  kPhiBelow180,    // π/2 + ψ/2 < φ < π:      β ∈ [π − φ, π/2 − ψ/2]           (thesis case II)
  kPhi180,         // φ = π, centric linkage:  β ∈ [0, π/2 − ψ/2]; β = 0 is the null crank
  kPhiAbove180,    // π < φ < π + ψ:           β ∈ [0, π/2 − ψ/2]               (thesis case I)
  kPhi180PlusPsi,  // φ = π + ψ: β fixed at π/2 − ψ/2, a = sin(ψ/2), b free     (case III)
  kPhiBeyond180PlusPsi,  // π + ψ < φ < 3π/2 + ψ/2:  β ∈ [π/2 − ψ/2, 2π − φ]  (beyond the thesis)
};

// RT-safe. A short fixed name for messages and CSV.
const char* crank_rocker_case_name(CrankRockerCase c);

struct BetaBounds {
  double lower_rad = 0.0;
  double upper_rad = 0.0;
  CrankRockerCase design_case = CrankRockerCase::kPhi180;
};

struct CrankRockerDesign {
  double crank = 0.0;    // a: A0 → A
  double coupler = 0.0;  // b: A → B
  double rocker = 0.0;   // c: B0 → B
  double ground = 1.0;   // d: A0 → B0 (lengths in its unit)
  double psi_rad = 0.0;
  double phi_rad = 0.0;
  double beta_rad = 0.0;
  double mu_min_rad = 0.0;           // minimum transmission angle over a turn (acute, ≤ π/2)
  double crank_extended_rad = 0.0;   // crank angle at the extended dead centre (= β)
  double crank_folded_rad = 0.0;     // crank angle at the folded dead centre (β + φ), [0, 2π)
  double rocker_extended_rad = 0.0;  // rocker direction B0 → B, counter-clockwise from +x
  double rocker_folded_rad = 0.0;
  CrankRockerCase design_case = CrankRockerCase::kPhi180;
  unsigned flags = 0;
};

// configure-time only. Feasible β for (ψ, φ); for φ = π + ψ lower = upper. Throws kInvalidInput
// unless 0 < ψ < π and π/2 + ψ/2 < φ < 3π/2 + ψ/2 (no crank-rocker exists outside).
BetaBounds khare_dave_beta_bounds(double psi_rad, double phi_rad);

// configure-time only. The design for one β (ground > 0 scales every length). β outside the bounds
// → kOutOfBounds naming them; β at a bound → flagged kDesignChangePoint with μ_min = 0, except the
// null crank (φ = π, β = 0: a = c = 0, not a mechanism; the thesis prints μ_min = ∞), which throws
// kOutOfBounds giving the limit μ_min → 90° − ψ/2 as β → 0. For φ = π + ψ the thesis' member of the
// family (transmission angle 90° at the crank-outward position) is returned; φ within
// kNearSpecialCase_rad of it is flagged kDesignNearSpecialCase.
CrankRockerDesign khare_dave_crank_rocker(double psi_rad, double phi_rad, double beta_rad,
                                          double ground = 1.0);

// configure-time only. The design whose β maximises μ_min (found numerically, |Δβ| < 1e-9 rad).
// φ = π: μ_min rises monotonically towards π/2 − ψ/2 as β → 0 where the crank vanishes, so no
// maximiser exists: kOutOfBounds (choose β, or a ratio with khare_dave_for_ratio).
CrankRockerDesign khare_dave_best_beta(double psi_rad, double phi_rad, double ground = 1.0);

// configure-time only. The design with crank/coupler ratio λ = a/b (the thesis' sley-eccentricity
// criterion, a/b ≤ 0.3). For φ = π + ψ, λ selects the member of the family (b = a/λ).
// kOutOfBounds when no feasible β gives that ratio.
CrankRockerDesign khare_dave_for_ratio(double psi_rad, double phi_rad, double lambda, double ground = 1.0);

// The same four with φ and its supplement given apart (CrankRotation::degrees for degree input).
BetaBounds khare_dave_beta_bounds(double psi_rad, const CrankRotation& phi);
CrankRockerDesign khare_dave_crank_rocker(double psi_rad, const CrankRotation& phi, double beta_rad,
                                          double ground = 1.0);
CrankRockerDesign khare_dave_best_beta(double psi_rad, const CrankRotation& phi, double ground = 1.0);
CrankRockerDesign khare_dave_for_ratio(double psi_rad, const CrankRotation& phi, double lambda,
                                       double ground = 1.0);

}  // namespace loom::motion

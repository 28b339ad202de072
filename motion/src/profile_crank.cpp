// Crank speed law. The offset Φc − Φm is written as [φ2(φ1) − φ1] − [φ2(c) − c]: with e = 0 the gear
// law is exactly the identity, so both brackets are exactly zero and the elliptic law reduces to the
// constant one bit for bit, not merely to rounding.
#include "loom/motion/profile_crank.hpp"

#include <cmath>
#include <cstring>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

const char* crank_law_name(CrankLawKind k) {
  return k == CrankLawKind::kElliptic ? "elliptic" : "constant";
}

bool parse_crank_law(const char* text, CrankLawKind& out) {
  for (CrankLawKind k : {CrankLawKind::kConstant, CrankLawKind::kElliptic}) {
    if (std::strcmp(text, crank_law_name(k)) == 0) {
      out = k;
      return true;
    }
  }
  return false;
}

namespace {

[[noreturn]] void bad(const char* field, double value, const char* why) {
  std::ostringstream os;
  os << "beat-up crank law: " << field << " = " << value << ": " << why;
  throw MotionError(ErrorCode::kInvalidInput, os.str());
}

// Third derivative of the gear law φ2(φ1): d/dφ1 of 2ek(1−e²) sin u / D², u = kφ1,
// D = 1 + e² + 2e cos u (in its cancellation-free form).
double third_derivative(double e, int k, double phi1) {
  const double kk = static_cast<double>(k);
  const double u = kk * phi1;
  const double c = std::cos(0.5 * u);
  const double d = (1.0 - e) * (1.0 - e) + 4.0 * e * c * c;
  const double s = std::sin(u);
  return 2.0 * e * kk * kk * (1.0 - e) * (1.0 + e) * (std::cos(u) * d + 4.0 * e * s * s) / (d * d * d);
}

}  // namespace

CrankLaw::CrankLaw(const CrankLawSpec& spec, double fell_phase, const TableSpec& table) : spec_(spec) {
  if (spec.kind == CrankLawKind::kElliptic) {
    if (!(spec.ellipse_e >= 0.0) || !(spec.ellipse_e < 1.0)) {
      bad("ellipse_e", spec.ellipse_e, "must be in [0, 1) (0 is constant speed, 1 an open curve)");
    }
    if (spec.ellipse_lobes < 1) bad("ellipse_lobes", spec.ellipse_lobes, "must be >= 1");
    if (!std::isfinite(spec.ellipse_phi02_rad))
      bad("ellipse_phi02", spec.ellipse_phi02_rad, "must be finite");
    if (!std::isfinite(fell_phase)) bad("fell phase", fell_phase, "must be finite");
    const EllipticGearPair gear(1.0, spec.ellipse_e, spec.ellipse_lobes);
    // The driving-pinion angle c at park: the crank reaches the fell (Φc = fell) when φ2 = φ02, and
    // Φc = fell + φ2(φ1) − φ02, so Φc(park) = 0 needs φ2(c) = φ02 − fell. φ2 is increasing and stays
    // within 2π/k of the identity, so the root is bracketed by ±(2π + 1) around the target.
    const double target = spec.ellipse_phi02_rad - fell_phase;
    double lo = target - kTwoPi - 1.0, hi = target + kTwoPi + 1.0;
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      (gear.phase(mid).phi2_rad < target ? lo : hi) = mid;
    }
    pinion_offset_ = 0.5 * (lo + hi);
    phase_offset_ = gear.phase(pinion_offset_).phi2_rad - pinion_offset_;
    max_ratio_ = gear.max_speed_ratio();
    min_ratio_ = 1.0 / max_ratio_;
  }
  TableSpec t = table;
  t.rise = 0.0;  // the offset is periodic: the crank turns exactly once per master turn
  table_ = PhaseTable(t, [this](double master) {
    const CrankLawExact e = exact(master);
    return PhaseExact{e.offset, e.d1 - 1.0, e.d2};
  });
}

CrankLawExact CrankLaw::exact(double master_phase) const {
  if (spec_.kind == CrankLawKind::kConstant) return {};
  const EllipticGearPair gear(1.0, spec_.ellipse_e, spec_.ellipse_lobes);
  const double phi1 = master_phase + pinion_offset_;
  const GearPhase g = gear.phase(phi1);
  CrankLawExact out;
  out.offset = (g.phi2_rad - phi1) - phase_offset_;
  out.d1 = g.dphi2;
  out.d2 = g.d2phi2;
  out.d3 = third_derivative(spec_.ellipse_e, spec_.ellipse_lobes, phi1);
  return out;
}

}  // namespace loom::motion

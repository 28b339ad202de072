// The beat-up crank's speed law as an electronic cam: a master phase Φm turns uniformly and the crank
// follows Φc(Φm). "constant" is Φc = Φm; "elliptic" reproduces the elliptic-gear batten drive of seed
// 004 — the crank on the driven pinion of a k-lobed elliptic pair — so the crank runs fastest where
// the beater meets the fell and beats harder, without cutting a gear.
#pragma once

#include <cstdint>

#include "loom/motion/elliptic_gear.hpp"
#include "loom/motion/phase.hpp"
#include "loom/motion/phase_table.hpp"

namespace loom::motion {

enum class CrankLawKind : std::uint8_t { kConstant, kElliptic };
const char* crank_law_name(CrankLawKind k);                 // RT-safe: "constant", "elliptic"
bool parse_crank_law(const char* text, CrankLawKind& out);  // configure-time only

struct CrankLawSpec {
  CrankLawKind kind = CrankLawKind::kConstant;
  double ellipse_e = 0.2;  // eccentricity of the pitch curves, [0, 1); 0 is the constant law
  // k of r = p/(1 + e cos kφ). 004's batten swings twice per crank turn and uses k = 2; the loom's
  // crank-rocker beats once per turn, so k = 1 (the classic focal elliptic pair) gives one fast
  // stretch per beat, at the fell, and one slow stretch — more time — in the clear window.
  int ellipse_lobes = 1;
  // Driven-pinion angle φ2 (004's φ02 role) at which the crank reaches the fell. π/k puts the pair's
  // fastest point, dφ2/dφ1 = (1+e)/(1-e), at the beat: the highest beater acceleration at the fell.
  double ellipse_phi02_rad = 3.141592653589793;
};

// Crank phase from park and its derivatives with respect to the master phase.
struct CrankSample {
  double phase = 0.0;  // Φc (rad, unwrapped like the master)
  double d1 = 1.0;     // dΦc/dΦm
  double d2 = 0.0;     // d²Φc/dΦm²
};

// Exact law: Φc − Φm (periodic) and the derivatives of Φc.
struct CrankLawExact {
  double offset = 0.0;
  double d1 = 1.0, d2 = 0.0, d3 = 0.0;
};

class CrankLaw {
 public:
  CrankLaw() = default;
  // Configure-time only. `fell_phase` is the fell's crank phase from park (BeatUp::warp().fell); the
  // master and crank phases agree at park (Φc(0) = 0). Throws MotionError(kInvalidInput) naming the
  // field for e outside [0, 1), lobes < 1 or a non-finite φ02, and whatever the table throws.
  CrankLaw(const CrankLawSpec& spec, double fell_phase, const TableSpec& table);

  // Configure-time and tests. The closed form (004's focal-ellipse law); exactly the identity for
  // the constant law and for e = 0.
  CrankLawExact exact(double master_phase) const;

  // RT-safe. The tabulated law at a master phase.
  CrankSample at(const Phase& master) const noexcept {
    const PhaseSample s = table_.at(master);
    return {master.to_rad() + s.value, 1.0 + s.d1, s.d2};
  }
  // RT-safe. at(master).phase alone. The constant law's table holds zeros only (exact() is the identity),
  // and x + ±0 is x for every x to_rad() returns, so its phase is the master's without the lookup.
  double phase_at(const Phase& master) const noexcept {
    return spec_.kind == CrankLawKind::kConstant ? master.to_rad()
                                                 : master.to_rad() + table_.at(master).value;
  }
  // RT-safe. The crank phase in fixed point, for indexing the rocker table.
  Phase crank_phase(const Phase& master) const noexcept {
    return master.plus_small_rad(table_.at(master).value);
  }

  // RT-safe accessors.
  const CrankLawSpec& spec() const noexcept { return spec_; }
  const PhaseTable& table() const noexcept { return table_; }
  // Largest and smallest dΦc/dΦm: the crank's speed swing at a constant master speed.
  double max_ratio() const noexcept { return max_ratio_; }
  double min_ratio() const noexcept { return min_ratio_; }

 private:
  CrankLawSpec spec_{};
  double pinion_offset_ = 0.0;  // driving-pinion angle at park, φ1(Φm = 0)
  double phase_offset_ = 0.0;   // φ2(pinion_offset_) − pinion_offset_: makes Φc(0) = 0
  double max_ratio_ = 1.0, min_ratio_ = 1.0;
  PhaseTable table_;
};

}  // namespace loom::motion

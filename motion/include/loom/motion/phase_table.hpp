// A function of an axis phase sampled once at configure time and read back in O(1) by linear, cubic
// Hermite or quintic Hermite interpolation from double or float32 knots. The function may be periodic
// or climb a fixed `rise` per turn (a cam that advances each turn); the table stores the periodic
// remainder relative to a base value, which keeps float32 knots accurate. Lookups take the
// fixed-point Phase (or a double, converted) and never branch on the data, allocate or throw.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "loom/motion/phase.hpp"
#include "loom/motion/profile_interp.hpp"

namespace loom::motion {

struct PhaseSample {
  double value = 0.0;
  double d1 = 0.0;  // d value / d phase (per rad)
  double d2 = 0.0;  // d² value / d phase² (of the interpolant: 0 for linear, piecewise linear for cubic)
};

// Exact value and phase derivatives of the function being tabulated.
struct PhaseExact {
  double value = 0.0;
  double d1 = 0.0;
  double d2 = 0.0;
};

struct TableSpec {
  std::size_t size = 4096;  // knots per turn (>= 4)
  Interp interp = Interp::kCubic;
  Precision precision = Precision::kDouble;
  double rise = 0.0;  // f(φ + 2π) - f(φ): 0 for a periodic function
};

class PhaseTable {
 public:
  static constexpr std::size_t kMaxSize = std::size_t{1} << 24;

  PhaseTable() = default;

  // Configure-time only. Samples f at spec.size points over one turn [0, 2π); f must satisfy
  // f(φ + 2π) = f(φ) + spec.rise with matching derivatives. Throws MotionError(kInvalidInput) naming
  // the bad size or the first non-finite sample.
  PhaseTable(const TableSpec& spec, const std::function<PhaseExact(double)>& f);

  // Configure-time only. The skeleton's form: periodic, cubic Hermite, double, from value and slope.
  struct Exact {
    double value = 0.0;
    double d1 = 0.0;
  };
  PhaseTable(std::size_t n, const std::function<Exact(double)>& f);

  // RT-safe. Value at any phase; whole turns add `rise` each.
  PhaseSample at(const Phase& phase) const noexcept { return lookup_(*this, phase); }
  // RT-safe. Any real phase (rad); a non-finite phase reads phase 0 rather than producing NaN.
  PhaseSample at(double phase_rad) const noexcept { return lookup_(*this, Phase::from_rad(phase_rad)); }

  // RT-safe accessors.
  std::size_t size() const noexcept { return n_; }
  std::size_t bytes() const noexcept;  // knot storage
  const TableSpec& spec() const noexcept { return spec_; }

 private:
  using Lookup = PhaseSample (*)(const PhaseTable&, const Phase&) noexcept;
  template <Interp I, class T>
  static PhaseSample lookup(const PhaseTable& t, const Phase& p) noexcept;
  static PhaseSample lookup_empty(const PhaseTable&, const Phase&) noexcept { return {}; }
  template <class T>
  void fill(const std::vector<PhaseExact>& residual, std::vector<T>& out) const;

  TableSpec spec_{};
  std::size_t n_ = 0;
  std::vector<double> knots_d_;  // interleaved per knot: value, h·slope, h²·curvature (as the order needs)
  std::vector<float> knots_f_;
  double base_ = 0.0;   // added to every value (the float32 knots store the offset from it)
  double slope_ = 0.0;  // rise / 2π: the linear part taken out of a rising function
  double inv_h_ = 0.0;  // knots per rad
  Lookup lookup_ = &lookup_empty;
};

}  // namespace loom::motion

// Phase table construction and the typed lookups. The knots hold exact derivatives (not finite
// differences), so cubic Hermite is O(h⁴) and quintic O(h⁶) in position at no extra sampling cost;
// the interpolation order and precision are chosen once here, as a function pointer, so a lookup
// never tests them.
#include "loom/motion/phase_table.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <type_traits>

#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

const char* interp_name(Interp i) {
  switch (i) {
    case Interp::kLinear:
      return "linear";
    case Interp::kCubic:
      return "cubic";
    case Interp::kQuintic:
      return "quintic";
  }
  return "?";
}

const char* precision_name(Precision p) {
  return p == Precision::kFloat ? "float32" : "double";
}

bool parse_interp(const char* text, Interp& out) {
  for (Interp i : {Interp::kLinear, Interp::kCubic, Interp::kQuintic}) {
    if (std::strcmp(text, interp_name(i)) == 0) {
      out = i;
      return true;
    }
  }
  return false;
}

bool parse_precision(const char* text, Precision& out) {
  for (Precision p : {Precision::kDouble, Precision::kFloat}) {
    if (std::strcmp(text, precision_name(p)) == 0) {
      out = p;
      return true;
    }
  }
  return false;
}

PhaseTable::PhaseTable(const TableSpec& spec, const std::function<PhaseExact(double)>& f) : spec_(spec) {
  if (spec.size < 4 || spec.size > kMaxSize) {
    std::ostringstream os;
    os << "phase table size " << spec.size << " must be between 4 and " << kMaxSize;
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  if (!std::isfinite(spec.rise)) {
    std::ostringstream os;
    os << "phase table rise per turn must be finite, got " << spec.rise;
    throw MotionError(ErrorCode::kInvalidInput, os.str());
  }
  n_ = spec.size;
  const double h = kTwoPi / static_cast<double>(n_);
  inv_h_ = static_cast<double>(n_) / kTwoPi;
  slope_ = spec.rise / kTwoPi;
  std::vector<PhaseExact> residual(n_ + 1);
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < n_; ++i) {
    const double phase = h * static_cast<double>(i);
    const PhaseExact e = f(phase);
    if (!std::isfinite(e.value) || !std::isfinite(e.d1) || !std::isfinite(e.d2)) {
      std::ostringstream os;
      os << "phase table sample " << i << " (phase " << phase << " rad) is not finite";
      throw MotionError(ErrorCode::kInvalidInput, os.str());
    }
    // Take the rise out: what remains is periodic, and small enough for float32 knots.
    residual[i] = {e.value - spec.rise * static_cast<double>(i) / static_cast<double>(n_), e.d1 - slope_,
                   e.d2};
    lo = std::min(lo, residual[i].value);
    hi = std::max(hi, residual[i].value);
  }
  residual[n_] = residual[0];  // the knot after the last is the first: no wrap test in the lookup
  base_ = 0.5 * (lo + hi);
  for (PhaseExact& r : residual) {
    r.value -= base_;
    r.d1 *= h;
    r.d2 *= h * h;
  }
  const auto pick = [&]<class T>(std::vector<T>& store) {
    fill(residual, store);
    switch (spec.interp) {
      case Interp::kLinear:
        lookup_ = &lookup<Interp::kLinear, T>;
        break;
      case Interp::kCubic:
        lookup_ = &lookup<Interp::kCubic, T>;
        break;
      case Interp::kQuintic:
        lookup_ = &lookup<Interp::kQuintic, T>;
        break;
    }
  };
  if (spec.precision == Precision::kFloat) {
    pick(knots_f_);
  } else {
    pick(knots_d_);
  }
}

PhaseTable::PhaseTable(std::size_t n, const std::function<Exact(double)>& f)
    : PhaseTable(
          [n] {
            if (n < 4) {
              std::ostringstream os;
              os << "phase table needs at least 4 samples, got " << n;
              throw MotionError(ErrorCode::kInvalidInput, os.str());
            }
            return TableSpec{
                .size = n, .interp = Interp::kCubic, .precision = Precision::kDouble, .rise = 0.0};
          }(),
          [&f](double p) {
            const Exact e = f(p);
            return PhaseExact{e.value, e.d1, 0.0};
          }) {}

template <class T>
void PhaseTable::fill(const std::vector<PhaseExact>& residual, std::vector<T>& out) const {
  const std::size_t fields = knot_fields(spec_.interp);
  out.resize(residual.size() * fields);
  for (std::size_t i = 0; i < residual.size(); ++i) {
    const double knot[3] = {residual[i].value, residual[i].d1, residual[i].d2};
    for (std::size_t k = 0; k < fields; ++k) out[i * fields + k] = static_cast<T>(knot[k]);
  }
}

std::size_t PhaseTable::bytes() const noexcept {
  return knots_d_.size() * sizeof(double) + knots_f_.size() * sizeof(float);
}

template <Interp I, class T>
PhaseSample PhaseTable::lookup(const PhaseTable& tb, const Phase& p) noexcept {
  const T* knots;
  if constexpr (std::is_same_v<T, double>) {
    knots = tb.knots_d_.data();
  } else {
    knots = tb.knots_f_.data();
  }
  T t;
  const std::size_t i = detail::locate(p.frac, tb.n_, t);
  const SegmentValue<T> s = interpolate<I, T>(knots + i * knot_fields(I), t);
  PhaseSample out;
  out.value =
      tb.base_ + static_cast<double>(s.p) + tb.spec_.rise * (static_cast<double>(p.turns) + p.frac_turns());
  out.d1 = static_cast<double>(s.dp) * tb.inv_h_ + tb.slope_;
  out.d2 = static_cast<double>(s.ddp) * (tb.inv_h_ * tb.inv_h_);
  return out;
}

}  // namespace loom::motion

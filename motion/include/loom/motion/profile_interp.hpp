// The interpolation kernels behind every phase table: linear, cubic Hermite (value + slope per knot)
// and quintic Hermite (value + slope + curvature per knot), in double or float arithmetic. Each is
// branch-free: the phase's 64-bit fraction times the knot count gives the segment (high word) and
// the position inside it (low word) in one multiply, and the table's extra knot at the end removes
// the wrap test.
#pragma once

#include <cstddef>
#include <cstdint>

namespace loom::motion {

enum class Interp : std::uint8_t { kLinear, kCubic, kQuintic };
enum class Precision : std::uint8_t { kDouble, kFloat };

// RT-safe. Stored numbers per knot: value; + h·slope; + h²·curvature.
constexpr std::size_t knot_fields(Interp i) {
  return i == Interp::kLinear ? 1 : i == Interp::kCubic ? 2 : 3;
}
// RT-safe. Names as the config and the report spell them.
const char* interp_name(Interp i);        // "linear", "cubic", "quintic"
const char* precision_name(Precision p);  // "double", "float32"
// Configure-time only. Parse the names above; false when the text is not one of them.
bool parse_interp(const char* text, Interp& out);
bool parse_precision(const char* text, Precision& out);

// A polynomial piece in the segment's own coordinate t ∈ [0, 1]: value and its first two t-derivatives.
template <class T>
struct SegmentValue {
  T p, dp, ddp;
};

namespace detail {
__extension__ using Wide = unsigned __int128;

// RT-safe. A 64-bit fraction of one as a real in [0, 1]. Through the signed top 63 bits: an unsigned
// 64-bit conversion costs a branch on x86-64, and 63 bits are more than any mantissa holds.
template <class T>
inline T unit_fraction(std::uint64_t f) noexcept {
  return static_cast<T>(static_cast<std::int64_t>(f >> 1)) * static_cast<T>(0x1p-63);
}

// RT-safe. Segment index in [0, n) and position t ∈ [0, 1] of a phase fraction on n segments.
template <class T>
inline std::size_t locate(std::uint64_t frac, std::size_t n, T& t) noexcept {
  const Wide x = static_cast<Wide>(frac) * static_cast<std::uint64_t>(n);
  t = unit_fraction<T>(static_cast<std::uint64_t>(x));
  return static_cast<std::size_t>(x >> 64);
}
}  // namespace detail

// RT-safe. Interpolate between knot k (at `a`) and knot k+1 (at `a + fields`) of interleaved data.
template <Interp I, class T>
inline SegmentValue<T> interpolate(const T* a, T t) noexcept {
  constexpr std::size_t f = knot_fields(I);
  const T* b = a + f;
  const T y0 = a[0], y1 = b[0], d = y1 - y0;
  if constexpr (I == Interp::kLinear) {
    return {y0 + d * t, d, T(0)};
  } else if constexpr (I == Interp::kCubic) {
    const T m0 = a[1], m1 = b[1];
    const T a2 = T(3) * d - T(2) * m0 - m1;
    const T a3 = m0 + m1 - T(2) * d;
    return {y0 + t * (m0 + t * (a2 + t * a3)), m0 + t * (T(2) * a2 + t * (T(3) * a3)),
            T(2) * a2 + T(6) * a3 * t};
  } else {
    const T m0 = a[1], m1 = b[1], c0 = a[2], c1 = b[2];
    const T a2 = T(0.5) * c0;
    const T a3 = T(10) * d - T(6) * m0 - T(4) * m1 - T(0.5) * (T(3) * c0 - c1);
    const T a4 = T(-15) * d + T(8) * m0 + T(7) * m1 + T(0.5) * (T(3) * c0 - T(2) * c1);
    const T a5 = T(6) * d - T(3) * (m0 + m1) - T(0.5) * (c0 - c1);
    const T p = y0 + t * (m0 + t * (a2 + t * (a3 + t * (a4 + t * a5))));
    const T dp = m0 + t * (T(2) * a2 + t * (T(3) * a3 + t * (T(4) * a4 + t * (T(5) * a5))));
    const T ddp = T(2) * a2 + t * (T(6) * a3 + t * (T(12) * a4 + t * (T(20) * a5)));
    return {p, dp, ddp};
  }
}

}  // namespace loom::motion

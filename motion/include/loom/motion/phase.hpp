// Phase of a turning axis as integer fixed point: whole turns plus a 64-bit fraction of a turn
// (1 unit = 2^-64 turn ≈ 3.4e-19 rad). Advancing by a fixed step is exact integer addition, so a
// constant-speed phase after N ticks is exactly N steps — no floating-point drift however long the
// loom runs — and the fraction indexes a phase table with one multiply and no wrap test.
#pragma once

#include <compare>
#include <cstdint>

namespace loom::motion {

struct Phase {
  std::int64_t turns = 0;  // whole turns (a phase before the origin has turns < 0)
  std::uint64_t frac = 0;  // fraction of a turn in units of 2^-64 turn, always in [0, 2^64)

  static constexpr double kUnitsPerTurn = 18446744073709551616.0;  // 2^64
  static constexpr double kTurnsPerUnit = 0x1p-64;

  // RT-safe. Exact addition with carry from the fraction into the turns.
  constexpr Phase& operator+=(const Phase& d) noexcept {
    const std::uint64_t f = frac + d.frac;
    turns += d.turns + static_cast<std::int64_t>(f < frac);
    frac = f;
    return *this;
  }
  friend constexpr Phase operator+(Phase a, const Phase& b) noexcept { return a += b; }
  // RT-safe. Exact negation: -(T + f) = (-T - 1) + (1 - f) when f ≠ 0.
  constexpr Phase operator-() const noexcept {
    return {-turns - static_cast<std::int64_t>(frac != 0), std::uint64_t{0} - frac};
  }
  friend constexpr Phase operator-(Phase a, const Phase& b) noexcept { return a += -b; }
  friend constexpr bool operator==(const Phase&, const Phase&) = default;
  friend constexpr auto operator<=>(const Phase&, const Phase&) = default;

  // RT-safe. This phase moved by a small finite angle, |rad| < 4π (a cam's offset from its master):
  // one multiply and an exact integer add, without the floor and rounding of from_rad (the result
  // is within four units, 1e-18 turn, of the exact sum). The offset is counted in quarter units so
  // that two whole turns either way fit an int64: whole turns are its top bits, the fraction the rest.
  Phase plus_small_rad(double rad) const noexcept {
    const auto quarters = static_cast<std::int64_t>(rad * (0.25 * kUnitsPerRad));
    return *this + Phase{quarters >> 62, static_cast<std::uint64_t>(quarters) << 2};
  }
  static constexpr double kUnitsPerRad = 18446744073709551616.0 / 6.283185307179586;  // 2^64 / 2π

  // RT-safe. n whole steps of this phase, exact (n·(T + f) with the fraction's carry), as if added
  // n times; wraps like int64 beyond 2^63 turns.
  Phase times(std::int64_t n) const noexcept;

  // RT-safe. Nearest fixed-point phase to a real one. A non-finite input gives phase 0 (a setpoint
  // must never become NaN); beyond ±2^62 turns the value saturates.
  static Phase from_turns(double turns) noexcept;
  static Phase from_rad(double rad) noexcept;

  // RT-safe. Back to real numbers; like any double, resolution degrades as |turns| grows.
  double to_turns() const noexcept;
  double to_rad() const noexcept;
  // RT-safe. The fraction as a real in [0, 1] (from its top 63 bits: branch-free on x86-64).
  double frac_turns() const noexcept {
    return static_cast<double>(static_cast<std::int64_t>(frac >> 1)) * 0x1p-63;
  }
  double frac_rad() const noexcept;  // [0, 2π]
};

// Configure-time only. The per-tick phase step nearest to `speed_rad_s` over `period_s` (a negative
// speed gives a step backwards), computed in extended precision where the platform has it: the step
// is off by at most half a unit (2^-65 turn), so a constant-speed phase stays within N·2^-65 turn of
// the exact ω·t after N ticks (10⁹ ticks: 1.7e-10 rad) — the step's rounding, never accumulation.
Phase phase_step(double speed_rad_s, double period_s);

// A constant-speed phase accumulator: the crank's master phase in a fixed-rate loop.
class PhaseClock {
 public:
  PhaseClock() = default;
  // Configure-time only.
  PhaseClock(Phase start, Phase step) : phase_(start), step_(step) {}
  // RT-safe. One tick.
  void tick() noexcept { phase_ += step_; }
  const Phase& phase() const noexcept { return phase_; }
  const Phase& step() const noexcept { return step_; }

 private:
  Phase phase_{};
  Phase step_{};
};

}  // namespace loom::motion

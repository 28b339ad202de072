// SI ↔ drive counts, the only place where counts exist. Drives report and accept 32-bit positions that
// wrap (2^20 counts/rev wraps after 2048 crank turns, about half an hour of weaving), while the HAL's
// positions are unwrapped: the unwrapper extends the wire value to 64 bits, and targets go back out as
// the low 32 bits, which the drive reads modulo 2^32 exactly as it counts.
#pragma once

#include <cstdint>

namespace loom::drivers {

// RT-safe. Nearest count; non-finite input gives 0 and out-of-range saturates (callers guard first).
std::int64_t si_to_counts(double si, double counts_per_unit) noexcept;
// RT-safe.
double counts_to_si(std::int64_t counts, double counts_per_unit) noexcept;
// RT-safe. The 32-bit value the drive sees for an unwrapped count (two's complement, modulo 2^32).
inline std::int32_t wire_counts(std::int64_t counts) noexcept {
  return static_cast<std::int32_t>(counts);
}

// Extends successive 32-bit positions to 64 bits, assuming less than 2^31 counts between samples.
class PositionUnwrapper {
 public:
  // RT-safe. Start from a known wire value (e.g. 0x6064 read at configure time).
  void reset(std::int32_t wire) noexcept {
    last_wire_ = wire;
    value_ = wire;
  }
  // RT-safe. Returns the unwrapped position after this sample.
  std::int64_t update(std::int32_t wire) noexcept {
    const auto delta =
        static_cast<std::int32_t>(static_cast<std::uint32_t>(wire) - static_cast<std::uint32_t>(last_wire_));
    last_wire_ = wire;
    value_ += delta;
    return value_;
  }
  std::int64_t value() const { return value_; }

 private:
  std::int32_t last_wire_ = 0;
  std::int64_t value_ = 0;
};

}  // namespace loom::drivers

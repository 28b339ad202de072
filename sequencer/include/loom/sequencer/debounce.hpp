// Debouncing of binary inputs (reed switches, arrival sensors, push buttons): a raw value must read the
// same for `ticks` consecutive ticks before it replaces the value in use, so one-tick contact bounce or
// EMI never reaches the row cycle. Push buttons additionally give one rising edge per press.
// Everything here is RT-safe (fixed size, no allocation).
#pragma once

#include <array>
#include <cstddef>
#include <cstring>

namespace loom::sequencer {

template <std::size_t N>
class Debouncer {
 public:
  explicit Debouncer(int ticks = 3) noexcept : ticks_(ticks < 1 ? 1 : ticks) {}

  // RT-safe. The first update adopts the raw values as they are (there is no history to filter with).
  void update(const std::array<bool, N>& raw) noexcept {
    // Almost every tick: every input reads what is in use and none is changing. Nothing to do.
    if (primed_ && !changing_ && std::memcmp(raw.data(), value_.data(), N) == 0) return;
    changing_ = false;
    for (std::size_t i = 0; i < N; ++i) {
      if (!primed_ || raw[i] == value_[i]) {
        value_[i] = raw[i];
        disagree_[i] = 0;
      } else if (++disagree_[i] >= ticks_) {
        value_[i] = raw[i];
        disagree_[i] = 0;
      }
      changing_ = changing_ || disagree_[i] != 0;
    }
    primed_ = true;
  }
  bool operator[](std::size_t i) const noexcept { return value_[i]; }
  const std::array<bool, N>& values() const noexcept { return value_; }

 private:
  int ticks_;
  bool primed_ = false;
  bool changing_ = false;  // some disagree_[i] != 0
  std::array<bool, N> value_{};
  std::array<int, N> disagree_{};
};

// One request per press: true on the tick a debounced button goes from released to pressed. A button
// already held when the machine starts is not a press (a jammed button must not start the loom).
class RisingEdge {
 public:
  bool update(bool pressed) noexcept {  // RT-safe
    const bool edge = primed_ && pressed && !last_;
    last_ = pressed;
    primed_ = true;
    return edge;
  }

 private:
  bool last_ = false;
  bool primed_ = false;
};

}  // namespace loom::sequencer

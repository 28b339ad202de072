// Two-channel safety sensors with discrepancy monitoring (the ISO 13849-1 category 3 pattern).
//
// A single switch cannot be told from the thing it watches when two faults meet: a shuttle that slipped
// off its carrier while the arrival switch sticks on just as the carrier arrives, or a piston that seized
// mid-stroke while its end switch sticks on in the window where the stroke would have ended. No timing
// or plausibility check sees either — the picture is the normal one. Where the machine has a second,
// independent switch at the same place (io.<sensor>_2_bit), the sequencer acts on a sensor only while
// BOTH channels say "on", and two channels that disagree for longer than the discrepancy time are a
// fault naming the sensor. One stuck channel then delays nothing that is safe and confirms nothing
// that did not happen.
//
// Each channel is debounced on its own before the two are compared, so a one-tick bounce on one
// channel is not a discrepancy; the discrepancy time covers the switching-point spread of two real
// switches (they never switch on the same millisecond). RT-safe: fixed size, no allocation.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "loom/hal/types.hpp"

namespace loom::sequencer {

class DualChannelSensors {
 public:
  using Channels = std::array<bool, hal::kSafetySensorCount>;

  DualChannelSensors() noexcept = default;
  // `wired`: which sensors have a second channel. `discrepancy_ticks` ≥ 1.
  DualChannelSensors(const Channels& wired, int discrepancy_ticks) noexcept
      : wired_(wired), wired_bits_(bits(wired)), limit_(discrepancy_ticks < 1 ? 1 : discrepancy_ticks) {}

  // What the sequencer acts on: where a second channel is wired, a sensor is on only while both
  // channels are on; elsewhere the first channel alone. (Per sensor: first && (!wired || second),
  // computed on all six at once.)
  Channels agreed(const Channels& first, const Channels& second) const noexcept {
    return channels(bits(first) & (bits(second) | (~wired_bits_ & kOnes)));
  }

  // RT-safe; once per tick with both channels debounced. Counts how long each pair has disagreed.
  void track(const Channels& first, const Channels& second) noexcept {
    // Almost every tick: the wired pairs agree and none was disagreeing. Every count stays 0.
    if (!counting_ && ((bits(first) ^ bits(second)) & wired_bits_) == 0) return;
    counting_ = false;
    discrepant_ = -1;
    for (std::size_t i = 0; i < first.size(); ++i) {
      disagree_[i] = wired_[i] && first[i] != second[i] ? disagree_[i] + (disagree_[i] < limit_) : 0;
      counting_ = counting_ || disagree_[i] != 0;
      if (discrepant_ < 0 && disagree_[i] >= limit_) discrepant_ = static_cast<int>(i);
    }
  }

  // The first sensor whose channels have disagreed for longer than the discrepancy time, or −1.
  int discrepant() const noexcept { return discrepant_; }

 private:
  // The six channels as the bytes of one word (a bool is one byte, 0 or 1), so the per-sensor logic
  // is three word operations instead of a loop of branches.
  static_assert(sizeof(bool) == 1 && hal::kSafetySensorCount <= sizeof(std::uint64_t));
  // A 1 in each sensor's byte (in memory order, so whatever the byte order).
  static constexpr std::uint64_t kOnes = [] {
    std::array<unsigned char, sizeof(std::uint64_t)> b{};
    for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i) b[i] = 1;
    return std::bit_cast<std::uint64_t>(b);
  }();
  static std::uint64_t bits(const Channels& c) noexcept {
    std::uint64_t b = 0;
    std::memcpy(&b, c.data(), c.size());
    return b;
  }
  static Channels channels(std::uint64_t b) noexcept {
    Channels c;
    std::memcpy(c.data(), &b, c.size());
    return c;
  }

  Channels wired_{};
  std::uint64_t wired_bits_ = 0;
  int limit_ = 1;
  std::array<int, hal::kSafetySensorCount> disagree_{};
  bool counting_ = false;  // some disagree_[i] != 0
  int discrepant_ = -1;    // what discrepant() returns: kept by track()
};

}  // namespace loom::sequencer

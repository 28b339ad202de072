// Which channels a snapshot goes out on: each channel is decimated to one message every n ticks, but
// STATUS also goes out whenever the state, a production counter or the first fault changes, so a
// technician never misses a row or a fault however coarse the heartbeat is.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "loom/hal/types.hpp"
#include "loom/telemetry/snapshot.hpp"

namespace loom::telemetry {

struct Decimation {
  // Defaults suit the 2 ms CAN cycle: STATUS heartbeat 10 Hz, AXES 50 Hz, RT 1 Hz.
  std::int64_t status_every_n_ticks = 50;
  std::int64_t axes_every_n_ticks = 10;
  std::int64_t rt_every_n_ticks = 500;
};

// Configure-time only. "" when every interval is >= 1, else a one-line reason naming the field.
std::string decimation_error(const Decimation& d);

struct ChannelSet {
  bool status = false;
  bool axes = false;
  bool rt = false;
};

class ChannelSchedule {
 public:
  // Configure-time only. `d` must have passed decimation_error().
  explicit ChannelSchedule(const Decimation& d) noexcept : d_(d) {}

  // RT-safe (pure bookkeeping; called on the publisher thread). Decides for snapshots in tick order.
  // A channel is due on its first snapshot, once its interval has elapsed since it was last due, and
  // and again on every channel when the tick does not increase (the loop was restarted). Intervals are
  // measured in ticks, not snapshots, so dropped snapshots do not stretch them.
  ChannelSet decide(const Snapshot& s) noexcept;

 private:
  // The part of a snapshot whose every change must reach STATUS subscribers.
  struct StatusKey {
    std::uint8_t state = 0;
    std::uint8_t first_fault = 0;
    std::uint16_t first_fault_code = 0;
    std::uint32_t row = 0;
    std::uint32_t pick = 0;
    std::uint32_t beat = 0;
    // Knotting heads: a new knot cycle, one done, or a weaver request opened or answered (STATUS carries
    // KNOTS, so the panel follows the row knot by knot).
    std::int16_t knot_cycle = -1;
    std::uint16_t knot_cycles_done = 0;
    std::uint8_t knot_ask = 0;
    std::uint32_t knot_requests = 0;
    bool operator==(const StatusKey&) const = default;
  };
  static StatusKey key_of(const Snapshot& s) noexcept;
  static bool due(hal::Tick now, hal::Tick& last, std::int64_t every) noexcept;
  void restart() noexcept;

  Decimation d_;
  hal::Tick prev_tick_ = hal::kNeverTick;  // tick of the previous snapshot, due or not
  hal::Tick last_status_ = hal::kNeverTick;
  hal::Tick last_axes_ = hal::kNeverTick;
  hal::Tick last_rt_ = hal::kNeverTick;
  StatusKey last_key_{};
};

}  // namespace loom::telemetry

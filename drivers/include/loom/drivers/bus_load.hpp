// Bus-load arithmetic for classic CAN 2.0A: bits per frame (nominal and with worst-case bit stuffing),
// bits per cycle and utilisation at a bitrate and cycle period, and the configure-time refusal of a
// cycle whose worst case exceeds the budget. Formula: Davis, Burns, Bril, Lukkien 2007 (CAN schedulability
// analysis).
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "loom/drivers/status.hpp"

namespace loom::drivers {

// Bits on the wire for one data frame with `data_bytes` (0..8), including the 3-bit interframe space.
// Nominal: 44 + 8s + 3. Worst case adds ⌊(34 + 8s − 1)/4⌋ stuff bits (Davis et al. 2007). RT-safe.
constexpr std::uint32_t frame_bits_nominal(std::uint32_t data_bytes) {
  return 44 + 8 * data_bytes + 3;
}
constexpr std::uint32_t frame_bits_worst(std::uint32_t data_bytes) {
  return 44 + 8 * data_bytes + (34 + 8 * data_bytes - 1) / 4 + 3;
}

// `count` frames of `data_bytes` each, per cycle.
struct FrameGroup {
  std::uint32_t data_bytes = 0;
  std::uint32_t count = 0;
};

struct BusLoad {
  std::uint32_t frames = 0;
  std::uint32_t bits_nominal = 0;  // per cycle
  std::uint32_t bits_worst = 0;    // per cycle
  std::uint32_t bitrate_bps = 0;
  double period_s = 0.0;
  double utilisation_nominal = 0.0;  // fraction of the bus (1.0 = 100 %)
  double utilisation_worst = 0.0;
};

// RT-safe (pure, no allocation). Frames and bits of one cycle, utilisation = bits / (bitrate · period).
BusLoad compute_bus_load(std::span<const FrameGroup> frames, std::uint32_t bitrate_bps, double period_s);

// RT-safe (pure). The servo cycle of CanAxisPort: SYNC + per axis RPDO1 (6 B) + TPDO1 (6 B) [+ TPDO2 (6 B)].
// The worst cycle counts TPDO2 even when it is sent only every n-th SYNC (all axes may fall on one SYNC).
BusLoad servo_cycle_bus_load(std::uint32_t axes, bool tpdo2, std::uint32_t bitrate_bps, double period_s);

// Configure-time only. Error naming frames, bits, bitrate, period and both percentages when the
// worst-case utilisation exceeds `budget` (a fraction, e.g. 0.70).
Status check_bus_load(const BusLoad& load, double budget);

// Configure-time only. One line for logs: "7 frames/cycle, 617 nominal / 745 worst-case bits per 2 ms
// at 1000 kbit/s = 30.9 % / 37.3 %".
std::string describe_bus_load(const BusLoad& load);

}  // namespace loom::drivers

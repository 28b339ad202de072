// Bus-load arithmetic for classic CAN 2.0A: bits per frame (nominal and with worst-case bit stuffing),
// the worst cycle's bits and utilisation at a bitrate and cycle period, and the configure-time refusal of
// a cycle whose worst case exceeds the budget. Frame lengths and the response-time argument the terms of
// a cycle follow: Davis, Burns, Bril, Lukkien 2007 (Controller Area Network (CAN) schedulability analysis:
// refuted, revisited and revised). The bits are integers, so the published tables are reproduced exactly.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "loom/drivers/status.hpp"

namespace loom::drivers {

// Bits on the wire for one data frame with `data_bytes` (0..8), including the 3-bit interframe space.
// Nominal: 44 + 8s + 3. Worst case adds ⌊(34 + 8s − 1)/4⌋ stuff bits (Davis et al. 2007). RT-safe.
constexpr std::uint32_t frame_bits_nominal(std::uint32_t data_bytes) noexcept {
  return 44 + 8 * data_bytes + 3;
}
constexpr std::uint32_t frame_bits_worst(std::uint32_t data_bytes) noexcept {
  return 44 + 8 * data_bytes + (34 + 8 * data_bytes - 1) / 4 + 3;
}

// The largest classic frame (8 data bytes): every SDO request and response, and every EMCY.
inline constexpr std::uint32_t kMaxFrameBytes = 8;
inline constexpr std::uint32_t kEmcyBytes = 8;       // CiA 301: error code, error register, 5 bytes
inline constexpr std::uint32_t kHeartbeatBytes = 1;  // CiA 301: the NMT state

// `count` frames of `data_bytes` each, per cycle.
struct FrameGroup {
  std::uint32_t data_bytes = 0;
  std::uint32_t count = 0;
};

// `count` frames of `data_bytes` each, each sent at most once per `min_interval_s` (a heartbeat's producer
// time, an event-driven PDO's inhibit time): counted in a cycle at their rate, bits × period / interval.
struct RateGroup {
  std::uint32_t data_bytes = 0;
  std::uint32_t count = 0;
  double min_interval_s = 0.0;
};

// Everything that competes for one bus in one cycle of `period_s` (compute_cycle_load()).
struct CycleTraffic {
  // Sent every cycle (or possibly all in the worst one): SYNC, cyclic PDOs, the I/O modules' PDOs, the
  // master's heartbeat.
  std::span<const FrameGroup> synchronous{};
  // The nodes' own heartbeats (0x700 + node, the lowest priority on the bus).
  std::span<const RateGroup> heartbeats{};
  // Event-driven PDOs (profile-position axes), at their fastest rate.
  std::span<const RateGroup> events{};
  // Non-preemptive bus: one lower-priority frame of the largest size already on the wire when the cycle
  // starts delays all of it.
  bool blocking = false;
  // EMCY frames (0x080 + node: above every PDO) reserved per cycle.
  std::uint32_t emcy_headroom = 0;
};

struct BusLoad {
  std::uint32_t frames = 0;        // synchronous frames per cycle
  std::uint32_t bits_nominal = 0;  // per cycle, every term below
  std::uint32_t bits_worst = 0;    // per cycle, every term below
  // The worst-case bits of each term beyond the synchronous frames (0: not counted).
  std::uint32_t synchronous_bits_worst = 0;
  std::uint32_t blocking_bits_worst = 0;
  std::uint32_t emcy_frames = 0;
  std::uint32_t emcy_bits_worst = 0;
  std::uint32_t heartbeats = 0;  // nodes whose heartbeat is counted at its rate
  std::uint32_t heartbeat_bits_worst = 0;
  std::uint32_t event_pdos = 0;  // event-driven PDOs counted at their fastest rate
  std::uint32_t event_bits_worst = 0;
  std::uint32_t bitrate_bps = 0;
  double period_s = 0.0;
  double utilisation_nominal = 0.0;  // fraction of the bus (1.0 = 100 %)
  double utilisation_worst = 0.0;
};

// RT-safe (pure, no allocation). Synchronous frames only: frames and bits of one cycle, utilisation =
// bits / (bitrate · period). The published tables' rows.
BusLoad compute_bus_load(std::span<const FrameGroup> frames, std::uint32_t bitrate_bps, double period_s);

// RT-safe (pure, no allocation). The bus time one cycle must hold in the worst case (see bus_load.cpp for
// why each term is counted as it is): the synchronous frames, the blocking frame, the EMCY headroom, and
// the heartbeats and event-driven PDOs at their rate over the cycle (bits × period / interval, rounded up
// to a whole bit per group). Intervals and the period are taken in whole microseconds.
BusLoad compute_cycle_load(const CycleTraffic& traffic, std::uint32_t bitrate_bps, double period_s);

// Configure-time only. Error naming frames, bits, bitrate, period and both percentages when the
// worst-case utilisation exceeds `budget` (a fraction, e.g. 0.70).
Status check_bus_load(const BusLoad& load, double budget);

// Configure-time only. One line for logs: "8 frames/cycle incl. blocking, EMCY headroom, 4 heartbeats:
// 911 nominal / 1315 worst-case bits per 2 ms at 1000 kbit/s = 45.5 % / 65.8 %" (the terms named only
// when counted).
std::string describe_bus_load(const BusLoad& load);

// Configure-time only. The worst-case bits term by term: "worst-case bits: 9 cyclic frames 1030, blocking
// 135, EMCY 1 × 135, 4 heartbeats 6, 2 event-driven PDOs 46".
std::string describe_bus_load_terms(const BusLoad& load);

}  // namespace loom::drivers

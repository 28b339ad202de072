// The fixed-size record the RT loop pushes once per tick into the telemetry ring. Plain data only:
// the loop fills it without allocating; the non-RT publisher turns it into LCM messages.
#pragma once

#include <array>
#include <cstdint>

#include "loom/hal/types.hpp"

namespace loom::telemetry {

struct AxisSample {
  double position = 0.0;         // SI (rad or m), measured
  double velocity = 0.0;         // SI per s, measured
  double target = 0.0;           // SI, commanded this tick
  double following_error = 0.0;  // target - position, SI
  double effort = 0.0;           // N·m or N as reported
  std::uint8_t drive_state = 0;  // hal::DriveState
  std::uint8_t request = 0;      // hal::AxisRequest
};

struct Snapshot {
  hal::Tick tick = 0;
  std::int64_t period_ns = 0;
  std::array<char, 24> state{};        // sequencer state name, NUL-terminated
  std::array<char, 32> first_fault{};  // latched first-fault name, "" when none
  std::uint16_t first_fault_code = 0;
  std::uint32_t row = 0;               // production counters (completed rows, picks, beats)
  std::uint32_t pick = 0;
  std::uint32_t beat = 0;
  double crank_phase_rad = 0.0;        // beat-up crank phase within the turn [0, 2π)
  double beater_angle_rad = 0.0;       // rocker angle from the profile
  double beat_force_n = 0.0;           // last measured/simulated beat force (0 when unknown)
  std::array<AxisSample, hal::kAxisCount> axes{};
  std::uint8_t outputs = 0;            // bit0 piston A extend, bit1 piston B extend
  std::uint8_t inputs = 0;             // bit0 A ext, 1 A ret, 2 B ext, 3 B ret, 4 shuttle L, 5 shuttle R, 6 estop ok
  std::uint32_t overruns = 0;          // RT loop overruns so far
  std::int64_t tick_cost_ns = 0;       // this tick's compute time (0 in virtual time if not measured)
  std::int64_t max_tick_cost_ns = 0;
  std::uint32_t telemetry_dropped = 0; // snapshots dropped because the ring was full
};

}  // namespace loom::telemetry

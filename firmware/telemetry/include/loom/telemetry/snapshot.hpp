// The fixed-size record the RT loop pushes once per tick into the telemetry ring. Plain data only:
// the loop fills it without allocating; the non-RT publisher turns it into LCM messages.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "loom/hal/types.hpp"

namespace loom::telemetry {

struct AxisSample {
  double position = 0.0;               // SI (rad or m), measured
  double velocity = 0.0;               // SI per s, measured
  double target = 0.0;                 // SI, commanded this tick
  double following_error = 0.0;        // target - position, SI
  double effort = 0.0;                 // N·m or N as reported
  double following_error_limit = 0.0;  // SI; 0 = not checked by the loop (the drive checks its own)
  std::uint16_t fault_code = 0;        // the drive's last EMCY / error code
  std::uint8_t drive_state = 0;        // hal::DriveState
  std::uint8_t request = 0;            // hal::AxisRequest
};

// Magazine slots a head can have (sequencer::kMaxMagazineSlots; telemetry does not include the sequencer
// in its public headers, so the bound is restated and checked where both are seen: control_loop.cpp).
inline constexpr std::size_t kMaxKnotSlots = 16;

// The knotting heads' progress (looms with knotting.mode = "heads"; heads = 0 otherwise, and then nothing
// else here is read). Numbers only: the publisher turns knots into colours with the machine's KnotProgram.
struct KnotSample {
  std::uint8_t heads = 0;            // stock[0 .. heads) is in use
  std::uint8_t slots = 0;            // stock[h][0 .. slots) is in use
  bool knotting = false;             // the sequencer is in its knotting state
  std::int16_t cycle = -1;           // knot cycle in progress (0-based), -1 when not knotting
  std::uint16_t cycles_started = 0;  // of the row in progress
  std::uint16_t cycles_done = 0;
  std::uint32_t tied = 0, retried = 0, by_hand = 0;              // production totals
  std::uint16_t row_tied = 0, row_retried = 0, row_by_hand = 0;  // the row in progress
  std::uint32_t requests = 0;                                    // weaver requests made so far
  std::uint8_t ask = 0;  // sequencer::WeaverAsk of the open request (0 = none)
  std::int16_t ask_knot = -1, ask_head = -1, ask_slot = -1;
  std::uint32_t ask_row = 0;  // its 1-based production row
  std::array<std::array<std::int32_t, kMaxKnotSlots>, hal::kMaxKnottingHeads>
      stock{};  // knots left, -1 unknown
};

// The sequencer's state and faults travel as its enums (telemetry does not include the sequencer in its
// public headers: bytes); the publisher names them (encode.cpp), the text edge.
struct Snapshot {
  hal::Tick tick = 0;
  std::int64_t period_ns = 0;
  std::uint8_t state = 0;        // sequencer::State
  std::uint8_t first_fault = 0;  // sequencer::Fault of the latched first fault, 0 (kNone) when none
  std::uint8_t stopped_by = 0;   // sequencer::Fault that stopped motion, 0 when none
  std::uint16_t first_fault_code = 0;
  std::uint32_t row = 0;  // production counters (completed rows, picks, beats)
  std::uint32_t pick = 0;
  std::uint32_t beat = 0;
  std::uint32_t row_in_progress = 0;  // 1-based row being woven (the last row once done)
  std::uint32_t rows_target = 0;      // rows this run weaves up to (0 = unknown / until stopped)
  std::uint16_t beats_per_row = 0;
  std::int8_t fault_axis = -1;          // axis of the first fault, -1 when none / not axis-specific
  std::int8_t fault_sensor = -1;        // hal::SafetySensor the first fault names, -1 when none
  std::uint16_t fault_device_code = 0;  // device (EMCY) code of the first fault
  hal::Tick fault_tick = hal::kNeverTick;
  double crank_phase_rad = 0.0;   // beat-up crank phase within the turn [0, 2π)
  double beater_angle_rad = 0.0;  // rocker angle from the profile
  double beat_force_n = 0.0;      // load-cell force at this tick (0 when not measured)
  bool beat_force_valid = false;
  std::uint8_t axis_count = 0;  // the machine's axes: axes[0 .. axis_count)
  std::array<AxisSample, hal::kMaxAxes> axes{};
  std::uint8_t outputs = 0;    // bit0 piston A extend, bit1 piston B extend
  std::uint8_t inputs = 0;     // bit0 A ext, 1 A ret, 2 B ext, 3 B ret, 4 shuttle L, 5 shuttle R, 6 estop ok
  std::uint8_t inputs_2 = 0;   // second switches of the safety sensors, same bits 0..5 (0 where none)
  std::uint32_t overruns = 0;  // RT loop overruns so far
  std::int64_t tick_cost_ns = 0;  // this tick's compute time (0 in virtual time if not measured)
  std::int64_t max_tick_cost_ns = 0;
  std::int64_t wake_latency_p50_ns = 0;  // wake-up latency figures from the runner (0 = not measured)
  std::int64_t wake_latency_p99_ns = 0;
  std::int64_t wake_latency_max_ns = 0;
  std::uint32_t telemetry_dropped = 0;  // snapshots dropped because the ring was full
  std::uint32_t can_tx_dropped = 0;     // link counters from the HAL (cumulative)
  std::uint32_t can_rx_errors = 0;
  KnotSample knots;  // last: its magazines are copied for the heads in use only
};

// Copies the part of a snapshot that is in use into a ring slot: everything but the axis slots at and
// beyond axis_count and the magazine rows at and beyond knots.heads, which nobody reads (the publisher
// encodes axes[0 .. axis_count) and stock[0 .. heads)). The record is sized for hal::kMaxAxes (32 axes,
// ~2 KB) and 12 heads of 16 slots (768 bytes); a three-axis loom without heads uses 168 bytes of its axes
// and none of the magazines. RT-safe.
inline void copy_in_use(Snapshot& to, const Snapshot& from) noexcept {
  constexpr std::size_t head = offsetof(Snapshot, axes);
  constexpr std::size_t tail = offsetof(Snapshot, outputs);
  constexpr std::size_t stock = offsetof(Snapshot, knots) + offsetof(KnotSample, stock);
  // The head and the axes in use are contiguous: one copy (a library memcpy call costs about as much as
  // a loop over three axes).
  const std::size_t n = from.axis_count < hal::kMaxAxes ? from.axis_count : hal::kMaxAxes;
  std::memcpy(static_cast<void*>(&to), &from, head + n * sizeof(AxisSample));
  std::memcpy(reinterpret_cast<unsigned char*>(&to) + tail,
              reinterpret_cast<const unsigned char*>(&from) + tail, stock - tail);
  const std::size_t h = from.knots.heads < hal::kMaxKnottingHeads ? from.knots.heads : hal::kMaxKnottingHeads;
  for (std::size_t i = 0; i < h; ++i) to.knots.stock[i] = from.knots.stock[i];
}

static_assert(std::is_standard_layout_v<Snapshot> && std::is_trivially_copyable_v<Snapshot>,
              "copy_in_use copies a snapshot by its layout");

// An event the loop reports once, never decimated (BEAT, FAULT, ROW, WEAVER). One plain struct for all kinds
// so one ring carries them in order; `kind` says which part is meaningful.
struct Event {
  enum class Kind : std::uint8_t { kBeat, kFault, kRow, kWeaver };
  Kind kind = Kind::kBeat;
  hal::Tick tick = 0;
  std::int64_t period_ns = 0;
  std::uint32_t row = 0;        // 1-based row the event belongs to
  std::uint32_t rows_done = 0;  // production counters at the event
  std::uint32_t pick = 0;
  std::uint32_t beat = 0;
  std::uint16_t beats_per_row = 0;
  double band_min_n = 0.0, band_max_n = 0.0;  // beat-force target band
  // kBeat
  std::uint16_t beat_index = 0;
  float x_m = 0.0f;
  float peak_force_n = 0.0f;
  bool force_measured = false;
  bool in_band = false;
  // kFault
  enum class FaultKind : std::uint8_t { kFirst, kDiagnosis, kDevice };
  FaultKind fault_kind = FaultKind::kFirst;
  std::uint8_t fault = 0;   // sequencer::Fault value
  std::int8_t axis = -1;    // -1 when not axis-specific
  std::int8_t sensor = -1;  // hal::SafetySensor the fault names, -1 when none
  std::uint16_t device_code = 0;
  std::uint8_t state = 0;  // sequencer::State just before the fault
  // kRow
  hal::Tick row_ticks = 0, shed_ticks = 0, pick_ticks = 0, beat_ticks = 0;
  hal::Tick knotting_ticks = 0;  // knotting mode: the weaver's time before the row
  std::uint16_t beats = 0, carriage_steps = 0, beats_in_band = 0;
  double force_min_n = 0.0, force_mean_n = 0.0, force_max_n = 0.0;
  hal::Tick knot_ticks = 0, weaver_ticks = 0;  // knotting heads: machine knotting, waiting for the weaver
  std::uint16_t knots_tied = 0, knots_retried = 0, knots_by_hand = 0;
  // kWeaver (the row is `row`): what the loom asks of the weaver; the publisher words it
  std::uint8_t ask = 0;         // sequencer::WeaverAsk
  std::uint32_t request = 0;    // requests made so far, this one included
  std::int32_t design_row = 0;  // 0-based
  std::int16_t knot = -1, head = -1, slot = -1;
};

}  // namespace loom::telemetry

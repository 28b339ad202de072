// CiA 402 power-state machine, master side: statusword → hal::DriveState, and the per-tick step that
// picks the next controlword from the *confirmed* drive state and the sequencer's request. It never
// sends a blind sequence and never waits: a transition not confirmed within a number of ticks latches a
// timeout the port reports as a fault. Pure functions, so every transition is unit-testable.
#pragma once

#include <cstdint>
#include <optional>

#include "loom/hal/types.hpp"

namespace loom::drivers {

namespace controlword {
inline constexpr std::uint16_t kDisableVoltage = 0x0000;   // transitions 7, 9, 10, 12
inline constexpr std::uint16_t kQuickStop = 0x0002;        // 7, 10, 11
inline constexpr std::uint16_t kShutdown = 0x0006;         // 2, 6, 8
inline constexpr std::uint16_t kSwitchOn = 0x0007;         // 3 (also "disable operation", 5)
inline constexpr std::uint16_t kEnableOperation = 0x000F;  // 4, 16
inline constexpr std::uint16_t kFaultReset = 0x0080;       // 15, acts on the rising edge of bit 7
inline constexpr std::uint16_t kFaultResetBit = 0x0080;
inline constexpr std::uint16_t kHomingStart = 0x0010;  // bit 4 in homing mode: start (rising edge) / run
// Profile position: bit 4 "new set-point" (the drive latches the target on its rising edge), bit 5
// "change set immediately" (the new set-point replaces a move in progress instead of queueing).
inline constexpr std::uint16_t kNewSetpoint = 0x0010;
inline constexpr std::uint16_t kChangeImmediately = 0x0020;
}  // namespace controlword

namespace statusword {
inline constexpr std::uint16_t kVoltageEnabled = 1U << 4;
inline constexpr std::uint16_t kQuickStopOff = 1U << 5;  // 1 = not quick-stopping
inline constexpr std::uint16_t kWarning = 1U << 7;
inline constexpr std::uint16_t kRemote = 1U << 9;
inline constexpr std::uint16_t kTargetReached = 1U << 10;
inline constexpr std::uint16_t kCspFollowsTarget = 1U << 12;
inline constexpr std::uint16_t kCspFollowingError = 1U << 13;
inline constexpr std::uint16_t kSetpointAcknowledge = 1U << 12;  // in profile position mode (1)
inline constexpr std::uint16_t kHomingAttained = 1U << 12;       // in homing mode (6)
inline constexpr std::uint16_t kHomingError = 1U << 13;          // in homing mode (6)
}  // namespace statusword

// RT-safe. kUnknown for bit patterns that match no state.
hal::DriveState decode_statusword(std::uint16_t statusword) noexcept;

// Bookkeeping carried from one tick to the next (one per axis).
struct Cia402Tracker {
  hal::DriveState last_state = hal::DriveState::kUnknown;
  hal::AxisRequest last_request = hal::AxisRequest::kDisable;
  std::uint16_t last_controlword = controlword::kDisableVoltage;
  std::uint32_t ticks_waiting = 0;  // ticks a commanded transition has gone unconfirmed
  bool reset_sent = false;          // fault reset edge already issued for the current request
  bool timed_out = false;           // latched until the next rising edge of a kFaultReset request
};

struct Cia402Step {
  std::uint16_t controlword = controlword::kDisableVoltage;
  bool awaiting_transition = false;  // the controlword asks the drive to change state
  Cia402Tracker next;
};

// RT-safe, pure. One tick of the master's state machine.
//   state          confirmed state from the latest statusword (kUnknown before the first one)
//   request        what the sequencer wants this tick
//   timeout_ticks  a commanded transition unconfirmed for more ticks than this latches `timed_out`
// Fault reset: bit 7 rises once per rising edge of a kFaultReset request and is held until the drive
// leaves Fault; a drive that faults again is not reset until the sequencer asks again.
Cia402Step cia402_step(hal::DriveState state, hal::AxisRequest request, const Cia402Tracker& prev,
                       std::uint32_t timeout_ticks) noexcept;

// RT-safe. True when `state` is where `request` wants the drive to rest.
bool cia402_goal_reached(hal::DriveState state, hal::AxisRequest request) noexcept;

// 0x60C2 interpolation time period: period = value · 10^index s.
struct InterpolationPeriod {
  std::uint8_t value = 0;
  std::int8_t index = 0;
};
// Configure-time only. The coarsest exact encoding (index −3 … −6), nullopt when none fits in 1..255.
std::optional<InterpolationPeriod> encode_interpolation_period(double period_s);

}  // namespace loom::drivers

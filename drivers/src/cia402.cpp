// CiA 402 master state machine (statusword masks and controlword commands from CiA 402-2 §8.1; the
// facts are summarised in CiA 402, summarised in README "Running against a CAN interface"). Each state maps
// to exactly one command per request, so the drive is led one confirmed transition at a time.
#include "loom/drivers/cia402.hpp"

#include <cmath>

namespace loom::drivers {

using hal::AxisRequest;
using hal::DriveState;

hal::DriveState decode_statusword(std::uint16_t sw) noexcept {
  if ((sw & 0x4F) == 0x00) return DriveState::kNotReadyToSwitchOn;
  if ((sw & 0x4F) == 0x40) return DriveState::kSwitchOnDisabled;
  if ((sw & 0x6F) == 0x21) return DriveState::kReadyToSwitchOn;
  if ((sw & 0x6F) == 0x23) return DriveState::kSwitchedOn;
  if ((sw & 0x6F) == 0x27) return DriveState::kOperationEnabled;
  if ((sw & 0x6F) == 0x07) return DriveState::kQuickStopActive;
  if ((sw & 0x4F) == 0x0F) return DriveState::kFaultReactionActive;
  if ((sw & 0x4F) == 0x08) return DriveState::kFault;
  return DriveState::kUnknown;
}

bool cia402_goal_reached(DriveState state, AxisRequest request) noexcept {
  switch (request) {
    case AxisRequest::kEnable:
    case AxisRequest::kHome:  // homing runs in Operation Enabled (mode 6)
      return state == DriveState::kOperationEnabled;
    case AxisRequest::kQuickStop:
      return state == DriveState::kQuickStopActive || state == DriveState::kSwitchOnDisabled;
    case AxisRequest::kDisable:
    case AxisRequest::kFaultReset:
      return state == DriveState::kSwitchOnDisabled;
  }
  return false;
}

namespace {

struct Command {
  std::uint16_t cw;
  bool awaiting;
};

// The one command that moves `state` one step toward `request` (ignoring fault-reset bookkeeping).
Command command_for(DriveState state, AxisRequest request) {
  namespace cw = controlword;
  const bool enable = request == AxisRequest::kEnable || request == AxisRequest::kHome;
  const bool quick = request == AxisRequest::kQuickStop;
  const std::uint16_t down = quick ? cw::kQuickStop : cw::kDisableVoltage;
  switch (state) {
    case DriveState::kUnknown:
    case DriveState::kNotReadyToSwitchOn:
      // The drive moves on by itself (or its first statusword is due); waiting is still supervised.
      return {down, true};
    case DriveState::kSwitchOnDisabled:
      return enable ? Command{cw::kShutdown, true} : Command{down, false};
    case DriveState::kReadyToSwitchOn:
      return enable ? Command{cw::kSwitchOn, true} : Command{down, true};
    case DriveState::kSwitchedOn:
      return enable ? Command{cw::kEnableOperation, true} : Command{down, true};
    case DriveState::kOperationEnabled:
      return enable ? Command{cw::kEnableOperation, false} : Command{down, true};
    case DriveState::kQuickStopActive:
      // Leaving quick stop goes through Switch On Disabled, so re-enabling re-seeds from the actual
      // position instead of resuming an old target (transition 16 is optional in drives anyway).
      return quick ? Command{cw::kQuickStop, false} : Command{cw::kDisableVoltage, true};
    case DriveState::kFaultReactionActive:
    case DriveState::kFault:
      return {cw::kDisableVoltage, false};
  }
  return {cw::kDisableVoltage, false};
}

}  // namespace

Cia402Step cia402_step(DriveState state, AxisRequest request, const Cia402Tracker& prev,
                       std::uint32_t timeout_ticks) noexcept {
  Cia402Step out;
  Cia402Tracker& next = out.next;
  next = prev;

  const bool reset_rising =
      request == AxisRequest::kFaultReset && prev.last_request != AxisRequest::kFaultReset;
  if (request != AxisRequest::kFaultReset) next.reset_sent = false;
  if (reset_rising) {
    next.timed_out = false;
    next.reset_sent = false;
  }
  if (state != prev.last_state || request != prev.last_request) next.ticks_waiting = 0;

  Command c = command_for(state, request);
  if (state == DriveState::kFault && request == AxisRequest::kFaultReset) {
    const bool holding = (prev.last_controlword & controlword::kFaultResetBit) != 0;
    if (!next.reset_sent || holding) {
      c = {controlword::kFaultReset, true};
      next.reset_sent = true;
    } else {
      c = {controlword::kDisableVoltage, false};  // faulted again after our reset: wait for a new request
    }
  }

  if (next.timed_out) {
    c = {request == AxisRequest::kQuickStop ? controlword::kQuickStop : controlword::kDisableVoltage, false};
  } else if (c.awaiting) {
    if (++next.ticks_waiting > timeout_ticks) {
      next.timed_out = true;
      c = {request == AxisRequest::kQuickStop ? controlword::kQuickStop : controlword::kDisableVoltage,
           false};
    }
  } else {
    next.ticks_waiting = 0;
  }

  next.last_state = state;
  next.last_request = request;
  next.last_controlword = c.cw;
  out.controlword = c.cw;
  out.awaiting_transition = c.awaiting;
  return out;
}

std::optional<InterpolationPeriod> encode_interpolation_period(double period_s) {
  if (!(period_s > 0.0) || !std::isfinite(period_s)) return std::nullopt;
  for (int index = -3; index >= -6; --index) {
    const double v = period_s * std::pow(10.0, -index);
    const double r = std::round(v);
    if (r >= 1.0 && r <= 255.0 && std::abs(v - r) <= 1e-6 * r) {
      return InterpolationPeriod{static_cast<std::uint8_t>(r), static_cast<std::int8_t>(index)};
    }
  }
  return std::nullopt;
}

}  // namespace loom::drivers

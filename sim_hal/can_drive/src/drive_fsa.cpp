// Drive-side CiA 402 state machine. Command decoding follows the controlword table of CiA 402-2:
// disable voltage = bit 1 clear; quick stop = bit 1 set, bit 2 clear; shutdown = xxxx x110;
// switch on = xxxx 0111; enable operation = xxxx 1111 (bit 7 clear for all); fault reset = bit 7 edge.
#include "loom/sim_can/drive_fsa.hpp"

namespace loom::sim_can {

using hal::DriveState;

namespace {
enum class Command { kDisableVoltage, kQuickStop, kShutdown, kSwitchOn, kEnableOperation, kNone };

Command decode(std::uint16_t cw) {
  if ((cw & 0x0002) == 0) return Command::kDisableVoltage;
  if ((cw & 0x0006) == 0x0002) return Command::kQuickStop;
  if ((cw & 0x0087) == 0x0006) return Command::kShutdown;
  if ((cw & 0x008F) == 0x0007) return Command::kSwitchOn;
  if ((cw & 0x008F) == 0x000F) return Command::kEnableOperation;
  return Command::kNone;
}
}  // namespace

DriveState drive_apply_controlword(DriveState state, std::uint16_t cw, std::uint16_t prev_cw) {
  const Command c = decode(cw);
  switch (state) {
    case DriveState::kFault:
      // Transition 15 on the rising edge of bit 7 only.
      return ((cw & 0x80) != 0 && (prev_cw & 0x80) == 0) ? DriveState::kSwitchOnDisabled : state;
    case DriveState::kSwitchOnDisabled:
      return c == Command::kShutdown ? DriveState::kReadyToSwitchOn : state;  // 2
    case DriveState::kReadyToSwitchOn:
      switch (c) {
        case Command::kSwitchOn:
          return DriveState::kSwitchedOn;  // 3
        case Command::kEnableOperation:
          return DriveState::kOperationEnabled;  // 3 + 4
        case Command::kDisableVoltage:
        case Command::kQuickStop:
          return DriveState::kSwitchOnDisabled;  // 7
        default:
          return state;
      }
    case DriveState::kSwitchedOn:
      switch (c) {
        case Command::kEnableOperation:
          return DriveState::kOperationEnabled;  // 4
        case Command::kShutdown:
          return DriveState::kReadyToSwitchOn;  // 6
        case Command::kDisableVoltage:
        case Command::kQuickStop:
          return DriveState::kSwitchOnDisabled;  // 10
        default:
          return state;
      }
    case DriveState::kOperationEnabled:
      switch (c) {
        case Command::kSwitchOn:
          return DriveState::kSwitchedOn;  // 5
        case Command::kShutdown:
          return DriveState::kReadyToSwitchOn;  // 8
        case Command::kDisableVoltage:
          return DriveState::kSwitchOnDisabled;  // 9
        case Command::kQuickStop:
          return DriveState::kQuickStopActive;  // 11
        default:
          return state;
      }
    case DriveState::kQuickStopActive:
      switch (c) {
        case Command::kDisableVoltage:
          return DriveState::kSwitchOnDisabled;  // 12
        case Command::kEnableOperation:
          return DriveState::kOperationEnabled;  // 16
        default:
          return state;
      }
    case DriveState::kUnknown:
    case DriveState::kNotReadyToSwitchOn:
    case DriveState::kFaultReactionActive:
      return state;
  }
  return state;
}

DriveState drive_settle(DriveState state) {
  switch (state) {
    case DriveState::kUnknown:
    case DriveState::kNotReadyToSwitchOn:
      return DriveState::kSwitchOnDisabled;
    case DriveState::kFaultReactionActive:
      return DriveState::kFault;
    default:
      return state;
  }
}

std::uint16_t drive_statusword(DriveState state, bool csp, bool target_reached, bool following_error) {
  std::uint16_t sw = 0;
  switch (state) {
    case DriveState::kUnknown:
    case DriveState::kNotReadyToSwitchOn:
      sw = 0x0000;
      break;
    case DriveState::kSwitchOnDisabled:
      sw = 0x0040;
      break;
    case DriveState::kReadyToSwitchOn:
      sw = 0x0031;
      break;
    case DriveState::kSwitchedOn:
      sw = 0x0033;
      break;
    case DriveState::kOperationEnabled:
      sw = 0x0037;
      break;
    case DriveState::kQuickStopActive:
      sw = 0x0017;
      break;
    case DriveState::kFaultReactionActive:
      sw = 0x001F;
      break;
    case DriveState::kFault:
      sw = 0x0008;
      break;
  }
  sw |= 1U << 9;  // remote: controlled over the bus
  if (state == DriveState::kOperationEnabled && csp) sw |= 1U << 12;
  if (target_reached) sw |= 1U << 10;
  if (following_error) sw |= 1U << 13;
  return sw;
}

}  // namespace loom::sim_can

// The drive side of the CiA 402 power-state machine: how a drive reacts to a controlword, and the
// statusword it then reports. Written from the drive's point of view (CiA 402-2 transitions 2–16),
// independently of the master's step function, so the two check each other in the tests.
#pragma once

#include <cstdint>

#include "loom/hal/types.hpp"

namespace loom::sim_can {

// RT-safe, pure. State after the drive receives `cw` (`prev_cw` is the controlword it had before, for
// the fault-reset rising edge). Automatic transitions (0, 1, 14) are not taken here; see drive_settle().
hal::DriveState drive_apply_controlword(hal::DriveState state, std::uint16_t cw, std::uint16_t prev_cw);

// RT-safe, pure. Automatic transitions: Not ready → Switch on disabled (1), Fault reaction → Fault (14).
hal::DriveState drive_settle(hal::DriveState state);

// RT-safe, pure. Statusword of `state`: state bits plus voltage-enabled (bit 4), remote (bit 9), and in
// Operation Enabled with CSP the "follows target" bit 12; `target_reached` sets bit 10.
std::uint16_t drive_statusword(hal::DriveState state, bool csp, bool target_reached, bool following_error);

}  // namespace loom::sim_can

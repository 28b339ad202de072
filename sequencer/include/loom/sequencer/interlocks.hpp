// The loom's interlocks as one pure check on a proposed tick of outputs, independent of the sequencer's
// own logic: even a sequencer bug cannot move the carriage inside the warp, pick into a closed shed or
// change the shed over the shuttle. RT-safe.
#pragma once

#include <array>
#include <cstdint>

#include "loom/hal/types.hpp"
#include "loom/motion/beatup.hpp"
#include "loom/sequencer/faults.hpp"

namespace loom::sequencer {

// True when the piston end sensors confirm an open shed (one frame up, the other down).
bool shed_confirmed(const hal::DigitalInputs& io);
// True when the shuttle sits at either selvedge (out of the shed).
bool shuttle_at_selvedge(const hal::DigitalInputs& io);

// True when each heald frame's end sensors show it at one end (none between ends, none reading both): the
// warp does not move. The knotting heads need this; it holds in either crossing and with both frames down.
bool shed_still(const hal::DigitalInputs& io);

// The knotting heads as the interlocks see them (heads = 0: none). Each knotting servo drives a one-degree-
// of-freedom linkage, so where its gripper is — inside the warp or clear of it — is a function of the
// servo's angle alone: the angles (relative to the TAKE pose) in (in_warp_from, in_warp_to) put it inside.
struct KnotGuard {
  int heads = 0;
  std::array<std::int8_t, hal::kMaxKnottingHeads> knotter{};   // axis slot of each head's knotting servo
  std::array<std::int8_t, hal::kMaxKnottingHeads> selector{};  // and of its colour selector
  double take_position_rad = 0.0;  // knotting servo reading at the TAKE pose (commissioning)
  double in_warp_from_rad = 0.0, in_warp_to_rad = 0.0;
  bool full_turn = false;  // the cycle turns the servo on by a full turn: angles wrap to [0, 2π)
};

struct InterlockContext {
  const motion::WarpWindow* warp = nullptr;
  double crank_park_position = 0.0;  // crank axis reading (rad) at the park pose
  KnotGuard knot;
};

// Measured gripper-in-warp test from a knotting servo's position (rad).
bool gripper_in_warp(const KnotGuard& g, double knotter_position);

// Returns Fault::kNone when `next` may be written after `prev` given the measured inputs.
Fault check_interlocks(const InterlockContext& ctx, const hal::HalInputs& measured,
                       const hal::HalOutputs& prev, const hal::HalOutputs& next);

// Measured beater-in-warp test from the crank axis position (rad).
bool beater_in_warp(const InterlockContext& ctx, double crank_position);

}  // namespace loom::sequencer

// The loom's interlocks as one pure check on a proposed tick of outputs, independent of the sequencer's
// own logic: even a sequencer bug cannot move the carriage inside the warp, pick into a closed shed or
// change the shed over the shuttle. RT-safe.
#pragma once

#include "loom/hal/types.hpp"
#include "loom/motion/beatup.hpp"
#include "loom/sequencer/faults.hpp"

namespace loom::sequencer {

// True when the piston end sensors confirm an open shed (one frame up, the other down).
bool shed_confirmed(const hal::DigitalInputs& io);
// True when the shuttle sits at either selvedge (out of the shed).
bool shuttle_at_selvedge(const hal::DigitalInputs& io);

struct InterlockContext {
  const motion::WarpWindow* warp = nullptr;
  double crank_park_position = 0.0;  // crank axis reading (rad) at the park pose
};

// Returns Fault::kNone when `next` may be written after `prev` given the measured inputs.
Fault check_interlocks(const InterlockContext& ctx, const hal::HalInputs& measured, const hal::HalOutputs& prev,
                       const hal::HalOutputs& next);

// Measured beater-in-warp test from the crank axis position (rad).
bool beater_in_warp(const InterlockContext& ctx, double crank_position);

}  // namespace loom::sequencer

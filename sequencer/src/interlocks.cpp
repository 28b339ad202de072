// Interlock checks. Motion is "commanded" when a target changes between ticks; holding still is always
// allowed, so a faulted machine can always be held.
#include "loom/sequencer/interlocks.hpp"

#include <cmath>

#include "loom/motion/angles.hpp"

namespace loom::sequencer {

bool shed_confirmed(const hal::DigitalInputs& io) {
  const bool a_up = io.piston_a_extended && !io.piston_a_retracted && io.piston_b_retracted && !io.piston_b_extended;
  const bool b_up = io.piston_b_extended && !io.piston_b_retracted && io.piston_a_retracted && !io.piston_a_extended;
  return a_up || b_up;
}

bool shuttle_at_selvedge(const hal::DigitalInputs& io) { return io.shuttle_at_left || io.shuttle_at_right; }

bool beater_in_warp(const InterlockContext& ctx, double crank_position) {
  const double phase = motion::wrap_two_pi(crank_position - ctx.crank_park_position);
  return phase > ctx.warp->enter && phase < ctx.warp->exit;
}

Fault check_interlocks(const InterlockContext& ctx, const hal::HalInputs& measured, const hal::HalOutputs& prev,
                       const hal::HalOutputs& next) {
  const auto moved = [&](hal::CoreAxis a) {
    return next.axes[hal::index(a)].target_position != prev.axes[hal::index(a)].target_position;
  };
  if (moved(hal::CoreAxis::kCarriage) &&
      beater_in_warp(ctx, measured.axes[hal::index(hal::CoreAxis::kBeatCrank)].position)) {
    return Fault::kCarriageInWarp;
  }
  if (moved(hal::CoreAxis::kHelix) && !shed_confirmed(measured.io)) return Fault::kPickWithoutShed;
  const bool valves_change =
      next.io.piston_a_extend != prev.io.piston_a_extend || next.io.piston_b_extend != prev.io.piston_b_extend;
  if (valves_change && !shuttle_at_selvedge(measured.io)) return Fault::kShedWithShuttle;
  return Fault::kNone;
}

}  // namespace loom::sequencer

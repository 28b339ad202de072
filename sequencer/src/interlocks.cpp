// Interlock checks. Motion is "commanded" when a target changes between ticks; holding still is always
// allowed, so a faulted machine can always be held.
#include "loom/sequencer/interlocks.hpp"

#include <cmath>

#include "loom/motion/angles.hpp"

namespace loom::sequencer {

bool shed_confirmed(const hal::DigitalInputs& io) {
  const bool a_up =
      io.piston_a_extended && !io.piston_a_retracted && io.piston_b_retracted && !io.piston_b_extended;
  const bool b_up =
      io.piston_b_extended && !io.piston_b_retracted && io.piston_a_retracted && !io.piston_a_extended;
  return a_up || b_up;
}

bool shed_still(const hal::DigitalInputs& io) {
  return io.piston_a_extended != io.piston_a_retracted && io.piston_b_extended != io.piston_b_retracted;
}

bool gripper_in_warp(const KnotGuard& g, double knotter_position) {
  double rel = knotter_position - g.take_position_rad;
  if (g.full_turn) rel = motion::wrap_two_pi(rel);
  return rel > g.in_warp_from_rad && rel < g.in_warp_to_rad;
}

bool shuttle_at_selvedge(const hal::DigitalInputs& io) {
  return io.shuttle_at_left || io.shuttle_at_right;
}

bool beater_in_warp(const InterlockContext& ctx, double crank_position) {
  const double phase = motion::wrap_two_pi(crank_position - ctx.crank_park_position);
  return phase > ctx.warp->enter && phase < ctx.warp->exit;
}

namespace {
// The knotting heads' interlocks: nothing crosses a gripper in the warp (carriage, beater, heald frames),
// no knot starts unless the beater is clear and the warp still, no selector turns under a closed gripper.
Fault check_knotting(const InterlockContext& ctx, const hal::HalInputs& measured, const hal::HalOutputs& prev,
                     const hal::HalOutputs& next, bool carriage_moves, bool crank_moves, bool valves_change) {
  const KnotGuard& g = ctx.knot;
  const auto moved = [&](int slot) {
    const auto i = static_cast<std::size_t>(slot);
    return next.axes[i].target_position != prev.axes[i].target_position;
  };
  const bool clear = !beater_in_warp(ctx, measured.axes[hal::index(hal::CoreAxis::kBeatCrank)].position) &&
                     shed_still(measured.io);
  for (int h = 0; h < g.heads; ++h) {
    const auto hh = static_cast<std::size_t>(h);
    const bool inside = gripper_in_warp(g, measured.axes[static_cast<std::size_t>(g.knotter[hh])].position);
    if (inside && (carriage_moves || crank_moves || valves_change)) return Fault::kGripperInWarp;
    if (moved(g.knotter[hh]) && !clear) return Fault::kKnotNotClear;
    if (moved(g.selector[hh]) && (prev.io.gripper_close[hh] || next.io.gripper_close[hh]))
      return Fault::kSelectorWithYarn;
  }
  return Fault::kNone;
}
}  // namespace

Fault check_interlocks(const InterlockContext& ctx, const hal::HalInputs& measured,
                       const hal::HalOutputs& prev, const hal::HalOutputs& next) {
  const auto moved = [&](hal::CoreAxis a) {
    return next.axes[hal::index(a)].target_position != prev.axes[hal::index(a)].target_position;
  };
  if (moved(hal::CoreAxis::kCarriage) &&
      beater_in_warp(ctx, measured.axes[hal::index(hal::CoreAxis::kBeatCrank)].position)) {
    return Fault::kCarriageInWarp;
  }
  if (moved(hal::CoreAxis::kHelix) && !shed_confirmed(measured.io)) return Fault::kPickWithoutShed;
  const bool valves_change = next.io.piston_a_extend != prev.io.piston_a_extend ||
                             next.io.piston_b_extend != prev.io.piston_b_extend;
  if (valves_change && !shuttle_at_selvedge(measured.io)) return Fault::kShedWithShuttle;
  if (ctx.knot.heads > 0)
    return check_knotting(ctx, measured, prev, next, moved(hal::CoreAxis::kCarriage),
                          moved(hal::CoreAxis::kBeatCrank), valves_change);
  return Fault::kNone;
}

}  // namespace loom::sequencer

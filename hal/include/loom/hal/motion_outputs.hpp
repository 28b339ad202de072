// Whether one tick's outputs set something moving that the tick before left standing: the judge of "stop
// means stop" (a stopping command never leads to motion), shared by the stop table test and the safety
// campaign so both hold the loom to the same definition. Pure and allocation-free.
//
// Motion is: an enabled (or homing) axis whose target moves; an axis asked to enable or home that was not;
// a heald-frame valve that switches; a gripper that closes; a cutter that fires. Not motion: lamps and the
// buzzer, an axis asked to quick-stop or disable (its drive stops by itself), a gripper that opens.
#pragma once

#include <cmath>
#include <cstddef>

#include "loom/hal/types.hpp"

namespace loom::hal {

struct MotionChange {
  enum class What : std::uint8_t { kNone, kAxisTarget, kAxisEnabled, kValve, kGripperClosed, kCutterFired };
  What what = What::kNone;
  int index = -1;  // the axis slot or head; the valve: 0 = piston A, 1 = piston B
  explicit operator bool() const noexcept { return what != What::kNone; }
};

constexpr const char* motion_change_name(MotionChange::What w) noexcept {
  switch (w) {
    case MotionChange::What::kNone:
      return "nothing";
    case MotionChange::What::kAxisTarget:
      return "an axis target moved";
    case MotionChange::What::kAxisEnabled:
      return "an axis was asked to enable or home";
    case MotionChange::What::kValve:
      return "a heald-frame valve switched";
    case MotionChange::What::kGripperClosed:
      return "a gripper closed";
    case MotionChange::What::kCutterFired:
      return "a cutter fired";
  }
  return "?";
}

// The first motion `now` starts against `before`, over the first `axes` slots and `heads` knotting heads.
// `epsilon`: how far a target may move before it counts (SI: m or rad).
inline MotionChange motion_started(const HalOutputs& before, const HalOutputs& now, std::size_t axes,
                                   int heads, double epsilon = 1e-9) noexcept {
  const auto drives = [](AxisRequest r) { return r == AxisRequest::kEnable || r == AxisRequest::kHome; };
  for (std::size_t i = 0; i < axes && i < kMaxAxes; ++i) {
    const AxisCommand& a = before.axes[i];
    const AxisCommand& b = now.axes[i];
    if (drives(b.request) && !drives(a.request))
      return {MotionChange::What::kAxisEnabled, static_cast<int>(i)};
    if (drives(b.request) && std::abs(b.target_position - a.target_position) > epsilon) {
      return {MotionChange::What::kAxisTarget, static_cast<int>(i)};
    }
  }
  if (now.io.piston_a_extend != before.io.piston_a_extend) return {MotionChange::What::kValve, 0};
  if (now.io.piston_b_extend != before.io.piston_b_extend) return {MotionChange::What::kValve, 1};
  for (int h = 0; h < heads && h < static_cast<int>(kMaxKnottingHeads); ++h) {
    const auto k = static_cast<std::size_t>(h);
    if (now.io.gripper_close[k] && !before.io.gripper_close[k])
      return {MotionChange::What::kGripperClosed, h};
    if (now.io.cutter[k] && !before.io.cutter[k]) return {MotionChange::What::kCutterFired, h};
  }
  return {};
}

}  // namespace loom::hal

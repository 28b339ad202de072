// The simulated weaver: in simulation only, the person at the loom who does what it asks. The knotting heads'
// requests (tie a knot by hand, check one, reload a slot) go to the simulated machine's knotter, which does
// the work after the scene's weaver_s and presses the pedal; with the weaver's own knotting
// (knotting.mode = "weaver") the weaver says "row knotted" a set time after the loom starts waiting.
// weave and serve both use it (Session builds it for every simulated machine); the runner only calls it.
#pragma once

#include <cstdint>

#include "loom/sequencer/row_knotter.hpp"
#include "loom/sequencer/sequencer.hpp"
#include "loom/sim_hal/sim_world.hpp"

namespace loom::firmware {

class SimWeaver {
 public:
  // Configure-time. `sim`: the simulated machine (its knotter, if the scene names one, does the work).
  SimWeaver(sim_hal::SimWorld& sim, double period_s) noexcept : sim_(sim), period_s_(period_s) {}
  // Configure-time. With the weaver's own knotting: say "row knotted" `seconds` after each wait begins
  // (0, the default: never; someone else answers, e.g. ctl next).
  void knot_rows_after(double seconds) noexcept { row_knotting_s_ = seconds; }

  // RT-safe, once per tick before the sequencer's step.
  void on_tick(sequencer::Sequencer& seq) noexcept;
  // RT-safe. A request the knotting heads made of the weaver.
  void answer(const sequencer::WeaverRequest& r) noexcept { sim_.ask_weaver(task_for(r)); }
  // RT-safe. The operator's reload (`ctl reload`, the panel): the simulated machine gets the yarn the
  // operator says was put in.
  void reloaded(int head, int slot, std::int32_t knots) noexcept { sim_.reload_slot(head, slot, knots); }
  // The request as the simulated knotter's task.
  static sim_hal::WeaverTask task_for(const sequencer::WeaverRequest& r) noexcept;

 private:
  sim_hal::SimWorld& sim_;
  double period_s_;
  double row_knotting_s_ = 0.0;
  std::int64_t waited_ = 0;  // ticks the loom has waited for the row to be knotted
};

}  // namespace loom::firmware

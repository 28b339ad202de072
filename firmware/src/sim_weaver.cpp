// The simulated weaver (see sim_weaver.hpp).
#include "loom/firmware/sim_weaver.hpp"

namespace loom::firmware {

void SimWeaver::on_tick(sequencer::Sequencer& seq) noexcept {
  if (row_knotting_s_ <= 0.0) return;
  waited_ = seq.state() == sequencer::State::kAwaitKnotting ? waited_ + 1 : 0;
  if (static_cast<double>(waited_) * period_s_ >= row_knotting_s_) seq.request_row_knotted();
}

sim_hal::WeaverTask SimWeaver::task_for(const sequencer::WeaverRequest& r) noexcept {
  sim_hal::WeaverTask t;
  t.kind = r.ask == sequencer::WeaverAsk::kReload      ? sim_hal::WeaverTask::Kind::kReload
           : r.ask == sequencer::WeaverAsk::kCheckKnot ? sim_hal::WeaverTask::Kind::kCheckKnot
                                                       : sim_hal::WeaverTask::Kind::kTieByHand;
  t.head = r.head;
  t.knot = r.knot;
  t.slot = r.slot;
  return t;
}

}  // namespace loom::firmware

#include "loom/sequencer/operator_requests.hpp"

namespace loom::sequencer {

void make_request(Sequencer& seq, OperatorRequest r) noexcept {
  switch (r) {
    case OperatorRequest::kNone:
      break;
    case OperatorRequest::kStart:
      // Start also resumes, and cancels a pause that was asked for but not reached yet.
      seq.request_resume();
      if (seq.state() == State::kIdle) seq.request_start();
      break;
    case OperatorRequest::kPause:
      if (seq.state() != State::kIdle) seq.request_pause();
      break;
    case OperatorRequest::kAcknowledge:
      seq.request_acknowledge();
      break;
    case OperatorRequest::kRowKnotted:
      seq.request_row_knotted();
      break;
  }
}

void apply_presses(Sequencer& seq) noexcept {
  const TickEvents& ev = seq.events();
  for (const TickEvent& e : ev) {  // bounded: TickEvents::kCapacity
    if (e.kind == EventKind::kButton) make_request(seq, request_of(e.button, ev.began_in()));
  }
}

}  // namespace loom::sequencer

// What an operator's press or command asks of the sequencer: the one place that says so, whatever station it
// came from (the I/O module's buttons and pedal, the control socket, the panel). The sequencer decodes and
// debounces the buttons and reports each press as an event (TickEvents, EventKind::kButton) but never acts
// on one itself: its owner turns the presses of a step into these requests before the next step, through the
// same request_*() calls every other operator path uses. A press therefore acts in the step after the one
// that saw it (one tick after its debounce), as a command from the socket does.
#pragma once

#include <cstdint>

#include "loom/sequencer/sequencer.hpp"
#include "loom/sequencer/tick_events.hpp"

namespace loom::sequencer {

enum class OperatorRequest : std::uint8_t {
  kNone,         // the press asks nothing (an ack press with no fault latched before it)
  kStart,        // start an idle loom; also resumes, and cancels a pause not yet reached
  kPause,        // hold at the next safe point
  kAcknowledge,  // acknowledge the latched fault
  kRowKnotted,   // the weaver has knotted the row, or done what the knotting heads asked
};

// RT-safe. What a press of `b` asks for, seen in a step that began in `began_in` (TickEvents::began_in()).
// An ack press counts only when that step began with the fault already latched: one seen in the step that
// latched it (its debounced edge means it was pressed before the fault) or earlier is no acknowledgement.
constexpr OperatorRequest request_of(Button b, State began_in) noexcept {
  switch (b) {
    case Button::kStart:
      return OperatorRequest::kStart;
    case Button::kPause:
      return OperatorRequest::kPause;
    case Button::kAck:
      return began_in == State::kFault ? OperatorRequest::kAcknowledge : OperatorRequest::kNone;
    case Button::kRowKnotted:
      return OperatorRequest::kRowKnotted;
  }
  return OperatorRequest::kNone;
}

// RT-safe. Makes `r` through the sequencer's request_*() calls, judged by the state it is in now (between
// two steps). A pause while idle is nothing to hold (it would pause the next start at its first safe point);
// an acknowledgement without a latched fault is discarded by request_acknowledge() itself.
void make_request(Sequencer& seq, OperatorRequest r) noexcept;

// RT-safe. Every press of the last step as its request, for an owner with no policy of its own (the
// simulation tests, the safety campaign). The runner does the same through its commands, where the
// service decides an acknowledgement itself (it re-arms).
void apply_presses(Sequencer& seq) noexcept;

}  // namespace loom::sequencer

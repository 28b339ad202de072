#include "loom/firmware/operator_policy.hpp"

#include "loom/sequencer/operator_requests.hpp"

namespace loom::firmware {

using sequencer::State;

Decision decide(const PolicyInputs& in) noexcept {
  Decision d;
  const auto has = [&](Command c) { return (in.commands & static_cast<std::uint32_t>(c)) != 0; };
  const State s = in.state;
  const bool stopping = (in.commands & kStoppingCommands) != 0;
  if (stopping) d.overridden = in.commands & kStartingCommands;  // stopping wins over starting

  if (has(Command::kStop)) {
    // request_stop() itself leaves a done or faulted loom alone and cancels an idle loom's pending start;
    // weave's run, with nothing moved yet, ends here instead of standing idle.
    d.stop = s != State::kDone && s != State::kFault;
    if (s == State::kIdle && !in.held_session) d.end = Decision::End::kStopped;
  }
  // A pause while idle is nothing to hold (it would pause the next start at its first hold point).
  if (has(Command::kPause)) d.pause = s != State::kIdle && s != State::kDone && s != State::kFault;
  if (has(Command::kExit)) {
    d.exit_when_quiet = true;
    if (!quiet(s)) d.stop = true;
  }
  // A held session standing still ends for the service to arm again from a changed job queue. Not with
  // exit (the service is going), and a start in the same tick has its own end (re-arm, then start).
  const bool standing = s == State::kIdle || s == State::kDone;
  if (has(Command::kRearm) && in.held_session && standing && !has(Command::kExit) &&
      !(has(Command::kStart) && !stopping)) {
    d.end = Decision::End::kRearmRequested;
  }
  if (stopping) return d;

  if (has(Command::kNext)) d.row_knotted = true;
  if (has(Command::kReload)) d.reload = true;  // in any state: the level is a fact; it may answer a request
  if (has(Command::kResume)) d.resume = true;
  if (has(Command::kStart)) {
    if (in.held_session && (s == State::kDone || (s == State::kIdle && has(Command::kRearm)))) {
      d.end = Decision::End::kStartRequested;
      return d;
    }
    if (in.nothing_to_weave && s == State::kIdle) {
      d.refusal = Decision::Refusal::kStartNothingToWeave;
      return d;
    }
    d.start = true;  // also resumes, and cancels a pause not yet reached (operator_requests.hpp)
  }
  if (has(Command::kAck) && s == State::kFault) {
    if (!in.held_session) {
      d.acknowledge =
          true;  // weave: back to idle in place (refused by the sequencer while the e-stop is open)
    } else if (in.link_recovery == hal::LinkRecovery::kBusOff ||
               in.link_recovery == hal::LinkRecovery::kNodeSilent) {
      // Re-arming reconfigures the link: pointless (and the operator would think it done) while the
      // controller is still off the bus or a lost node is still silent.
      d.refusal = Decision::Refusal::kAckLinkDown;
    } else if (!in.estop_ok) {
      // The fault stays latched (re-arming would show no fault until the next start re-latched it).
      d.refusal = Decision::Refusal::kAckEStopOpen;
    } else if (in.last_save_failed) {
      // Re-arming reads the counters back from disk: while the last save failed the file lags what was
      // woven, and re-arming from it would weave those rows again. The fault stays until a save succeeds.
      d.refusal = Decision::Refusal::kAckCountersUnsaved;
    } else {
      d.end = Decision::End::kAckRequested;
    }
  }
  return d;
}

void apply(const Decision& d, sequencer::Sequencer& seq) noexcept {
  if (d.stop) seq.request_stop();
  if (d.pause) sequencer::make_request(seq, sequencer::OperatorRequest::kPause);
  if (d.resume) seq.request_resume();
  if (d.start) sequencer::make_request(seq, sequencer::OperatorRequest::kStart);
  if (d.acknowledge) sequencer::make_request(seq, sequencer::OperatorRequest::kAcknowledge);
  if (d.row_knotted) sequencer::make_request(seq, sequencer::OperatorRequest::kRowKnotted);
}

}  // namespace loom::firmware

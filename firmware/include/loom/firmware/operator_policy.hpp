// What the operator's commands of one tick do: the one place that says so, a pure function of the loop's
// state, table-tested over every state × command (tests/firmware/runner/operator_policy_test.cpp). The runner
// takes the tick's commands (the control socket's, the panel's through it, the I/O module's presses, weave's
// signals), asks decide() and applies the decision; the safety campaign does the same.
//
// Commands come in two classes (IEC 60204-1 stop categories; ISO 12100):
//   stopping  pause, stop, exit (and the second SIGINT/SIGTERM: stop now) — from anywhere; never lead to
//             motion: a stopping command only ever keeps the next motion from starting
//             (Sequencer::request_stop).
//   starting  start, resume, next (row knotted / the weaver's answer), reload, acknowledge — from where the
//             loom is seen. A starting command given in the same tick as a stopping one is dropped: stopping
//             wins.
// and one that is neither:
//   rearm     the service changed its job queue (loomctl ctl job add/remove/start-over): a held session
//             standing idle or done ends, so the service arms again from the queue. Never motion: the
//             new session waits for a start like any other; a start in the same tick is the start's.
#pragma once

#include <cstdint>

#include "loom/hal/types.hpp"
#include "loom/sequencer/sequencer.hpp"

namespace loom::firmware {

enum class Command : std::uint32_t {
  kStart =
      1u
      << 0,  // idle → weave; paused → resume; done → a new session (held: the runner returns kStartRequested)
  kPause = 1u << 1,  // hold at the next point where the loom may stand
  kResume = 1u << 2,
  kStop = 1u << 3,  // stand at the next point where the loom may stand, then done (never sets it moving)
  kAck = 1u << 4,   // acknowledge a latched fault (held session: kAckRequested, the owner re-arms)
  kExit = 1u << 5,  // leave the loop (service shutdown): a stop first when the loom is moving
  kNext = 1u << 6,  // knotting: the weaver has knotted the row, or done what the heads asked
  // knotting heads: the weaver reloaded magazine slots (OperatorLink::post_reload says which and how much);
  // answers the heads' request to reload that slot, so it is a starting command
  kReload = 1u << 7,
  // The job queue changed under a held session (serve): standing idle or done, the session ends for the
  // owner to arm again from the queue (Decision::End::kRearmRequested); in any other state nothing (the
  // armed job goes on; the next session boundary reads the queue). Never a start.
  kRearm = 1u << 8,
};

constexpr std::uint32_t kStoppingCommands = static_cast<std::uint32_t>(Command::kPause) |
                                            static_cast<std::uint32_t>(Command::kStop) |
                                            static_cast<std::uint32_t>(Command::kExit);
constexpr std::uint32_t kStartingCommands =
    static_cast<std::uint32_t>(Command::kStart) | static_cast<std::uint32_t>(Command::kResume) |
    static_cast<std::uint32_t>(Command::kNext) | static_cast<std::uint32_t>(Command::kAck) |
    static_cast<std::uint32_t>(Command::kReload);

struct PolicyInputs {
  std::uint32_t commands = 0;  // Command bits of this tick
  sequencer::State state = sequencer::State::kIdle;
  // The service's sessions: a start from done and an acknowledgement end the session for the owner to
  // re-arm (weave acknowledges in place and ends when the loom is done).
  bool held_session = false;
  bool estop_ok = true;
  hal::LinkRecovery link_recovery = hal::LinkRecovery::kHealthy;
  bool last_save_failed = false;  // the counters file lags what was woven
  // The service's carpet job queue has nothing to weave (the last job is carpet_done, none queued): a
  // start from idle is refused (the loom waits for the cut-off and the next job); from done it still ends
  // the session, so the owner re-arms and looks at the queue again.
  bool nothing_to_weave = false;
};

struct Decision {
  // The sequencer's requests, applied in this order by apply(): stop, pause, resume, start, ack, row knotted.
  bool stop = false;
  bool pause = false;
  bool resume = false;
  bool start = false;
  bool acknowledge = false;
  bool row_knotted = false;
  bool reload = false;           // take the reloads posted (the runner: OperatorLink::take_reloads)
  bool exit_when_quiet = false;  // leave the loop once nothing is moving towards a goal
  enum class End : std::uint8_t {
    kNone,
    kStopped,         // weave: a stop while idle (nothing moved): the run ends here
    kStartRequested,  // held session, done: the owner starts a new session
    kAckRequested,    // held session, faulted: the owner re-arms
    kRearmRequested,  // held session, idle or done, the job queue changed: the owner arms again, no start
  };
  End end = End::kNone;
  enum class Refusal : std::uint8_t {
    kNone,
    kAckLinkDown,          // the controller is off the bus or a lost node is still silent
    kAckEStopOpen,         // the e-stop chain is still open
    kAckCountersUnsaved,   // the last save failed: re-arming from the file would weave rows again
    kStartNothingToWeave,  // the job queue has no job to weave
  };
  Refusal refusal = Refusal::kNone;
  std::uint32_t overridden = 0;  // starting commands dropped because a stopping one came in the same tick
};

// RT-safe, pure.
Decision decide(const PolicyInputs& in) noexcept;

// RT-safe. Makes `d`'s requests of `seq`.
void apply(const Decision& d, sequencer::Sequencer& seq) noexcept;

// RT-safe. The loom is not moving towards a goal: leaving the loop here loses no row in progress.
constexpr bool quiet(sequencer::State s) noexcept {
  return s == sequencer::State::kIdle || s == sequencer::State::kPaused || s == sequencer::State::kDone ||
         s == sequencer::State::kFault;
}

}  // namespace loom::firmware

// The operator policy (firmware/include/loom/firmware/operator_policy.hpp) over every sequencer state × every
// command, alone and with every other command in the same tick: what each command asks of the sequencer, when
// the session ends, which acknowledgements are refused — and the rule the whole table keeps: a stopping
// command (pause, stop, exit) never comes with a starting request (start, resume, row knotted, reload,
// acknowledge)
// and never ends a session for a start.
#include "loom/firmware/operator_policy.hpp"

#include <gtest/gtest.h>

#include <array>
#include <string>

using namespace loom;
using firmware::Command;
using firmware::Decision;
using firmware::PolicyInputs;
using sequencer::State;

namespace {

constexpr std::array kStates = {
    State::kIdle,     State::kEnabling, State::kHoming,    State::kPositioning, State::kShedTest,
    State::kShed,     State::kPick,     State::kBeatSweep, State::kRowEnd,      State::kAwaitKnotting,
    State::kKnotting, State::kPaused,   State::kDone,      State::kFault};
constexpr std::array kCommands = {Command::kStart, Command::kPause,  Command::kResume,
                                  Command::kStop,  Command::kAck,    Command::kExit,
                                  Command::kNext,  Command::kReload, Command::kRearm};

std::uint32_t bit(Command c) {
  return static_cast<std::uint32_t>(c);
}
bool stopping(std::uint32_t cmds) {
  return (cmds & firmware::kStoppingCommands) != 0;
}
bool moving(State s) {
  return s != State::kIdle && s != State::kPaused && s != State::kDone && s != State::kFault;
}
std::string name(std::uint32_t cmds) {
  static const char* names[] = {"start", "pause", "resume", "stop", "ack", "exit", "next", "reload", "rearm"};
  std::string out;
  for (int i = 0; i < 9; ++i) {
    if ((cmds & (1u << i)) != 0) out += (out.empty() ? "" : "+") + std::string(names[i]);
  }
  return out;
}
bool starts_anything(const Decision& d) {
  return d.start || d.resume || d.row_knotted || d.reload || d.acknowledge ||
         d.end == Decision::End::kStartRequested || d.end == Decision::End::kAckRequested;
}

// Every state, held session or not, every command alone and every pair: the stopping class never starts.
TEST(OperatorPolicy, AStoppingCommandNeverComesWithAStartingRequestInAnyState) {
  int checked = 0;
  for (const bool held : {false, true}) {
    for (const State s : kStates) {
      for (std::uint32_t cmds = 1; cmds < (1u << kCommands.size()); ++cmds) {
        PolicyInputs in;
        in.commands = cmds;
        in.state = s;
        in.held_session = held;
        const Decision d = firmware::decide(in);
        const std::string what =
            name(cmds) + " in " + sequencer::state_name(s) + (held ? " (serve)" : " (weave)");
        if (stopping(cmds)) {
          EXPECT_FALSE(starts_anything(d)) << what;
          EXPECT_EQ(d.overridden, cmds & firmware::kStartingCommands) << what;
          ++checked;
        }
        // A stop is never a resume: the defect of a paused loom that a stop set weaving again.
        if ((cmds & bit(Command::kStop)) != 0) {
          EXPECT_FALSE(d.resume) << what;
        }
      }
    }
  }
  EXPECT_EQ(checked, 2 * 14 * (512 - 64));  // every set that holds pause, stop or exit
}

struct Expect {
  bool stop = false, pause = false, resume = false, start = false, acknowledge = false, row_knotted = false;
  bool reload = false;
  bool exit_when_quiet = false;
  Decision::End end = Decision::End::kNone;
};

// What each command alone asks in each state (weave: held_session false; serve: true).
Expect expected(Command c, State s, bool held) {
  Expect e;
  const bool done_or_fault = s == State::kDone || s == State::kFault;
  switch (c) {
    case Command::kStop:
      e.stop = !done_or_fault;  // the sequencer stands at its next hold point (request_stop)
      if (s == State::kIdle && !held) e.end = Decision::End::kStopped;
      break;
    case Command::kPause:
      e.pause = s != State::kIdle && !done_or_fault;
      break;
    case Command::kExit:
      e.exit_when_quiet = true;
      e.stop = moving(s);
      break;
    case Command::kResume:
      e.resume = true;
      break;
    case Command::kNext:
      e.row_knotted = true;
      break;
    case Command::kReload:
      e.reload = true;  // in every state: the yarn put in is a fact (it answers only an open reload request)
      break;
    case Command::kStart:
      if (s == State::kDone && held) {
        e.end = Decision::End::kStartRequested;
      } else {
        e.start = true;
      }
      break;
    case Command::kRearm:
      if (held && (s == State::kIdle || s == State::kDone)) e.end = Decision::End::kRearmRequested;
      break;
    case Command::kAck:
      if (s == State::kFault) {
        if (held) {
          e.end = Decision::End::kAckRequested;
        } else {
          e.acknowledge = true;
        }
      }
      break;
  }
  return e;
}

TEST(OperatorPolicy, EachCommandAloneInEachState) {
  for (const bool held : {false, true}) {
    for (const State s : kStates) {
      for (const Command c : kCommands) {
        PolicyInputs in;
        in.commands = bit(c);
        in.state = s;
        in.held_session = held;
        const Decision d = firmware::decide(in);
        const Expect e = expected(c, s, held);
        const std::string what =
            name(bit(c)) + " in " + sequencer::state_name(s) + (held ? " (serve)" : " (weave)");
        EXPECT_EQ(d.stop, e.stop) << what;
        EXPECT_EQ(d.pause, e.pause) << what;
        EXPECT_EQ(d.resume, e.resume) << what;
        EXPECT_EQ(d.start, e.start) << what;
        EXPECT_EQ(d.acknowledge, e.acknowledge) << what;
        EXPECT_EQ(d.row_knotted, e.row_knotted) << what;
        EXPECT_EQ(d.reload, e.reload) << what;
        EXPECT_EQ(d.exit_when_quiet, e.exit_when_quiet) << what;
        EXPECT_EQ(d.end, e.end) << what;
        EXPECT_EQ(d.refusal, Decision::Refusal::kNone) << what;
        EXPECT_EQ(d.overridden, 0u) << what;
      }
    }
  }
}

// The service re-arms on an acknowledgement only when re-arming can work; each refusal says why.
TEST(OperatorPolicy, AServiceAcknowledgementIsRefusedWhileItCannotReArm) {
  const auto ack = [](hal::LinkRecovery link, bool estop_ok, bool unsaved) {
    PolicyInputs in;
    in.commands = bit(Command::kAck);
    in.state = State::kFault;
    in.held_session = true;
    in.link_recovery = link;
    in.estop_ok = estop_ok;
    in.last_save_failed = unsaved;
    return firmware::decide(in);
  };
  EXPECT_EQ(ack(hal::LinkRecovery::kBusOff, true, false).refusal, Decision::Refusal::kAckLinkDown);
  EXPECT_EQ(ack(hal::LinkRecovery::kNodeSilent, true, false).refusal, Decision::Refusal::kAckLinkDown);
  EXPECT_EQ(ack(hal::LinkRecovery::kReady, false, false).refusal, Decision::Refusal::kAckEStopOpen);
  EXPECT_EQ(ack(hal::LinkRecovery::kHealthy, true, true).refusal, Decision::Refusal::kAckCountersUnsaved);
  for (const auto& d :
       {ack(hal::LinkRecovery::kBusOff, true, false), ack(hal::LinkRecovery::kReady, false, false),
        ack(hal::LinkRecovery::kHealthy, true, true)}) {
    EXPECT_EQ(d.end, Decision::End::kNone);
  }
  EXPECT_EQ(ack(hal::LinkRecovery::kReady, true, false).end, Decision::End::kAckRequested);
  EXPECT_EQ(ack(hal::LinkRecovery::kHealthy, true, false).end, Decision::End::kAckRequested);
}

}  // namespace

// A carpet finished with nothing queued: a start (button or command) never sets the idle loom moving;
// from done it still ends the held session, so the service re-arms and reads the queue again.
TEST(OperatorPolicy, NothingToWeaveRefusesAStartFromIdleOnly) {
  const auto start = [](State s, bool nothing, bool held) {
    PolicyInputs in;
    in.commands = bit(Command::kStart);
    in.state = s;
    in.held_session = held;
    in.nothing_to_weave = nothing;
    return firmware::decide(in);
  };
  const Decision idle = start(State::kIdle, true, true);
  EXPECT_FALSE(starts_anything(idle));
  EXPECT_EQ(idle.refusal, Decision::Refusal::kStartNothingToWeave);
  EXPECT_EQ(idle.end, Decision::End::kNone);
  EXPECT_TRUE(start(State::kIdle, false, true).start);
  EXPECT_EQ(start(State::kDone, true, true).end, Decision::End::kStartRequested);
  // Paused in a row of a job: a start resumes it (the job is being woven; nothing_to_weave is not set then,
  // and if it were, a resume is not a new carpet).
  EXPECT_TRUE(start(State::kPaused, true, true).start);
}

// The job queue changed (serve): a standing held session ends to arm again, and nothing else ever follows
// from it — no start, no acknowledgement, not in any state, whatever comes with it in the same tick but a
// start (which then re-arms and starts: the start's doing, from a station allowed to start).
TEST(OperatorPolicy, ARearmNeverStartsAndOnlyEndsAStandingHeldSession) {
  int checked = 0;
  for (const bool held : {false, true}) {
    for (const State s : kStates) {
      for (std::uint32_t cmds = 0; cmds < (1u << kCommands.size()); ++cmds) {
        if ((cmds & bit(Command::kRearm)) == 0) continue;
        PolicyInputs in;
        in.commands = cmds;
        in.state = s;
        in.held_session = held;
        const Decision with = firmware::decide(in);
        in.commands = cmds & ~bit(Command::kRearm);
        const Decision without = firmware::decide(in);
        const std::string what =
            name(cmds) + " in " + sequencer::state_name(s) + (held ? " (serve)" : " (weave)");
        const bool standing = held && (s == State::kIdle || s == State::kDone);
        const bool exits = (cmds & bit(Command::kExit)) != 0;
        const bool starts = (cmds & bit(Command::kStart)) != 0 && !stopping(cmds);
        // The sequencer is asked what it is asked without the rearm — but a start from a standing session,
        // which goes to the session armed from the changed queue.
        if (standing && starts) {
          EXPECT_FALSE(with.start) << what;
        } else {
          EXPECT_EQ(with.start, without.start) << what;
        }
        EXPECT_EQ(with.resume, without.resume) << what;
        EXPECT_EQ(with.acknowledge, without.acknowledge) << what;
        EXPECT_EQ(with.row_knotted, without.row_knotted) << what;
        EXPECT_EQ(with.stop, without.stop) << what;
        EXPECT_EQ(with.pause, without.pause) << what;
        if (!standing || exits) {
          EXPECT_EQ(with.end, without.end) << what;
        } else if (starts) {
          EXPECT_EQ(with.end, Decision::End::kStartRequested) << what;  // re-arm from the queue, then start
        } else {
          EXPECT_EQ(with.end, Decision::End::kRearmRequested) << what;
        }
        if (stopping(cmds)) {
          EXPECT_NE(with.end, Decision::End::kStartRequested) << what;
        }
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 2 * 14 * 256);
}

// The service's decision on each control-socket request: who gave it (the kernel's word on the local
// user; a panel client's address and pairing), whether that station may give it (control_protocol.hpp:
// stopping from anyone allowed, starting only from a trusted station), and whether it would change
// anything in the loom's present state. A reply is `ok WORD ...` only when the command is carried out;
// otherwise `refused: WORD: why` (the CLI exits 1). Non-RT, on the control socket's thread; pure apart
// from the pairings it keeps, so every command is tested in every state without a loom.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "loom/firmware/runner.hpp"
#include "loom/firmware/serve/control_protocol.hpp"
#include "loom/firmware/serve/control_socket.hpp"
#include "loom/firmware/serve/pairings.hpp"
#include "loom/hal/types.hpp"
#include "loom/sequencer/sequencer.hpp"

namespace loom::firmware::serve {

// What the desk needs to know of the loom (a snapshot of the OperatorLink's status).
struct LoomView {
  sequencer::State state = sequencer::State::kIdle;
  sequencer::Fault fault = sequencer::Fault::kNone;
  hal::LinkRecovery recovery = hal::LinkRecovery::kHealthy;
  int silent_node = 0;
  bool estop_ok = true;
  bool knotting = false;  // the recipe has a knotting mode (`next` exists)
  sequencer::WeaverAsk weaver_ask = sequencer::WeaverAsk::kNone;  // the knotting heads wait for the weaver
  // The last counters save failed: the file lags what was woven, and the loop refuses an ack until a
  // retried save succeeds (an ack would re-arm from the older counts and weave those rows again). Not in
  // the OperatorLink: serve sets it from its own save bookkeeping.
  bool counters_unsaved = false;
  // A pause was given and the loom has not reached the safe point it holds at yet (serve's own record:
  // set by an accepted pause, cleared when the loom pauses, resumes, faults or a session ends). A resume
  // then withdraws it.
  bool pause_pending = false;
  // The knotting heads' magazines (0 heads: none), for `reload`'s range check.
  int heads = 0, slots = 0, knots_per_slot = 0;
};
LoomView view_of(const OperatorLink& link, bool knotting);

struct Decision {
  // kJob: a `job VERB` request the service carries out on its queue (it knows the armed job); the
  // changing verbs come here only from a trusted station, with audit set.
  enum class Read { kNone, kStatus, kFaults, kJob };
  std::string reply;            // complete unless read != kNone (then the caller answers)
  std::optional<Command> post;  // the command to hand to the loop
  struct Reload {
    int head = 0, slot = 0;   // 0-based
    std::int32_t knots = -1;  // -1: full
  };
  std::optional<Reload> reload;  // post == kReload: what to post with it (OperatorLink::post_reload)
  Read read = Read::kNone;
  std::optional<ParsedRequest> request;  // read == kJob: the request as parsed
  std::string who;      // "local user anna (uid 1000, pid 42)", "panel client 10.0.0.5 paired as tab1 ..."
  std::string station;  // "local" (the socket) or "panel" (a loom-panel client): the COMMAND event's station
  bool audit = false;   // a command that changes or would change the loom: log and record it
  bool accepted() const { return reply.rfind("ok", 0) == 0; }
};

class OperatorDesk {
 public:
  // `iface`: the CAN interface named in the bus-off advice.
  OperatorDesk(Pairings& pairings, std::string iface) : pairings_(pairings), iface_(std::move(iface)) {}
  Decision decide(const ControlRequest& req, const LoomView& v, std::int64_t now_s);
  // The reply a start/pause/ack (or any state-dependent word) gets in `v` from a station allowed to give
  // it: "ok WORD" or "refused: WORD: why". For the I/O module's buttons, whose presses the loop takes
  // directly: their audit says what the same command from the socket would have answered.
  std::string answer_in_state(const std::string& word, const LoomView& v) const;

 private:
  std::string refuse_for_state(const ParsedRequest& r, const LoomView& v) const;
  Pairings& pairings_;
  std::string iface_;
};

// Whether the loom is weaving (in a state that `stop`/`pause` act on).
bool weaving(sequencer::State s);

}  // namespace loom::firmware::serve

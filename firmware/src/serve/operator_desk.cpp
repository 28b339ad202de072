// Authority and truthful replies for the control socket's commands (see operator_desk.hpp).
#include "loom/firmware/serve/operator_desk.hpp"

#include <ctime>

namespace loom::firmware::serve {

using sequencer::State;

bool weaving(State s) {
  switch (s) {
    case State::kEnabling:
    case State::kHoming:
    case State::kPositioning:
    case State::kShedTest:
    case State::kShed:
    case State::kPick:
    case State::kBeatSweep:
    case State::kRowEnd:
    case State::kAwaitKnotting:
    case State::kKnotting:
      return true;
    default:
      return false;
  }
}

LoomView view_of(const OperatorLink& l, bool knotting) {
  constexpr auto r = std::memory_order_relaxed;
  LoomView v;
  v.state = static_cast<State>(l.state.load(r));
  v.fault = static_cast<sequencer::Fault>(l.first_fault.load(r));
  v.recovery = static_cast<hal::LinkRecovery>(l.link_recovery.load(r));
  v.silent_node = l.silent_node.load(r);
  v.estop_ok = l.estop_ok.load(r);
  v.knotting = knotting;
  v.weaver_ask = static_cast<sequencer::WeaverAsk>(l.weaver_ask.load(r));
  return v;
}

namespace {

std::string fault_of(const LoomView& v) {
  return v.fault == sequencer::Fault::kNone ? std::string("a fault") : sequencer::fault_name(v.fault);
}

std::string utc(std::int64_t s) {
  std::tm tm{};
  const std::time_t t = static_cast<std::time_t>(s);
  gmtime_r(&t, &tm);
  char b[32];
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return b;
}

}  // namespace

std::string OperatorDesk::answer_in_state(const std::string& word, const LoomView& v) const {
  ParsedRequest r;
  r.word = word;
  const std::string why = refuse_for_state(r, v);
  return why.empty() ? "ok " + word : "refused: " + word + ": " + why;
}

// "" when the command would change something now, else why not.
std::string OperatorDesk::refuse_for_state(const ParsedRequest& r, const LoomView& v) const {
  const std::string& w = r.word;
  const std::string state = sequencer::state_name(v.state);
  if (w == "reload") {  // in any state, a fault too: the yarn the weaver put in is a fact
    if (v.heads == 0) return "this loom has no knotting heads (knotting.mode is not \"heads\")";
    const int head = std::stoi(r.field("head")), slot = std::stoi(r.field("slot"));
    if (head > v.heads) {
      return "head=" + r.field("head") + ": this loom has heads 1 to " + std::to_string(v.heads);
    }
    if (slot >= v.slots) {
      return "slot=" + r.field("slot") + ": the magazines have slots 0 to " + std::to_string(v.slots - 1);
    }
    if (!r.field("knots").empty() && std::stoi(r.field("knots")) > v.knots_per_slot) {
      return "knots=" + r.field("knots") + ": a slot holds at most " + std::to_string(v.knots_per_slot) +
             " knots (knotting.knots_per_slot)";
    }
    return "";
  }
  if (v.state == State::kFault && w != "ack") {
    return fault_of(v) + " is latched: acknowledge it first (ctl ack)";
  }
  if (w == "start") {
    if (v.state == State::kPaused) return "paused: resume it (ctl resume)";
    if (v.state != State::kIdle && v.state != State::kDone) return "already weaving (state " + state + ")";
    if (!v.estop_ok) return "the e-stop chain is open: close it first";
    return "";
  }
  if (w == "pause") return weaving(v.state) ? "" : "not weaving (state " + state + ")";
  if (w == "resume") {
    // A pause not reached yet (the loom holds at the next safe point): resume withdraws it.
    if (v.pause_pending && weaving(v.state)) return "";
    return v.state == State::kPaused ? "" : "not paused (state " + state + ")";
  }
  if (w == "stop") {
    return weaving(v.state) || v.state == State::kPaused
               ? ""
               : "not weaving (state " + state + "): nothing to stop";
  }
  if (w == "next") {
    // The knotting heads' request (a knot to tie by hand, a slot to reload) is answered the same way.
    if (v.state == State::kKnotting) {
      return v.weaver_ask != sequencer::WeaverAsk::kNone
                 ? ""
                 : "the knotting heads are not waiting for the weaver";
    }
    if (!v.knotting) return "this loom has no weaver's knotting (knotting.mode is not \"weaver\")";
    return v.state == State::kAwaitKnotting ? "" : "not waiting for the weaver (state " + state + ")";
  }
  if (w == "ack") {
    if (v.state != State::kFault) return "no fault is latched (state " + state + ")";
    if (!v.estop_ok) return "the e-stop chain is still open: close it (release the e-stop), then acknowledge";
    if (v.counters_unsaved) {
      return "the counters woven are not on disk yet (the last save failed): free space in the state "
             "directory; "
             "the save is retried every second, then acknowledge";
    }
    if (v.recovery == hal::LinkRecovery::kBusOff) {
      return "the CAN controller is still bus-off; it must restart first (ip link set " +
             (iface_.empty() ? std::string("can0") : iface_) +
             " type can restart-ms 100, or ip link set ... type can restart)";
    }
    if (v.recovery == hal::LinkRecovery::kNodeSilent) {
      return "node " + std::to_string(v.silent_node) +
             " is still silent (no heartbeat, no boot-up): check its power and cable, then acknowledge";
    }
    return "";
  }
  return "";
}

Decision OperatorDesk::decide(const ControlRequest& req, const LoomView& v, std::int64_t now_s) {
  Decision d;
  std::string error;
  const auto parsed = parse_request(req.line, error);
  d.who = describe(req.peer);
  d.station = "local";
  if (!parsed) {
    d.reply = "error: " + error + "\n";
    return d;
  }
  const ParsedRequest& r = *parsed;
  // Who: the kernel's word on the local user; a panel adds its client's address and pairing.
  // A token counts only from the device that redeemed it: its address and the page's device secret.
  std::optional<Pairing> paired;
  bool elsewhere = false;
  std::string unpaired_why = "not paired";
  if (r.via_panel()) {
    d.station = "panel";
    if (!r.field("token").empty()) {
      paired = pairings_.find(r.field("token"), r.field("client"), r.field("device"), now_s, &elsewhere);
      unpaired_why = elsewhere ? "token of another device" : "token unknown or expired";
    }
    d.who = "panel client " + r.field("client") +
            (paired ? " paired as " + paired->name : " (" + unpaired_why + ")") + " via " +
            describe(req.peer);
  }
  const auto refuse = [&](const std::string& why) {
    d.reply = "refused: " + r.word + ": " + why + "\n";
    return d;
  };
  switch (r.cls) {
    case CommandClass::kReading:
      if (r.word == "job") {
        d.read = Decision::Read::kJob;
        d.request = r;
      } else if (r.word == "status")
        d.read = Decision::Read::kStatus;
      else if (r.word == "faults")
        d.read = Decision::Read::kFaults;
      else if (r.word == "whoami") {
        if (!r.via_panel())
          d.reply = "ok whoami local " + d.who + " may_start=1\n";
        else if (paired)
          d.reply =
              "ok whoami paired " + paired->name + " expires=" + utc(paired->expires_s) + " may_start=1\n";
        else
          return refuse("not paired: stopping commands only");
      } else {  // pairs
        std::string out;
        for (const Pairing& p : pairings_.list(now_s)) {
          out += "paired " + p.name + " client " + p.client + " until " + utc(p.expires_s) + "\n";
        }
        d.reply = out.empty() ? "no panel clients paired\n" : out;
      }
      return d;
    case CommandClass::kPairing:
      d.audit = true;
      if (r.word == "redeem") {
        if (!r.via_panel()) return refuse("only a panel redeems a pairing code for its client");
        auto p = pairings_.redeem(r.field("code"), r.field("client"), r.field("device"), now_s, error);
        if (!p) return refuse(error);
        d.who = "panel client " + r.field("client") + " paired as " + p->name + " via " + describe(req.peer);
        // valid_s: what the panel gives its cookie as Max-Age (the cookie ends with the pairing).
        d.reply = "ok redeem " + p->name + " token=" + p->token + " expires=" + utc(p->expires_s) +
                  " valid_s=" + std::to_string(p->expires_s - now_s) + "\n";
        return d;
      }
      if (r.via_panel())
        return refuse("pairing is done at the loom (its local socket), never through a panel");
      if (r.word == "pair") {
        int hours = Pairings::kDefaultHours;
        if (!r.field("hours").empty()) {
          const std::string& h = r.field("hours");
          if (h.size() > 3 || h.find_first_not_of("0123456789") != std::string::npos || std::stoi(h) < 1 ||
              std::stoi(h) > Pairings::kMaxHours) {
            return refuse("hours=" + h + ": 1 to " + std::to_string(Pairings::kMaxHours));
          }
          hours = std::stoi(h);
        }
        const std::string code = pairings_.new_code(r.arg, hours, now_s);
        d.reply = "ok pair " + r.arg + " code=" + code +
                  " valid=" + std::to_string(Pairings::kCodeLifetimeS) + "s hours=" + std::to_string(hours) +
                  " (enter the code on the panel's pairing field)\n";
        return d;
      }
      {  // unpair
        const int n = pairings_.revoke(r.arg);
        if (n == 0) return refuse("no pairing named " + r.arg);
        d.reply = "ok unpair " + r.arg + " (" + std::to_string(n) + " revoked)\n";
        return d;
      }
    case CommandClass::kStarting:
    case CommandClass::kStopping:
    case CommandClass::kQueue:
      break;
  }
  d.audit = true;
  const auto unpaired = [&] {
    return std::string(r.field("token").empty() ? "not paired"
                       : elsewhere              ? "not paired: its token was redeemed on another device"
                                                : "not paired: token unknown or expired");
  };
  if (r.cls == CommandClass::kQueue) {
    // What the loom weaves next is decided where it can be seen, as its starts are.
    if (r.via_panel() && !paired) {
      d.reply = "refused: job " + r.arg +
                ": changing the job queue needs a paired panel client (this one is " + unpaired() +
                "; pair it with `loomctl ctl pair NAME` at the loom)\n";
      return d;
    }
    d.read = Decision::Read::kJob;
    d.request = r;
    return d;
  }
  if (r.cls == CommandClass::kStarting && r.via_panel() && !paired) {
    return refuse("a command that starts motion or resets a fault needs a paired panel client (this one is " +
                  unpaired() + "; pair it with `loomctl ctl pair NAME` at the loom)");
  }
  if (auto why = refuse_for_state(r, v); !why.empty()) return refuse(why);
  if (r.word == "start")
    d.post = Command::kStart;
  else if (r.word == "pause")
    d.post = Command::kPause;
  else if (r.word == "resume")
    d.post = Command::kResume;
  else if (r.word == "stop")
    d.post = Command::kStop;
  else if (r.word == "ack")
    d.post = Command::kAck;
  else if (r.word == "reload") {
    d.post = Command::kReload;
    d.reload = Decision::Reload{std::stoi(r.field("head")) - 1, std::stoi(r.field("slot")),
                                r.field("knots").empty() ? -1 : std::stoi(r.field("knots"))};
  } else
    d.post = Command::kNext;
  d.reply = "ok " + r.word + "\n";
  return d;
}

}  // namespace loom::firmware::serve

// The control socket's request line, parsed without trusting it: `WORD [ARG] [key=value ...]`, printable
// ASCII only, bounded. The words and their classes (operator authority, IEC 60204-1 / ISO 12100 practice:
// a command that starts motion or resets a fault is given where the hazard zone can be seen):
//   stopping  stop, pause                     — from anyone allowed on the socket, paired or not
//   starting  start, resume, next, ack        — only from a trusted station: a local socket user, or a
//             reload head=H slot=S [knots=K]    panel client paired with this loom (a reload answers the
//                                                heads' request to reload that slot: they go on)
//   reading   status, faults, pairs, whoami, job list, job show id=N
//   queue     job add design=/ABS/PATH [rows=R | metres=M | repeat=K], job remove id=N,
//             job start-over id=N     — the carpet job queue: only from a trusted station (as starting
//                                       commands); never motion (a job is started by `start`)
//   pairing   pair NAME [hours=H], unpair NAME — local socket users only (never through the panel)
//             redeem code=CODE                — a panel client turns a pairing code into its token
// A panel forwarding for one of its clients adds `via=panel client=ADDR [token=TOKEN]`: the command then
// carries that client's authority, not the panel process's own.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace loom::firmware::serve {

enum class CommandClass { kStopping, kStarting, kReading, kPairing, kQueue };

struct ParsedRequest {
  std::string word;  // "start", "pair", ...
  std::string arg;   // the positional argument (pair/unpair NAME, job's verb), else ""
  // key=value pairs (via, client, token, device, code, hours; reload's head, slot, knots)
  std::map<std::string, std::string> fields;
  CommandClass cls = CommandClass::kReading;
  bool via_panel() const { return fields.count("via") != 0 && fields.at("via") == "panel"; }
  std::string field(const std::string& k) const {
    const auto it = fields.find(k);
    return it == fields.end() ? std::string() : it->second;
  }
};

// The command words, in the order help lists them.
inline constexpr const char* kCommandWords[] = {"start", "pause",  "resume", "stop",   "ack",
                                                "next",  "reload", "status", "faults", "job",
                                                "pair",  "unpair", "pairs",  "redeem", "whoami"};
// job's verbs (loomctl job's, on the control socket).
inline constexpr const char* kJobVerbs[] = {"list", "show", "add", "remove", "start-over"};

// reload's numbers as the weaver reads them in the request ("reload colour R into slot 1 of head 2"):
// head=2 slot=1; knots= optional (the slot is full without it).
inline constexpr int kMaxReloadKnots = 1000000;

// Parses one request line. nullopt and `error` set ("unknown command 'x' (start, ...)", "bad field ...")
// when the line is not a request; never throws on any input.
std::optional<ParsedRequest> parse_request(std::string_view line, std::string& error);

// Whether `s` is a name a pairing may carry (1..32 of [A-Za-z0-9_.-]); "" when it is, else why not.
std::string pairing_name_error(std::string_view s);

}  // namespace loom::firmware::serve

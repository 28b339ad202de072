// libFuzzer harness: the control socket's protocol — a request line as any client (a local user, or a
// panel forwarding for one of its clients) may send it, parsed and decided by the OperatorDesk in a loom
// state chosen by the first input bytes. Checked on every input: the reply is one or more lines of
// printable ASCII ending in '\n' (nothing a client sends can forge a log or reply line); a command is
// handed to the loop only with an `ok` reply; a starting command through a panel is handed on only with
// the live pairing's token ("token=@" in the input stands for it; anything else is a forgery; it counts
// only with client=10.0.0.9 device=0123456789abcdef0123456789abcdef, the device that redeemed it); nothing
// escapes as an exception.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "loom/firmware/serve/operator_desk.hpp"

using namespace loom;
using namespace loom::firmware::serve;

namespace {
constexpr int kStates = static_cast<int>(sequencer::State::kFault) + 1;

[[noreturn]] void bug(const char* what) {
  std::fprintf(stderr, "control protocol invariant broken: %s\n", what);
  std::abort();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  static Pairings pairings;
  static OperatorDesk desk(pairings, "can0");
  static std::string token;
  if (token.empty()) {
    std::string error;
    const std::string code = pairings.new_code("fuzz", 1, 1'000'000'000);
    token =
        pairings.redeem(code, "10.0.0.9", "0123456789abcdef0123456789abcdef", 1'000'000'000, error)->token;
  }
  LoomView v;
  v.state = static_cast<sequencer::State>(data[0] % kStates);
  v.fault = v.state == sequencer::State::kFault ? sequencer::Fault::kEStop : sequencer::Fault::kNone;
  v.estop_ok = (data[1] & 1) != 0;
  v.knotting = (data[1] & 2) != 0;
  v.recovery = static_cast<hal::LinkRecovery>((data[1] >> 2) % 4);
  v.silent_node = data[1] >> 4;
  std::string line(reinterpret_cast<const char*>(data + 2), size - 2);
  bool real_token = false;
  if (const auto at = line.find("token=@"); at != std::string::npos) {
    line.replace(at + 6, 1, token);
    real_token = true;
  }
  ControlRequest req{line, Peer{42, 1000, 1000, "weaver"}};
  const Decision d = desk.decide(req, v, 1'000'000'100);
  if (d.reply.empty() && d.read == Decision::Read::kNone) bug("no reply");
  if (!d.reply.empty() && d.reply.back() != '\n') bug("reply does not end its line");
  for (char c : d.reply) {
    if (c != '\n' && (c < ' ' || c > '~')) bug("reply carries a non-printable byte");
  }
  if (d.post && !d.accepted()) bug("a command handed on without an ok");
  if (d.post && d.read != Decision::Read::kNone) bug("a read that also commands");
  const bool starting = d.post && *d.post != firmware::Command::kPause && *d.post != firmware::Command::kStop;
  // A panel request is one whose fields (space-separated) include via=panel exactly; "client=dvia=panel"
  // from the local socket is the local user's own request (found by this harness: its first check matched
  // the text anywhere in the line).
  const bool via_panel = (" " + line + " ").find(" via=panel ") != std::string::npos;
  if (starting && via_panel && !real_token) bug("a panel client started without its token");
  if (d.post && *d.post == firmware::Command::kAck && (v.state != sequencer::State::kFault || !v.estop_ok)) {
    bug("an acknowledgement handed on with no fault latched or the chain open");
  }
  return 0;
}

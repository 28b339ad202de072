// What loom-panel checks before a request reaches a handler, and the authority of operator commands.
//   Host: must name this panel — the bound address, localhost names on a loopback bind, an IP literal on
//         a wildcard bind, or a name given with --host. Anything else (DNS rebinding: evil.example.com
//         resolving to the panel) is refused with 421 before any handler runs.
//   Origin: a state-changing request (POST) from a browser carries Origin; it must be this panel's own
//         (http://<Host>). A POST also needs X-Loom-Panel: 1 (a plain cross-site form cannot send it).
//   Commands: stopping ones (stop, pause) from any client; starting ones (resume, next, ack, reload —
//         `start` stays at the machine) only from a client paired with that loom (pairings.hpp in the
//         firmware: the loom decides, the panel forwards the client's token and address and never forwards a
//         starting command without a token).
#pragma once

#include <string>
#include <vector>

namespace loom::panel {

struct GateConfig {
  std::string bind;                // --bind
  int port = 0;                    // the port actually listened on
  std::vector<std::string> hosts;  // --host NAME (names the hall uses for the panel, e.g. panel.hall.lan)
};

// "" when `host_header` (with or without :port) names this panel, else why not.
std::string host_refusal(const GateConfig& g, const std::string& host_header);
// "" when a POST's Origin (may be empty: not a browser) matches the Host, else why not.
std::string origin_refusal(const std::string& origin, const std::string& host_header);

enum class PanelCommand { kUnknown, kStopping, kStarting };
// The buttons the panel may send: pause, stop (stopping); resume, next, ack, reload (starting). Not `start`.
PanelCommand panel_command(const std::string& c);

// Whether `s` is a 32-hex-digit token (what a pairing cookie must hold before it is forwarded).
bool token_shape(const std::string& s);
// Whether `s` is a device secret as the page makes it (X-Loom-Device: 32 to 64 lower-case hex digits):
// the page keeps it in its storage and sends it with each command; the loom binds a token to it.
bool device_shape(const std::string& s);

// The pairing cookie for `loom`: HttpOnly, SameSite=Strict, for as long as the pairing lasts (`valid_s`,
// the loom's word), and Secure when the panel serves over TLS.
std::string token_cookie(const std::string& loom, const std::string& token, long long valid_s, bool tls);

}  // namespace loom::panel

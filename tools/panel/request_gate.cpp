// Host/Origin checks and command classes for loom-panel (see request_gate.hpp).
#include "request_gate.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <cctype>

namespace loom::panel {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// Splits "host[:port]" / "[v6][:port]" into host (brackets kept off) and port ("" when none).
bool split_host(const std::string& h, std::string& host, std::string& port) {
  if (h.empty()) return false;
  if (h[0] == '[') {
    const auto close = h.find(']');
    if (close == std::string::npos) return false;
    host = h.substr(1, close - 1);
    const std::string rest = h.substr(close + 1);
    if (!rest.empty() && rest[0] != ':') return false;
    port = rest.empty() ? "" : rest.substr(1);
  } else {
    const auto colon = h.find(':');
    host = h.substr(0, colon);
    port = colon == std::string::npos ? "" : h.substr(colon + 1);
  }
  return !host.empty() &&
         std::all_of(port.begin(), port.end(), [](unsigned char c) { return std::isdigit(c); });
}

bool ip_literal(const std::string& h) {
  in_addr a4{};
  in6_addr a6{};
  return ::inet_pton(AF_INET, h.c_str(), &a4) == 1 || ::inet_pton(AF_INET6, h.c_str(), &a6) == 1;
}

bool loopback(const std::string& bind) {
  return bind.rfind("127.", 0) == 0 || bind == "::1" || bind == "localhost";
}

}  // namespace

std::string host_refusal(const GateConfig& g, const std::string& host_header) {
  std::string host, port;
  if (!split_host(lower(host_header), host, port)) return "no usable Host header";
  if (!port.empty() && port != std::to_string(g.port)) return "Host names another port (" + port + ")";
  const std::string bind = lower(g.bind);
  if (host == bind) return "";
  if (std::find(g.hosts.begin(), g.hosts.end(), host) != g.hosts.end()) return "";
  if (loopback(bind) && (host == "localhost" || host == "127.0.0.1" || host == "::1")) return "";
  // Bound to every address: any IP literal reaches the panel only through that address; a name (which
  // an attacker's DNS can point anywhere) must be one given with --host.
  if ((bind == "0.0.0.0" || bind == "::" || bind.empty()) && ip_literal(host)) return "";
  return "Host '" + host_header.substr(0, 80) +
         "' is not this panel (give the hall's name for it with --host)";
}

std::string origin_refusal(const std::string& origin, const std::string& host_header) {
  if (origin.empty()) return "";  // not a browser: the X-Loom-Panel header still applies
  const std::string o = lower(origin), h = lower(host_header);
  if (o == "http://" + h || o == "https://" + h) return "";
  return "Origin '" + origin.substr(0, 80) + "' is not this panel";
}

PanelCommand panel_command(const std::string& c) {
  if (c == "pause" || c == "stop") return PanelCommand::kStopping;
  // A reload acknowledges yarn put in a slot: the heads may go on (motion), so it is a starting command.
  if (c == "resume" || c == "next" || c == "ack" || c == "reload") return PanelCommand::kStarting;
  return PanelCommand::kUnknown;
}

bool token_shape(const std::string& s) {
  return s.size() == 32 && std::all_of(s.begin(), s.end(), [](char c) {
           return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
         });
}

bool device_shape(const std::string& s) {
  return s.size() >= 32 && s.size() <= 64 && std::all_of(s.begin(), s.end(), [](char c) {
           return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
         });
}

std::string token_cookie(const std::string& loom, const std::string& token, long long valid_s, bool tls) {
  return "loom_token_" + loom + "=" + token +
         "; Path=/; HttpOnly; SameSite=Strict; Max-Age=" + std::to_string(valid_s < 0 ? 0 : valid_s) +
         (tls ? "; Secure" : "");
}

}  // namespace loom::panel

// Panel clients paired with this loom: the only remote stations allowed to give starting commands
// (start, resume, next, ack). A local operator (`loomctl ctl pair NAME` on the loom's own socket) gets a
// six-digit code, valid 2 minutes and for 5 tries; the phone or tablet enters it on the panel, which
// redeems it for a per-client token (128 random bits) valid `hours` (default 12: a shift). Tokens live
// only in the service's memory: a restart of `serve` unpairs every client; `unpair NAME` revokes one.
// Non-RT; thread-safe.
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace loom::firmware::serve {

struct Pairing {
  std::string name;
  std::string token;            // 32 hex digits
  std::int64_t expires_s = 0;   // unix seconds
  std::string client;           // the address that redeemed the code
};

class Pairings {
 public:
  static constexpr int kCodeLifetimeS = 120, kCodeTries = 5, kDefaultHours = 12, kMaxHours = 24 * 7;
  static constexpr std::size_t kMaxPairings = 64;

  // A fresh code for `name` (replacing any code not yet redeemed); `hours` in 1..kMaxHours.
  std::string new_code(const std::string& name, int hours, std::int64_t now_s);
  // The code's pairing (a new token), or nullopt and `error` (no code waiting, wrong, expired, used up).
  std::optional<Pairing> redeem(const std::string& code, const std::string& client, std::int64_t now_s,
                                std::string& error);
  // The live pairing holding `token` (compared in constant time), or nullopt.
  std::optional<Pairing> find(const std::string& token, std::int64_t now_s) const;
  // Revokes every pairing named `name`; how many there were.
  int revoke(const std::string& name);
  std::vector<Pairing> list(std::int64_t now_s) const;

 private:
  mutable std::mutex mu_;
  std::vector<Pairing> pairings_;
  std::string code_, code_name_;
  int code_hours_ = kDefaultHours, code_tries_ = 0;
  std::int64_t code_expires_s_ = 0;
};

// `bytes` random bytes from the kernel (getrandom), as hex. Throws std::runtime_error when unavailable.
std::string random_hex(std::size_t bytes);

}  // namespace loom::firmware::serve

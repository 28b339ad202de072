// Panel clients paired with this loom: the only remote stations allowed to give starting commands
// (start, resume, next, ack). A local operator (`loomctl ctl pair NAME` on the loom's own socket) gets a
// six-digit code, valid 2 minutes; the phone or tablet enters it on the panel, which redeems it for a
// per-client token (128 random bits) valid `hours` (default 12: a shift). Tokens live only in the
// service's memory: a restart of `serve` unpairs every client; `unpair NAME` revokes one.
//
// Against a hall client guessing or jamming (issue 30): wrong codes are counted per client address, never
// for everyone. An address gets kCodeTries wrong tries per code, each followed by a wait that doubles (1,
// 2, 4, 8 s: a try during the wait is refused without being judged), so one device sending codes at full
// speed neither voids the code nor keeps the device the operator is pairing from entering it. Only
// kCodeWrongTriesAll wrong tries from all addresses together void a code (an attacker with hundreds of
// addresses; the chance that they guessed it stays below kCodeWrongTriesAll in 10^6).
//
// Against a captured token (a cookie read off a plain-HTTP hall network): a token is bound to the device
// that redeemed it — its client address and a per-device secret the panel's page keeps (device=) — and
// is refused from any other address or without that secret. Non-RT; thread-safe.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace loom::firmware::serve {

struct Pairing {
  std::string name;
  std::string token;           // 32 hex digits
  std::int64_t expires_s = 0;  // unix seconds
  std::string client;          // the address that redeemed the code
  std::string device;          // the secret the redeeming page keeps (compared in constant time)
};

class Pairings {
 public:
  static constexpr int kCodeLifetimeS = 120, kCodeTries = 5, kDefaultHours = 12, kMaxHours = 24 * 7;
  static constexpr int kCodeWrongTriesAll = 1000;  // from all addresses together: then the code is void
  static constexpr std::size_t kMaxPairings = 64;

  // A fresh code for `name` (replacing any code not yet redeemed, and every address' count of wrong
  // tries); `hours` in 1..kMaxHours.
  std::string new_code(const std::string& name, int hours, std::int64_t now_s);
  // The code's pairing (a new token bound to `client` and `device`), or nullopt and `error` (no code
  // waiting, wrong, expired, this address waiting or out of tries, void).
  std::optional<Pairing> redeem(const std::string& code, const std::string& client, const std::string& device,
                                std::int64_t now_s, std::string& error);
  // The live pairing holding `token` redeemed from `client` with `device` (compared in constant time), or
  // nullopt. `elsewhere` (when given) says whether the token is live but was presented by another device.
  std::optional<Pairing> find(const std::string& token, const std::string& client, const std::string& device,
                              std::int64_t now_s, bool* elsewhere = nullptr) const;
  // Revokes every pairing named `name`; how many there were.
  int revoke(const std::string& name);
  std::vector<Pairing> list(std::int64_t now_s) const;

 private:
  struct Tries {
    int wrong = 0;
    std::int64_t next_s = 0;  // no try judged before this
  };
  mutable std::mutex mu_;
  std::vector<Pairing> pairings_;
  std::string code_, code_name_;
  int code_hours_ = kDefaultHours, code_wrong_all_ = 0;
  std::int64_t code_expires_s_ = 0;
  std::map<std::string, Tries>
      tries_;  // per client address, for the code waiting (bounded by kCodeWrongTriesAll)
};

// `bytes` random bytes from the kernel (getrandom), as hex. Throws std::runtime_error when unavailable.
std::string random_hex(std::size_t bytes);

// Whether `s` is a device secret as the panel's page makes it: 32 to 64 hex digits.
bool device_secret_shape(const std::string& s);

}  // namespace loom::firmware::serve

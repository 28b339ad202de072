// Pairing codes and tokens for panel clients (see pairings.hpp).
#include "loom/firmware/serve/pairings.hpp"

#include <sys/random.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace loom::firmware::serve {
namespace {

bool same(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d |= static_cast<unsigned char>(a[i] ^ b[i]);
  return d == 0;
}

void expire(std::vector<Pairing>& v, std::int64_t now_s) {
  v.erase(std::remove_if(v.begin(), v.end(), [&](const Pairing& p) { return p.expires_s <= now_s; }), v.end());
}

}  // namespace

std::string random_hex(std::size_t bytes) {
  std::string raw(bytes, '\0');
  std::size_t got = 0;
  while (got < bytes) {
    const ssize_t n = ::getrandom(raw.data() + got, bytes - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(std::string("no random bytes from the kernel: ") + std::strerror(errno));
    got += static_cast<std::size_t>(n);
  }
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  for (unsigned char c : raw) {
    out += kHex[c >> 4];
    out += kHex[c & 15];
  }
  return out;
}

std::string Pairings::new_code(const std::string& name, int hours, std::int64_t now_s) {
  // Six decimal digits from 32 random bits (the bias of 2^32 mod 10^6 is below 0.03 %).
  const std::uint32_t r = static_cast<std::uint32_t>(std::stoul(random_hex(4), nullptr, 16));
  char code[8];
  std::snprintf(code, sizeof code, "%06u", r % 1000000u);
  std::lock_guard<std::mutex> lock(mu_);
  code_ = code;
  code_name_ = name;
  code_hours_ = std::clamp(hours, 1, kMaxHours);
  code_tries_ = kCodeTries;
  code_expires_s_ = now_s + kCodeLifetimeS;
  return code_;
}

std::optional<Pairing> Pairings::redeem(const std::string& code, const std::string& client, std::int64_t now_s,
                                        std::string& error) {
  std::lock_guard<std::mutex> lock(mu_);
  if (code_.empty()) {
    error = "no pairing code is waiting (run `loomctl ctl pair NAME` at the loom)";
    return std::nullopt;
  }
  if (now_s >= code_expires_s_) {
    code_.clear();
    error = "the pairing code expired (codes last " + std::to_string(kCodeLifetimeS) + " s): ask for a new one";
    return std::nullopt;
  }
  if (!same(code, code_)) {
    if (--code_tries_ <= 0) {
      code_.clear();
      error = "wrong pairing code; the code is now void (too many tries)";
    } else {
      error = "wrong pairing code (" + std::to_string(code_tries_) + " tries left)";
    }
    return std::nullopt;
  }
  code_.clear();
  expire(pairings_, now_s);
  if (pairings_.size() >= kMaxPairings) pairings_.erase(pairings_.begin());  // the oldest goes
  Pairing p{code_name_, random_hex(16), now_s + static_cast<std::int64_t>(code_hours_) * 3600, client};
  pairings_.push_back(p);
  return p;
}

std::optional<Pairing> Pairings::find(const std::string& token, std::int64_t now_s) const {
  if (token.size() != 32) return std::nullopt;
  std::lock_guard<std::mutex> lock(mu_);
  std::optional<Pairing> found;
  for (const Pairing& p : pairings_) {
    if (same(p.token, token) && p.expires_s > now_s) found = p;
  }
  return found;
}

int Pairings::revoke(const std::string& name) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto before = pairings_.size();
  pairings_.erase(std::remove_if(pairings_.begin(), pairings_.end(), [&](const Pairing& p) { return p.name == name; }),
                  pairings_.end());
  if (code_name_ == name) code_.clear();
  return static_cast<int>(before - pairings_.size());
}

std::vector<Pairing> Pairings::list(std::int64_t now_s) const {
  std::lock_guard<std::mutex> lock(mu_);
  std::vector<Pairing> v = pairings_;
  expire(v, now_s);
  return v;
}

}  // namespace loom::firmware::serve

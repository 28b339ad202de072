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
  v.erase(std::remove_if(v.begin(), v.end(), [&](const Pairing& p) { return p.expires_s <= now_s; }),
          v.end());
}

}  // namespace

std::string random_hex(std::size_t bytes) {
  std::string raw(bytes, '\0');
  std::size_t got = 0;
  while (got < bytes) {
    const ssize_t n = ::getrandom(raw.data() + got, bytes - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw std::runtime_error(std::string("no random bytes from the kernel: ") + std::strerror(errno));
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

bool device_secret_shape(const std::string& s) {
  return s.size() >= 32 && s.size() <= 64 && std::all_of(s.begin(), s.end(), [](char c) {
           return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
         });
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
  code_wrong_all_ = 0;
  tries_.clear();
  code_expires_s_ = now_s + kCodeLifetimeS;
  return code_;
}

std::optional<Pairing> Pairings::redeem(const std::string& code, const std::string& client,
                                        const std::string& device, std::int64_t now_s, std::string& error) {
  if (!device_secret_shape(device)) {
    error = "no device secret came with the code (the panel's page keeps one: reload the page and try again)";
    return std::nullopt;
  }
  std::lock_guard<std::mutex> lock(mu_);
  if (code_.empty()) {
    error = "no pairing code is waiting (run `loomctl ctl pair NAME` at the loom)";
    return std::nullopt;
  }
  if (now_s >= code_expires_s_) {
    code_.clear();
    tries_.clear();
    error =
        "the pairing code expired (codes last " + std::to_string(kCodeLifetimeS) + " s): ask for a new one";
    return std::nullopt;
  }
  // This address' wrong tries: out of them, or still waiting after the last one. Judged before the code
  // is compared, so a try during the wait tells nothing, right or wrong.
  if (const auto t = tries_.find(client); t != tries_.end()) {
    if (t->second.wrong >= kCodeTries) {
      error = "this device gave " + std::to_string(kCodeTries) +
              " wrong codes: ask for a new code at the loom (`loomctl ctl pair NAME`)";
      return std::nullopt;
    }
    if (now_s < t->second.next_s) {
      error = "wrong codes from this device: wait " + std::to_string(t->second.next_s - now_s) +
              " s, then try again";
      return std::nullopt;
    }
  }
  if (!same(code, code_)) {
    Tries& t = tries_[client];
    ++t.wrong;
    t.next_s = now_s + (std::int64_t{1} << (t.wrong - 1));  // 1, 2, 4, 8 s
    if (++code_wrong_all_ >= kCodeWrongTriesAll) {
      code_.clear();
      tries_.clear();
      error = "wrong pairing code; the code is now void (" + std::to_string(kCodeWrongTriesAll) +
              " wrong tries from all devices): ask for a new one";
    } else if (t.wrong >= kCodeTries) {
      error = "wrong pairing code; no tries left from this device: ask for a new code at the loom";
    } else {
      error = "wrong pairing code (" + std::to_string(kCodeTries - t.wrong) +
              " tries left from this device; the next in " + std::to_string(t.next_s - now_s) + " s)";
    }
    return std::nullopt;
  }
  code_.clear();
  tries_.clear();
  expire(pairings_, now_s);
  if (pairings_.size() >= kMaxPairings) pairings_.erase(pairings_.begin());  // the oldest goes
  Pairing p{code_name_, random_hex(16), now_s + static_cast<std::int64_t>(code_hours_) * 3600, client,
            device};
  pairings_.push_back(p);
  return p;
}

std::optional<Pairing> Pairings::find(const std::string& token, const std::string& client,
                                      const std::string& device, std::int64_t now_s, bool* elsewhere) const {
  if (elsewhere != nullptr) *elsewhere = false;
  if (token.size() != 32) return std::nullopt;
  std::lock_guard<std::mutex> lock(mu_);
  std::optional<Pairing> found;
  for (const Pairing& p : pairings_) {
    if (!same(p.token, token) || p.expires_s <= now_s) continue;
    // Both compared whatever the first says: the time taken tells nothing of which one differed.
    const bool same_client = same(p.client, client);
    const bool same_device = same(p.device, device);
    if (same_client && same_device) {
      found = p;
    } else if (elsewhere != nullptr) {
      *elsewhere = true;
    }
  }
  return found;
}

int Pairings::revoke(const std::string& name) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto before = pairings_.size();
  pairings_.erase(
      std::remove_if(pairings_.begin(), pairings_.end(), [&](const Pairing& p) { return p.name == name; }),
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

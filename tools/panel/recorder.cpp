#include "recorder.hpp"

#include <algorithm>

namespace loom::panel {

namespace {
void put_be(std::string& out, std::uint64_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
}  // namespace

void Recorder::pop_front(Loom& l) {
  const std::size_t c = l.events.front().cost();
  l.bytes -= c;
  bytes_ -= c;
  l.events.pop_front();
}

void Recorder::add(std::string_view id, std::string_view channel, const void* data, std::size_t size,
                   std::int64_t recv_us) {
  if (!enabled()) return;
  std::lock_guard lock(mu_);
  auto it = looms_.find(id);
  if (it == looms_.end()) it = looms_.emplace(std::string(id), Loom{}).first;
  Loom& l = it->second;
  Event e{recv_us, std::string(channel), std::string(static_cast<const char*>(data), size)};
  if (e.cost() > max_bytes_) return;  // one message larger than the whole budget is not kept
  l.bytes += e.cost();
  bytes_ += e.cost();
  l.events.push_back(std::move(e));
  while (!l.events.empty() && recv_us - l.events.front().recv_us > window_us_) pop_front(l);
  while (bytes_ > max_bytes_) {  // the loom holding the most gives up its oldest message
    auto big = std::max_element(looms_.begin(), looms_.end(),
                                [](const auto& a, const auto& b) { return a.second.bytes < b.second.bytes; });
    pop_front(big->second);
  }
}

std::optional<std::string> Recorder::lcmlog(const std::string& id, std::int64_t now_us) const {
  std::lock_guard lock(mu_);
  const auto it = looms_.find(id);
  if (it == looms_.end()) return std::nullopt;
  std::string out;
  out.reserve(it->second.bytes);
  std::uint64_t n = 0;
  for (const Event& e : it->second.events) {
    if (now_us - e.recv_us > window_us_) continue;
    put_be(out, 0xEDA1DA01u, 4);
    put_be(out, n++, 8);
    put_be(out, static_cast<std::uint64_t>(e.recv_us), 8);
    put_be(out, e.channel.size(), 4);
    put_be(out, e.data.size(), 4);
    out += e.channel;
    out += e.data;
  }
  if (n == 0) return std::nullopt;
  return out;
}

std::size_t Recorder::bytes() const {
  std::lock_guard lock(mu_);
  return bytes_;
}

}  // namespace loom::panel

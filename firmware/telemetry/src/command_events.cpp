#include "loom/telemetry/command_events.hpp"

#include <lcm/lcm.h>

#include <chrono>
#include <stdexcept>
#include <vector>

#include "loom/telemetry/channels.hpp"

namespace loom::telemetry {

loomlcm::command_t to_command(const CommandAudit& a, const std::string& loom_id, std::int64_t utime) {
  loomlcm::command_t m;
  m.utime = utime;
  m.loom_id = loom_id;
  m.word = a.word;
  m.station = a.station;
  m.who = a.who;
  m.accepted = a.accepted;
  m.reply = a.reply;
  m.state = a.state;
  return m;
}

CommandEvents::CommandEvents(const std::string& lcm_url, const std::string& prefix,
                             const std::string& loom_id)
    : channel_(channel_names(prefix, loom_id).command), loom_id_(loom_id) {
  lcm_ = lcm_create(lcm_url.empty() ? nullptr : lcm_url.c_str());
  if (lcm_ == nullptr)
    throw std::invalid_argument("telemetry lcm_url '" + lcm_url + "' could not be opened by LCM");
}

CommandEvents::~CommandEvents() {
  lcm_destroy(lcm_);
}

bool CommandEvents::publish(const CommandAudit& a) noexcept {
  try {
    const std::int64_t utime = std::chrono::duration_cast<std::chrono::microseconds>(
                                   std::chrono::system_clock::now().time_since_epoch())
                                   .count();
    const loomlcm::command_t m = to_command(a, loom_id_, utime);
    std::vector<std::uint8_t> buf(static_cast<std::size_t>(m.getEncodedSize()));
    const int n = m.encode(buf.data(), 0, static_cast<int>(buf.size()));
    std::lock_guard<std::mutex> lock(mu_);
    const bool ok = n >= 0 && lcm_publish(lcm_, channel_.c_str(), buf.data(), static_cast<unsigned>(n)) == 0;
    ++(ok ? published_ : failures_);
    return ok;
  } catch (...) {  // an allocation failure loses this event, never the command or the service
    std::lock_guard<std::mutex> lock(mu_);
    ++failures_;
    return false;
  }
}

std::uint64_t CommandEvents::published() const {
  std::lock_guard<std::mutex> lock(mu_);
  return published_;
}

std::uint64_t CommandEvents::failures() const {
  std::lock_guard<std::mutex> lock(mu_);
  return failures_;
}

}  // namespace loom::telemetry

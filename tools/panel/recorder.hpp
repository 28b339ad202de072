// The panel's flight recorder: every LCM message it hears on a loom's channels over the last few minutes,
// kept raw (as received, before any decoding or throttling), so a technician can download an lcmlog of
// what led up to a fault and replay it with lcm-logplayer / loom-replay or open it in lcm-spy. Bounded in
// time (`window_s`) and in bytes for all looms together (`max_bytes`: the loom holding the most gives up
// its oldest messages first). Fed by the LCM thread, read by the HTTP threads; one mutex.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

namespace loom::panel {

class Recorder {
 public:
  Recorder(double window_s, std::size_t max_bytes)
      : window_us_(static_cast<std::int64_t>(window_s * 1e6)), max_bytes_(max_bytes) {}
  bool enabled() const { return window_us_ > 0 && max_bytes_ > 0; }
  // LCM thread: one message of loom `id` on `channel`, received at `recv_us` (wall clock, µs).
  void add(std::string_view id, std::string_view channel, const void* data, std::size_t size,
           std::int64_t recv_us);
  // HTTP threads: the loom's messages kept, oldest first, as an LCM log file (the format lcm-logger writes:
  // big-endian sync word 0xEDA1DA01, event number, timestamp µs, channel length, data length, channel,
  // data), of the last window before `now_us` (a loom gone quiet keeps older ones until the byte budget
  // takes them). nullopt when nothing of that loom is kept.
  std::optional<std::string> lcmlog(const std::string& id, std::int64_t now_us) const;
  std::size_t bytes() const;

 private:
  struct Event {
    std::int64_t recv_us;
    std::string channel, data;
    std::size_t cost() const { return channel.size() + data.size() + 64; }  // + bookkeeping
  };
  struct Loom {
    std::deque<Event> events;
    std::size_t bytes = 0;
  };
  void pop_front(Loom& l);
  std::int64_t window_us_;
  std::size_t max_bytes_;
  mutable std::mutex mu_;
  std::map<std::string, Loom, std::less<>> looms_;
  std::size_t bytes_ = 0;
};

}  // namespace loom::panel

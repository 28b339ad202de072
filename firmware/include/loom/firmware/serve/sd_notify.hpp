// systemd's readiness and watchdog protocol, spoken directly: one datagram to the AF_UNIX socket named
// by $NOTIFY_SOCKET ("@name" = abstract namespace). A dozen lines instead of a libsystemd dependency
// (the board image stays the same with or without systemd; tests can be the receiver). Non-RT.
#pragma once

#include <cstdint>
#include <string>

namespace loom::firmware::serve {

class SystemdNotifier {
 public:
  // Reads $NOTIFY_SOCKET, $WATCHDOG_USEC and $WATCHDOG_PID once. Without NOTIFY_SOCKET every call is a no-op.
  SystemdNotifier();
  ~SystemdNotifier();
  SystemdNotifier(const SystemdNotifier&) = delete;
  SystemdNotifier& operator=(const SystemdNotifier&) = delete;

  bool enabled() const { return fd_ >= 0; }
  // The watchdog interval systemd expects pings within (0: no watchdog for this process).
  std::int64_t watchdog_ns() const { return watchdog_ns_; }
  // Sends `state` ("READY=1", "WATCHDOG=1", "STATUS=...", "STOPPING=1"); false when it could not be sent.
  bool notify(const std::string& state) const;

 private:
  int fd_ = -1;
  std::string address_;
  std::int64_t watchdog_ns_ = 0;
};

// Feeds the watchdog only while the control loop is alive — the loop's tick counter must have moved
// recently — and the control socket's thread answers: it must have gone round its loop within half the
// interval (a handler stuck on a hung disk leaves every operator unanswered; systemd restarts the
// service, which comes back armed and waiting). Called from the non-RT reporter as often as it likes;
// pings at half the interval.
class LoopWatchdog {
 public:
  explicit LoopWatchdog(const SystemdNotifier& n) : n_(n) {}
  // `loop_tick`: the tick the loop last published; `now_ns`: a monotonic clock; `control_idle_ns`: how
  // long ago the control socket's thread last went round its loop.
  void poll(std::int64_t loop_tick, std::int64_t now_ns, std::int64_t control_idle_ns = 0);
  // Whether `control_idle_ns` counts as hung (no ping for it).
  bool control_hung(std::int64_t control_idle_ns) const {
    return n_.watchdog_ns() > 0 && control_idle_ns > n_.watchdog_ns() / 2;
  }
  // Between sessions (re-arming) no loop runs: the serve thread itself is the proof of life.
  void ping_outside_loop() const;

 private:
  const SystemdNotifier& n_;
  std::int64_t last_tick_ = -1;
  std::int64_t last_move_ns_ = 0;
  std::int64_t last_ping_ns_ = 0;
};

}  // namespace loom::firmware::serve

#include "loom/firmware/serve/sd_notify.hpp"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstddef>
#include <cstdlib>
#include <cstring>

namespace loom::firmware::serve {

SystemdNotifier::SystemdNotifier() {
  const char* sock = std::getenv("NOTIFY_SOCKET");
  if (sock == nullptr || (sock[0] != '/' && sock[0] != '@') ||
      std::strlen(sock) >= sizeof(sockaddr_un::sun_path))
    return;
  address_ = sock;
  fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  const char* usec = std::getenv("WATCHDOG_USEC");
  const char* wpid = std::getenv("WATCHDOG_PID");
  // WATCHDOG_PID, when set, names the process the watchdog is meant for (not a child we might run).
  const bool for_me =
      wpid == nullptr || std::strtoll(wpid, nullptr, 10) == static_cast<long long>(::getpid());
  if (usec != nullptr && for_me) {
    char* end = nullptr;
    const long long us = std::strtoll(usec, &end, 10);
    if (end != usec && *end == '\0' && us > 0 && us < 3600LL * 1'000'000) watchdog_ns_ = us * 1000;
  }
}

SystemdNotifier::~SystemdNotifier() {
  if (fd_ >= 0) ::close(fd_);
}

bool SystemdNotifier::notify(const std::string& state) const {
  if (fd_ < 0) return false;
  sockaddr_un sa{};
  sa.sun_family = AF_UNIX;
  std::memcpy(sa.sun_path, address_.data(), address_.size());
  if (address_[0] == '@') sa.sun_path[0] = '\0';  // abstract namespace
  const auto len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + address_.size());
  return ::sendto(fd_, state.data(), state.size(), MSG_NOSIGNAL, reinterpret_cast<const sockaddr*>(&sa),
                  len) == static_cast<ssize_t>(state.size());
}

void LoopWatchdog::poll(std::int64_t loop_tick, std::int64_t now_ns, std::int64_t control_idle_ns) {
  if (n_.watchdog_ns() == 0) return;
  if (loop_tick != last_tick_) {
    last_tick_ = loop_tick;
    last_move_ns_ = now_ns;
  }
  // Alive = the tick moved recently (a quarter of the interval: a loop of any sane period ticks many
  // times in that). A stalled loop gets no ping, and systemd kills and restarts the service.
  const bool alive = last_move_ns_ != 0 && now_ns - last_move_ns_ <= n_.watchdog_ns() / 4;
  if (!alive || control_hung(control_idle_ns) || now_ns - last_ping_ns_ < n_.watchdog_ns() / 2) return;
  last_ping_ns_ = now_ns;
  n_.notify("WATCHDOG=1");
}

void LoopWatchdog::ping_outside_loop() const {
  if (n_.watchdog_ns() > 0) n_.notify("WATCHDOG=1");
}

}  // namespace loom::firmware::serve

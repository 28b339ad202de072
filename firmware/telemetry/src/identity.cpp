#include "loom/telemetry/identity.hpp"

#include <lcm/lcm.h>
#include <poll.h>
#include <unistd.h>

#include <random>
#include <stdexcept>

#include "loom/telemetry/channels.hpp"
#include "loomlcm/identity_t.hpp"
#include "loomlcm/status_t.hpp"

namespace loom::telemetry {

std::int64_t process_instance() {
  static const std::int64_t instance = [] {
    std::random_device rd;
    const std::uint64_t v =
        (static_cast<std::uint64_t>(rd()) << 32) ^ rd() ^ static_cast<std::uint64_t>(::getpid());
    return static_cast<std::int64_t>(v >> 1) + 1;  // never 0
  }();
  return instance;
}

loomlcm::identity_t this_process_identity(const std::string& loom_id, std::int64_t utime) {
  loomlcm::identity_t m;
  m.utime = utime;
  m.loom_id = loom_id;
  char host[256] = "";
  if (::gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
  m.host = host[0] != '\0' ? host : "unknown-host";
  m.pid = static_cast<std::int32_t>(::getpid());
  m.instance = process_instance();
  m.version = LOOM_VERSION;
  return m;
}

namespace {

// What the listen window heard. Fed by plain C callbacks on the lcm_t (lcm_subscribe with our own
// decode), not by lcm-cpp's member-handler wrapper: under ASan/UBSan that wrapper's dispatch here called
// back through a corrupted subscription pointer (board_serve_service, a UBSan abort in lcm-cpp-impl.hpp).
struct Listener {
  std::string heard;
  bool status_seen = false;
  std::string status_note;
  std::int64_t now_utime = 0;
  std::string status_channel;
};

void on_identity(const lcm_recv_buf_t* rbuf, const char*, void* user) {
  auto& l = *static_cast<Listener*>(user);
  loomlcm::identity_t m;
  if (m.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) < 0) return;
  if (m.instance == process_instance() || !l.heard.empty()) return;
  l.heard = "host " + m.host + " (pid " + std::to_string(m.pid) + ", loomctl " + m.version + ")";
}

void on_status(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  auto& l = *static_cast<Listener*>(user);
  if (!l.heard.empty() || l.status_seen) return;
  loomlcm::status_t m;
  if (m.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) < 0) return;
  l.status_seen = true;
  const std::int64_t age_s = (l.now_utime - m.utime) / 1'000'000;
  l.status_note =
      "a publisher that sends no IDENTITY (" + std::string(channel) + " heard, state " + m.state +
      (age_s > 60 || age_s < -60 ? ", stamped " + std::to_string(age_s) + " s ago: a replayed recording?)"
                                 : ")");
}

}  // namespace

std::string other_publisher(const std::string& lcm_url, const std::string& prefix, const std::string& loom_id,
                            std::chrono::milliseconds window) {
  lcm_t* lcm = lcm_create(lcm_url.empty() ? nullptr : lcm_url.c_str());
  if (lcm == nullptr)
    throw std::invalid_argument("telemetry lcm_url '" + lcm_url + "' could not be opened by LCM");
  const ChannelNames ch = channel_names(prefix, loom_id);
  Listener l;
  l.now_utime = std::chrono::duration_cast<std::chrono::microseconds>(
                    std::chrono::system_clock::now().time_since_epoch())
                    .count();
  lcm_subscription_t* s1 = lcm_subscribe(lcm, ch.identity.c_str(), on_identity, &l);
  lcm_subscription_t* s2 = lcm_subscribe(lcm, ch.status.c_str(), on_status, &l);
  const auto end = std::chrono::steady_clock::now() + window;
  // Our own STATUS never comes in here: nothing of this process publishes while it listens (a previous
  // session's publisher was stopped before), and IDENTITY of our own instance is ignored.
  while (l.heard.empty()) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd p{lcm_get_fileno(lcm), POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) > 0) lcm_handle(lcm);
  }
  lcm_unsubscribe(lcm, s1);
  lcm_unsubscribe(lcm, s2);
  lcm_destroy(lcm);
  if (!l.heard.empty()) return l.heard;
  return l.status_seen ? l.status_note : "";
}

}  // namespace loom::telemetry

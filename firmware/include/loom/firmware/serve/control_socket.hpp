// The operator's local control channel: a UNIX stream socket (default /run/loomctl/<loom-id>.sock),
// mode 0660 and group `loom` when that group exists, so only the loom's operators reach it; nothing
// listens on the network. One request per connection: a line with a command word (control_protocol.hpp),
// answered with one or more lines and the connection closed. The server thread is normal priority
// (SCHED_OTHER); it hands commands to the loop through the OperatorLink's atomics, never by calling into
// the loop.
//
// One thread serves every client through poll(2), each with a deadline and bounded buffers: a client that
// trickles its request, or never reads a long reply, is dropped at its deadline and never holds the
// others (nor the service's shutdown). A request is carried out only while its client still waits for the
// answer: one whose client hung up (e.g. `ctl` gave up) is dropped unexecuted.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>
#include <thread>

namespace loom::firmware::serve {

// Who is at the other end of a connection, from the kernel (SO_PEERCRED): never from what the client says.
struct Peer {
  pid_t pid = -1;
  uid_t uid = static_cast<uid_t>(-1);
  gid_t gid = static_cast<gid_t>(-1);
  std::string user;  // the uid's login name, or "uid N" when it has none
};
// "local user anna (uid 1000, pid 4242)".
std::string describe(const Peer& p);

struct ControlRequest {
  std::string line;  // the request line, trimmed
  Peer peer;
};

// Non-RT. Called on the server thread; returns the reply (ends with \n). Must not block.
using RequestHandler = std::function<std::string(const ControlRequest& request)>;

struct ControlLimits {
  int request_deadline_ms = 2000;  // from accept to the request's newline (or EOF)
  int reply_deadline_ms = 5000;    // to write the whole reply, once the request is complete
  std::size_t max_clients = 16;    // connections served at once; more wait in the listen backlog
  std::size_t max_request_bytes = 1024;
  std::size_t max_reply_bytes = 2u << 20;  // longer replies are cut, with a last line saying so
};

class ControlServer {
 public:
  // Configure-time. Binds and listens at `path` (creating its folder, mode 0750, when missing).
  // A stale socket left by a killed server is replaced; a live one (another serve answering) is an
  // error, and so is anything at `path` that is not a socket (never deleted). Throws std::runtime_error
  // naming the path and the reason.
  ControlServer(std::string path, std::string group, RequestHandler handler, ControlLimits limits = {});
  ~ControlServer();  // stops the thread (within ~100 ms, whatever the clients do), removes the socket file
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;

  const std::string& path() const { return path_; }
  // "" when the socket's group was set, else why not (e.g. the group does not exist).
  const std::string& group_note() const { return group_note_; }
  // Clients dropped at a deadline or over a limit, and requests dropped unexecuted (client gone).
  std::uint64_t clients_dropped() const { return dropped_.load(std::memory_order_relaxed); }
  // When the server's thread last went round its loop (std::chrono::steady_clock, ns): at least every
  // 100 ms while it is well. A handler that hangs (a stuck disk under the audit) stops it: the service's
  // watchdog stops pinging (sd_notify.hpp).
  std::int64_t alive_ns() const { return alive_ns_.load(std::memory_order_relaxed); }

 private:
  void serve();
  std::string path_;
  std::string group_note_;
  RequestHandler handler_;
  ControlLimits limits_;
  int fd_ = -1;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::int64_t> alive_ns_{0};
  std::thread thread_;
};

// Client side (`loomctl ctl`): sends `request` and returns the whole reply. Throws std::runtime_error
// ("cannot connect to PATH: ...") when no server answers within `timeout_ms`; the connection is then
// closed, so a request not yet taken up by the server is never carried out.
std::string control_request(const std::string& path, const std::string& request, int timeout_ms = 5000);

}  // namespace loom::firmware::serve

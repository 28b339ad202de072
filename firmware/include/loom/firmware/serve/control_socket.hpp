// The operator's local control channel: a UNIX stream socket (default /run/loomctl/<loom-id>.sock),
// mode 0660 and group `loom` when that group exists, so only the loom's operators reach it; nothing
// listens on the network. One request per connection: a line with a command word, answered with one or
// more lines and the connection closed. The server thread is normal priority (SCHED_OTHER); it hands
// commands to the loop through the OperatorLink's atomics, never by calling into the loop.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <thread>

namespace loom::firmware::serve {

// Non-RT. Called on the server thread with the request line (trimmed); returns the reply (ends with \n).
using RequestHandler = std::function<std::string(const std::string& request)>;

class ControlServer {
 public:
  // Configure-time. Binds and listens at `path` (creating its folder, mode 0750, when missing).
  // A stale socket left by a killed server is replaced; a live one (another serve answering) is an
  // error. Throws std::runtime_error naming the path and the reason.
  ControlServer(std::string path, std::string group, RequestHandler handler);
  ~ControlServer();  // stops the thread, removes the socket file
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;

  const std::string& path() const { return path_; }
  // "" when the socket's group was set, else why not (e.g. the group does not exist).
  const std::string& group_note() const { return group_note_; }

 private:
  void serve();
  std::string path_;
  std::string group_note_;
  RequestHandler handler_;
  int fd_ = -1;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// Client side (`loomctl ctl`): sends `request` and returns the whole reply. Throws std::runtime_error
// ("cannot connect to PATH: ...") when no server answers within `timeout_ms`.
std::string control_request(const std::string& path, const std::string& request, int timeout_ms = 5000);

}  // namespace loom::firmware::serve

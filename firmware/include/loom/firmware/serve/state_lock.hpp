// One serve per state directory. Two serves sharing counters.json and sim-state.bin would weave the
// same rows twice and publish invented state changes, so serve takes an exclusive lock on
// STATE_DIR/serve.lock (flock, released by the kernel when the process dies — a power cut or kill -9
// leaves no stale lock) and writes who holds it there, so the second one can say whom it collides with.
#pragma once

#include <string>

namespace loom::firmware::serve {

class StateDirLock {
 public:
  // Throws std::runtime_error naming the directory and, when another serve holds it, that serve's
  // pid, loom id and control socket.
  StateDirLock(const std::string& state_dir, const std::string& loom_id, const std::string& socket_path);
  ~StateDirLock();
  StateDirLock(const StateDirLock&) = delete;
  StateDirLock& operator=(const StateDirLock&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
};

}  // namespace loom::firmware::serve

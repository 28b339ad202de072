#include "loom/firmware/serve/state_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace loom::firmware::serve {

StateDirLock::StateDirLock(const std::string& state_dir, const std::string& loom_id,
                           const std::string& socket_path)
    : path_(state_dir + "/serve.lock") {
  fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd_ < 0)
    throw std::runtime_error("cannot open the state directory's lock " + path_ + ": " + std::strerror(errno));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    char holder[256] = "";
    const ssize_t n = ::pread(fd_, holder, sizeof holder - 1, 0);
    std::string who = n > 0 ? std::string(holder, static_cast<std::size_t>(n)) : "";
    while (!who.empty() && (who.back() == '\n' || who.back() == ' ')) who.pop_back();
    ::close(fd_);
    fd_ = -1;
    if (err == EWOULDBLOCK) {
      throw std::runtime_error("state directory " + state_dir +
                               " is in use by another loomctl serve or weave (" +
                               (who.empty() ? "holder unknown" : who) + ", lock " + path_ +
                               "): two on one state directory would share its counters and machine "
                               "state; give each loom its own --state-dir and loom id");
    }
    throw std::runtime_error("cannot lock " + path_ + ": " + std::strerror(err));
  }
  const std::string me =
      "pid=" + std::to_string(::getpid()) + " loom=" + loom_id + " socket=" + socket_path + "\n";
  // Who holds it is information for the next one only: a failed write does not stop this serve.
  if (::ftruncate(fd_, 0) == 0) {
    [[maybe_unused]] const ssize_t w = ::pwrite(fd_, me.data(), me.size(), 0);
  }
}

StateDirLock::~StateDirLock() {
  if (fd_ >= 0) ::close(fd_);  // closing releases the flock; the file stays (removing it would race)
}

}  // namespace loom::firmware::serve

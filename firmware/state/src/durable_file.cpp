#include "loom/state/durable_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace loom::state {
namespace {

[[noreturn]] void sys_fail(const std::string& what, const std::string& path) {
  const int err = errno;
  throw DurableWriteError(what + " " + path + ": " + std::strerror(err), err);
}

}  // namespace

void write_file_durably(const std::string& path, const std::string& body) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) sys_fail("cannot create", tmp);
  const ssize_t n = ::write(fd, body.data(), body.size());
  if (n != static_cast<ssize_t>(body.size()) || ::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    errno = n >= 0 && n != static_cast<ssize_t>(body.size()) ? ENOSPC : err;
    sys_fail("cannot write", tmp);
  }
  if (::close(fd) != 0) sys_fail("cannot close", tmp);
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    errno = err;
    sys_fail("cannot rename onto", path);
  }
  // Make the rename itself durable: a failed directory sync is a failed save.
  const std::string dir = path.find('/') == std::string::npos ? "." : path.substr(0, path.rfind('/'));
  const int dfd = ::open(dir.empty() ? "/" : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) sys_fail("cannot open directory of", path);
  const int rc = ::fsync(dfd);
  ::close(dfd);
  if (rc != 0 && errno != EINVAL) sys_fail("cannot sync directory of", path);
}

void DiskReserve::ensure() const {
  struct stat st {};
  if (::stat(path_.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
      static_cast<std::size_t>(st.st_blocks) * 512 >= bytes_) {
    return;  // there whole, its blocks allocated
  }
  // Allocated, not a sparse hole (a hole frees nothing when deleted), then made durable like any state file.
  const std::string tmp = path_ + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) sys_fail("cannot create the disk reserve", tmp);
  const int rc = ::posix_fallocate(fd, 0, static_cast<off_t>(bytes_));
  if (rc != 0 || ::fsync(fd) != 0) {
    const int err = rc != 0 ? rc : errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    errno = err;
    sys_fail("cannot keep " + std::to_string(bytes_ / 1024) + " KiB in reserve for the fault record at",
             path_);
  }
  ::close(fd);
  if (::rename(tmp.c_str(), path_.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    errno = err;
    sys_fail("cannot rename onto", path_);
  }
}

bool DiskReserve::release() const noexcept {
  if (::unlink(path_.c_str()) != 0) return false;
  const std::string dir = path_.find('/') == std::string::npos ? "." : path_.substr(0, path_.rfind('/'));
  const int dfd = ::open(dir.empty() ? "/" : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
  return true;
}

void write_file_durably(const std::string& path, const std::string& body, const DiskReserve& reserve) {
  try {
    write_file_durably(path, body);
  } catch (const DurableWriteError& e) {
    if (e.error != ENOSPC && e.error != EDQUOT) throw;
    if (!reserve.release()) throw;
    write_file_durably(path, body);
  }
}

StateFileRead read_state_file(const std::string& path, std::size_t max_bytes) {
  using O = StateFileRead::Outcome;
  StateFileRead r;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);  // a FIFO must not block the reader
  if (fd < 0) {
    r.outcome = errno == ENOENT ? O::kAbsent : O::kCannotOpen;
    r.error = std::strerror(errno);
    return r;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || static_cast<std::size_t>(st.st_size) > max_bytes) {
    ::close(fd);
    r.outcome = O::kNotRegular;
    return r;
  }
  r.text.assign(static_cast<std::size_t>(st.st_size), '\0');
  std::size_t got = 0;
  while (got < r.text.size()) {
    const ssize_t n = ::read(fd, r.text.data() + got, r.text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      r.error = n < 0 ? std::strerror(errno) : "it shrank";
      ::close(fd);
      r.outcome = O::kCannotRead;
      r.text.clear();
      return r;
    }
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  r.outcome = O::kRead;
  return r;
}

}  // namespace loom::state

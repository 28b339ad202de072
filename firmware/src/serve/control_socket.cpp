// UNIX-socket control channel: poll-driven accept loop on a normal-priority thread.
#include "loom/firmware/serve/control_socket.hpp"

#include <fcntl.h>
#include <grp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace loom::firmware::serve {
namespace {

sockaddr_un make_addr(const std::string& path) {
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  if (path.size() >= sizeof a.sun_path) {
    throw std::runtime_error("control socket path too long (" + std::to_string(path.size()) + " > " +
                             std::to_string(sizeof a.sun_path - 1) + " bytes): " + path);
  }
  std::memcpy(a.sun_path, path.c_str(), path.size() + 1);
  return a;
}

// Reads until newline, EOF or timeout; at most 4 KiB (requests are one short line).
std::string read_line(int fd, int timeout_ms) {
  std::string s;
  char buf[256];
  while (s.size() < 4096 && s.find('\n') == std::string::npos) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) <= 0) break;
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) break;
    s.append(buf, static_cast<std::size_t>(n));
  }
  return s;
}

void write_all(int fd, const std::string& s) {
  std::size_t off = 0;
  while (off < s.size()) {
    const ssize_t n = ::send(fd, s.data() + off, s.size() - off, MSG_NOSIGNAL);
    if (n <= 0) return;
    off += static_cast<std::size_t>(n);
  }
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  std::size_t i = 0;
  while (i < s.size() && s[i] == ' ') ++i;
  return s.substr(i);
}

}  // namespace

ControlServer::ControlServer(std::string path, std::string group_name, RequestHandler handler)
    : path_(std::move(path)), handler_(std::move(handler)) {
  const sockaddr_un addr = make_addr(path_);
  const std::filesystem::path dir = std::filesystem::path(path_).parent_path();
  if (!dir.empty() && !std::filesystem::exists(dir)) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw std::runtime_error("cannot create " + dir.string() + ": " + ec.message());
    ::chmod(dir.c_str(), 0750);
  }
  // A socket file already there: live server → refuse; stale (connect refused) → replace.
  if (std::filesystem::exists(std::filesystem::symlink_status(path_))) {
    const int probe = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const bool live = probe >= 0 && ::connect(probe, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
    if (probe >= 0) ::close(probe);
    if (live) throw std::runtime_error("control socket " + path_ + " is in use: another loomctl serve is running");
    ::unlink(path_.c_str());
  }
  fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error(std::string("cannot create a UNIX socket: ") + std::strerror(errno));
  // Created with no access for others from the first instant; opened up to the group just below.
  const mode_t old = ::umask(0117);
  const int rc = ::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr);
  const int err = errno;
  ::umask(old);
  if (rc != 0 || ::listen(fd_, 8) != 0) {
    ::close(fd_);
    throw std::runtime_error("cannot listen on " + path_ + ": " + std::strerror(rc != 0 ? err : errno));
  }
  ::chmod(path_.c_str(), 0660);
  if (!group_name.empty()) {
    if (const struct group* g = ::getgrnam(group_name.c_str())) {
      if (::chown(path_.c_str(), static_cast<uid_t>(-1), g->gr_gid) != 0) {
        group_note_ = "cannot give " + path_ + " to group '" + group_name + "': " + std::strerror(errno);
      }
    } else {
      group_note_ = "group '" + group_name + "' does not exist; " + path_ + " stays with the service's own group";
    }
  }
  thread_ = std::thread([this] { serve(); });
}

ControlServer::~ControlServer() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
  if (fd_ >= 0) ::close(fd_);
  ::unlink(path_.c_str());
}

void ControlServer::serve() {
  pthread_setname_np(pthread_self(), "loom-ctl");
  while (!stop_.load()) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    const int c = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (c < 0) continue;
    const std::string req = trim(read_line(c, 1000));
    std::string reply;
    try {
      reply = handler_(req);
    } catch (const std::exception& e) {
      reply = std::string("error: ") + e.what() + "\n";
    }
    write_all(c, reply);
    ::close(c);
  }
}

std::string control_request(const std::string& path, const std::string& request, int timeout_ms) {
  const sockaddr_un addr = make_addr(path);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw std::runtime_error(std::string("cannot create a UNIX socket: ") + std::strerror(errno));
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const int err = errno;
    ::close(fd);
    throw std::runtime_error("cannot connect to " + path + ": " + std::strerror(err) +
                             (err == ENOENT ? " (is loomctl serve running for this loom id?)" : ""));
  }
  write_all(fd, request + "\n");
  ::shutdown(fd, SHUT_WR);
  std::string reply;
  char buf[4096];
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) <= 0) {
      ::close(fd);
      throw std::runtime_error("no reply from " + path + " within " + std::to_string(timeout_ms) + " ms");
    }
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) break;
    reply.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return reply;
}

}  // namespace loom::firmware::serve

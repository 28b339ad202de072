// UNIX-socket control channel: one poll(2)-driven thread multiplexing every client, each with deadlines
// and bounded buffers.
#include "loom/firmware/serve/control_socket.hpp"

#include <fcntl.h>
#include <grp.h>
#include <poll.h>
#include <pwd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace loom::firmware::serve {
namespace {

using Clock = std::chrono::steady_clock;

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

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  std::size_t i = 0;
  while (i < s.size() && s[i] == ' ') ++i;
  return s.substr(i);
}

Peer peer_of(int fd) {
  Peer p;
  ucred cred{};
  socklen_t len = sizeof cred;
  if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cred, &len) != 0) return p;
  p.pid = cred.pid;
  p.uid = cred.uid;
  p.gid = cred.gid;
  passwd pw{};
  passwd* found = nullptr;
  char buf[1024];
  if (::getpwuid_r(cred.uid, &pw, buf, sizeof buf, &found) == 0 && found != nullptr)
    p.user = found->pw_name;
  else
    p.user = "uid " + std::to_string(cred.uid);
  return p;
}

// One connection: reading its request, then writing its reply.
struct Client {
  int fd = -1;
  Peer peer;
  std::string in, out;
  std::size_t written = 0;
  bool replying = false;
  Clock::time_point deadline;
};

}  // namespace

std::string describe(const Peer& p) {
  if (p.pid < 0) return "local user (unknown: no SO_PEERCRED)";
  return "local user " + p.user + " (uid " + std::to_string(p.uid) + ", pid " + std::to_string(p.pid) + ")";
}

ControlServer::ControlServer(std::string path, std::string group_name, RequestHandler handler,
                             ControlLimits limits)
    : path_(std::move(path)), handler_(std::move(handler)), limits_(limits) {
  const sockaddr_un addr = make_addr(path_);
  const std::filesystem::path dir = std::filesystem::path(path_).parent_path();
  if (!dir.empty() && !std::filesystem::exists(dir)) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw std::runtime_error("cannot create " + dir.string() + ": " + ec.message());
    ::chmod(dir.c_str(), 0750);
  }
  // Something already at the path: a live server → refuse; a stale socket (connect refused) → replace;
  // anything that is not a socket (a file, a link, a folder) is never deleted.
  struct stat st {};
  if (::lstat(path_.c_str(), &st) == 0) {
    if (!S_ISSOCK(st.st_mode)) {
      throw std::runtime_error("control socket path " + path_ +
                               " exists and is not a socket: refusing to replace it");
    }
    const int probe = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const bool live =
        probe >= 0 && ::connect(probe, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
    if (probe >= 0) ::close(probe);
    if (live)
      throw std::runtime_error("control socket " + path_ + " is in use: another loomctl serve is running");
    ::unlink(path_.c_str());
  }
  fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd_ < 0) throw std::runtime_error(std::string("cannot create a UNIX socket: ") + std::strerror(errno));
  // Created with no access for others from the first instant; opened up to the group just below.
  const mode_t old = ::umask(0117);
  const int rc = ::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr);
  const int err = errno;
  ::umask(old);
  if (rc != 0 || ::listen(fd_, 16) != 0) {
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
      group_note_ =
          "group '" + group_name + "' does not exist; " + path_ + " stays with the service's own group";
    }
  }
  alive_ns_.store(
      std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count());
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
  std::vector<Client> clients;
  std::vector<pollfd> fds;
  const auto drop = [&](std::size_t i, bool counted) {
    ::close(clients[i].fd);
    clients.erase(clients.begin() + static_cast<std::ptrdiff_t>(i));
    if (counted) dropped_.fetch_add(1, std::memory_order_relaxed);
  };
  const auto answer = [&](Client& c) {
    const std::string req = trim(c.in);
    // Carried out only while the client still waits for the answer (a client that gave up hung up).
    pollfd p{c.fd, 0, 0};
    if (::poll(&p, 1, 0) > 0 && (p.revents & (POLLHUP | POLLERR)) != 0) return false;
    try {
      c.out = handler_(ControlRequest{req, c.peer});
    } catch (const std::exception& e) {
      c.out = std::string("error: ") + e.what() + "\n";
    }
    if (c.out.size() > limits_.max_reply_bytes) {
      c.out.resize(limits_.max_reply_bytes);
      c.out += "\nerror: reply cut at " + std::to_string(limits_.max_reply_bytes) + " bytes\n";
    }
    c.replying = true;
    c.deadline = Clock::now() + std::chrono::milliseconds(limits_.reply_deadline_ms);
    return true;
  };
  while (!stop_.load()) {
    alive_ns_.store(
        std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count(),
        std::memory_order_relaxed);
    fds.clear();
    fds.push_back({clients.size() < limits_.max_clients ? fd_ : -1, POLLIN, 0});
    Clock::time_point next =
        Clock::now() + std::chrono::milliseconds(100);  // notice stop_ at least this often
    for (const Client& c : clients) {
      fds.push_back({c.fd, static_cast<short>(c.replying ? POLLOUT : POLLIN), 0});
      if (c.deadline < next) next = c.deadline;
    }
    const auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(next - Clock::now()).count();
    const int n = ::poll(fds.data(), fds.size(), static_cast<int>(std::max<long long>(0, wait) + 1));
    if (n < 0 && errno != EINTR) break;
    const Clock::time_point now = Clock::now();
    // Existing clients first (indices shift as they are dropped: walk backwards).
    for (std::size_t k = clients.size(); k-- > 0;) {
      Client& c = clients[k];
      const short rev = fds[k + 1].revents;
      if (!c.replying && (rev & (POLLIN | POLLHUP | POLLERR)) != 0) {
        char buf[512];
        const ssize_t r = ::read(c.fd, buf, sizeof buf);
        if (r < 0 && (errno == EAGAIN || errno == EINTR)) continue;
        if (r > 0) c.in.append(buf, static_cast<std::size_t>(r));
        const bool line = c.in.find('\n') != std::string::npos;
        if (c.in.size() > limits_.max_request_bytes && !line) {
          c.out = "error: request longer than " + std::to_string(limits_.max_request_bytes) + " bytes\n";
          c.replying = true;
          c.deadline = now + std::chrono::milliseconds(limits_.reply_deadline_ms);
          continue;
        }
        if (line || (r == 0 && !c.in.empty())) {
          if (line) c.in.resize(c.in.find('\n'));
          if (!answer(c)) drop(k, true);
        } else if (r <= 0) {
          drop(k, false);  // closed without a request
        }
        continue;
      }
      if (c.replying && (rev & (POLLOUT | POLLHUP | POLLERR)) != 0) {
        const ssize_t w =
            ::send(c.fd, c.out.data() + c.written, c.out.size() - c.written, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (w < 0 && (errno == EAGAIN || errno == EINTR)) continue;
        if (w <= 0) {
          drop(k, true);
          continue;
        }
        c.written += static_cast<std::size_t>(w);
        if (c.written == c.out.size()) drop(k, false);
        continue;
      }
      if (now >= c.deadline) drop(k, true);  // trickled its request, or does not read its reply
    }
    if ((fds[0].revents & POLLIN) != 0) {
      const int c = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
      if (c >= 0) {
        Client cl;
        cl.fd = c;
        cl.peer = peer_of(c);
        cl.deadline = now + std::chrono::milliseconds(limits_.request_deadline_ms);
        clients.push_back(std::move(cl));
      }
    }
  }
  for (const Client& c : clients) ::close(c.fd);
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
  const std::string line = request + "\n";
  std::size_t off = 0;
  while (off < line.size()) {
    const ssize_t n = ::send(fd, line.data() + off, line.size() - off, MSG_NOSIGNAL);
    if (n <= 0) break;
    off += static_cast<std::size_t>(n);
  }
  ::shutdown(fd, SHUT_WR);
  std::string reply;
  char buf[4096];
  const Clock::time_point deadline = Clock::now() + std::chrono::milliseconds(timeout_ms);
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    pollfd p{fd, POLLIN, 0};
    if (left <= 0 || ::poll(&p, 1, static_cast<int>(left)) <= 0) {
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

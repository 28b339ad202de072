// LCM udpm receiving for the panel (see udpm_receiver.hpp).
#include "udpm_receiver.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace loom::panel {
namespace {
constexpr std::uint32_t kMagicShort = 0x4c433032;  // "LC02"
constexpr std::size_t kBatch = 64;
constexpr std::size_t kMaxDatagram = 65536;
}  // namespace

std::optional<UdpmAddress> parse_udpm_url(const std::string& url_in) {
  std::string url = url_in;
  if (url.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    url = env != nullptr && *env != '\0' ? env : "udpm://239.255.76.67:7667";
  }
  constexpr std::string_view kScheme = "udpm://";
  if (url.rfind(kScheme, 0) != 0) return std::nullopt;
  std::string rest = url.substr(kScheme.size());
  rest = rest.substr(0, rest.find('?'));
  UdpmAddress a;
  const auto colon = rest.find(':');
  a.group = rest.substr(0, colon);
  if (a.group.empty()) a.group = "239.255.76.67";
  unsigned long port = 7667;
  if (colon != std::string::npos) {
    const std::string p = rest.substr(colon + 1);
    char* end = nullptr;
    port = std::strtoul(p.c_str(), &end, 10);
    if (p.empty() || *end != '\0' || port == 0 || port > 65535) return std::nullopt;
  }
  a.port = static_cast<std::uint16_t>(port);
  in_addr probe{};
  if (inet_pton(AF_INET, a.group.c_str(), &probe) != 1 || !IN_MULTICAST(ntohl(probe.s_addr)))
    return std::nullopt;
  return a;
}

std::optional<LcmPacket> parse_lcm_packet(const std::uint8_t* buf, std::size_t len) {
  if (len < 9) return std::nullopt;
  std::uint32_t magic = 0;
  std::memcpy(&magic, buf, 4);
  if (ntohl(magic) != kMagicShort) return std::nullopt;
  const auto* chan = reinterpret_cast<const char*>(buf + 8);
  const void* nul = std::memchr(chan, '\0', len - 8);
  if (nul == nullptr) return std::nullopt;
  const std::size_t chan_len = static_cast<std::size_t>(static_cast<const char*>(nul) - chan);
  LcmPacket p;
  p.channel = std::string_view(chan, chan_len);
  p.data = buf + 8 + chan_len + 1;
  p.size = len - 8 - chan_len - 1;
  return p;
}

UdpmReceiver::UdpmReceiver(const UdpmAddress& addr) {
  const std::string where = addr.group + ":" + std::to_string(addr.port);
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error("socket for " + where + ": " + std::strerror(errno));
  const int one = 1;
  // Several listeners on one host (loom-panel, lcm-logger, loom-monitor) share the port, as LCM does.
  ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
#ifdef SO_REUSEPORT
  ::setsockopt(fd_, SOL_SOCKET, SO_REUSEPORT, &one, sizeof one);
#endif
  const int rcvbuf = 2 * 1024 * 1024;
  ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(addr.port);
  sa.sin_addr.s_addr = htonl(INADDR_ANY);
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) {
    const std::string e = std::strerror(errno);
    ::close(fd_);
    throw std::runtime_error("bind " + where + ": " + e);
  }
  ip_mreq mreq{};
  inet_pton(AF_INET, addr.group.c_str(), &mreq.imr_multiaddr);
  mreq.imr_interface.s_addr = htonl(INADDR_ANY);
  if (::setsockopt(fd_, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) != 0) {
    const std::string e = std::strerror(errno);
    ::close(fd_);
    throw std::runtime_error("join multicast group " + where + ": " + e +
                             " (a multicast route is needed: ip route add 224.0.0.0/4 dev lo)");
  }
}

UdpmReceiver::~UdpmReceiver() {
  if (fd_ >= 0) ::close(fd_);
}

int UdpmReceiver::poll(int timeout_ms, const std::function<void(const LcmPacket&)>& on_message) {
  pollfd pfd{fd_, POLLIN, 0};
  const int r = ::poll(&pfd, 1, timeout_ms);
  if (r < 0) return errno == EINTR ? 0 : -1;
  if (r == 0) return 0;
  static thread_local std::vector<std::uint8_t> bufs(kBatch * kMaxDatagram);
  std::array<mmsghdr, kBatch> msgs{};
  std::array<iovec, kBatch> iov{};
  for (std::size_t i = 0; i < kBatch; ++i) {
    iov[i] = {bufs.data() + i * kMaxDatagram, kMaxDatagram};
    msgs[i].msg_hdr.msg_iov = &iov[i];
    msgs[i].msg_hdr.msg_iovlen = 1;
  }
  int handled = 0;
  for (;;) {
    const int n = ::recvmmsg(fd_, msgs.data(), kBatch, MSG_DONTWAIT, nullptr);
    if (n < 0) return (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) ? handled : -1;
    for (int i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const auto p = parse_lcm_packet(bufs.data() + k * kMaxDatagram, msgs[k].msg_len);
      if (!p) {
        ++skipped_;
        continue;
      }
      on_message(*p);
      ++handled;
    }
    if (static_cast<std::size_t>(n) < kBatch) return handled;
  }
}

}  // namespace loom::panel

// SocketCAN raw socket: opening with diagnoses a user can act on, and the non-blocking send/receive
// used every tick. Error frames are requested from the kernel so bus-off is seen, not guessed.
#include "loom/drivers/socket_can_bus.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace loom::drivers {
namespace {

// How many 29-bit frames one receive() call may skip before reporting "nothing for us"; keeps the call
// bounded when a foreign device floods the bus.
constexpr int kMaxSkippedPerReceive = 16;

std::string errno_text(int err) {
  return std::string(std::strerror(err));
}

std::string open_error(const std::string& iface, const std::string& what) {
  return "cannot open CAN interface '" + iface + "': " + what;
}

}  // namespace

Result<std::unique_ptr<SocketCanBus>> SocketCanBus::open(const std::string& iface) {
  if (iface.empty()) return Status::error("cannot open CAN interface: the interface name is empty");
  if (iface.size() >= IFNAMSIZ) {
    return Status::error(
        open_error(iface, "name longer than " + std::to_string(IFNAMSIZ - 1) + " characters"));
  }

  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    const int err = errno;
    if (err == EAFNOSUPPORT) {
      return Status::error(open_error(
          iface, "this kernel has no CAN support (socket(PF_CAN) failed: " + errno_text(err) +
                     "); load the can and can-raw modules (modprobe can can-raw), or run the HIL "
                     "tests in a qemu VM that has CAN: tools/vcan/hil-run, see tools/vcan/README.md"));
    }
    if (err == EPROTONOSUPPORT) {
      return Status::error(open_error(
          iface, "the kernel has CAN but no raw CAN protocol (load the can-raw module): " + errno_text(err)));
    }
    return Status::error(open_error(iface, "socket(PF_CAN, SOCK_RAW) failed: " + errno_text(err)));
  }
  std::unique_ptr<SocketCanBus> bus(new SocketCanBus(fd, iface));

  const unsigned ifindex = ::if_nametoindex(iface.c_str());
  if (ifindex == 0) {
    return Status::error(open_error(iface, "no network interface of that name (" + errno_text(errno) +
                                               "); create it, e.g. ip link add dev " + iface +
                                               " type vcan && ip link set up " + iface));
  }

  ifreq ifr{};
  std::memcpy(ifr.ifr_name, iface.c_str(), iface.size() + 1);
  if (::ioctl(fd, SIOCGIFFLAGS, &ifr) == 0 && (ifr.ifr_flags & IFF_UP) == 0) {
    return Status::error(open_error(iface, "the interface is down (ip link set up " + iface + ")"));
  }

  // Every error class: bus-off must latch a fault, the rest is counted.
  const can_err_mask_t err_mask = CAN_ERR_MASK;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof(err_mask)) != 0) {
    return Status::error(
        open_error(iface, "enabling error frames (CAN_RAW_ERR_FILTER) failed: " + errno_text(errno)));
  }

  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(ifindex);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) {
    const int err = errno;
    if (err == ENODEV) {
      return Status::error(open_error(iface, "the interface exists but is not a CAN interface"));
    }
    return Status::error(open_error(iface, "bind failed: " + errno_text(err)));
  }
  return bus;
}

SocketCanBus::~SocketCanBus() {
  if (fd_ >= 0) ::close(fd_);
}

SendResult SocketCanBus::send(const CanFrame& frame) noexcept {
  if (frame.is_error() || frame.dlc > CAN_MAX_DLEN || frame.id > kMaxStandardId) {
    ++tx_errors_;
    return SendResult::kError;
  }
  can_frame cf{};
  cf.can_id = frame.id | (frame.is_rtr() ? CAN_RTR_FLAG : 0U);
  cf.len = frame.dlc;
  std::memcpy(cf.data, frame.data.data(), frame.dlc);
  const ssize_t n = ::send(fd_, &cf, sizeof(cf), MSG_DONTWAIT);
  if (n == static_cast<ssize_t>(sizeof(cf))) return SendResult::kOk;
  if (n < 0 && (errno == ENOBUFS || errno == EAGAIN || errno == EWOULDBLOCK)) {
    ++tx_would_block_;
    return SendResult::kWouldBlock;
  }
  ++tx_errors_;
  return SendResult::kError;
}

bool SocketCanBus::receive(CanFrame& frame) noexcept {
  for (int skipped = 0; skipped <= kMaxSkippedPerReceive; ++skipped) {
    can_frame cf{};
    const ssize_t n = ::recv(fd_, &cf, sizeof(cf), MSG_DONTWAIT);
    if (n < 0) {
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) ++rx_errors_;
      return false;
    }
    if (n != static_cast<ssize_t>(sizeof(cf)) || cf.len > CAN_MAX_DLEN) {
      ++rx_errors_;
      return false;
    }
    if ((cf.can_id & CAN_ERR_FLAG) != 0) {
      frame = CanFrame{};
      frame.flags = CanFrame::kError;
      frame.id = cf.can_id & CAN_ERR_MASK;
      frame.dlc = cf.len;
      std::memcpy(frame.data.data(), cf.data, cf.len);
      return true;
    }
    if ((cf.can_id & CAN_EFF_FLAG) != 0) {
      ++rx_skipped_;
      continue;
    }
    frame = CanFrame{};
    frame.id = cf.can_id & CAN_SFF_MASK;
    frame.flags = (cf.can_id & CAN_RTR_FLAG) != 0 ? CanFrame::kRtr : std::uint8_t{0};
    frame.dlc = cf.len;
    std::memcpy(frame.data.data(), cf.data, cf.len);
    return true;
  }
  return false;
}

}  // namespace loom::drivers

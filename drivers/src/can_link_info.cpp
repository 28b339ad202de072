// rtnetlink query of a CAN interface's kind and bitrate (see can_link_info.hpp).
#include "loom/drivers/can_link_info.hpp"

#include <linux/can/netlink.h>
#include <linux/if_link.h>
#include <linux/netlink.h>
#include <linux/rtnetlink.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

namespace loom::drivers {

namespace {

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// Walk the attributes in [data, data + len).
template <class F>
void for_each_attr(const unsigned char* data, std::size_t len, F&& f) {
  while (len >= sizeof(rtattr)) {
    rtattr a{};
    std::memcpy(&a, data, sizeof(a));
    if (a.rta_len < sizeof(rtattr) || a.rta_len > len) return;
    f(a.rta_type & 0x3FFF, data + RTA_LENGTH(0), a.rta_len - RTA_LENGTH(0));
    const std::size_t step = RTA_ALIGN(a.rta_len);
    if (step >= len) return;
    data += step;
    len -= step;
  }
}

}  // namespace

Result<CanLinkInfo> read_can_link_info(const std::string& iface) {
  const unsigned index = ::if_nametoindex(iface.c_str());
  if (index == 0) return Status::error("CAN interface '" + iface + "' does not exist");
  Fd s;
  s.fd = ::socket(AF_NETLINK, SOCK_RAW | SOCK_CLOEXEC, NETLINK_ROUTE);
  if (s.fd < 0) return Status::error("netlink socket: " + std::string(std::strerror(errno)));

  struct {
    nlmsghdr h;
    ifinfomsg i;
  } req{};
  req.h.nlmsg_len = sizeof(req);
  req.h.nlmsg_type = RTM_GETLINK;
  req.h.nlmsg_flags = NLM_F_REQUEST;
  req.h.nlmsg_seq = 1;
  req.i.ifi_family = AF_UNSPEC;
  req.i.ifi_index = static_cast<int>(index);
  if (::send(s.fd, &req, sizeof(req), 0) < 0) {
    return Status::error("netlink RTM_GETLINK for '" + iface + "': " + std::strerror(errno));
  }
  std::array<unsigned char, 16384> buf{};
  const ssize_t n = ::recv(s.fd, buf.data(), buf.size(), 0);
  if (n < static_cast<ssize_t>(sizeof(nlmsghdr))) {
    return Status::error("netlink RTM_GETLINK for '" + iface + "': no answer");
  }
  nlmsghdr h{};
  std::memcpy(&h, buf.data(), sizeof(h));
  if (h.nlmsg_type == NLMSG_ERROR) {
    nlmsgerr e{};
    std::memcpy(&e, buf.data() + NLMSG_LENGTH(0), sizeof(e));
    return Status::error("netlink RTM_GETLINK for '" + iface + "': " + std::strerror(-e.error));
  }
  if (h.nlmsg_type != RTM_NEWLINK || h.nlmsg_len > static_cast<std::uint32_t>(n)) {
    return Status::error("netlink RTM_GETLINK for '" + iface + "': unexpected answer");
  }
  ifinfomsg info{};
  std::memcpy(&info, buf.data() + NLMSG_LENGTH(0), sizeof(info));
  CanLinkInfo out;
  out.up = (info.ifi_flags & IFF_UP) != 0;
  const std::size_t head = NLMSG_LENGTH(sizeof(ifinfomsg));
  for_each_attr(buf.data() + head, h.nlmsg_len - head,
                [&](unsigned type, const unsigned char* d, std::size_t len) {
                  if (type != IFLA_LINKINFO) return;
                  for_each_attr(d, len, [&](unsigned t2, const unsigned char* d2, std::size_t len2) {
                    if (t2 == IFLA_INFO_KIND) {
                      out.kind.assign(reinterpret_cast<const char*>(d2),
                                      strnlen(reinterpret_cast<const char*>(d2), len2));
                    } else if (t2 == IFLA_INFO_DATA) {
                      for_each_attr(d2, len2, [&](unsigned t3, const unsigned char* d3, std::size_t len3) {
                        if (t3 == IFLA_CAN_BITTIMING && len3 >= sizeof(can_bittiming)) {
                          can_bittiming bt{};
                          std::memcpy(&bt, d3, sizeof(bt));
                          out.bitrate_bps = bt.bitrate;
                        }
                      });
                    }
                  });
                });
  return out;
}

Status check_can_bitrate(const std::string& iface, const CanLinkInfo& info, std::uint32_t bitrate_bps,
                         std::string& note) {
  note.clear();
  if (info.kind == "vcan" || info.kind == "vxcan") {
    note = iface + " is a virtual CAN link (" + info.kind +
           "): it has no bitrate; can.bitrate = " + std::to_string(bitrate_bps) +
           " is used for the bus-load arithmetic only";
    return Status::ok();
  }
  if (info.kind != "can") {
    return Status::error(iface + " is not a CAN interface (link kind '" + info.kind + "')");
  }
  if (info.bitrate_bps != bitrate_bps) {
    return Status::error(iface + " runs at " + std::to_string(info.bitrate_bps) +
                         " bit/s but can.bitrate = " + std::to_string(bitrate_bps) +
                         "; bring it up with: ip link set " + iface + " down && ip link set " + iface +
                         " type can bitrate " + std::to_string(bitrate_bps) + " && ip link set " + iface +
                         " up");
  }
  return Status::ok();
}

}  // namespace loom::drivers

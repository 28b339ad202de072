// What the kernel says about a CAN interface: its link kind ("can", "vcan", ...) and, for real CAN
// controllers, the configured bitrate (rtnetlink RTM_GETLINK → IFLA_LINKINFO → IFLA_INFO_DATA →
// IFLA_CAN_BITTIMING). The master compares it with the configured bitrate before it opens the bus, so
// a controller brought up at 500 kbit/s is refused rather than silently overloaded.
#pragma once

#include <cstdint>
#include <string>

#include "loom/drivers/status.hpp"

namespace loom::drivers {

struct CanLinkInfo {
  std::string kind;               // IFLA_INFO_KIND: "can", "vcan", "vxcan", "" when none
  std::uint32_t bitrate_bps = 0;  // 0 when the link has no bit timing (vcan) or is down/unset
  bool up = false;                // IFF_UP
};

// Configure-time only (netlink syscalls). Error naming the interface when it does not exist or the
// kernel does not answer.
Result<CanLinkInfo> read_can_link_info(const std::string& iface);

// Configure-time only. OK when `info` is a CAN link running at `bitrate_bps`, or a virtual CAN link
// (no bit timing: `note` says so). Else an error naming interface, both bitrates and the command to fix it.
Status check_can_bitrate(const std::string& iface, const CanLinkInfo& info, std::uint32_t bitrate_bps,
                         std::string& note);

}  // namespace loom::drivers

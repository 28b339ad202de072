// A lean receiver for LCM's UDP multicast transport, for a process that listens to a whole hall: one
// socket, datagrams read in batches (recvmmsg), the LCM packet header parsed here and each message
// handed over with its channel — no receive thread and no per-message wake-up pipe, which is where
// LCM 1.3.1's own receive path spends most of its time at 20 looms x 60 messages/s.
// Wire format (LCM's, "LC02" small messages): u32 magic 0x4c433032, u32 sequence number, channel
// NUL-terminated, then the encoded message. Fragmented messages ("LC03", over 64 KB) are counted and
// skipped: no loom message comes near that size.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace loom::panel {

struct UdpmAddress {
  std::string group;  // dotted IPv4 multicast group
  std::uint16_t port = 0;
};

// Configure-time. The group and port of a udpm:// URL ("" = $LCM_DEFAULT_URL, else LCM's default
// udpm://239.255.76.67:7667); nullopt for other providers (file://, memq://) or a malformed URL.
std::optional<UdpmAddress> parse_udpm_url(const std::string& url);

// One LCM packet's channel and payload, or nullopt if it is not a complete small LCM message.
struct LcmPacket {
  std::string_view channel;
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
};
std::optional<LcmPacket> parse_lcm_packet(const std::uint8_t* buf, std::size_t len);

class UdpmReceiver {
 public:
  // Opens, binds and joins the group; throws std::runtime_error naming the address on failure.
  explicit UdpmReceiver(const UdpmAddress& addr);
  ~UdpmReceiver();
  UdpmReceiver(const UdpmReceiver&) = delete;
  UdpmReceiver& operator=(const UdpmReceiver&) = delete;

  // Waits up to timeout_ms for datagrams, then hands every complete message to `on_message`.
  // Returns the number of messages handled, -1 on a socket error.
  int poll(int timeout_ms, const std::function<void(const LcmPacket&)>& on_message);
  std::uint64_t skipped() const { return skipped_; }  // fragmented or malformed datagrams

 private:
  int fd_ = -1;
  std::uint64_t skipped_ = 0;
};

}  // namespace loom::panel

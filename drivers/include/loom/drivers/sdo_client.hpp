// Configure-time SDO client: one expedited read or write at a time (one outstanding request per server,
// as CiA 301 requires), waiting for the reply with a timeout on the injected clock. Frames that are not
// the awaited reply are handed to a callback, so boot-ups, heartbeats and EMCYs seen meanwhile count.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "loom/drivers/can_frame.hpp"
#include "loom/drivers/configure_clock.hpp"
#include "loom/drivers/sdo.hpp"
#include "loom/drivers/status.hpp"

namespace loom::drivers {

class SdoClient {
 public:
  using FrameHandler = std::function<void(const CanFrame&)>;

  // Configure-time only. `other_frames` may be empty.
  SdoClient(CanBus& bus, ConfigureClock& clock, std::int64_t timeout_us, FrameHandler other_frames);

  // Configure-time only. Expedited download of `size` (1..4) bytes. Errors read like
  // "SDO write 0x60C2:01 (interpolation time period) = 0x02 aborted: 0x06020000 (object does not exist
  // in the object dictionary)" or "... no reply within 100 ms (sent abort 0x05040000)".
  Status write(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t value,
               std::uint8_t size);
  // Configure-time only. Expedited upload; the value is zero-extended from the reply's size.
  Result<std::uint32_t> read(std::uint8_t node, std::uint16_t index, std::uint8_t sub);
  // The abort code of the last request the server aborted (0 when it was answered or timed out), so
  // callers can apply CiA 301 interoperability rules to specific codes (read-only mapping, no object).
  std::uint32_t last_abort() const { return last_abort_; }

  // Configure-time only. While on, write() first reads the value and sends no download when it is
  // already `value` (a node configured from its EDS: only what differs is written); an object the node
  // lacks (the read aborted 0x06020000 / 0x06090011) fails with that abort code, unsent; a value that
  // cannot be read otherwise is written as before. skipped_writes() counts the downloads saved.
  void set_skip_unchanged(bool on) { skip_unchanged_ = on; }
  bool skips_unchanged() const { return skip_unchanged_; }
  int skipped_writes() const { return skipped_writes_; }
  // Downloads the node acknowledged so far (what it really took: skipped and aborted ones not counted).
  int downloads() const { return downloads_; }

 private:
  Result<SdoReply> exchange(std::uint8_t node, const CanFrame& request, const std::string& what);

  CanBus& bus_;
  ConfigureClock& clock_;
  std::int64_t timeout_us_;
  FrameHandler other_frames_;
  std::uint32_t last_abort_ = 0;
  bool skip_unchanged_ = false;
  int skipped_writes_ = 0;
  int downloads_ = 0;
};

// "0x60C2:01 (interpolation time period)". Configure-time only.
std::string describe_object(std::uint16_t index, std::uint8_t sub);

}  // namespace loom::drivers

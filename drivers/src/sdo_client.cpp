// Blocking-with-timeout SDO client for bring-up (never used by the RT loop).
#include "loom/drivers/sdo_client.hpp"

#include <cstdio>

#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/drivers/sdo.hpp"

namespace loom::drivers {

std::string describe_object(std::uint16_t index, std::uint8_t sub) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "0x%04X:%02X (%s)", index, sub, object_name(index));
  return buf;
}

namespace {
std::string hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "0x%08X", v);
  return buf;
}
}  // namespace

SdoClient::SdoClient(CanBus& bus, ConfigureClock& clock, std::int64_t timeout_us, FrameHandler other_frames)
    : bus_(bus), clock_(clock), timeout_us_(timeout_us), other_frames_(std::move(other_frames)) {}

Result<SdoReply> SdoClient::exchange(std::uint8_t node, const CanFrame& request, const std::string& what) {
  const SdoRequest req = parse_sdo_request(request);
  last_abort_ = 0;
  const std::int64_t deadline = clock_.now_us() + timeout_us_;

  // A full transmit queue is not an error during bring-up: retry until the deadline.
  for (;;) {
    const SendResult r = bus_.send(request);
    if (r == SendResult::kOk) break;
    if (r == SendResult::kError) return Status::error(what + ": the CAN bus refused the request frame");
    if (clock_.now_us() >= deadline) return Status::error(what + ": the transmit queue stayed full");
    clock_.idle();
  }

  for (;;) {
    CanFrame f;
    while (bus_.receive(f)) {
      if (f.is_error() || f.id != cob::sdo_tx(node)) {
        if (other_frames_) other_frames_(f);
        continue;
      }
      const SdoReply reply = parse_sdo_reply(f);
      if (reply.kind == SdoReplyKind::kAbort) {
        last_abort_ = reply.value;
        return Status::error(what + " aborted: " + hex32(reply.value) + " (" + sdo_abort_text(reply.value) +
                             ")");
      }
      if (reply.kind == SdoReplyKind::kInvalid || reply.index != req.index || reply.sub != req.sub) {
        bus_.send(make_sdo_abort(cob::sdo_rx(node), req.index, req.sub, sdo_abort::kInvalidCommand));
        return Status::error(what + ": unexpected reply (command byte " + std::to_string(f.data[0]) +
                             " for " + describe_object(reply.index, reply.sub) + ")");
      }
      return reply;
    }
    if (clock_.now_us() >= deadline) {
      bus_.send(make_sdo_abort(cob::sdo_rx(node), req.index, req.sub, sdo_abort::kTimeout));
      char buf[80];
      std::snprintf(buf, sizeof(buf), ": no reply within %.0f ms (sent abort 0x05040000)",
                    static_cast<double>(timeout_us_) / 1e3);
      return Status::error(what + buf);
    }
    clock_.idle();
  }
}

Status SdoClient::write(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                        std::uint8_t size) {
  if (skip_unchanged_ && size >= 1 && size <= 4) {
    const std::uint32_t mask = size == 4 ? 0xFFFFFFFFu : (1u << (8 * size)) - 1u;
    Result<std::uint32_t> now = read(node, index, sub);
    if (now && (now.value() & mask) == (value & mask)) {
      ++skipped_writes_;
      return Status::ok();
    }
    // An object the node does not have refuses the write the same way: not sent, the same abort code.
    if (!now && (last_abort_ == sdo_abort::kNoObject || last_abort_ == sdo_abort::kNoSubIndex)) {
      char v[16];
      std::snprintf(v, sizeof(v), "0x%0*X", 2 * size, value);
      return Status::error("SDO write " + describe_object(index, sub) + " = " + v +
                           " not sent: " + now.error());
    }
  }
  char v[16];
  std::snprintf(v, sizeof(v), "0x%0*X", 2 * size, value);
  const std::string what = "SDO write " + describe_object(index, sub) + " = " + v;
  Result<SdoReply> r = exchange(node, make_sdo_download(node, index, sub, value, size), what);
  if (!r) return r.status();
  if (r.value().kind != SdoReplyKind::kDownloadAck) {
    return Status::error(what + ": the server answered with an upload reply instead of a download ack");
  }
  ++downloads_;
  return Status::ok();
}

Result<std::uint32_t> SdoClient::read(std::uint8_t node, std::uint16_t index, std::uint8_t sub) {
  const std::string what = "SDO read " + describe_object(index, sub);
  Result<SdoReply> r = exchange(node, make_sdo_upload(node, index, sub), what);
  if (!r) return r.status();
  const SdoReply& reply = r.value();
  if (reply.kind == SdoReplyKind::kUploadSegmented) {
    bus_.send(make_sdo_abort(cob::sdo_rx(node), index, sub, sdo_abort::kInvalidCommand));
    return Status::error(what + ": the server started a segmented transfer (" + std::to_string(reply.value) +
                         " bytes); only expedited transfers are supported");
  }
  if (reply.kind != SdoReplyKind::kUploadExpedited) {
    return Status::error(what + ": the server answered with a download ack instead of data");
  }
  return reply.value;
}

}  // namespace loom::drivers

// Expedited SDO codec and abort-code texts (CiA 301 §7.2.4.3, abort codes Table 22). The command byte
// carries "n" = number of unused data bytes in bits 3..2 with e = s = 1 for a sized expedited transfer.
#include "loom/drivers/sdo.hpp"

#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/le_bytes.hpp"

namespace loom::drivers {
namespace {

constexpr std::uint8_t kCcsDownloadInitiate = 1;  // client command specifiers (bits 7..5)
constexpr std::uint8_t kCcsUploadInitiate = 2;
constexpr std::uint8_t kCsAbort = 4;
constexpr std::uint8_t kScsUploadInitiate = 2;  // server command specifiers
constexpr std::uint8_t kScsDownloadInitiate = 3;

CanFrame sdo_frame(std::uint32_t id, std::uint8_t command, std::uint16_t index, std::uint8_t sub) {
  CanFrame f;
  f.id = id;
  f.dlc = 8;
  f.data[0] = command;
  put_u16(&f.data[1], index);
  f.data[3] = sub;
  return f;
}

// Expedited command byte for `size` data bytes with the given command specifier: ccs<<5 | n<<2 | e | s.
std::uint8_t expedited_command(std::uint8_t cs, std::uint8_t size) {
  return static_cast<std::uint8_t>((cs << 5) | ((4 - size) << 2) | 0x03);
}

std::uint32_t masked_value(const std::uint8_t* p, std::uint8_t size) {
  const std::uint32_t v = get_u32(p);
  return size >= 4 ? v : (v & ((1U << (8 * size)) - 1U));
}

}  // namespace

const char* sdo_abort_text(std::uint32_t code) noexcept {
  switch (code) {
    case sdo_abort::kToggleBit:
      return "toggle bit not alternated";
    case sdo_abort::kTimeout:
      return "SDO protocol timed out";
    case sdo_abort::kInvalidCommand:
      return "client/server command specifier not valid or unknown";
    case 0x05040002:
      return "invalid block size";
    case 0x05040003:
      return "invalid sequence number";
    case 0x05040004:
      return "CRC error";
    case 0x05040005:
      return "out of memory";
    case sdo_abort::kUnsupportedAccess:
      return "unsupported access to an object";
    case sdo_abort::kWriteOnly:
      return "attempt to read a write-only object";
    case sdo_abort::kReadOnly:
      return "attempt to write a read-only object";
    case sdo_abort::kNoObject:
      return "object does not exist in the object dictionary";
    case sdo_abort::kNotMappable:
      return "object cannot be mapped to the PDO";
    case sdo_abort::kPdoLengthExceeded:
      return "number and length of mapped objects exceed the PDO length";
    case sdo_abort::kParameterIncompatible:
      return "general parameter incompatibility";
    case 0x06040047:
      return "general internal incompatibility in the device";
    case sdo_abort::kHardwareError:
      return "access failed due to a hardware error";
    case sdo_abort::kLengthMismatch:
      return "data type does not match, length of service parameter does not match";
    case sdo_abort::kLengthTooHigh:
      return "data type does not match, length of service parameter too high";
    case sdo_abort::kLengthTooLow:
      return "data type does not match, length of service parameter too low";
    case sdo_abort::kNoSubIndex:
      return "sub-index does not exist";
    case sdo_abort::kValueRange:
      return "invalid value for parameter (value range exceeded)";
    case sdo_abort::kValueTooHigh:
      return "value of parameter written too high";
    case sdo_abort::kValueTooLow:
      return "value of parameter written too low";
    case 0x06090036:
      return "maximum value is less than minimum value";
    case sdo_abort::kGeneral:
      return "general error";
    case sdo_abort::kCannotStore:
      return "data cannot be transferred or stored to the application";
    case sdo_abort::kCannotStoreLocal:
      return "data cannot be transferred or stored because of local control";
    case sdo_abort::kCannotStoreState:
      return "data cannot be transferred or stored in the present device state";
    case 0x08000023:
      return "object dictionary dynamic generation failed or no object dictionary present";
    case sdo_abort::kNoData:
      return "no data available";
    default:
      return "unknown abort code";
  }
}

CanFrame make_sdo_download(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                           std::uint8_t size) noexcept {
  if (size < 1) size = 1;
  if (size > 4) size = 4;
  CanFrame f = sdo_frame(cob::sdo_rx(node), expedited_command(kCcsDownloadInitiate, size), index, sub);
  put_u32(&f.data[4], size >= 4 ? value : (value & ((1U << (8 * size)) - 1U)));
  return f;
}

CanFrame make_sdo_upload(std::uint8_t node, std::uint16_t index, std::uint8_t sub) noexcept {
  return sdo_frame(cob::sdo_rx(node), static_cast<std::uint8_t>(kCcsUploadInitiate << 5), index, sub);
}

CanFrame make_sdo_abort(std::uint32_t cob_id, std::uint16_t index, std::uint8_t sub,
                        std::uint32_t code) noexcept {
  CanFrame f = sdo_frame(cob_id, static_cast<std::uint8_t>(kCsAbort << 5), index, sub);
  put_u32(&f.data[4], code);
  return f;
}

SdoReply parse_sdo_reply(const CanFrame& frame) noexcept {
  SdoReply r;
  if (frame.is_error() || frame.is_rtr() || frame.dlc != 8) return r;
  const std::uint8_t cmd = frame.data[0];
  r.index = get_u16(&frame.data[1]);
  r.sub = frame.data[3];
  const std::uint8_t scs = cmd >> 5;
  if (scs == kCsAbort) {
    r.kind = SdoReplyKind::kAbort;
    r.value = get_u32(&frame.data[4]);
  } else if (scs == kScsDownloadInitiate && cmd == 0x60) {
    r.kind = SdoReplyKind::kDownloadAck;
  } else if (scs == kScsUploadInitiate) {
    const bool expedited = (cmd & 0x02) != 0;
    const bool size_indicated = (cmd & 0x01) != 0;
    if (!expedited) {
      r.kind = SdoReplyKind::kUploadSegmented;
      r.value = get_u32(&frame.data[4]);  // announced size when indicated
    } else {
      r.kind = SdoReplyKind::kUploadExpedited;
      r.size = size_indicated ? static_cast<std::uint8_t>(4 - ((cmd >> 2) & 0x03)) : std::uint8_t{4};
      r.value = masked_value(&frame.data[4], r.size);
    }
  }
  return r;
}

SdoRequest parse_sdo_request(const CanFrame& frame) noexcept {
  SdoRequest r;
  if (frame.is_error() || frame.is_rtr() || frame.dlc != 8) return r;
  const std::uint8_t cmd = frame.data[0];
  r.index = get_u16(&frame.data[1]);
  r.sub = frame.data[3];
  const std::uint8_t ccs = cmd >> 5;
  if (ccs == kCsAbort) {
    r.kind = SdoRequestKind::kAbort;
    r.value = get_u32(&frame.data[4]);
  } else if (ccs == kCcsUploadInitiate) {
    r.kind = SdoRequestKind::kUpload;
  } else if (ccs == kCcsDownloadInitiate) {
    const bool expedited = (cmd & 0x02) != 0;
    const bool size_indicated = (cmd & 0x01) != 0;
    if (!expedited) {
      r.kind = SdoRequestKind::kDownloadSegmented;
    } else {
      r.kind = SdoRequestKind::kDownloadExpedited;
      r.size = size_indicated ? static_cast<std::uint8_t>(4 - ((cmd >> 2) & 0x03)) : std::uint8_t{0};
      r.value = masked_value(&frame.data[4], r.size == 0 ? std::uint8_t{4} : r.size);
    }
  }
  return r;
}

CanFrame make_sdo_download_ack(std::uint8_t node, std::uint16_t index, std::uint8_t sub) noexcept {
  return sdo_frame(cob::sdo_tx(node), static_cast<std::uint8_t>(kScsDownloadInitiate << 5), index, sub);
}

CanFrame make_sdo_upload_reply(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                               std::uint8_t size) noexcept {
  if (size < 1) size = 1;
  if (size > 4) size = 4;
  CanFrame f = sdo_frame(cob::sdo_tx(node), expedited_command(kScsUploadInitiate, size), index, sub);
  put_u32(&f.data[4], size >= 4 ? value : (value & ((1U << (8 * size)) - 1U)));
  return f;
}

}  // namespace loom::drivers

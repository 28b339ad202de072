// CiA 301 SDO frames, expedited transfers only (every object the servo master touches fits in 4 bytes):
// client requests, server replies, aborts, and the abort-code table turned into readable text so a
// refused configuration tells the user which object failed and why.
#pragma once

#include <cstdint>
#include <optional>

#include "loom/drivers/can_frame.hpp"

namespace loom::drivers {

// Abort codes (CiA 301 Table 22) the master and the simulated node use by name.
namespace sdo_abort {
inline constexpr std::uint32_t kToggleBit = 0x05030000;
inline constexpr std::uint32_t kTimeout = 0x05040000;
inline constexpr std::uint32_t kInvalidCommand = 0x05040001;
inline constexpr std::uint32_t kUnsupportedAccess = 0x06010000;
inline constexpr std::uint32_t kWriteOnly = 0x06010001;
inline constexpr std::uint32_t kReadOnly = 0x06010002;
inline constexpr std::uint32_t kNoObject = 0x06020000;
inline constexpr std::uint32_t kNotMappable = 0x06040041;
inline constexpr std::uint32_t kPdoLengthExceeded = 0x06040042;
inline constexpr std::uint32_t kParameterIncompatible = 0x06040043;
inline constexpr std::uint32_t kHardwareError = 0x06060000;
inline constexpr std::uint32_t kLengthMismatch = 0x06070010;
inline constexpr std::uint32_t kLengthTooHigh = 0x06070012;
inline constexpr std::uint32_t kLengthTooLow = 0x06070013;
inline constexpr std::uint32_t kNoSubIndex = 0x06090011;
inline constexpr std::uint32_t kValueRange = 0x06090030;
inline constexpr std::uint32_t kValueTooHigh = 0x06090031;
inline constexpr std::uint32_t kValueTooLow = 0x06090032;
inline constexpr std::uint32_t kGeneral = 0x08000000;
inline constexpr std::uint32_t kCannotStore = 0x08000020;
inline constexpr std::uint32_t kCannotStoreLocal = 0x08000021;
inline constexpr std::uint32_t kCannotStoreState = 0x08000022;
inline constexpr std::uint32_t kNoData = 0x08000024;
}  // namespace sdo_abort

// RT-safe. Text of an abort code ("object does not exist in the object dictionary"); "unknown abort
// code" for codes outside the table.
const char* sdo_abort_text(std::uint32_t code) noexcept;

// ---- Client side (master) -------------------------------------------------------------------------
// RT-safe. Expedited download of `size` (1..4) bytes of `value` (LE) into index:sub of `node`.
CanFrame make_sdo_download(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                           std::uint8_t size) noexcept;
// RT-safe. Upload request for index:sub.
CanFrame make_sdo_upload(std::uint8_t node, std::uint16_t index, std::uint8_t sub) noexcept;
// RT-safe. Abort sent by the client (id 0x600+node) or by the server (id 0x580+node).
CanFrame make_sdo_abort(std::uint32_t cob_id, std::uint16_t index, std::uint8_t sub,
                        std::uint32_t code) noexcept;

enum class SdoReplyKind : std::uint8_t {
  kDownloadAck,      // 0x60: the write was accepted
  kUploadExpedited,  // 0x4F/0x4B/0x47/0x43 (or 0x42: size not indicated, 4 bytes taken)
  kUploadSegmented,  // 0x41: the server wants a segmented transfer (not supported by this master)
  kAbort,            // 0x80
  kInvalid,          // anything else
};
struct SdoReply {
  SdoReplyKind kind = SdoReplyKind::kInvalid;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint32_t value = 0;  // upload data (LE), or the abort code
  std::uint8_t size = 0;    // upload data bytes (1..4)
};
// RT-safe. Parse a server→client frame (caller checked the COB-ID); kInvalid for DLC ≠ 8.
SdoReply parse_sdo_reply(const CanFrame& frame) noexcept;

// ---- Server side (simulated node) -----------------------------------------------------------------
enum class SdoRequestKind : std::uint8_t {
  kDownloadExpedited,  // 0x2F/0x2B/0x27/0x23 (size indicated) or 0x22 (size not indicated → 0)
  kDownloadSegmented,  // 0x21: initiate of a segmented download (not supported by the simulated node)
  kUpload,             // 0x40
  kAbort,              // 0x80
  kInvalid,
};
struct SdoRequest {
  SdoRequestKind kind = SdoRequestKind::kInvalid;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint32_t value = 0;
  std::uint8_t size = 0;  // 1..4 for expedited downloads with size indicated, 0 otherwise
};
// RT-safe. Parse a client→server frame; kInvalid for DLC ≠ 8 or an unknown command specifier.
SdoRequest parse_sdo_request(const CanFrame& frame) noexcept;
// RT-safe. Server replies (id 0x580 + node).
CanFrame make_sdo_download_ack(std::uint8_t node, std::uint16_t index, std::uint8_t sub) noexcept;
CanFrame make_sdo_upload_reply(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                               std::uint8_t size) noexcept;

}  // namespace loom::drivers

// libFuzzer harness: every CANopen frame decoder of drivers/ on one arbitrary frame — SDO replies and
// requests, EMCY, NMT, heartbeat/boot-up, SYNC, TPDO1/TPDO2/RPDO1, SocketCAN error frames, the COB-ID
// dispatcher and the CiA 402 statusword — plus the text tables a decoded value is looked up in.
// Besides crashes and sanitizer reports, every accepted frame is checked against the bytes read here
// by hand (not through le_bytes.hpp), and re-encoded by the matching make_/pack_ function must decode
// to the same value.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "loom/drivers/can_error_frame.hpp"
#include "loom/drivers/can_frame.hpp"
#include "loom/drivers/cia402.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/drivers/sdo.hpp"

namespace {

using namespace loom::drivers;

[[noreturn]] void fail(const char* what, const CanFrame& f) {
  std::fprintf(stderr, "decoder property violated: %s (id 0x%X dlc %u flags %u data", what, f.id, f.dlc,
               f.flags);
  for (const auto b : f.data) std::fprintf(stderr, " %02X", b);
  std::fprintf(stderr, ")\n");
  std::abort();
}
#define CHECK(cond, f)           \
  do {                           \
    if (!(cond)) fail(#cond, f); \
  } while (0)

std::uint32_t le(const CanFrame& f, std::size_t at, std::size_t bytes) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < bytes; ++i) v |= static_cast<std::uint32_t>(f.data[at + i]) << (8 * i);
  return v;
}
bool is_data(const CanFrame& f) {
  return !f.is_error() && !f.is_rtr();
}

// The frame from the input: 2 bytes id (11 bits; all 32 bits of the class mask for error frames), 1 byte
// flags, 1 byte DLC (0..8, as SocketCAN delivers classic frames), 8 data bytes. Short inputs are padded.
CanFrame frame_from(const std::uint8_t* data, std::size_t size) {
  std::uint8_t b[12] = {};
  for (std::size_t i = 0; i < size && i < sizeof b; ++i) b[i] = data[i];
  CanFrame f;
  f.flags = static_cast<std::uint8_t>(b[2] & (CanFrame::kError | CanFrame::kRtr));
  const std::uint32_t raw = static_cast<std::uint32_t>(b[0]) | (static_cast<std::uint32_t>(b[1]) << 8);
  f.id = f.is_error() ? raw | (size > 12 ? static_cast<std::uint32_t>(data[12]) << 16 : 0U)
                      : raw & kMaxStandardId;
  f.dlc = static_cast<std::uint8_t>(b[3] % 9);
  for (std::size_t i = 0; i < 8; ++i) f.data[i] = b[4 + i];
  return f;
}

void check_emcy(const CanFrame& f) {
  const auto e = parse_emcy(f);
  if (!e) return;
  CHECK(is_data(f) && f.dlc == 8 && f.id >= 0x081 && f.id <= 0x0FF, f);
  CHECK(e->node == f.id - 0x080 && e->code == le(f, 0, 2) && e->error_register == f.data[2], f);
  for (std::size_t i = 0; i < 5; ++i) CHECK(e->vendor[i] == f.data[3 + i], f);
  const auto again = parse_emcy(make_emcy(e->node, e->code, e->error_register));
  CHECK(
      again && again->node == e->node && again->code == e->code && again->error_register == e->error_register,
      f);
  CHECK(fault_code_text(e->code) != nullptr, f);
}

void check_nmt(const CanFrame& f) {
  if (const auto m = parse_nmt(f)) {
    CHECK(is_data(f) && f.id == 0 && f.dlc == 2 && m->node == f.data[1], f);
    CHECK(static_cast<std::uint8_t>(m->command) == f.data[0], f);
    const auto again = parse_nmt(make_nmt(m->command, m->node));
    CHECK(again && again->command == m->command && again->node == m->node, f);
  }
  if (const auto hb = parse_heartbeat(f)) {
    CHECK(is_data(f) && f.dlc == 1 && f.id >= 0x701 && f.id <= 0x77F && hb->node == f.id - 0x700, f);
    const std::uint8_t s = f.data[0] & 0x7F;
    CHECK(static_cast<std::uint8_t>(hb->state) == s && (s == 0x00 || s == 0x04 || s == 0x05 || s == 0x7F), f);
    const auto again = parse_heartbeat(make_heartbeat(hb->node, hb->state));
    CHECK(again && again->node == hb->node && again->state == hb->state, f);
    CHECK(nmt_state_name(hb->state) != nullptr, f);
  }
  if (is_sync(f)) CHECK(is_data(f) && f.id == 0x080, f);
}

void check_pdos(const CanFrame& f) {
  const auto node = static_cast<std::uint8_t>(f.id & 0x7F);
  if (const auto p = unpack_tpdo1(f, node)) {
    CHECK(is_data(f) && f.id == 0x180u + node && f.dlc >= 6, f);
    CHECK(p->statusword == le(f, 0, 2) && p->position_actual == static_cast<std::int32_t>(le(f, 2, 4)), f);
    const auto again = unpack_tpdo1(pack_tpdo1(node, *p), node);
    CHECK(again && again->statusword == p->statusword && again->position_actual == p->position_actual, f);
    // The statusword of a TPDO is what the master decodes the drive state from.
    (void)decode_statusword(p->statusword);
  }
  if (const auto p = unpack_tpdo2(f, node)) {
    CHECK(is_data(f) && f.id == 0x280u + node && f.dlc >= 6, f);
    CHECK(p->velocity_actual == static_cast<std::int32_t>(le(f, 0, 4)) &&
              p->torque_actual == static_cast<std::int16_t>(le(f, 4, 2)),
          f);
    const auto again = unpack_tpdo2(pack_tpdo2(node, *p), node);
    CHECK(again && again->velocity_actual == p->velocity_actual && again->torque_actual == p->torque_actual,
          f);
  }
  if (const auto p = unpack_rpdo1(f, node)) {
    CHECK(is_data(f) && f.id == 0x200u + node && f.dlc >= 6, f);
    CHECK(p->controlword == le(f, 0, 2) && p->target_position == static_cast<std::int32_t>(le(f, 2, 4)), f);
    const auto again = unpack_rpdo1(pack_rpdo1(node, *p), node);
    CHECK(again && again->controlword == p->controlword && again->target_position == p->target_position, f);
  }
}

void check_sdo(const CanFrame& f) {
  const SdoReply r = parse_sdo_reply(f);
  if (r.kind != SdoReplyKind::kInvalid) {
    CHECK(is_data(f) && f.dlc == 8 && r.index == le(f, 1, 2) && r.sub == f.data[3], f);
    if (r.kind == SdoReplyKind::kAbort)
      CHECK(r.value == le(f, 4, 4) && sdo_abort_text(r.value) != nullptr, f);
    if (r.kind == SdoReplyKind::kUploadExpedited) {
      CHECK(r.size >= 1 && r.size <= 4 && r.value == le(f, 4, r.size), f);
      const SdoReply again = parse_sdo_reply(make_sdo_upload_reply(1, r.index, r.sub, r.value, r.size));
      CHECK(again.kind == r.kind && again.index == r.index && again.sub == r.sub && again.value == r.value &&
                again.size == r.size,
            f);
    }
    CHECK(object_name(r.index) != nullptr, f);
  }
  const SdoRequest q = parse_sdo_request(f);
  if (q.kind != SdoRequestKind::kInvalid) {
    CHECK(is_data(f) && f.dlc == 8 && q.index == le(f, 1, 2) && q.sub == f.data[3], f);
    if (q.kind == SdoRequestKind::kDownloadExpedited && q.size > 0) {
      CHECK(q.size <= 4 && q.value == le(f, 4, q.size), f);
      const SdoRequest again = parse_sdo_request(make_sdo_download(1, q.index, q.sub, q.value, q.size));
      CHECK(again.kind == q.kind && again.index == q.index && again.value == q.value && again.size == q.size,
            f);
    }
    if (q.kind == SdoRequestKind::kAbort) CHECK(q.value == le(f, 4, 4), f);
  }
}

void check_error_frame(const CanFrame& f) {
  const CanErrorInfo e = decode_error_frame(f);
  if (!f.is_error()) {
    CHECK(!e.bus_off && !e.restarted && !e.error_passive && !e.warning && !e.overflow && !e.no_ack &&
              !e.protocol && !e.tx_timeout,
          f);
  }
}

void check_cob(const CanFrame& f) {
  const CobDecoded c = decode_cob_id(f.id);
  if (f.is_error()) return;  // the id of an error frame is a class mask, not a COB-ID
  if (c.function != CobFunction::kOther && c.function != CobFunction::kNmt &&
      c.function != CobFunction::kSync) {
    CHECK(c.node >= kMinNodeId && c.node <= kMaxNodeId && c.node == (f.id & 0x7F), f);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const CanFrame f = frame_from(data, size);
  check_cob(f);
  check_emcy(f);
  check_nmt(f);
  check_pdos(f);
  check_sdo(f);
  check_error_frame(f);
  return 0;
}

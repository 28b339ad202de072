// CANopen frame codecs checked byte for byte against CiA 301 facts (pre-defined connection set, NMT,
// SYNC, heartbeat, expedited SDO command bytes, abort codes, EMCY layout, PDO mapping entries) and the
// SocketCAN error-frame bits as documented in linux/can/error.h (literal values, not the macros).
#include <gtest/gtest.h>

#include <vector>

#include "loom/drivers/can_error_frame.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/drivers/sdo.hpp"

namespace loom::drivers {
namespace {

std::vector<int> bytes(const CanFrame& f) {
  return std::vector<int>(f.data.begin(), f.data.begin() + f.dlc);
}

CanFrame frame(std::uint32_t id, std::vector<std::uint8_t> data) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<std::uint8_t>(data.size());
  for (std::size_t i = 0; i < data.size(); ++i) f.data[i] = data[i];
  return f;
}

TEST(CobId, PredefinedConnectionSetForNode5) {
  EXPECT_EQ(cob::emcy(5), 0x085u);
  EXPECT_EQ(cob::tpdo(1, 5), 0x185u);
  EXPECT_EQ(cob::rpdo(1, 5), 0x205u);
  EXPECT_EQ(cob::tpdo(2, 5), 0x285u);
  EXPECT_EQ(cob::rpdo(2, 5), 0x305u);
  EXPECT_EQ(cob::tpdo(4, 5), 0x485u);
  EXPECT_EQ(cob::rpdo(4, 5), 0x505u);
  EXPECT_EQ(cob::sdo_tx(5), 0x585u);
  EXPECT_EQ(cob::sdo_rx(5), 0x605u);
  EXPECT_EQ(cob::heartbeat(5), 0x705u);
}

TEST(CobId, DecodeInvertsEveryFunctionForEveryNode) {
  for (int n = 1; n <= 127; ++n) {
    const auto node = static_cast<std::uint8_t>(n);
    const std::pair<std::uint32_t, CobFunction> cases[] = {
        {cob::emcy(node), CobFunction::kEmcy},     {cob::tpdo(1, node), CobFunction::kTpdo1},
        {cob::tpdo(2, node), CobFunction::kTpdo2}, {cob::tpdo(3, node), CobFunction::kTpdo3},
        {cob::tpdo(4, node), CobFunction::kTpdo4}, {cob::rpdo(1, node), CobFunction::kRpdo1},
        {cob::rpdo(4, node), CobFunction::kRpdo4}, {cob::sdo_tx(node), CobFunction::kSdoTx},
        {cob::sdo_rx(node), CobFunction::kSdoRx},  {cob::heartbeat(node), CobFunction::kHeartbeat},
    };
    for (const auto& [id, fn] : cases) {
      const CobDecoded d = decode_cob_id(id);
      EXPECT_EQ(d.function, fn) << std::hex << id;
      EXPECT_EQ(d.node, node) << std::hex << id;
    }
  }
  EXPECT_EQ(decode_cob_id(0x000).function, CobFunction::kNmt);
  EXPECT_EQ(decode_cob_id(0x080).function, CobFunction::kSync);
  EXPECT_EQ(decode_cob_id(0x700).function, CobFunction::kOther);  // node 0 does not exist
}

TEST(Nmt, CommandFramesAreTwoBytesOnId0) {
  const CanFrame reset = make_nmt(NmtCommand::kResetNode, 3);
  EXPECT_EQ(reset.id, 0u);
  EXPECT_EQ(bytes(reset), (std::vector<int>{0x81, 0x03}));
  EXPECT_EQ(bytes(make_nmt(NmtCommand::kStart, 0)), (std::vector<int>{0x01, 0x00}));
  EXPECT_EQ(bytes(make_nmt(NmtCommand::kStop, 7)), (std::vector<int>{0x02, 0x07}));
  EXPECT_EQ(bytes(make_nmt(NmtCommand::kEnterPreOperational, 7)), (std::vector<int>{0x80, 0x07}));
  EXPECT_EQ(bytes(make_nmt(NmtCommand::kResetCommunication, 7)), (std::vector<int>{0x82, 0x07}));

  const auto parsed = parse_nmt(frame(0x000, {0x81, 0x02}));
  ASSERT_TRUE(parsed);
  EXPECT_EQ(parsed->command, NmtCommand::kResetNode);
  EXPECT_EQ(parsed->node, 2);
  EXPECT_FALSE(parse_nmt(frame(0x000, {0x81})));        // DLC 1
  EXPECT_FALSE(parse_nmt(frame(0x000, {0x03, 0x02})));  // no such command specifier
  EXPECT_FALSE(parse_nmt(frame(0x000, {0x01, 0x80})));  // node 128
}

TEST(Nmt, SyncIsId080WithoutData) {
  const CanFrame s = make_sync();
  EXPECT_EQ(s.id, 0x080u);
  EXPECT_EQ(s.dlc, 0);
  EXPECT_TRUE(is_sync(s));
  EXPECT_TRUE(is_sync(frame(0x080, {0x05})));  // with counter (0x1019 > 0)
  EXPECT_FALSE(is_sync(frame(0x081, {})));
}

TEST(Nmt, HeartbeatStatesAndBootUp) {
  EXPECT_EQ(make_heartbeat(4, NmtState::kBootUp).id, 0x704u);
  EXPECT_EQ(bytes(make_heartbeat(4, NmtState::kBootUp)), (std::vector<int>{0x00}));
  EXPECT_EQ(bytes(make_heartbeat(4, NmtState::kStopped)), (std::vector<int>{0x04}));
  EXPECT_EQ(bytes(make_heartbeat(4, NmtState::kOperational)), (std::vector<int>{0x05}));
  EXPECT_EQ(bytes(make_heartbeat(4, NmtState::kPreOperational)), (std::vector<int>{0x7F}));

  const auto hb = parse_heartbeat(frame(0x77F, {0x85}));  // node 127, toggle bit set, operational
  ASSERT_TRUE(hb);
  EXPECT_EQ(hb->node, 127);
  EXPECT_EQ(hb->state, NmtState::kOperational);
  EXPECT_FALSE(parse_heartbeat(frame(0x701, {0x06})));        // no such state
  EXPECT_FALSE(parse_heartbeat(frame(0x701, {0x05, 0x00})));  // DLC 2
  EXPECT_FALSE(parse_heartbeat(frame(0x181, {0x05})));        // not an error-control id
}

TEST(Sdo, ExpeditedDownloadCommandBytesBySize) {
  // 0x6060:00 = 8 (INT8) → 2F 60 60 00 08 00 00 00 on 0x600 + node.
  const CanFrame mode = make_sdo_download(1, 0x6060, 0x00, 8, 1);
  EXPECT_EQ(mode.id, 0x601u);
  EXPECT_EQ(bytes(mode), (std::vector<int>{0x2F, 0x60, 0x60, 0x00, 0x08, 0, 0, 0}));
  // 0x1017:00 = 100 ms (UNSIGNED16) → 2B 17 10 00 64 00 00 00.
  EXPECT_EQ(bytes(make_sdo_download(2, 0x1017, 0, 100, 2)),
            (std::vector<int>{0x2B, 0x17, 0x10, 0x00, 0x64, 0x00, 0, 0}));
  EXPECT_EQ(make_sdo_download(2, 0x2000, 1, 0xABCDEF, 3).data[0], 0x27);
  // 0x1A00:01 = 0x60410010 → 23 00 1A 01 10 00 41 60.
  EXPECT_EQ(bytes(make_sdo_download(3, 0x1A00, 1, 0x60410010, 4)),
            (std::vector<int>{0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60}));
  // Bytes beyond the size stay zero even if the value has more bits.
  EXPECT_EQ(bytes(make_sdo_download(3, 0x6060, 0, 0x1234, 1)),
            (std::vector<int>{0x2F, 0x60, 0x60, 0x00, 0x34, 0, 0, 0}));
}

TEST(Sdo, UploadRequestAndReplies) {
  EXPECT_EQ(bytes(make_sdo_upload(1, 0x6064, 0)), (std::vector<int>{0x40, 0x64, 0x60, 0x00, 0, 0, 0, 0}));

  const std::pair<std::uint8_t, std::uint8_t> sizes[] = {{0x4F, 1}, {0x4B, 2}, {0x47, 3}, {0x43, 4}};
  for (const auto& [cmd, size] : sizes) {
    const SdoReply r = parse_sdo_reply(frame(0x581, {cmd, 0x64, 0x60, 0x00, 0x78, 0x56, 0x34, 0x12}));
    EXPECT_EQ(r.kind, SdoReplyKind::kUploadExpedited);
    EXPECT_EQ(r.index, 0x6064);
    EXPECT_EQ(r.size, size);
    const std::uint32_t full = 0x12345678;
    EXPECT_EQ(r.value, size == 4 ? full : (full & ((1u << (8 * size)) - 1))) << int{cmd};
  }
  // 0x42: expedited, size not indicated → all four bytes.
  EXPECT_EQ(parse_sdo_reply(frame(0x581, {0x42, 0, 0x10, 0, 1, 2, 3, 4})).value, 0x04030201u);
  EXPECT_EQ(parse_sdo_reply(frame(0x581, {0x60, 0x17, 0x10, 0x00, 0, 0, 0, 0})).kind,
            SdoReplyKind::kDownloadAck);
  const SdoReply seg = parse_sdo_reply(frame(0x581, {0x41, 0x08, 0x10, 0x00, 20, 0, 0, 0}));
  EXPECT_EQ(seg.kind, SdoReplyKind::kUploadSegmented);
  EXPECT_EQ(seg.value, 20u);
  EXPECT_EQ(parse_sdo_reply(frame(0x581, {0x60, 0, 0, 0})).kind, SdoReplyKind::kInvalid);  // DLC 4

  // The server side encodes what the client side decodes.
  const CanFrame reply = make_sdo_upload_reply(9, 0x6061, 0, 8, 1);
  EXPECT_EQ(reply.id, 0x589u);
  EXPECT_EQ(bytes(reply), (std::vector<int>{0x4F, 0x61, 0x60, 0x00, 0x08, 0, 0, 0}));
  EXPECT_EQ(bytes(make_sdo_download_ack(9, 0x6060, 0)), (std::vector<int>{0x60, 0x60, 0x60, 0, 0, 0, 0, 0}));
}

TEST(Sdo, AbortFramesCarryTheCodeLittleEndian) {
  const CanFrame a = make_sdo_abort(0x582, 0x60C2, 0x01, 0x06020000);
  EXPECT_EQ(a.id, 0x582u);
  EXPECT_EQ(bytes(a), (std::vector<int>{0x80, 0xC2, 0x60, 0x01, 0x00, 0x00, 0x02, 0x06}));
  const SdoReply r = parse_sdo_reply(a);
  EXPECT_EQ(r.kind, SdoReplyKind::kAbort);
  EXPECT_EQ(r.value, 0x06020000u);
  EXPECT_EQ(r.index, 0x60C2);
  EXPECT_EQ(r.sub, 1);
}

TEST(Sdo, AbortCodesReadAsText) {
  EXPECT_STREQ(sdo_abort_text(0x06020000), "object does not exist in the object dictionary");
  EXPECT_STREQ(sdo_abort_text(0x06090011), "sub-index does not exist");
  EXPECT_STREQ(sdo_abort_text(0x05040000), "SDO protocol timed out");
  EXPECT_STREQ(sdo_abort_text(0x06010002), "attempt to write a read-only object");
  EXPECT_STREQ(sdo_abort_text(0x06040041), "object cannot be mapped to the PDO");
  EXPECT_STREQ(sdo_abort_text(0x12345678), "unknown abort code");
}

TEST(Sdo, ServerParsesRequests) {
  const SdoRequest d = parse_sdo_request(make_sdo_download(1, 0x1017, 0, 250, 2));
  EXPECT_EQ(d.kind, SdoRequestKind::kDownloadExpedited);
  EXPECT_EQ(d.size, 2);
  EXPECT_EQ(d.value, 250u);
  const SdoRequest unsized = parse_sdo_request(frame(0x601, {0x22, 0x7A, 0x60, 0, 0xFF, 0xFF, 0xFF, 0xFF}));
  EXPECT_EQ(unsized.kind, SdoRequestKind::kDownloadExpedited);
  EXPECT_EQ(unsized.size, 0);
  EXPECT_EQ(unsized.value, 0xFFFFFFFFu);
  EXPECT_EQ(parse_sdo_request(frame(0x601, {0x21, 0, 0x10, 0, 9, 0, 0, 0})).kind,
            SdoRequestKind::kDownloadSegmented);
  EXPECT_EQ(parse_sdo_request(make_sdo_upload(1, 0x6041, 0)).kind, SdoRequestKind::kUpload);
  EXPECT_EQ(parse_sdo_request(frame(0x601, {0xE0, 0, 0, 0, 0, 0, 0, 0})).kind, SdoRequestKind::kInvalid);
}

TEST(Emcy, LayoutCodeRegisterVendor) {
  const CanFrame e = make_emcy(2, 0x8611, 0x81);
  EXPECT_EQ(e.id, 0x082u);
  EXPECT_EQ(bytes(e), (std::vector<int>{0x11, 0x86, 0x81, 0, 0, 0, 0, 0}));
  const auto parsed = parse_emcy(frame(0x0FF, {0x10, 0x23, 0x01, 1, 2, 3, 4, 5}));
  ASSERT_TRUE(parsed);
  EXPECT_EQ(parsed->node, 127);
  EXPECT_EQ(parsed->code, 0x2310);
  EXPECT_EQ(parsed->error_register, 0x01);
  EXPECT_EQ(parsed->vendor[4], 5);
  EXPECT_FALSE(parse_emcy(frame(0x082, {0x11, 0x86, 0x81, 0, 0, 0, 0})));  // DLC 7
  EXPECT_FALSE(parse_emcy(frame(0x080, {0, 0, 0, 0, 0, 0, 0, 0})));        // that is SYNC's id
  EXPECT_STREQ(fault_code_text(0x8130), "heartbeat lost (life guard / heartbeat error)");
  EXPECT_STREQ(fault_code_text(0x2310), "current");
  EXPECT_STREQ(fault_code_text(0x4210), "temperature");
}

TEST(Pdo, MappingEntriesEncodeIndexSubBits) {
  EXPECT_EQ(encode_map_entry(kRpdo1Mapping[0]), 0x60400010u);
  EXPECT_EQ(encode_map_entry(kRpdo1Mapping[1]), 0x607A0020u);
  EXPECT_EQ(encode_map_entry(kTpdo1Mapping[0]), 0x60410010u);
  EXPECT_EQ(encode_map_entry(kTpdo1Mapping[1]), 0x60640020u);
  EXPECT_EQ(encode_map_entry(kTpdo2Mapping[0]), 0x606C0020u);
  EXPECT_EQ(encode_map_entry(kTpdo2Mapping[1]), 0x60770010u);
  const PdoMapEntry e = decode_map_entry(0x60C20108);
  EXPECT_EQ(e.index, 0x60C2);
  EXPECT_EQ(e.sub, 1);
  EXPECT_EQ(e.bits, 8);
  // The fixed PDO sizes follow from the mapping.
  EXPECT_EQ((kRpdo1Mapping[0].bits + kRpdo1Mapping[1].bits) / 8, kRpdo1Bytes);
  EXPECT_EQ((kTpdo1Mapping[0].bits + kTpdo1Mapping[1].bits) / 8, kTpdo1Bytes);
  EXPECT_EQ((kTpdo2Mapping[0].bits + kTpdo2Mapping[1].bits) / 8, kTpdo2Bytes);
}

TEST(Pdo, PackingIsLittleEndianInMappingOrder) {
  const CanFrame r = pack_rpdo1(1, Rpdo1{0x000F, -2});
  EXPECT_EQ(r.id, 0x201u);
  EXPECT_EQ(bytes(r), (std::vector<int>{0x0F, 0x00, 0xFE, 0xFF, 0xFF, 0xFF}));
  const auto t1 = unpack_tpdo1(frame(0x183, {0x37, 0x16, 0x78, 0x56, 0x34, 0x12}), 3);
  ASSERT_TRUE(t1);
  EXPECT_EQ(t1->statusword, 0x1637);
  EXPECT_EQ(t1->position_actual, 0x12345678);
  EXPECT_FALSE(unpack_tpdo1(frame(0x183, {0x37, 0x16, 0x78, 0x56, 0x34}), 3));  // 5 bytes
  EXPECT_FALSE(unpack_tpdo1(frame(0x184, {0x37, 0x16, 0x78, 0x56, 0x34, 0x12}), 3));
  const auto t2 = unpack_tpdo2(pack_tpdo2(2, Tpdo2{-1000, -5}), 2);
  ASSERT_TRUE(t2);
  EXPECT_EQ(t2->velocity_actual, -1000);
  EXPECT_EQ(t2->torque_actual, -5);
}

// Bit values from linux/can/error.h: CAN_ERR_BUSOFF 0x40, CAN_ERR_CRTL 0x04, CAN_ERR_RESTARTED 0x100,
// CAN_ERR_ACK 0x20; data[1]: RX_OVERFLOW 0x01, RX_WARNING 0x04, RX_PASSIVE 0x10, TX_PASSIVE 0x20.
TEST(ErrorFrame, DecodesKernelErrorClasses) {
  CanFrame f;
  f.flags = CanFrame::kError;
  f.dlc = 8;
  f.id = 0x40;
  EXPECT_TRUE(decode_error_frame(f).bus_off);
  f.id = 0x04;
  f.data[1] = 0x20;
  CanErrorInfo passive = decode_error_frame(f);
  EXPECT_TRUE(passive.error_passive);
  EXPECT_FALSE(passive.bus_off);
  f.data[1] = 0x01 | 0x04;
  const CanErrorInfo ow = decode_error_frame(f);
  EXPECT_TRUE(ow.overflow);
  EXPECT_TRUE(ow.warning);
  f.id = 0x100;
  EXPECT_TRUE(decode_error_frame(f).restarted);
  f.id = 0x20;
  EXPECT_TRUE(decode_error_frame(f).no_ack);
  CanFrame data = frame(0x40, {0, 0, 0});
  EXPECT_FALSE(decode_error_frame(data).bus_off);  // a data frame with id 0x40 is not an error
  EXPECT_TRUE(decode_error_frame(make_bus_off_error_frame()).bus_off);
}

}  // namespace
}  // namespace loom::drivers

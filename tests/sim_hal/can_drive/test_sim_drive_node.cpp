// The simulated CiA 402 drive seen from the bus: boot-up, NMT states, SDO server answers and aborts,
// PDO re-map rules, heartbeat timing, PDOs only when operational, EMCY on length error and following
// error. A raw test endpoint plays the master, so these checks do not depend on drivers::CanAxisPort.
#include <gtest/gtest.h>

#include <cstdlib>
#include <initializer_list>
#include <optional>
#include <vector>

#include "fake_can_network.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/drivers/sdo.hpp"
#include "loom/sim_can/sim_drive_node.hpp"

namespace loom::sim_can {
namespace {

using drivers::CanFrame;
using drivers::NmtCommand;
using drivers::NmtState;

class SimDriveNodeTest : public ::testing::Test {
 protected:
  SimDriveNodeTest() : node_(drive_ep_, config()) {}
  static SimDriveConfig config() {
    SimDriveConfig c;
    c.node_id = 5;
    c.initial_position = 4242;
    c.max_step_counts = 1000;
    return c;
  }
  // Deliver everything the tester sent to the node and let the node's timers run.
  void pump() {
    CanFrame f;
    while (drive_ep_.receive(f)) node_.handle(f, now_);
    node_.step(now_);
  }
  void advance_to(std::int64_t t) {
    while (now_ < t) {
      now_ = std::min(t, now_ + 1000);
      net_.set_time(now_);
      pump();
    }
  }
  std::vector<CanFrame> take() {
    std::vector<CanFrame> out;
    CanFrame f;
    while (tester_.receive(f)) out.push_back(f);
    return out;
  }
  drivers::SdoReply sdo(const CanFrame& request) {
    take();
    tester_.send(request);
    pump();
    for (const CanFrame& f : take()) {
      if (f.id == drivers::cob::sdo_tx(5)) return drivers::parse_sdo_reply(f);
    }
    return {};
  }
  std::uint32_t write(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::uint8_t size) {
    const drivers::SdoReply r = sdo(drivers::make_sdo_download(5, index, sub, value, size));
    return r.kind == drivers::SdoReplyKind::kAbort ? r.value : 0;
  }
  std::optional<std::uint32_t> read(std::uint16_t index, std::uint8_t sub) {
    const drivers::SdoReply r = sdo(drivers::make_sdo_upload(5, index, sub));
    if (r.kind != drivers::SdoReplyKind::kUploadExpedited) return std::nullopt;
    return r.value;
  }
  std::uint32_t read_abort(std::uint16_t index, std::uint8_t sub) {
    const drivers::SdoReply r = sdo(drivers::make_sdo_upload(5, index, sub));
    return r.kind == drivers::SdoReplyKind::kAbort ? r.value : 0;
  }
  void send(const CanFrame& f) {
    tester_.send(f);
    pump();
  }

  test::FakeCanNetwork net_;
  test::FakeCanNetwork::Endpoint& tester_ = net_.add_endpoint();
  test::FakeCanNetwork::Endpoint& drive_ep_ = net_.add_endpoint();
  SimDriveNode node_;
  std::int64_t now_ = 0;
};

TEST_F(SimDriveNodeTest, PowerOnSendsBootUpAndEntersPreOperational) {
  node_.power_on(now_);
  const auto frames = take();
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].id, 0x705u);
  EXPECT_EQ(frames[0].dlc, 1);
  EXPECT_EQ(frames[0].data[0], 0x00);
  EXPECT_EQ(node_.nmt_state(), NmtState::kPreOperational);
  EXPECT_EQ(node_.drive_state(), hal::DriveState::kSwitchOnDisabled);
}

TEST_F(SimDriveNodeTest, SdoServerAnswersAndAborts) {
  node_.power_on(now_);
  EXPECT_EQ(read(0x1000, 0), 0x00020192u);  // device type: CiA 402 servo
  EXPECT_EQ(read(0x6064, 0), 4242u);
  EXPECT_EQ(read(0x6502, 0).value() & (1u << 7), 1u << 7);
  EXPECT_EQ(read(0x6041, 0).value() & 0x4F, 0x40u);  // switch on disabled
  EXPECT_EQ(read_abort(0x2000, 0), 0x06020000u);     // no such object
  EXPECT_EQ(read_abort(0x6041, 1), 0x06090011u);     // no such sub-index
  EXPECT_EQ(write(0x6041, 0, 0, 2), 0x06010002u);    // read-only
  EXPECT_EQ(write(0x6060, 0, 8, 2), 0x06070012u);    // INT8 written with 2 bytes
  EXPECT_EQ(write(0x6060, 0, 3, 1), 0x06090030u);    // profile velocity is not offered
  EXPECT_EQ(write(0x6060, 0, 8, 1), 0u);
  EXPECT_EQ(read(0x6061, 0), 8u);
  EXPECT_EQ(write(0x60C2, 1, 2, 1), 0u);
  EXPECT_EQ(write(0x60C2, 2, 0xFD, 1), 0u);  // −3
  EXPECT_EQ(read(0x60C2, 2), 0xFDu);
  // A segmented download is refused, not misread.
  CanFrame seg = drivers::make_sdo_download(5, 0x1008, 0, 0, 4);
  seg.data[0] = 0x21;
  EXPECT_EQ(sdo(seg).kind, drivers::SdoReplyKind::kAbort);
}

TEST_F(SimDriveNodeTest, MissingObjectsAbortAsConfigured) {
  SimDriveConfig c = config();
  c.missing_objects = {0x60C2};
  SimDriveNode lacking(drive_ep_, c);
  lacking.power_on(now_);
  take();
  tester_.send(drivers::make_sdo_download(5, 0x60C2, 1, 2, 1));
  CanFrame f;
  ASSERT_TRUE(drive_ep_.receive(f));
  lacking.handle(f, now_);
  const auto frames = take();
  ASSERT_EQ(frames.size(), 1u);
  const drivers::SdoReply r = drivers::parse_sdo_reply(frames[0]);
  EXPECT_EQ(r.kind, drivers::SdoReplyKind::kAbort);
  EXPECT_EQ(r.value, 0x06020000u);
}

TEST_F(SimDriveNodeTest, PdoRemapFollowsTheCia301Procedure) {
  node_.power_on(now_);
  // Mapping a valid PDO is refused; invalidate first.
  EXPECT_EQ(write(0x1A00, 0, 0, 1), 0x06010000u);
  EXPECT_EQ(write(0x1800, 1, 0x80000185u, 4), 0u);
  // Entries only while :00 = 0.
  EXPECT_EQ(write(0x1A00, 1, 0x60410010u, 4), 0x06010000u);
  EXPECT_EQ(write(0x1A00, 0, 0, 1), 0u);
  EXPECT_EQ(write(0x1A00, 1, 0x60400010u, 4), 0x06040041u);  // controlword is not a TPDO object
  EXPECT_EQ(write(0x1A00, 1, 0x60410020u, 4), 0x06040041u);  // wrong bit length
  EXPECT_EQ(write(0x1A00, 1, 0x60640020u, 4), 0u);
  EXPECT_EQ(write(0x1A00, 2, 0x606C0020u, 4), 0u);
  EXPECT_EQ(write(0x1A00, 3, 0x60410010u, 4), 0u);
  EXPECT_EQ(write(0x1A00, 0, 3, 1), 0x06040042u);  // 80 bits do not fit 8 bytes
  EXPECT_EQ(write(0x1A00, 0, 2, 1), 0u);
  // Changing a valid COB-ID directly is refused.
  EXPECT_EQ(write(0x1800, 1, 0x185u, 4), 0u);
  EXPECT_EQ(write(0x1800, 1, 0x186u, 4), 0x06090030u);
  EXPECT_EQ(write(0x1800, 2, 241, 1), 0x06090030u);  // reserved transmission type
}

TEST_F(SimDriveNodeTest, HeartbeatAtTheProducerTime) {
  node_.power_on(now_);
  EXPECT_EQ(write(0x1017, 0, 50, 2), 0u);
  take();
  advance_to(500'000);
  std::vector<std::int64_t> times;
  for (const auto& l : net_.log()) {
    if (l.frame.id == 0x705 && l.frame.data[0] == 0x7F) times.push_back(l.time_us);
  }
  ASSERT_EQ(times.size(), 10u);
  for (std::size_t i = 1; i < times.size(); ++i) EXPECT_EQ(times[i] - times[i - 1], 50'000);
}

TEST_F(SimDriveNodeTest, PdosOnlyWhenOperational) {
  node_.power_on(now_);
  take();
  send(drivers::make_sync());
  EXPECT_TRUE(take().empty());  // pre-operational: SYNC ignored
  send(drivers::make_nmt(NmtCommand::kStart, 5));
  send(drivers::make_sync());
  auto frames = take();
  // Factory default: TPDO1 and TPDO2 both active.
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].id, 0x185u);
  EXPECT_EQ(frames[1].id, 0x285u);
  const auto t1 = drivers::unpack_tpdo1(frames[0], 5);
  ASSERT_TRUE(t1);
  EXPECT_EQ(t1->position_actual, 4242);
  // NMT stop: silent except for NMT.
  send(drivers::make_nmt(NmtCommand::kStop, 0));
  send(drivers::make_sync());
  EXPECT_TRUE(take().empty());
  // Reset node: boot-up again, pre-operational, defaults back.
  send(drivers::make_nmt(NmtCommand::kResetNode, 5));
  frames = take();
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].id, 0x705u);
  EXPECT_EQ(frames[0].data[0], 0x00);
  EXPECT_EQ(node_.nmt_state(), NmtState::kPreOperational);
}

TEST_F(SimDriveNodeTest, RpdoAppliedAtTheNextSyncAndCspTracks) {
  node_.power_on(now_);
  write(0x6060, 0, 8, 1);
  send(drivers::make_nmt(NmtCommand::kStart, 5));
  const std::uint16_t sequence[] = {0x0006, 0x0007, 0x000F};
  for (std::uint16_t cw : sequence) {
    send(drivers::pack_rpdo1(5, {cw, 4242}));
    send(drivers::make_sync());
  }
  EXPECT_EQ(node_.drive_state(), hal::DriveState::kOperationEnabled);
  send(drivers::pack_rpdo1(5, {0x000F, 4242 + 900}));
  EXPECT_EQ(node_.position(), 4242);  // not before SYNC
  take();
  send(drivers::make_sync());
  EXPECT_EQ(node_.position(), 4242 + 900);
  const auto frames = take();
  ASSERT_FALSE(frames.empty());
  const auto t1 = drivers::unpack_tpdo1(frames[0], 5);
  ASSERT_TRUE(t1);
  EXPECT_EQ(t1->position_actual, 4242 + 900);
  EXPECT_EQ(t1->statusword & 0x6F, 0x27);
  EXPECT_NE(t1->statusword & (1u << 12), 0u);  // CSP: drive follows the target
  const auto t2 = drivers::unpack_tpdo2(frames[1], 5);
  ASSERT_TRUE(t2);
  EXPECT_EQ(t2->velocity_actual, 900'000);  // 900 counts per 1 ms default interpolation period
}

TEST_F(SimDriveNodeTest, JumpBeyondTheWindowIsAFollowingErrorFault) {
  node_.power_on(now_);
  write(0x6060, 0, 8, 1);
  send(drivers::make_nmt(NmtCommand::kStart, 5));
  for (std::uint16_t cw : {std::uint16_t{0x0006}, std::uint16_t{0x0007}, std::uint16_t{0x000F}}) {
    send(drivers::pack_rpdo1(5, {cw, 4242}));
    send(drivers::make_sync());
  }
  take();
  send(drivers::pack_rpdo1(5, {0x000F, 0}));  // the jump-on-enable bug: target 0 instead of actual
  send(drivers::make_sync());
  EXPECT_EQ(node_.position(), 4242);
  const auto frames = take();
  bool emcy = false;
  for (const CanFrame& f : frames) {
    if (auto e = drivers::parse_emcy(f)) {
      EXPECT_EQ(e->code, 0x8611);
      emcy = true;
    }
  }
  EXPECT_TRUE(emcy);
  EXPECT_EQ(node_.drive_state(), hal::DriveState::kFault);
  // Fault reset: rising edge of bit 7 → switch on disabled and an EMCY "error reset".
  send(drivers::pack_rpdo1(5, {0x0080, 4242}));
  send(drivers::make_sync());
  EXPECT_EQ(node_.drive_state(), hal::DriveState::kSwitchOnDisabled);
  bool reset_seen = false;
  for (const CanFrame& f : take()) {
    if (auto e = drivers::parse_emcy(f)) reset_seen = e->code == 0x0000;
  }
  EXPECT_TRUE(reset_seen);
}

TEST_F(SimDriveNodeTest, ShortRpdoRaisesPdoLengthEmcy) {
  node_.power_on(now_);
  send(drivers::make_nmt(NmtCommand::kStart, 5));
  take();
  CanFrame shortp = drivers::pack_rpdo1(5, {0x0006, 0});
  shortp.dlc = 4;
  send(shortp);
  const auto frames = take();
  ASSERT_EQ(frames.size(), 1u);
  const auto e = drivers::parse_emcy(frames[0]);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->code, 0x8210);
}

TEST_F(SimDriveNodeTest, PoweredOffNodeIsSilent) {
  node_.power_on(now_);
  EXPECT_EQ(write(0x1017, 0, 10, 2), 0u);
  take();
  node_.power_off();
  advance_to(100'000);
  tester_.send(drivers::make_sdo_upload(5, 0x1000, 0));
  pump();
  EXPECT_TRUE(take().empty());
}

// ---- Raw frames (bytes written out from CiA 301, not through drivers/' codecs) ---------------------
class SimDriveNodeRawTest : public ::testing::Test {
 protected:
  // One node with `c` on the bus; everything it sent so far is discarded.
  void start(SimDriveConfig c) {
    c.node_id = 5;
    node_.emplace(drive_ep_, c);
    node_->power_on(now_);
    take();
  }
  void pump() {
    CanFrame f;
    while (drive_ep_.receive(f)) node_->handle(f, now_);
    node_->step(now_);
  }
  void advance_to(std::int64_t t) {
    while (now_ < t) {
      now_ = std::min(t, now_ + 1000);
      net_.set_time(now_);
      pump();
    }
  }
  std::vector<CanFrame> take() {
    std::vector<CanFrame> out;
    CanFrame f;
    while (tester_.receive(f)) out.push_back(f);
    return out;
  }
  void send(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
    CanFrame f;
    f.id = id;
    f.dlc = static_cast<std::uint8_t>(bytes.size());
    std::size_t k = 0;
    for (std::uint8_t b : bytes) f.data[k++] = b;
    tester_.send(f);
    pump();
  }
  // The SDO reply (0x585) to one request on 0x605.
  std::array<std::uint8_t, 8> sdo(std::initializer_list<std::uint8_t> request) {
    take();
    send(0x605, request);
    for (const CanFrame& f : take()) {
      if (f.id == 0x585 && f.dlc == 8) return f.data;
    }
    return {};
  }

  test::FakeCanNetwork net_;
  test::FakeCanNetwork::Endpoint& tester_ = net_.add_endpoint();
  test::FakeCanNetwork::Endpoint& drive_ep_ = net_.add_endpoint();
  std::optional<SimDriveNode> node_;
  std::int64_t now_ = 0;
};

using Bytes = std::array<std::uint8_t, 8>;

TEST_F(SimDriveNodeRawTest, StatuswordUploadIs4BWithTheStatuswordLittleEndian) {
  start({});
  const std::uint16_t sw = node_->statusword();
  EXPECT_EQ(sdo({0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0}),
            (Bytes{0x4B, 0x41, 0x60, 0x00, static_cast<std::uint8_t>(sw & 0xFF),
                   static_cast<std::uint8_t>(sw >> 8), 0, 0}));
  EXPECT_EQ(sw & 0x4F, 0x40);  // switch on disabled
  // Device type 0x00020192 and the CSP bit of 0x6502.
  EXPECT_EQ(sdo({0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}),
            (Bytes{0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}));
  EXPECT_EQ(sdo({0x40, 0x02, 0x65, 0x00, 0, 0, 0, 0}),
            (Bytes{0x43, 0x02, 0x65, 0x00, 0x85, 0x00, 0x00, 0x00}));
  // Factory TPDO2 mapping: velocity (32 bits), torque (16 bits).
  EXPECT_EQ(sdo({0x40, 0x01, 0x1A, 0x00, 0, 0, 0, 0}), (Bytes{0x4F, 0x01, 0x1A, 0x00, 0x02, 0, 0, 0}));
  EXPECT_EQ(sdo({0x40, 0x01, 0x1A, 0x02, 0, 0, 0, 0}),
            (Bytes{0x43, 0x01, 0x1A, 0x02, 0x10, 0x00, 0x77, 0x60}));
}

TEST_F(SimDriveNodeRawTest, CommercialPersonalityLacksTpdo3And4And1016AndHasFixedMapping) {
  SimDriveConfig c;
  c.fixed_mapping = true;
  c.missing_objects = {0x1802, 0x1803, 0x1A02, 0x1A03, 0x1016};
  start(c);
  for (std::uint8_t index_lo : {std::uint8_t{0x02}, std::uint8_t{0x03}}) {
    EXPECT_EQ(sdo({0x23, index_lo, 0x18, 0x01, 0x80, 0x03, 0x00, 0x80}),
              (Bytes{0x80, index_lo, 0x18, 0x01, 0x00, 0x00, 0x02, 0x06}));
  }
  EXPECT_EQ(sdo({0x40, 0x16, 0x10, 0x01, 0, 0, 0, 0}),
            (Bytes{0x80, 0x16, 0x10, 0x01, 0x00, 0x00, 0x02, 0x06}));
  // Invalidating the PDO is allowed; its mapping stays read-only, sub-index 0 included.
  EXPECT_EQ(sdo({0x23, 0x00, 0x14, 0x01, 0x05, 0x02, 0x00, 0x80}),
            (Bytes{0x60, 0x00, 0x14, 0x01, 0, 0, 0, 0}));
  EXPECT_EQ(sdo({0x2F, 0x00, 0x16, 0x00, 0x00, 0, 0, 0}),
            (Bytes{0x80, 0x00, 0x16, 0x00, 0x02, 0x00, 0x01, 0x06}));
  EXPECT_EQ(sdo({0x23, 0x00, 0x16, 0x01, 0x10, 0x00, 0x40, 0x60}),
            (Bytes{0x80, 0x00, 0x16, 0x01, 0x02, 0x00, 0x01, 0x06}));
  EXPECT_EQ(sdo({0x40, 0x00, 0x16, 0x02, 0, 0, 0, 0}),
            (Bytes{0x43, 0x00, 0x16, 0x02, 0x20, 0x00, 0x7A, 0x60}));
}

TEST_F(SimDriveNodeRawTest, FactoryTpdo1MappingOfThePersonalityIsWhatTheDriveSends) {
  SimDriveConfig c;
  c.fixed_mapping = true;
  c.tpdo1_factory_mapping = {0x60410010, 0x60630020};
  start(c);
  EXPECT_EQ(sdo({0x40, 0x00, 0x1A, 0x02, 0, 0, 0, 0}),
            (Bytes{0x43, 0x00, 0x1A, 0x02, 0x20, 0x00, 0x63, 0x60}));
  send(0x000, {0x01, 0x05});
  take();
  send(0x080, {});
  const auto frames = take();
  ASSERT_FALSE(frames.empty());
  EXPECT_EQ(frames[0].id, 0x185u);
  EXPECT_EQ(frames[0].dlc, 6);  // 16 + 32 bits, whatever the drive does not have reads 0
}

TEST_F(SimDriveNodeRawTest, DriveWithoutCspRefusesMode8) {
  SimDriveConfig c;
  c.supports_csp = false;
  start(c);
  EXPECT_EQ(sdo({0x40, 0x02, 0x65, 0x00, 0, 0, 0, 0}),
            (Bytes{0x43, 0x02, 0x65, 0x00, 0x05, 0x00, 0x00, 0x00}));
  EXPECT_EQ(sdo({0x2F, 0x60, 0x60, 0x00, 0x08, 0, 0, 0}),
            (Bytes{0x80, 0x60, 0x60, 0x00, 0x30, 0x00, 0x09, 0x06}));
  EXPECT_EQ(sdo({0x2F, 0x60, 0x60, 0x00, 0x00, 0, 0, 0}), (Bytes{0x60, 0x60, 0x60, 0x00, 0, 0, 0, 0}));
}

TEST_F(SimDriveNodeRawTest, MasterHeartbeatLostQuickStopsAndRaisesEmcy8130) {
  start({});
  // Consumer: master node 0x7F, 100 ms.
  EXPECT_EQ(sdo({0x23, 0x16, 0x10, 0x01, 0x64, 0x00, 0x7F, 0x00}),
            (Bytes{0x60, 0x16, 0x10, 0x01, 0, 0, 0, 0}));
  EXPECT_EQ(sdo({0x2F, 0x60, 0x60, 0x00, 0x08, 0, 0, 0}), (Bytes{0x60, 0x60, 0x60, 0x00, 0, 0, 0, 0}));
  send(0x000, {0x01, 0x05});
  for (std::uint8_t cw : {std::uint8_t{0x06}, std::uint8_t{0x07}, std::uint8_t{0x0F}}) {
    EXPECT_EQ(sdo({0x2B, 0x40, 0x60, 0x00, cw, 0x00, 0, 0}), (Bytes{0x60, 0x40, 0x60, 0x00, 0, 0, 0, 0}));
  }
  EXPECT_EQ(node_->drive_state(), hal::DriveState::kOperationEnabled);
  send(0x77F, {0x05});  // the master's heartbeat starts the consumer
  take();
  advance_to(now_ + 100'000);
  EXPECT_FALSE(node_->master_lost());
  advance_to(now_ + 2'000);
  EXPECT_TRUE(node_->master_lost());
  EXPECT_EQ(node_->drive_state(), hal::DriveState::kQuickStopActive);
  bool emcy = false;
  for (const CanFrame& f : take()) {
    if (f.id == 0x085) {
      EXPECT_EQ(f.data, (Bytes{0x30, 0x81, 0x10, 0, 0, 0, 0, 0}));
      emcy = true;
    }
  }
  EXPECT_TRUE(emcy);
}

TEST_F(SimDriveNodeRawTest, InjectedFaultSendsEmcyAndReportsItIn603F) {
  start({});
  node_->inject_fault(0x2310);
  const auto frames = take();
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].id, 0x085u);
  EXPECT_EQ(frames[0].data, (Bytes{0x10, 0x23, 0x01, 0, 0, 0, 0, 0}));
  EXPECT_EQ(sdo({0x40, 0x3F, 0x60, 0x00, 0, 0, 0, 0}), (Bytes{0x4B, 0x3F, 0x60, 0x00, 0x10, 0x23, 0, 0}));
  EXPECT_EQ(sdo({0x40, 0x01, 0x10, 0x00, 0, 0, 0, 0}), (Bytes{0x4F, 0x01, 0x10, 0x00, 0x01, 0, 0, 0}));
}

TEST_F(SimDriveNodeRawTest, SlowPersonalityBootsAndStartsLate) {
  SimDriveConfig c;
  c.boot_delay_us = 300'000;
  c.operational_delay_us = 400'000;
  c.node_id = 5;
  node_.emplace(drive_ep_, c);
  node_->power_on(now_);
  EXPECT_TRUE(take().empty());
  advance_to(299'000);
  EXPECT_TRUE(take().empty());
  advance_to(300'000);
  const auto boot = take();
  ASSERT_EQ(boot.size(), 1u);
  EXPECT_EQ(boot[0].id, 0x705u);
  EXPECT_EQ(boot[0].data[0], 0x00);
  send(0x000, {0x01, 0x00});
  EXPECT_EQ(node_->nmt_state(), NmtState::kPreOperational);
  advance_to(now_ + 400'000);
  EXPECT_EQ(node_->nmt_state(), NmtState::kOperational);
}

// Profile position (mode 1), driven with frames built here byte by byte (CiA 301 little-endian): the
// set-point handshake, the trapezoid against its closed form, and the event-driven TPDO1's timing.
CanFrame rpdo1(std::uint8_t node, std::uint16_t controlword, std::int32_t target) {
  CanFrame f;
  f.id = 0x200u + node;
  f.dlc = 6;
  const auto t = static_cast<std::uint32_t>(target);
  f.data = {static_cast<std::uint8_t>(controlword & 0xFF),
            static_cast<std::uint8_t>(controlword >> 8),
            static_cast<std::uint8_t>(t & 0xFF),
            static_cast<std::uint8_t>((t >> 8) & 0xFF),
            static_cast<std::uint8_t>((t >> 16) & 0xFF),
            static_cast<std::uint8_t>(t >> 24),
            0,
            0};
  return f;
}
std::uint16_t tpdo_statusword(const CanFrame& f) {
  return static_cast<std::uint16_t>(f.data[0] | f.data[1] << 8);
}

TEST_F(SimDriveNodeTest, ProfilePositionRunsTheHandshakeAndATrapezoidWithTimedTpdos) {
  node_.power_on(now_);
  EXPECT_EQ(read(0x6502, 0).value() & 1u, 1u);     // profile position offered
  EXPECT_EQ(write(0x6086, 0, 3, 2), 0x06090030u);  // jerk-limited: not offered (linear ramp only)
  EXPECT_EQ(write(0x6060, 0, 1, 1), 0u);
  EXPECT_EQ(read(0x6061, 0), 1u);
  const double v = 100000.0, a = 1000000.0;  // counts/s, counts/s²
  EXPECT_EQ(write(0x6081, 0, 100000, 4), 0u);
  EXPECT_EQ(write(0x6083, 0, 1000000, 4), 0u);
  EXPECT_EQ(write(0x6084, 0, 1000000, 4), 0u);
  EXPECT_EQ(write(0x1400, 2, 255, 1), 0u);
  EXPECT_EQ(write(0x1800, 2, 255, 1), 0u);
  EXPECT_EQ(write(0x1800, 3, 100, 2), 0u);          // 10 ms
  EXPECT_EQ(write(0x1800, 5, 100, 2), 0u);          // 100 ms
  EXPECT_EQ(write(0x1801, 1, 0x80000285u, 4), 0u);  // TPDO2 off
  send(drivers::make_nmt(NmtCommand::kStart, 5));
  for (const int cw : {0x06, 0x07, 0x0F}) send(rpdo1(5, static_cast<std::uint16_t>(cw), 4242));
  advance_to(now_ + 20000);
  ASSERT_EQ(node_.drive_state(), hal::DriveState::kOperationEnabled);
  take();

  // Set-point: the drive acknowledges (bit 12) at once, event-driven, and keeps it until bit 4 falls.
  const std::int32_t goal = 4242 + 20000;
  send(rpdo1(5, 0x1F, goal));
  auto frames = take();
  ASSERT_FALSE(frames.empty());
  EXPECT_EQ(frames.back().id, 0x185u);
  EXPECT_NE(tpdo_statusword(frames.back()) & (1u << 12), 0u);
  EXPECT_EQ(tpdo_statusword(frames.back()) & (1u << 10), 0u);  // a move to run: not reached
  EXPECT_EQ(node_.setpoints_latched(), 1u);
  send(rpdo1(5, 0x0F, goal));
  EXPECT_EQ(node_.statusword() & (1u << 12), 0u);
  send(rpdo1(5, 0x0F, goal));  // no rising edge: no new set-point
  EXPECT_EQ(node_.setpoints_latched(), 1u);

  // SYNC every 1 ms (0x60C2's default): the trapezoid d/v + v/a = 0.3 s, speed never above v.
  std::vector<std::int64_t> tpdo_at;
  const std::int64_t t0 = now_;
  std::int64_t reached_at = -1;
  std::int32_t last = node_.position();
  for (int k = 0; k < 600; ++k) {
    send(drivers::make_sync());
    for (const CanFrame& f : take()) {
      if (f.id == 0x185u) tpdo_at.push_back(now_);
    }
    EXPECT_LE(std::abs(node_.position() - last), static_cast<int>(v * 1e-3) + 1) << k;
    last = node_.position();
    if (reached_at < 0 && node_.position() == goal) reached_at = now_ - t0;
    advance_to(now_ + 1000);
    for (const CanFrame& f : take()) {
      if (f.id == 0x185u) tpdo_at.push_back(now_);
    }
  }
  const double t_closed = 20000.0 / v + v / a;
  ASSERT_GT(reached_at, 0);
  EXPECT_NEAR(static_cast<double>(reached_at) * 1e-6, t_closed, 0.004);
  EXPECT_NE(node_.statusword() & (1u << 10), 0u);
  // Never closer than the inhibit time; moving, about every inhibit time; still, every event timer period.
  ASSERT_GE(tpdo_at.size(), 30u);
  for (std::size_t k = 1; k < tpdo_at.size(); ++k) EXPECT_GE(tpdo_at[k] - tpdo_at[k - 1], 10000) << k;
  EXPECT_LE(tpdo_at[1] - tpdo_at[0], 11000);
  EXPECT_NEAR(static_cast<double>(tpdo_at.back() - tpdo_at[tpdo_at.size() - 2]), 100000.0, 1000.0);
}

TEST_F(SimDriveNodeTest, ADriveWithoutProfilePositionRefusesModeOne) {
  SimDriveConfig c = config();
  c.supports_pp = false;
  test::FakeCanNetwork net;
  auto& tester = net.add_endpoint();
  auto& ep = net.add_endpoint();
  SimDriveNode node(ep, c);
  node.power_on(0);
  CanFrame f;
  while (tester.receive(f)) {
  }
  tester.send(drivers::make_sdo_download(5, 0x6060, 0, 1, 1));
  while (ep.receive(f)) node.handle(f, 0);
  bool aborted = false;
  while (tester.receive(f)) {
    const auto r = drivers::parse_sdo_reply(f);
    aborted |= r.kind == drivers::SdoReplyKind::kAbort && r.value == 0x06090030u;
  }
  EXPECT_TRUE(aborted);
  EXPECT_EQ(node.mode(), 0);
}

}  // namespace
}  // namespace loom::sim_can

// The simulated nodes' slave-side CiA 301 (slave_od): SDO server, PDO parameter rules, PDO packing
// and the fixed frames, checked byte by byte against layouts written here from CiA 301 (§7.2.4.3 SDO,
// table 22 abort codes, §7.2.2 PDO, §7.2.7 EMCY, §7.2.8 NMT and heartbeat). Nothing here goes through
// drivers/' codecs or a round trip through slave_od's own encoders: the expected bytes are the truth.
#include <gtest/gtest.h>

#include <initializer_list>
#include <optional>
#include <vector>

#include "loom/sim_can/slave_od.hpp"

namespace loom::sim_can::slave {
namespace {

using drivers::CanFrame;
using Bytes = std::array<std::uint8_t, 8>;

constexpr std::uint8_t kNode = 5;

// A small device: device type, heartbeat producer, RPDO1 {controlword}, TPDO1 {statusword, position}.
constexpr Objects<1> kHead{{{0x1000, 0, 4, Access::kConst, Pdo::kNone, 0x00020192}}};
constexpr Objects<1> kProducer{{{0x1017, 0, 2, Access::kRw, Pdo::kNone, 0}}};
constexpr Objects<5> kProfile{{
    {0x6040, 0, 2, Access::kRw, Pdo::kRx, 0},
    {0x6041, 0, 2, Access::kRo, Pdo::kTx, 0},
    {0x6060, 0, 1, Access::kRw, Pdo::kRx, 0},
    {0x6064, 0, 4, Access::kRo, Pdo::kTx, 0},
    {0x607A, 0, 4, Access::kRw, Pdo::kRx, 0},
}};
constexpr auto kTable =
    concat(kHead, kProducer, pdo_comm(0x1400, 0x200, 255), pdo_map(0x1600, {0x60400010}),
           pdo_comm(0x1800, 0x180, 1), pdo_map(0x1A00, {0x60410010, 0x60640020}), kProfile);
static_assert(sorted(kTable));

// Records what the dictionary tells the device; refuses 0x6060 values other than 0 and 8.
struct Recorder final : ObjectHooks {
  std::uint32_t check(std::uint16_t index, std::uint8_t, std::uint32_t value) const override {
    return (index == 0x6060 && value != 0 && value != 8) ? 0x06090030U : 0U;
  }
  void written(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::int64_t now_us) override {
    writes.push_back({index, sub, value, now_us});
  }
  struct Write {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint32_t value;
    std::int64_t now_us;
  };
  std::vector<Write> writes;
};

CanFrame frame(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<std::uint8_t>(bytes.size());
  std::size_t k = 0;
  for (std::uint8_t b : bytes) f.data[k++] = b;
  return f;
}

class SimSlaveOd : public ::testing::Test {
 protected:
  explicit SimSlaveOd(OdOptions options = {}) : od_(kTable, std::move(options)) {
    od_.reset_communication(kNode);
  }

  // The server's answer to a request on 0x600 + node.
  std::optional<CanFrame> serve(std::initializer_list<std::uint8_t> request) {
    return sdo_serve(od_, hooks_, kNode, frame(0x605, request), 1234);
  }
  void expect_reply(std::initializer_list<std::uint8_t> request, const Bytes& reply) {
    const std::optional<CanFrame> f = serve(request);
    ASSERT_TRUE(f.has_value());
    EXPECT_EQ(f->id, 0x585u);
    EXPECT_EQ(f->dlc, 8);
    EXPECT_EQ(f->data, reply);
  }

  ObjectDictionary od_;
  Recorder hooks_;
};

class SimSlaveOdFixedMapping : public SimSlaveOd {
 protected:
  SimSlaveOdFixedMapping() : SimSlaveOd(OdOptions{{}, true}) {}
};

class SimSlaveOdWithoutTpdo1 : public SimSlaveOd {
 protected:
  SimSlaveOdWithoutTpdo1() : SimSlaveOd(OdOptions{{0x1800, 0x1A00}, false}) {}
};

// ---- SDO upload (expedited reply: 0x4F/0x4B/0x43 for 1/2/4 bytes) ---------------------------------
TEST_F(SimSlaveOd, UploadOfTheStatuswordIs4BWithTwoDataBytes) {
  od_.set(0x6041, 0, 0x0237);
  expect_reply({0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0}, {0x4B, 0x41, 0x60, 0x00, 0x37, 0x02, 0x00, 0x00});
}

TEST_F(SimSlaveOd, UploadSizesFollowTheObject) {
  od_.set(0x6060, 0, 8);
  expect_reply({0x40, 0x60, 0x60, 0x00, 0, 0, 0, 0}, {0x4F, 0x60, 0x60, 0x00, 0x08, 0x00, 0x00, 0x00});
  expect_reply({0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00});
  // COB-ID with the node id added at reset communication.
  expect_reply({0x40, 0x00, 0x18, 0x01, 0, 0, 0, 0}, {0x43, 0x00, 0x18, 0x01, 0x85, 0x01, 0x00, 0x00});
  expect_reply({0x40, 0x00, 0x14, 0x01, 0, 0, 0, 0}, {0x43, 0x00, 0x14, 0x01, 0x05, 0x02, 0x00, 0x00});
  // A mapping object's :00 is the number of entries, :01 the first entry.
  expect_reply({0x40, 0x00, 0x1A, 0x00, 0, 0, 0, 0}, {0x4F, 0x00, 0x1A, 0x00, 0x02, 0x00, 0x00, 0x00});
  expect_reply({0x40, 0x00, 0x1A, 0x02, 0, 0, 0, 0}, {0x43, 0x00, 0x1A, 0x02, 0x20, 0x00, 0x64, 0x60});
}

TEST_F(SimSlaveOd, UploadAbortsNameObjectAndCode) {
  expect_reply({0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0}, {0x80, 0x00, 0x20, 0x00, 0x00, 0x00, 0x02, 0x06});
  expect_reply({0x40, 0x41, 0x60, 0x01, 0, 0, 0, 0}, {0x80, 0x41, 0x60, 0x01, 0x11, 0x00, 0x09, 0x06});
}

// ---- SDO download (0x2F/0x2B/0x23 for 1/2/4 bytes, 0x22 size not indicated; reply 0x60) -------------
TEST_F(SimSlaveOd, ExpeditedDownloadIsAcknowledgedStoredAndReported) {
  expect_reply({0x2B, 0x17, 0x10, 0x00, 0x64, 0x00, 0x00, 0x00}, {0x60, 0x17, 0x10, 0x00, 0, 0, 0, 0});
  EXPECT_EQ(od_.get(0x1017, 0), 100u);
  ASSERT_EQ(hooks_.writes.size(), 1u);
  EXPECT_EQ(hooks_.writes[0].index, 0x1017);
  EXPECT_EQ(hooks_.writes[0].value, 100u);
  EXPECT_EQ(hooks_.writes[0].now_us, 1234);
}

TEST_F(SimSlaveOd, DownloadWithoutSizeIndicatedTakesTheObjectsWidth) {
  expect_reply({0x22, 0x40, 0x60, 0x00, 0x0F, 0x00, 0xAA, 0xBB}, {0x60, 0x40, 0x60, 0x00, 0, 0, 0, 0});
  EXPECT_EQ(od_.get(0x6040, 0), 0x000Fu);
}

TEST_F(SimSlaveOd, DownloadAbortsFollowTable22) {
  // Read-only object.
  expect_reply({0x2B, 0x41, 0x60, 0x00, 0x00, 0x00, 0, 0}, {0x80, 0x41, 0x60, 0x00, 0x02, 0x00, 0x01, 0x06});
  // Constant object (device type).
  expect_reply({0x23, 0x00, 0x10, 0x00, 1, 2, 3, 4}, {0x80, 0x00, 0x10, 0x00, 0x02, 0x00, 0x01, 0x06});
  // INT8 written with 2 bytes: too high; UNSIGNED16 with 1 byte: too low.
  expect_reply({0x2B, 0x60, 0x60, 0x00, 0x08, 0x00, 0, 0}, {0x80, 0x60, 0x60, 0x00, 0x12, 0x00, 0x07, 0x06});
  expect_reply({0x2F, 0x17, 0x10, 0x00, 0x08, 0, 0, 0}, {0x80, 0x17, 0x10, 0x00, 0x13, 0x00, 0x07, 0x06});
  // No such object / sub-index.
  expect_reply({0x2F, 0x00, 0x20, 0x00, 0x08, 0, 0, 0}, {0x80, 0x00, 0x20, 0x00, 0x00, 0x00, 0x02, 0x06});
  expect_reply({0x2F, 0x60, 0x60, 0x01, 0x08, 0, 0, 0}, {0x80, 0x60, 0x60, 0x01, 0x11, 0x00, 0x09, 0x06});
  // The device's own value rule (through its hooks): nothing stored, nothing reported.
  expect_reply({0x2F, 0x60, 0x60, 0x00, 0x03, 0, 0, 0}, {0x80, 0x60, 0x60, 0x00, 0x30, 0x00, 0x09, 0x06});
  EXPECT_EQ(od_.get(0x6060, 0), 0u);
  EXPECT_TRUE(hooks_.writes.empty());
}

TEST_F(SimSlaveOd, TransfersOtherThanExpeditedAreRefused) {
  // Segmented download initiate (e = 0, s = 1, size 4 bytes): unsupported access.
  expect_reply({0x21, 0x17, 0x10, 0x00, 0x04, 0, 0, 0}, {0x80, 0x17, 0x10, 0x00, 0x00, 0x00, 0x01, 0x06});
  // Block download initiate (ccs 6): command specifier not valid.
  expect_reply({0xC0, 0x17, 0x10, 0x00, 0, 0, 0, 0}, {0x80, 0x17, 0x10, 0x00, 0x01, 0x00, 0x04, 0x05});
  // A short frame: no multiplexer to echo.
  EXPECT_EQ(serve({0x40, 0x41, 0x60})->data, (Bytes{0x80, 0, 0, 0, 0x01, 0x00, 0x04, 0x05}));
  // The client's abort is not answered.
  EXPECT_FALSE(serve({0x80, 0x41, 0x60, 0x00, 0x00, 0x00, 0x04, 0x05}).has_value());
}

// ---- PDO communication and mapping parameters (CiA 301 re-map procedure) ---------------------------
TEST_F(SimSlaveOd, MappingWhileThePdoIsValidIsUnsupportedAccess) {
  expect_reply({0x2F, 0x00, 0x1A, 0x00, 0x00, 0, 0, 0}, {0x80, 0x00, 0x1A, 0x00, 0x00, 0x00, 0x01, 0x06});
  expect_reply({0x23, 0x00, 0x1A, 0x01, 0x20, 0x00, 0x64, 0x60},
               {0x80, 0x00, 0x1A, 0x01, 0x00, 0x00, 0x01, 0x06});
}

TEST_F(SimSlaveOd, RemapProcedure) {
  // 1. Invalidate TPDO1 (bit 31).
  expect_reply({0x23, 0x00, 0x18, 0x01, 0x85, 0x01, 0x00, 0x80}, {0x60, 0x00, 0x18, 0x01, 0, 0, 0, 0});
  EXPECT_FALSE(od_.pdo_valid(0x1800));
  // 2. Entries only while :00 = 0.
  expect_reply({0x23, 0x00, 0x1A, 0x01, 0x20, 0x00, 0x64, 0x60},
               {0x80, 0x00, 0x1A, 0x01, 0x00, 0x00, 0x01, 0x06});
  expect_reply({0x2F, 0x00, 0x1A, 0x00, 0x00, 0, 0, 0}, {0x60, 0x00, 0x1A, 0x00, 0, 0, 0, 0});
  // 3. Entries: receive-only object, wrong length and missing object are not mappable (0x06040041).
  expect_reply({0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x40, 0x60},
               {0x80, 0x00, 0x1A, 0x01, 0x41, 0x00, 0x04, 0x06});
  expect_reply({0x23, 0x00, 0x1A, 0x01, 0x20, 0x00, 0x41, 0x60},
               {0x80, 0x00, 0x1A, 0x01, 0x41, 0x00, 0x04, 0x06});
  expect_reply({0x23, 0x00, 0x1A, 0x01, 0x20, 0x00, 0x6C, 0x60},
               {0x80, 0x00, 0x1A, 0x01, 0x41, 0x00, 0x04, 0x06});
  for (std::uint8_t sub = 1; sub <= 3; ++sub) {
    expect_reply({0x23, 0x00, 0x1A, sub, 0x20, 0x00, 0x64, 0x60}, {0x60, 0x00, 0x1A, sub, 0, 0, 0, 0});
  }
  // 4. :00 = n: more than 8 entries is out of range, 96 bits do not fit 8 bytes.
  expect_reply({0x2F, 0x00, 0x1A, 0x00, 0x09, 0, 0, 0}, {0x80, 0x00, 0x1A, 0x00, 0x30, 0x00, 0x09, 0x06});
  expect_reply({0x2F, 0x00, 0x1A, 0x00, 0x03, 0, 0, 0}, {0x80, 0x00, 0x1A, 0x00, 0x42, 0x00, 0x04, 0x06});
  expect_reply({0x2F, 0x00, 0x1A, 0x00, 0x02, 0, 0, 0}, {0x60, 0x00, 0x1A, 0x00, 0, 0, 0, 0});
  // 5. Valid again, on a new identifier.
  expect_reply({0x23, 0x00, 0x18, 0x01, 0x86, 0x01, 0x00, 0x00}, {0x60, 0x00, 0x18, 0x01, 0, 0, 0, 0});
  EXPECT_TRUE(od_.pdo_valid(0x1800));
  EXPECT_EQ(od_.pdo_can_id(0x1800), 0x186u);
}

TEST_F(SimSlaveOd, CommunicationParameterRules) {
  // A valid PDO's COB-ID does not change in one step; bit 29 (extended id) is not supported.
  expect_reply({0x23, 0x00, 0x18, 0x01, 0x86, 0x01, 0x00, 0x00},
               {0x80, 0x00, 0x18, 0x01, 0x30, 0x00, 0x09, 0x06});
  expect_reply({0x23, 0x00, 0x18, 0x01, 0x85, 0x01, 0x00, 0xA0},
               {0x80, 0x00, 0x18, 0x01, 0x30, 0x00, 0x09, 0x06});
  // Writing the same valid COB-ID is accepted.
  expect_reply({0x23, 0x00, 0x18, 0x01, 0x85, 0x01, 0x00, 0x00}, {0x60, 0x00, 0x18, 0x01, 0, 0, 0, 0});
  // Transmission types: 241 reserved; 252 (RTR only) legal for a TPDO, not an RPDO.
  expect_reply({0x2F, 0x00, 0x18, 0x02, 241, 0, 0, 0}, {0x80, 0x00, 0x18, 0x02, 0x30, 0x00, 0x09, 0x06});
  expect_reply({0x2F, 0x00, 0x18, 0x02, 252, 0, 0, 0}, {0x60, 0x00, 0x18, 0x02, 0, 0, 0, 0});
  expect_reply({0x2F, 0x00, 0x14, 0x02, 252, 0, 0, 0}, {0x80, 0x00, 0x14, 0x02, 0x30, 0x00, 0x09, 0x06});
  // :00 (number of sub-indices) is constant.
  expect_reply({0x2F, 0x00, 0x18, 0x00, 2, 0, 0, 0}, {0x80, 0x00, 0x18, 0x00, 0x02, 0x00, 0x01, 0x06});
}

TEST_F(SimSlaveOdFixedMapping, MappingObjectsAreReadOnlySubIndexZeroIncluded) {
  expect_reply({0x23, 0x00, 0x18, 0x01, 0x85, 0x01, 0x00, 0x80}, {0x60, 0x00, 0x18, 0x01, 0, 0, 0, 0});
  expect_reply({0x2F, 0x00, 0x1A, 0x00, 0x00, 0, 0, 0}, {0x80, 0x00, 0x1A, 0x00, 0x02, 0x00, 0x01, 0x06});
  expect_reply({0x23, 0x00, 0x16, 0x01, 0x10, 0x00, 0x40, 0x60},
               {0x80, 0x00, 0x16, 0x01, 0x02, 0x00, 0x01, 0x06});
  // Still readable: the master reads the fixed mapping back.
  expect_reply({0x40, 0x00, 0x1A, 0x01, 0, 0, 0, 0}, {0x43, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60});
}

TEST_F(SimSlaveOdWithoutTpdo1, AbsentObjectsDoNotExistAndTheirPdoIsNeverValid) {
  expect_reply({0x40, 0x00, 0x18, 0x01, 0, 0, 0, 0}, {0x80, 0x00, 0x18, 0x01, 0x00, 0x00, 0x02, 0x06});
  expect_reply({0x23, 0x00, 0x18, 0x01, 0x85, 0x01, 0x00, 0x80},
               {0x80, 0x00, 0x18, 0x01, 0x00, 0x00, 0x02, 0x06});
  expect_reply({0x40, 0x00, 0x1A, 0x00, 0, 0, 0, 0}, {0x80, 0x00, 0x1A, 0x00, 0x00, 0x00, 0x02, 0x06});
  EXPECT_FALSE(od_.exists(0x1800));
  EXPECT_FALSE(od_.pdo_valid(0x1800));
  EXPECT_TRUE(od_.exists(0x1400));
}

// ---- PDO data: little-endian, mapped objects back to back ------------------------------------------
TEST_F(SimSlaveOd, TpdoPacksTheMappedObjectsInOrder) {
  od_.set(0x6041, 0, 0x1237);
  od_.set(0x6064, 0, 0x89ABCDEF);
  Bytes data{};
  EXPECT_EQ(od_.pack_tpdo(0, data), 6);
  EXPECT_EQ(data, (Bytes{0x37, 0x12, 0xEF, 0xCD, 0xAB, 0x89, 0, 0}));
}

TEST_F(SimSlaveOd, RpdoStoresReceiveMappableObjectsAndChecksItsLength) {
  EXPECT_EQ(od_.rpdo_for(0x205), 0);
  EXPECT_EQ(od_.rpdo_for(0x206), -1);
  EXPECT_FALSE(od_.rpdo_length_ok(0, 1));
  EXPECT_TRUE(od_.rpdo_length_ok(0, 2));
  od_.unpack_rpdo(0, {0x0F, 0x00, 0xFF, 0xFF, 0, 0, 0, 0}, hooks_, 77);
  EXPECT_EQ(od_.get(0x6040, 0), 0x000Fu);
  ASSERT_EQ(hooks_.writes.size(), 1u);
  EXPECT_EQ(hooks_.writes[0].index, 0x6040);
  EXPECT_EQ(hooks_.writes[0].now_us, 77);
}

TEST(SimSlaveOdTiming, TransmissionTypes) {
  EXPECT_TRUE(tpdo_due_on_sync(1, 7));
  EXPECT_TRUE(tpdo_due_on_sync(0, 7));
  EXPECT_TRUE(tpdo_due_on_sync(4, 8));
  EXPECT_FALSE(tpdo_due_on_sync(4, 9));
  EXPECT_FALSE(tpdo_due_on_sync(254, 1));
  EXPECT_FALSE(tpdo_due_on_sync(255, 1));
  EXPECT_TRUE(rpdo_synchronous(1));
  EXPECT_TRUE(rpdo_synchronous(240));
  EXPECT_FALSE(rpdo_synchronous(255));
}

// ---- NMT, SYNC, heartbeat, EMCY -------------------------------------------------------------------
TEST(SimSlaveOdFrames, HeartbeatAndBootUp) {
  const CanFrame hb = heartbeat(5, 0x7F);
  EXPECT_EQ(hb.id, 0x705u);
  EXPECT_EQ(hb.dlc, 1);
  EXPECT_EQ(hb.data[0], 0x7F);
  EXPECT_EQ(heartbeat(127, 0x00).id, 0x77Fu);
}

TEST(SimSlaveOdFrames, EmcyCarriesCodeLittleEndianThenTheErrorRegister) {
  const CanFrame e = emcy(5, 0x8611, 0x01);
  EXPECT_EQ(e.id, 0x085u);
  EXPECT_EQ(e.dlc, 8);
  EXPECT_EQ(e.data, (Bytes{0x11, 0x86, 0x01, 0, 0, 0, 0, 0}));
}

TEST(SimSlaveOdFrames, NmtAddressedToTheNodeOrToAll) {
  EXPECT_EQ(parse_nmt(frame(0x000, {0x01, 0x05}), 5)->command, 0x01);
  EXPECT_EQ(parse_nmt(frame(0x000, {0x81, 0x00}), 5)->command, 0x81);
  EXPECT_FALSE(parse_nmt(frame(0x000, {0x01, 0x06}), 5));
  EXPECT_FALSE(parse_nmt(frame(0x000, {0x01}), 5));
  EXPECT_FALSE(parse_nmt(frame(0x000, {0x03, 0x05}), 5));  // not a command
  EXPECT_FALSE(parse_nmt(frame(0x001, {0x01, 0x05}), 5));
}

TEST(SimSlaveOdFrames, SyncWithOrWithoutCounter) {
  EXPECT_TRUE(is_sync(frame(0x080, {})));
  EXPECT_TRUE(is_sync(frame(0x080, {0x07})));
  EXPECT_FALSE(is_sync(frame(0x080, {0x07, 0x00})));
  EXPECT_FALSE(is_sync(frame(0x081, {})));
}

// ---- Routing a received frame, and the RPDO inbox (shared by the simulated drive and I/O module) ---
TEST_F(SimSlaveOd, FramesAreRoutedByServiceAndNmtState) {
  using To = Route::To;
  const auto to = [&](std::uint8_t state, const CanFrame& f) { return route(od_, kNode, state, f).to; };
  // NMT to this node or to all, in any state; to another node, nowhere.
  EXPECT_EQ(to(nmt::kStopped, frame(0x000, {0x01, kNode})), To::kNmt);
  EXPECT_EQ(route(od_, kNode, nmt::kStopped, frame(0x000, {0x81, 0x00})).nmt_command, 0x81);
  EXPECT_EQ(to(nmt::kOperational, frame(0x000, {0x01, 0x06})), To::kNothing);
  // The SDO server answers in every state but stopped.
  const CanFrame upload = frame(0x605, {0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0});
  EXPECT_EQ(to(nmt::kPreOperational, upload), To::kSdo);
  EXPECT_EQ(to(nmt::kOperational, upload), To::kSdo);
  EXPECT_EQ(to(nmt::kStopped, upload), To::kNothing);
  EXPECT_EQ(to(nmt::kOperational, frame(0x606, {0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0})), To::kNothing);
  // SYNC and RPDOs only while operational.
  EXPECT_EQ(to(nmt::kOperational, frame(0x080, {})), To::kSync);
  EXPECT_EQ(to(nmt::kPreOperational, frame(0x080, {})), To::kNothing);
  const Route rpdo = route(od_, kNode, nmt::kOperational, frame(0x205, {0x0F, 0x00}));
  EXPECT_EQ(rpdo.to, To::kRpdo);
  EXPECT_EQ(rpdo.pdo, 0);
  EXPECT_EQ(to(nmt::kPreOperational, frame(0x205, {0x0F, 0x00})), To::kNothing);
  // Error and remote frames go nowhere, whatever their id.
  CanFrame rtr = frame(0x080, {});
  rtr.flags = CanFrame::kRtr;
  EXPECT_EQ(to(nmt::kOperational, rtr), To::kNothing);
  CanFrame error = frame(0x000, {0x01, kNode});
  error.flags = CanFrame::kError;
  EXPECT_EQ(to(nmt::kOperational, error), To::kNothing);
  // This device has no 0x1016: it watches no heartbeat.
  EXPECT_EQ(to(nmt::kOperational, frame(0x77F, {0x05})), To::kNothing);
}

TEST(SimSlaveOdRouting, OnlyTheHeartbeatThe1016ConsumerNamesIsWatched) {
  static constexpr auto table = concat(communication_objects(0x00020192));
  ObjectDictionary od(table, {});
  od.reset_communication(kNode);
  EXPECT_FALSE(is_watched_heartbeat(od, frame(0x77F, {0x05})));  // 0x1016:01 = 0: nothing watched
  od.set(kConsumerHeartbeatObject, 1, (127U << 16) | 500U);
  EXPECT_TRUE(is_watched_heartbeat(od, frame(0x77F, {0x05})));
  EXPECT_EQ(route(od, kNode, nmt::kStopped, frame(0x77F, {0x05})).to, Route::To::kWatchedHeartbeat);
  EXPECT_FALSE(is_watched_heartbeat(od, frame(0x77E, {0x05})));  // another node's
  EXPECT_FALSE(is_watched_heartbeat(od, frame(0x77F, {})));      // no state byte: not a heartbeat
}

TEST_F(SimSlaveOd, ASynchronousRpdoIsWrittenAtTheNextSyncAnEventOneAtOnce) {
  RpdoInbox inbox;
  // RPDO1 is event-driven (type 255) in this table: written on receipt.
  ASSERT_TRUE(inbox.receive(od_, hooks_, 0, frame(0x205, {0x06, 0x00}), 10));
  EXPECT_EQ(od_.get(0x6040, 0), 0x0006U);
  // Made synchronous (type 1): held until the SYNC, and the last frame before it wins.
  od_.set(0x1400, 2, 1);
  ASSERT_TRUE(inbox.receive(od_, hooks_, 0, frame(0x205, {0x07, 0x00}), 20));
  ASSERT_TRUE(inbox.receive(od_, hooks_, 0, frame(0x205, {0x0F, 0x00}), 21));
  EXPECT_EQ(od_.get(0x6040, 0), 0x0006U);
  inbox.apply_at_sync(od_, hooks_, 30);
  EXPECT_EQ(od_.get(0x6040, 0), 0x000FU);
  EXPECT_EQ(hooks_.writes.back().now_us, 30);
  // Applied once: a second SYNC writes nothing more; a reset drops what was held.
  const std::size_t writes = hooks_.writes.size();
  inbox.apply_at_sync(od_, hooks_, 40);
  EXPECT_EQ(hooks_.writes.size(), writes);
  ASSERT_TRUE(inbox.receive(od_, hooks_, 0, frame(0x205, {0x02, 0x00}), 50));
  inbox.clear();
  inbox.apply_at_sync(od_, hooks_, 60);
  EXPECT_EQ(od_.get(0x6040, 0), 0x000FU);
  // A frame shorter than the mapping is refused, nothing written.
  EXPECT_FALSE(inbox.receive(od_, hooks_, 0, frame(0x205, {0x0F}), 70));
  EXPECT_EQ(hooks_.writes.size(), writes);
}

}  // namespace
}  // namespace loom::sim_can::slave

// The simulated CiA 401 I/O module seen from the bus: its 32 digital inputs (0x6000:01..04), both
// switches of every safety sensor on their own terminals (0..5 and 16..21), a stuck switch departing
// from the plant on its terminal only, and the factory mapping of a fixed-mapping module. Every request
// and every expected byte is written out here from CiA 301 / CiA 401, not built with the master's codecs
// (drivers/), so a shared misreading of the standard cannot pass unnoticed.
#include <gtest/gtest.h>

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include "fake_can_network.hpp"
#include "loom/sim_can/io_control.hpp"
#include "loom/sim_can/sim_io_node.hpp"

namespace loom::sim_can {
namespace {

using drivers::CanFrame;

constexpr std::uint8_t kNode = 4;
constexpr std::uint32_t kSdoRequest = 0x600 + kNode;
constexpr std::uint32_t kSdoReply = 0x580 + kNode;
constexpr std::uint32_t kTpdo1 = 0x180 + kNode;
constexpr double kPi = 3.14159265358979323846;

CanFrame frame(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<std::uint8_t>(bytes.size());
  std::size_t k = 0;
  for (std::uint8_t b : bytes) f.data[k++] = b;
  return f;
}

// Terminal bits as the test computes them: bit b of the inputs is byte b / 8, bit b % 8; terminals
// beyond the `bytes` a frame carries are not in it.
std::vector<std::uint8_t> terminals(std::initializer_list<int> on, std::size_t bytes) {
  std::vector<std::uint8_t> v(bytes, 0);
  for (int b : on) {
    const auto byte = static_cast<std::size_t>(b / 8);
    if (byte < bytes) v[byte] |= static_cast<std::uint8_t>(1U << (b % 8));
  }
  return v;
}

class SimIoNodeTest : public ::testing::Test {
 protected:
  explicit SimIoNodeTest(SimIoConfig c = config()) : node_(node_ep_, std::move(c)) {}
  static SimIoConfig config() {
    SimIoConfig c;
    c.node_id = kNode;
    return c;
  }
  void pump() {
    CanFrame f;
    while (node_ep_.receive(f)) node_.handle(f, now_);
    now_ += 1000;
    net_.set_time(now_);
    node_.step(now_, plant_);
  }
  std::vector<CanFrame> take() {
    std::vector<CanFrame> out;
    CanFrame f;
    while (tester_.receive(f)) out.push_back(f);
    return out;
  }
  void send(const CanFrame& f) {
    tester_.send(f);
    pump();
  }
  void power_on() {
    node_.power_on(now_);
    pump();  // boot-up, then the inputs follow the plant
    take();
  }
  // Expedited SDO upload (CiA 301 §7.2.4.3.6): request 0x40 index(LE) sub; the reply 0x4F/0x4B/0x43 for
  // 1/2/4 bytes carries the value, 0x80 is an abort.
  std::optional<std::uint32_t> read(std::uint16_t index, std::uint8_t sub) {
    take();
    send(frame(kSdoRequest, {0x40, static_cast<std::uint8_t>(index & 0xFF),
                             static_cast<std::uint8_t>(index >> 8), sub, 0, 0, 0, 0}));
    for (const CanFrame& f : take()) {
      if (f.id != kSdoReply || f.dlc != 8) continue;
      EXPECT_EQ(f.data[1] | f.data[2] << 8, index);
      EXPECT_EQ(f.data[3], sub);
      if (f.data[0] == 0x4F) return f.data[4];
      if (f.data[0] == 0x4B) return static_cast<std::uint32_t>(f.data[4] | f.data[5] << 8);
      if (f.data[0] == 0x43) {
        return static_cast<std::uint32_t>(f.data[4] | f.data[5] << 8 | f.data[6] << 16) |
               static_cast<std::uint32_t>(f.data[7]) << 24;
      }
      return std::nullopt;
    }
    return std::nullopt;
  }
  // Expedited SDO download of one byte (0x2F); 0 or the abort code.
  std::uint32_t write_u8(std::uint16_t index, std::uint8_t sub, std::uint8_t value) {
    take();
    send(frame(kSdoRequest, {0x2F, static_cast<std::uint8_t>(index & 0xFF),
                             static_cast<std::uint8_t>(index >> 8), sub, value, 0, 0, 0}));
    for (const CanFrame& f : take()) {
      if (f.id != kSdoReply) continue;
      if (f.data[0] == 0x80) {
        return static_cast<std::uint32_t>(f.data[4] | f.data[5] << 8 | f.data[6] << 16) |
               static_cast<std::uint32_t>(f.data[7]) << 24;
      }
      return 0;
    }
    return 0xFFFFFFFF;  // no answer
  }
  // Expedited SDO download of four bytes (0x23); 0 or the abort code.
  std::uint32_t write_u32(std::uint16_t index, std::uint8_t sub, std::uint32_t value) {
    take();
    send(frame(kSdoRequest,
               {0x23, static_cast<std::uint8_t>(index & 0xFF), static_cast<std::uint8_t>(index >> 8), sub,
                static_cast<std::uint8_t>(value), static_cast<std::uint8_t>(value >> 8),
                static_cast<std::uint8_t>(value >> 16), static_cast<std::uint8_t>(value >> 24)}));
    for (const CanFrame& f : take()) {
      if (f.id != kSdoReply) continue;
      if (f.data[0] == 0x80) {
        return static_cast<std::uint32_t>(f.data[4] | f.data[5] << 8 | f.data[6] << 16) |
               static_cast<std::uint32_t>(f.data[7]) << 24;
      }
      return 0;
    }
    return 0xFFFFFFFF;  // no answer
  }
  // TPDO1 synchronous (type 1), NMT start: from now on one TPDO1 per SYNC.
  void start_synchronous() {
    ASSERT_EQ(write_u8(0x1800, 2, 1), 0u);
    send(frame(0x000, {0x01, kNode}));
  }
  // One SYNC; the TPDO1 it triggers.
  std::optional<CanFrame> sync_tpdo1() {
    take();
    send(frame(0x080, {}));
    for (const CanFrame& f : take()) {
      if (f.id == kTpdo1) return f;
    }
    return std::nullopt;
  }
  static std::vector<std::uint8_t> payload(const CanFrame& f) {
    return {f.data.begin(), f.data.begin() + f.dlc};
  }

  test::FakeCanNetwork net_;
  test::FakeCanNetwork::Endpoint& tester_ = net_.add_endpoint();
  test::FakeCanNetwork::Endpoint& node_ep_ = net_.add_endpoint();
  SimIoNode node_;
  IoPlant plant_{};
  std::int64_t now_ = 0;
};

// Pistons retracted, helix at 0 (shuttle at the left selvedge), e-stop chain closed: piston A retracted
// (1), piston B retracted (3), shuttle at left (4), e-stop (6); their second switches on 17, 19, 20.
const std::initializer_list<int> kAtRest = {1, 3, 4, 6, 17, 19, 20};

TEST_F(SimIoNodeTest, DictionaryHasEightInputGroupsAndAnswersSdoReadsOf6000Sub3) {
  power_on();
  EXPECT_EQ(read(0x6000, 0), 8u);  // highest sub-index: 64 inputs (the knotting heads' from terminal 24)
  EXPECT_EQ(read(0x6200, 0), 4u);  // 32 outputs (the heads' grippers from 8, cutters from 20)
  const std::vector<std::uint8_t> in = terminals(kAtRest, 4);
  EXPECT_EQ(read(0x6000, 1), in[0]);
  EXPECT_EQ(read(0x6000, 2), in[1]);
  EXPECT_EQ(read(0x6000, 3), in[2]);
  EXPECT_EQ(read(0x6000, 3), 0x1Au);  // the second switches of A retracted, B retracted, shuttle left
  EXPECT_EQ(read(0x6000, 4), 0u);
  // The pre-defined TPDO1 carries the three groups the loom wires: 0x6000:01..03, 8 bits each.
  EXPECT_EQ(read(0x1A00, 0), 3u);
  EXPECT_EQ(read(0x1A00, 1), 0x60000108u);
  EXPECT_EQ(read(0x1A00, 2), 0x60000208u);
  EXPECT_EQ(read(0x1A00, 3), 0x60000308u);
}

TEST_F(SimIoNodeTest, Tpdo1CarriesThreeBytesWithBothSwitchesOfEverySensor) {
  power_on();
  start_synchronous();
  std::optional<CanFrame> f = sync_tpdo1();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->dlc, 3);
  EXPECT_EQ(payload(*f), terminals(kAtRest, 3));
  EXPECT_EQ(payload(*f), (std::vector<std::uint8_t>{0x5A, 0x00, 0x1A}));

  // The shuttle at the right selvedge (1.2 m at 0.1 m per helix turn), start pressed: both switches of
  // shuttle-at-right (5, 21) on, both of shuttle-at-left (4, 20) off.
  plant_.helix_rad = 1.2 / 0.1 * 2.0 * kPi;
  plant_.button_start = true;
  pump();
  f = sync_tpdo1();
  ASSERT_TRUE(f);
  EXPECT_EQ(payload(*f), terminals({1, 3, 5, 6, 8, 17, 19, 21}, 3));
}

TEST_F(SimIoNodeTest, AStuckSwitchDepartsFromThePlantOnItsOwnTerminalOnly) {
  power_on();
  start_synchronous();
  // The second switch of shuttle-at-right stuck closed while the shuttle is at the left: terminal 21
  // reads 1, terminal 5 (its first switch) still follows the plant.
  plant_.stuck = {true, hal::SafetySensor::kShuttleAtRight, true, true};
  pump();
  std::optional<CanFrame> f = sync_tpdo1();
  ASSERT_TRUE(f);
  EXPECT_EQ(payload(*f), terminals({1, 3, 4, 6, 17, 19, 20, 21}, 3));
  // The first switch of piston-A-retracted stuck open: terminal 1 reads 0, terminal 17 still 1.
  plant_.stuck = {true, hal::SafetySensor::kPistonARetracted, false, false};
  pump();
  f = sync_tpdo1();
  ASSERT_TRUE(f);
  EXPECT_EQ(payload(*f), terminals({3, 4, 6, 17, 19, 20}, 3));
  plant_.stuck.active = false;
  pump();
  f = sync_tpdo1();
  ASSERT_TRUE(f);
  EXPECT_EQ(payload(*f), terminals(kAtRest, 3));
}

// loom-sim-drive's --io-control words (io_control.hpp): stuck=<sensor>[_2]:on|off names a switch as the
// config's io keys do, and whatever the file does not say is inactive.
TEST(SimIoControl, StuckWordNamesTheSensorAndItsSwitch) {
  std::string error;
  std::optional<StuckSwitch> sw = parse_stuck_switch("shuttle_at_right_2:on", error);
  ASSERT_TRUE(sw) << error;
  EXPECT_TRUE(sw->active);
  EXPECT_EQ(sw->sensor, hal::SafetySensor::kShuttleAtRight);
  EXPECT_TRUE(sw->second);
  EXPECT_TRUE(sw->level);
  sw = parse_stuck_switch("piston_a_extended:off", error);
  ASSERT_TRUE(sw) << error;
  EXPECT_EQ(sw->sensor, hal::SafetySensor::kPistonAExtended);
  EXPECT_FALSE(sw->second);
  EXPECT_FALSE(sw->level);
  // Every sensor, both switches, by the HAL's own names.
  for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i) {
    const std::string name = hal::safety_sensor_name(static_cast<hal::SafetySensor>(i));
    for (const bool second : {false, true}) {
      sw = parse_stuck_switch(name + (second ? "_2" : "") + ":on", error);
      ASSERT_TRUE(sw) << name << ": " << error;
      EXPECT_EQ(static_cast<std::size_t>(sw->sensor), i);
      EXPECT_EQ(sw->second, second);
    }
  }
}

TEST(SimIoControl, StuckWordRefusesBadSyntaxAndUnknownSensors) {
  std::string error;
  EXPECT_FALSE(parse_stuck_switch("shuttle_at_right_2", error));
  EXPECT_EQ(error, "expected stuck=<sensor>[_2]:on|off");
  EXPECT_FALSE(parse_stuck_switch(":on", error));
  EXPECT_EQ(error, "expected stuck=<sensor>[_2]:on|off");
  EXPECT_FALSE(parse_stuck_switch("shuttle_at_right:1", error));
  EXPECT_EQ(error, "level '1' is not on or off (stuck=<sensor>[_2]:on|off)");
  EXPECT_FALSE(parse_stuck_switch("shuttle_at_right_3:on", error));
  EXPECT_EQ(
      error,
      "unknown sensor 'shuttle_at_right_3' (known: piston_a_extended, piston_a_retracted, piston_b_extended, "
      "piston_b_retracted, shuttle_at_left, shuttle_at_right; add _2 for the second switch)");
  EXPECT_FALSE(parse_stuck_switch("shuttle_at_right_2_2:on", error));
}

TEST(SimIoControl, FileSetsWhatItNamesAndClearsTheRest) {
  IoPlant p;
  p.helix_rad = 3.0;  // the plant's positions are the rack's, not the file's
  EXPECT_TRUE(set_io_controls("estop  stuck=shuttle_at_right_2:on\nack\n", p).empty());
  EXPECT_TRUE(p.estop_open);
  EXPECT_TRUE(p.button_ack);
  EXPECT_FALSE(p.silent);
  EXPECT_TRUE(p.stuck.active);
  EXPECT_EQ(p.stuck.sensor, hal::SafetySensor::kShuttleAtRight);
  EXPECT_TRUE(p.stuck.second);
  EXPECT_TRUE(p.stuck.level);
  // The word removed, the switch works again.
  EXPECT_TRUE(set_io_controls("silent\n", p).empty());
  EXPECT_FALSE(p.estop_open);
  EXPECT_FALSE(p.button_ack);
  EXPECT_TRUE(p.silent);
  EXPECT_FALSE(p.stuck.active);
  EXPECT_EQ(p.helix_rad, 3.0);
}

TEST(SimIoControl, FileNamesEveryWordItIgnores) {
  IoPlant p;
  const std::vector<std::string> ignored = set_io_controls(
      "bogus stuck=nozzle:on stuck=shuttle_at_left:on stuck=piston_b_extended_2:off estop", p);
  ASSERT_EQ(ignored.size(), 3u);
  EXPECT_EQ(ignored[0], "unknown word 'bogus' ignored");
  EXPECT_EQ(ignored[1].rfind("'stuck=nozzle:on': unknown sensor 'nozzle' (known: piston_a_extended", 0), 0u)
      << ignored[1];
  EXPECT_EQ(ignored[2], "'stuck=piston_b_extended_2:off': only one switch can be stuck at a time; ignored");
  // The good words still count: the first stuck switch stays, the e-stop after the bad words opens.
  EXPECT_TRUE(p.stuck.active);
  EXPECT_EQ(p.stuck.sensor, hal::SafetySensor::kShuttleAtLeft);
  EXPECT_FALSE(p.stuck.second);
  EXPECT_TRUE(p.estop_open);
}

// A fixed-mapping 16-input personality: its TPDO1 is {0x6000:01, 0x6000:02} and cannot be changed.
class SimIoNodeFixed16Test : public SimIoNodeTest {
 protected:
  SimIoNodeFixed16Test() : SimIoNodeTest(fixed16()) {}
  static SimIoConfig fixed16() {
    SimIoConfig c = config();
    c.fixed_mapping = true;
    c.tpdo1_factory_mapping = {0x60000108, 0x60000208};
    return c;
  }
};

TEST_F(SimIoNodeFixed16Test, FactoryTpdo1IsReadOnlyAndCarriesTwoBytes) {
  power_on();
  EXPECT_EQ(read(0x1A00, 0), 2u);
  EXPECT_EQ(read(0x1A00, 3), 0u);
  EXPECT_EQ(write_u8(0x1A00, 0, 0), 0x06010002u);  // read-only
  start_synchronous();
  const std::optional<CanFrame> f = sync_tpdo1();
  ASSERT_TRUE(f);
  EXPECT_EQ(payload(*f), terminals(kAtRest, 2));
}

// A writable 16-input module (two input groups): says so in 0x6000:00, pre-defines TPDO1 with both,
// refuses to map the third and sends only terminals 0..15.
class SimIoNode16Test : public SimIoNodeTest {
 protected:
  SimIoNode16Test() : SimIoNodeTest(sixteen()) {}
  static SimIoConfig sixteen() {
    SimIoConfig c = config();
    c.digital_input_groups = 2;
    return c;
  }
};

TEST_F(SimIoNode16Test, HasTwoInputGroupsAndRefusesToMapAThird) {
  power_on();
  EXPECT_EQ(read(0x6000, 0), 2u);
  EXPECT_EQ(read(0x1A00, 0), 2u);
  EXPECT_EQ(read(0x1A00, 2), 0x60000208u);
  // Re-mapping as CiA 301 asks: invalidate the PDO, clear the count, write entries, set the count.
  ASSERT_EQ(write_u32(0x1800, 1, 0x80000000u | kTpdo1), 0u);
  ASSERT_EQ(write_u8(0x1A00, 0, 0), 0u);
  EXPECT_EQ(write_u32(0x1A00, 1, 0x60000108), 0u);
  EXPECT_EQ(write_u32(0x1A00, 2, 0x60000208), 0u);
  EXPECT_EQ(write_u32(0x1A00, 3, 0x60000308), 0x06040041u);  // object cannot be mapped
  ASSERT_EQ(write_u8(0x1A00, 0, 2), 0u);
  ASSERT_EQ(write_u32(0x1800, 1, kTpdo1), 0u);
  start_synchronous();
  const std::optional<CanFrame> f = sync_tpdo1();
  ASSERT_TRUE(f);
  EXPECT_EQ(payload(*f), terminals({1, 3, 4, 6}, 2));  // no second switches: those terminals do not exist
}

}  // namespace
}  // namespace loom::sim_can

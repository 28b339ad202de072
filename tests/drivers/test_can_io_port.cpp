// The CiA 401 I/O node driver and the master's interoperability and fault rules, against simulated
// nodes on the fake CAN network. The I/O node's peer (sim_can::SimIoNode) has its own object dictionary
// and frame layouts, independent of the master's codec.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <string>

#include "drive_rig.hpp"
#include "loom/drivers/can_hal.hpp"
#include "loom/drivers/can_io_port.hpp"
#include "loom/drivers/can_network.hpp"
#include "loom/drivers/cia402.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/drivers/required_objects.hpp"
#include "loom/sim_can/sim_io_node.hpp"

namespace loom::test {
namespace {

using drivers::CanIoConfig;
using drivers::CanIoPort;
using drivers::IoWiring;
using hal::AxisRequest;
using hal::DriveState;

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}
bool any_note(const std::vector<std::string>& notes, const std::string& part) {
  return std::any_of(notes.begin(), notes.end(), [&](const std::string& n) { return contains(n, part); });
}

// The module brought up on a network of its own (a re-arm, or a node that must be refused).
drivers::Status bring_up_alone(CanIoPort& port, drivers::CanBus& bus, drivers::ConfigureClock& clock) {
  drivers::CanNetwork alone(port.master_config(), 1);
  if (!alone.add(port)) return drivers::Status::error("the module could not be registered");
  return alone.configure(bus, clock);
}

// The DLC of the last frame on the wire with `id` (the I/O node's TPDO1 is 0x184), −1 none.
int last_dlc(const test::FakeCanNetwork& net, std::uint32_t id) {
  int dlc = -1;
  for (const auto& l : net.log()) {
    if (l.frame.id == id && !l.frame.is_error()) dlc = l.frame.dlc;
  }
  return dlc;
}

// Servo drives + the I/O node on one endpoint, the master's two ports on the other.
struct IoRig {
  explicit IoRig(sim_can::SimIoConfig io_cfg = {},
                 std::vector<sim_can::SimDriveConfig> drives = three_drives(),
                 drivers::CanAxisPortConfig axis_cfg = {}, CanIoConfig port_cfg = {})
      : rig(std::move(drives), with_io_frames(axis_cfg, port_cfg)), io(rig.drives, io_cfg), port(port_cfg) {
    rig.rack.attach_io(io, {0, 2, drivers::kDefaultCountsPerRad, drivers::kDefaultCountsPerRad});
    EXPECT_TRUE(rig.network.add(port));
  }
  static drivers::CanAxisPortConfig with_io_frames(drivers::CanAxisPortConfig c, const CanIoConfig& io) {
    c.other_frames_per_cycle[0] = drivers::io_frames_per_cycle(io.wiring);
    return c;
  }
  // The axis port's master brings the I/O node up in the same NMT sequence as the drives.
  drivers::Status configure() { return rig.configure(); }
  // One RT cycle through the joined HAL, as the control loop runs it.
  void tick(AxisRequest r, const hal::DigitalOutputs& out = {}) {
    drivers::CanHal hal(rig.network, rig.port, port);
    hal.read(rig.tick_index, in);
    rig.feedback = in.axes;
    hal::HalOutputs o;
    for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i) {
      o.axes[i].request = r;
      o.axes[i].target_position = in.axes[i].position;
    }
    o.io = out;
    hal.write(rig.tick_index, o);
    ++rig.tick_index;
    rig.advance(rig.period_us());
  }
  void enable_all() {
    for (int i = 0; i < 50 && !rig.all_in(DriveState::kOperationEnabled); ++i) tick(AxisRequest::kEnable);
    ASSERT_TRUE(rig.all_in(DriveState::kOperationEnabled));
  }

  DriveRig rig;
  sim_can::SimIoNode io;
  CanIoPort port;
  hal::HalInputs in{};
};

// ---------------------------------------------------------------------------------------------------
// Wiring validation
// ---------------------------------------------------------------------------------------------------
TEST(IoWiring, DefaultsAreValid) {
  EXPECT_TRUE(drivers::validate(IoWiring{}));
}

TEST(IoWiring, DuplicateBitNamesBothSignals) {
  IoWiring w;
  w.estop_ok.bit = 3;
  const drivers::Status s = drivers::validate(w);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(), "io.inputs.estop_ok.bit = 3 is already used by io.inputs.piston_b_retracted");
}

TEST(IoWiring, BitOutOfRangeAndUnwiredRequiredSignal) {
  IoWiring w;
  w.lamp_red.bit = 64;
  EXPECT_EQ(drivers::validate(w).message(), "io.outputs.lamp_red.bit = 64 is outside 0..63 (-1 = not wired)");
  IoWiring u;
  u.piston_b_extend.bit = -1;
  EXPECT_EQ(drivers::validate(u).message(), "io.outputs.piston_b_extend.bit = -1: this signal must be wired");
  IoWiring b;
  b.button_ack.bit = -1;  // optional
  EXPECT_TRUE(drivers::validate(b));
  IoWiring g;
  g.load_cell_n_per_count = 0.0;
  EXPECT_TRUE(contains(drivers::validate(g).message(), "io.load_cell.n_per_count = 0"));
}

// The wiring with single-channel sensing: every second channel unwired.
IoWiring single_channel() {
  IoWiring w;
  for (drivers::IoBit& b : w.second) b.bit = -1;
  return w;
}

TEST(IoWiring, DuplicateBitBetweenAFirstAndASecondChannelNamesBoth) {
  // Each second channel on its own sensor's first-channel bit (0..5 in SafetySensor order): refused,
  // named with the config's sensor names.
  for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i) {
    IoWiring w;
    w.second[i].bit = static_cast<int>(i);
    const std::string name = hal::safety_sensor_name(static_cast<hal::SafetySensor>(i));
    EXPECT_EQ(drivers::validate(w).message(), "io.inputs." + name + "_2.bit = " + std::to_string(i) +
                                                  " is already used by io.inputs." + name);
  }
  IoWiring w;
  w.second[5].bit = 11;  // the knotting pedal's input
  EXPECT_EQ(drivers::validate(w).message(),
            "io.inputs.shuttle_at_right_2.bit = 11 is already used by io.inputs.row_knotted");
  IoWiring twice;
  twice.second[1].bit = 20;  // two second channels on one input
  EXPECT_EQ(drivers::validate(twice).message(),
            "io.inputs.shuttle_at_left_2.bit = 20 is already used by io.inputs.piston_a_retracted_2");
}

TEST(IoWiring, InputBitsReach63AndSecondChannelsAreOptional) {
  IoWiring w;
  w.second[0].bit = 63;
  EXPECT_TRUE(drivers::validate(w));
  w.second[0].bit = 64;
  EXPECT_EQ(drivers::validate(w).message(),
            "io.inputs.piston_a_extended_2.bit = 64 is outside 0..63 (-1 = not wired)");
  EXPECT_TRUE(drivers::validate(single_channel()));
}

// Two knotting heads on the module: grippers on outputs 8, 9, cutters on 20, 21, yarn-present on inputs
// 24, 25 (the simulated module's terminals).
IoWiring two_heads() {
  IoWiring w;
  w.heads = 2;
  w.gripper_close = {drivers::IoBit{8}, drivers::IoBit{9}};
  w.cutter = {drivers::IoBit{20}, drivers::IoBit{21}};
  w.yarn_present = {drivers::IoBit{24}, drivers::IoBit{25}};
  return w;
}

TEST(IoWiring, EveryHeadUsedIsWiredAndNamedByItsNumber) {
  EXPECT_TRUE(drivers::validate(two_heads()));
  IoWiring unwired = two_heads();
  unwired.cutter[1].bit = -1;
  EXPECT_EQ(drivers::validate(unwired).message(),
            "io.outputs.cutter.head2.bit = -1: this signal must be wired");
  IoWiring clash = two_heads();
  clash.gripper_close[1].bit = 5;  // the amber lamp's output
  EXPECT_EQ(drivers::validate(clash).message(),
            "io.outputs.gripper_close.head2.bit = 5 is already used by io.outputs.lamp_amber");
  IoWiring input_clash = two_heads();
  input_clash.yarn_present[0].bit = 11;  // the weaver's pedal
  EXPECT_EQ(drivers::validate(input_clash).message(),
            "io.inputs.yarn_present.head1.bit = 11 is already used by io.inputs.row_knotted");
  // Heads not used (0: the loom has none) are not looked at, whatever their bits say.
  IoWiring unused = two_heads();
  unused.heads = 0;
  unused.cutter[0].bit = 0;
  EXPECT_TRUE(drivers::validate(unused));
  IoWiring too_many = two_heads();
  too_many.heads = 13;
  EXPECT_EQ(drivers::validate(too_many).message(), "io: 13 knotting heads wired; at most 12");
}

TEST(IoWiring, FramesPerCycle) {
  IoWiring w;
  auto g = drivers::io_frames_per_cycle(w);
  ASSERT_EQ(g.size(), 3u);  // outputs RPDO (1 B), inputs TPDO, load cell TPDO
  EXPECT_EQ(g[0].data_bytes, 1u);
  EXPECT_EQ(g[1].data_bytes, 3u);  // second channels on bits 16..21: 0x6000:01..03
  EXPECT_EQ(g[2].data_bytes, 2u);
  EXPECT_EQ(drivers::io_input_subs(w), 3u);
  // Single-channel sensing: buttons on bits 8..11 are the highest, 0x6000:01..02.
  EXPECT_EQ(drivers::io_frames_per_cycle(single_channel())[1].data_bytes, 2u);
  EXPECT_EQ(drivers::io_input_subs(single_channel()), 2u);
  IoWiring high;
  high.second[5].bit = 30;  // 0x6000:04
  EXPECT_EQ(drivers::io_frames_per_cycle(high)[1].data_bytes, 4u);
  w.load_cell_channel = 0;
  EXPECT_EQ(drivers::io_frames_per_cycle(w).size(), 2u);
}

// What a loom builder checks in a module's EDS: as many 8-bit input groups as the wiring uses.
std::string required_line(const std::vector<drivers::RequiredObject>& objects, std::uint16_t index) {
  for (const drivers::RequiredObject& o : objects) {
    if (o.index == index) return drivers::describe(o);
  }
  return "";
}

TEST(IoWiring, HeadsWidenTheFramesAndTheObjectsAModuleMustHave) {
  const IoWiring w = two_heads();
  const auto g = drivers::io_frames_per_cycle(w);
  EXPECT_EQ(g[0].data_bytes, 3u);  // outputs up to the cutters on 20, 21: 0x6200:01..03
  EXPECT_EQ(g[1].data_bytes, 4u);  // inputs up to yarn-present on 24, 25: 0x6000:01..04
  EXPECT_EQ(
      required_line(drivers::io_module_objects(w), 0x6000),
      "0x6000:01..04 read digital inputs, 8-bit: sensors and their second channels, e-stop chain, buttons, "
      "the heads' yarn-present switches");
  EXPECT_EQ(required_line(drivers::io_module_objects(w), 0x6200),
            "0x6200:01..03 write digital outputs, 8-bit: valves, stack light, buzzer, the heads' grippers "
            "and cutters");
}

TEST(IoWiring, RequiredObjectsCountTheInputGroupsTheWiringUses) {
  EXPECT_EQ(
      required_line(drivers::io_module_objects(IoWiring{}), 0x6000),
      "0x6000:01..03 read digital inputs, 8-bit: sensors and their second channels, e-stop chain, buttons");
  EXPECT_EQ(required_line(drivers::io_module_objects(IoWiring{}), 0x6200),
            "0x6200:01 write digital outputs, 8-bit: valves, stack light, buzzer");
  EXPECT_TRUE(
      contains(required_line(drivers::io_module_objects(single_channel()), 0x6000), "0x6000:01..02 "));
  IoWiring high;
  high.second[5].bit = 30;
  EXPECT_TRUE(contains(required_line(drivers::io_module_objects(high), 0x6000), "0x6000:01..04 "));
  // Without a wiring: the objects only.
  EXPECT_TRUE(contains(required_line(drivers::io_module_objects(), 0x6000), "0x6000 read digital inputs"));
}

// ---------------------------------------------------------------------------------------------------
// Bring-up and the exchange
// ---------------------------------------------------------------------------------------------------
TEST(CanIoPort, BringsUpTheModuleAndExchangesEverySignal) {
  IoRig r;
  const drivers::Status s = r.configure();
  ASSERT_TRUE(s) << s.message();
  EXPECT_TRUE(r.port.notes().empty()) << r.port.notes().front();
  // Before the first TPDO: no news (never refreshed), not an opened e-stop chain, no sensor confirmed.
  hal::DigitalInputs before;
  r.port.read_io(0, {}, before);
  EXPECT_EQ(before.refreshed, hal::kNeverTick);
  EXPECT_TRUE(before.estop_ok);
  EXPECT_FALSE(before.piston_a_retracted || before.shuttle_at_left);
  r.enable_all();
  ASSERT_TRUE(r.in.io.estop_ok);
  EXPECT_TRUE(r.in.io.piston_a_retracted);
  EXPECT_TRUE(r.in.io.piston_b_retracted);
  EXPECT_TRUE(r.in.io.shuttle_at_left);  // helix at 0
  EXPECT_FALSE(r.in.io.shuttle_at_right);
  EXPECT_EQ(r.in.io.refreshed, r.rig.tick_index - 1);  // a TPDO every SYNC

  // Valve A on: after the piston's travel time, A's extended sensor.
  hal::DigitalOutputs out;
  out.piston_a_extend = true;
  out.lamp_green = true;
  for (int i = 0; i < 10; ++i) r.tick(AxisRequest::kEnable, out);
  EXPECT_EQ(r.io.outputs(0) & 0x13, 0x11);  // valve A (bit 0) and green (bit 4), not valve B
  EXPECT_FALSE(r.in.io.piston_a_extended);
  for (int i = 0; i < 150; ++i) r.tick(AxisRequest::kEnable, out);
  EXPECT_TRUE(r.in.io.piston_a_extended);
  EXPECT_FALSE(r.in.io.piston_a_retracted);
  EXPECT_TRUE(r.in.io.piston_b_retracted);

  // Buttons and the e-stop chain.
  r.rig.rack.io_controls().button_ack = true;
  r.rig.rack.io_controls().row_knotted = true;
  for (int i = 0; i < 3; ++i) r.tick(AxisRequest::kEnable, out);
  EXPECT_TRUE(r.in.io.button_ack);
  EXPECT_TRUE(r.in.io.row_knotted);
  EXPECT_FALSE(r.in.io.button_start);
  r.rig.rack.io_controls().estop_open = true;
  for (int i = 0; i < 3; ++i) r.tick(AxisRequest::kEnable, out);
  EXPECT_FALSE(r.in.io.estop_ok);
}

// Second channels of the six safety sensors (hal::SafetySensor order) as the master read them.
std::array<bool, hal::kSafetySensorCount> second(const IoRig& r) {
  return r.in.io.second_channel;
}
using Channels = std::array<bool, hal::kSafetySensorCount>;
// Pistons retracted, shuttle at the left selvedge: A retracted, B retracted, shuttle at left.
constexpr Channels kAtRest{false, true, false, true, true, false};

TEST(CanIoPort, DefaultWiringReadsBothChannelsOfEverySafetySensorFromThreeInputBytes) {
  IoRig r;
  const drivers::Status s = r.configure();
  ASSERT_TRUE(s) << s.message();
  hal::DigitalInputs before;
  r.port.read_io(0, {}, before);
  EXPECT_EQ(before.second_channel, Channels{});  // nothing seen yet: nothing confirmed
  r.enable_all();
  EXPECT_EQ(last_dlc(r.rig.net, 0x184), 3);  // 0x6000:01..03 in TPDO1
  EXPECT_EQ(hal::safety_sensors(r.in.io), kAtRest);
  EXPECT_EQ(second(r), kAtRest);
  // Valve A on: both switches of "A extended" close, both of "A retracted" open.
  hal::DigitalOutputs out;
  out.piston_a_extend = true;
  for (int i = 0; i < 160; ++i) r.tick(AxisRequest::kEnable, out);
  const Channels extended{true, false, false, true, true, false};
  EXPECT_EQ(hal::safety_sensors(r.in.io), extended);
  EXPECT_EQ(second(r), extended);
}

// A stuck switch on one channel shows on that channel only: the master reports the two independently.
// The heads' signals through the bus, against the module's own plant: head 1's gripper closes at TAKE with
// its selector at slot 0 and its cutter fires in the warp over knot 0; the module's yarn-present switch
// then sees the knot, and the master reads it. On the wire: the outputs' RPDO grows to three bytes, the
// inputs' TPDO to four. When the master dies the module opens the grippers by itself (0x6206/0x6207).
TEST(CanIoPort, KnottingHeadsSignalsTravelBothWaysAndFailSafe) {
  sim_can::SimIoConfig io_cfg;
  sim_hal::SimKnotting& k = io_cfg.knotting;
  k.heads = 2;
  k.knots_per_row = 20;
  k.stripe = 10;
  k.slots = 3;
  k.knots_per_slot = 5;
  k.pitch_m = 0.01;
  k.carriage_home_m = -0.005;  // the carriage drive at 0 stands over the middle of knot 0's pitch
  k.knotter_axis = {3, 5};
  k.selector_axis = {4, 6};
  k.in_warp_from_rad = -1.0;  // the knotting servo at 0 is both at TAKE and in the warp: a plant test only
  k.in_warp_to_rad = 1.0;
  k.full_turn = false;
  CanIoConfig port_cfg;
  port_cfg.wiring = two_heads();
  IoRig r(io_cfg, three_drives(), {}, port_cfg);
  // The three drives stand for the carriage (slot 1), head 1's knotting servo (slot 3) and selector (slot 4);
  // head 2's servos read 0 as well (unmapped slots).
  sim_can::SimDriveRack::IoPlantSource src{
      0, 2, drivers::kDefaultCountsPerRad, drivers::kDefaultCountsPerRad, {}};
  src.axes = {{1, 1, drivers::kDefaultCountsPerM},
              {0, 3, drivers::kDefaultCountsPerRad},
              {2, 4, drivers::kDefaultCountsPerRad}};
  r.rig.rack.attach_io(r.io, src);
  const drivers::Status s = r.configure();
  ASSERT_TRUE(s) << s.message();
  r.enable_all();
  EXPECT_EQ(last_dlc(r.rig.net, 0x204), 3);  // RPDO1: 0x6200:01..03
  EXPECT_EQ(last_dlc(r.rig.net, 0x184), 4);  // TPDO1: 0x6000:01..04
  EXPECT_FALSE(r.in.io.yarn_present[0]);

  hal::DigitalOutputs out;
  out.gripper_close[0] = true;
  for (int i = 0; i < 5; ++i) r.tick(AxisRequest::kEnable, out);
  EXPECT_EQ(r.io.outputs(1) & 0x03, 0x01);  // head 1's gripper (terminal 8), not head 2's
  EXPECT_FALSE(r.in.io.yarn_present[0]);    // holding yarn is not a knot
  out.cutter[0] = true;
  for (int i = 0; i < 5; ++i) r.tick(AxisRequest::kEnable, out);
  EXPECT_EQ(r.io.outputs(2) & 0x30, 0x10);  // head 1's cutter (terminal 20)
  EXPECT_TRUE(r.in.io.yarn_present[0]);     // the knot, seen by the module's switch and read by the master
  EXPECT_FALSE(r.in.io.yarn_present[1]);
  ASSERT_NE(r.io.knotter(), nullptr);
  EXPECT_EQ(r.io.knotter()->cell(0, 0).ties, 1);
  EXPECT_EQ(r.io.knotter()->cell(0, 0).slot, 0);

  // The host dies with the gripper closed and the cutter firing: the module opens and retracts them.
  out.cutter[0] = false;
  for (int i = 0; i < 3; ++i) r.tick(AxisRequest::kEnable, out);
  EXPECT_EQ(r.io.outputs(1) & 0x01, 0x01);
  r.rig.advance(700'000);
  ASSERT_TRUE(r.io.comm_lost());
  EXPECT_EQ(r.io.outputs(1), 0x00);  // grippers open
  EXPECT_EQ(r.io.outputs(2), 0x00);  // cutters retracted
}

TEST(CanIoPort, AStuckSwitchShowsOnItsOwnChannelOnly) {
  IoRig r;
  ASSERT_TRUE(r.configure());
  r.enable_all();
  // The second switch of shuttle-at-right welded closed, the shuttle at the left.
  r.rig.rack.io_controls().stuck = {true, hal::SafetySensor::kShuttleAtRight, true, true};
  for (int i = 0; i < 3; ++i) r.tick(AxisRequest::kEnable);
  EXPECT_FALSE(r.in.io.shuttle_at_right);
  EXPECT_TRUE(second(r)[5]);
  EXPECT_EQ(hal::safety_sensors(r.in.io), kAtRest);
  // The first switch of piston-A-retracted stuck open.
  r.rig.rack.io_controls().stuck = {true, hal::SafetySensor::kPistonARetracted, false, false};
  for (int i = 0; i < 3; ++i) r.tick(AxisRequest::kEnable);
  EXPECT_FALSE(r.in.io.piston_a_retracted);
  EXPECT_EQ(second(r), kAtRest);
}

TEST(CanIoPort, SecondChannelPolarityIsItsOwn) {
  CanIoConfig pc;
  pc.wiring.second[1].active_low = true;  // piston A retracted's second switch: a break contact
  pc.wiring.second[5].active_low = true;  // shuttle at right's second switch
  IoRig r({}, three_drives(), {}, pc);
  ASSERT_TRUE(r.configure());
  r.enable_all();
  EXPECT_TRUE(r.in.io.piston_a_retracted);
  EXPECT_FALSE(second(r)[1]);  // terminal 17 closed = not retracted, read through its polarity
  EXPECT_TRUE(second(r)[5]);   // terminal 21 open
  EXPECT_TRUE(second(r)[4]);   // the others as wired
}

// Inputs never seen read false whatever their polarity (found by tests/fuzz/fuzz_can_io_port): the
// cleared input bytes before the first TPDO used to read as true through an active-low wiring — a
// break-contact sensor confirmed, a button pressed — after bring-up and again after every re-arm.
TEST(CanIoPort, ActiveLowInputsReadFalseBeforeTheFirstTpdo) {
  CanIoConfig pc;
  pc.wiring.piston_a_retracted.active_low = true;
  pc.wiring.second[1].active_low = true;
  pc.wiring.button_start.active_low = true;
  pc.wiring.estop_ok.active_low = true;
  IoRig r({}, three_drives(), {}, pc);
  ASSERT_TRUE(r.configure());
  const auto expect_nothing_seen = [&] {
    hal::DigitalInputs before;
    r.port.read_io(0, {}, before);
    EXPECT_EQ(before.refreshed, hal::kNeverTick);
    EXPECT_TRUE(before.estop_ok);  // no news, not an opened chain
    EXPECT_EQ(hal::safety_sensors(before), Channels{});
    EXPECT_EQ(before.second_channel, Channels{});
    EXPECT_FALSE(before.button_start);
  };
  expect_nothing_seen();
  // Once sampled, through their polarity: terminals 1, 6 and 17 closed, 8 open.
  r.enable_all();
  EXPECT_FALSE(r.in.io.piston_a_retracted);
  EXPECT_FALSE(second(r)[1]);
  EXPECT_TRUE(r.in.io.button_start);
  EXPECT_FALSE(r.in.io.estop_ok);
  // Re-armed: nothing seen again until the next TPDO.
  ASSERT_TRUE(bring_up_alone(r.port, r.rig.master, r.rig.clock));
  expect_nothing_seen();
}

TEST(CanIoPort, ASecondChannelOnBit30MapsTheFourthInputByte) {
  CanIoConfig pc;
  pc.wiring.second[5] = {30, true};  // terminal 30 is never closed on the simulated module: reads true
  IoRig r({}, three_drives(), {}, pc);
  const drivers::Status s = r.configure();
  ASSERT_TRUE(s) << s.message();
  r.enable_all();
  EXPECT_EQ(last_dlc(r.rig.net, 0x184), 4);  // 0x6000:01..04
  EXPECT_EQ(r.in.io.second_channel, (Channels{false, true, false, true, true, true}));
}

TEST(CanIoPort, SingleChannelSensingMapsTwoInputBytesAndLeavesSecondChannelsFalse) {
  CanIoConfig pc;
  pc.wiring = single_channel();
  IoRig r({}, three_drives(), {}, pc);
  ASSERT_TRUE(r.configure());
  r.enable_all();
  EXPECT_EQ(last_dlc(r.rig.net, 0x184), 2);  // the module's default 0x6000:01..03 re-mapped to :01..02
  EXPECT_EQ(hal::safety_sensors(r.in.io), kAtRest);
  EXPECT_EQ(second(r), Channels{});
}

// A remote request on the module's TPDO COB-IDs (another master, a bus analyser) carries no data: it is
// counted as a receive error, never taken as a sample (found by tests/fuzz/fuzz_can_io_port: an RTR
// frame on 0x184 read as all inputs 0 — e-stop opened, every active-low input true — refreshed now).
TEST(CanIoPort, RemoteRequestsOnItsTpdosAreNotSamples) {
  IoRig r;
  ASSERT_TRUE(r.configure());
  r.enable_all();
  ASSERT_TRUE(r.in.io.estop_ok);
  ASSERT_TRUE(r.in.io.piston_a_retracted);
  ASSERT_TRUE(r.in.analog.beat_force_valid);
  r.rig.rack.io_controls().silent = true;                    // only the requests below on 0x184/0x284
  for (int i = 0; i < 2; ++i) r.tick(AxisRequest::kEnable);  // the TPDOs in flight arrive
  const hal::DigitalInputs io = r.in.io;
  const hal::AnalogInputs analog = r.in.analog;
  const std::uint32_t errors = r.port.rx_errors();
  drivers::CanFrame rtr;
  rtr.flags = drivers::CanFrame::kRtr;
  rtr.id = 0x184;
  rtr.dlc = 3;  // as on the wire: a length, no data (the driver's zeros)
  r.rig.drives.send(rtr);
  rtr.id = 0x284;
  rtr.dlc = 2;
  r.rig.drives.send(rtr);
  r.rig.advance(100);
  r.tick(AxisRequest::kEnable);
  EXPECT_EQ(r.port.rx_errors(), errors + 2);
  EXPECT_EQ(r.in.io.refreshed, io.refreshed);
  EXPECT_TRUE(r.in.io.estop_ok);
  EXPECT_TRUE(r.in.io.piston_a_retracted);
  EXPECT_EQ(r.in.io.second_channel, io.second_channel);
  EXPECT_EQ(r.in.analog.refreshed, analog.refreshed);
  EXPECT_EQ(r.in.analog.beat_force_n, analog.beat_force_n);
}

TEST(CanIoPort, LoadCellScaledByTheWiringAndShuttleFollowsTheHelix) {
  CanIoConfig pc;
  pc.wiring.load_cell_n_per_count = 0.02;  // master's scaling
  pc.wiring.load_cell_offset_n = 1.0;
  sim_can::SimIoConfig ic;
  ic.load_cell_n_per_count = 0.01;  // the module's: the master sees twice the force plus 1 N
  ic.beat_peak_n = 90.0;
  ic.fell_crank_rad = 0.0;  // crank at 0 rad = at the fell
  IoRig r(ic,
          three_drives(
              0, 0, static_cast<std::int32_t>(11.97 * 2 * 3.14159265358979 * drivers::kDefaultCountsPerRad)),
          {}, pc);
  ASSERT_TRUE(r.configure());
  r.enable_all();
  EXPECT_TRUE(r.in.analog.beat_force_valid);
  EXPECT_NEAR(r.in.analog.beat_force_n, 2.0 * 90.0 + 1.0, 1e-9);
  EXPECT_EQ(r.in.analog.refreshed, r.rig.tick_index - 1);
  EXPECT_TRUE(r.in.io.shuttle_at_right);  // 11.97 turns × 0.1 m within 5 mm of the 1.2 m selvedge
}

TEST(CanIoPort, RefusesAModuleThatIsNotCiA401) {
  IoRig r;
  drivers::Status s = r.rig.configure();
  ASSERT_TRUE(s);
  CanIoConfig pc;
  pc.node_id = 1;  // a servo drive: device type 0x00020192
  CanIoPort wrong(pc);
  s = bring_up_alone(wrong, r.rig.master, r.rig.clock);
  ASSERT_FALSE(s);
  EXPECT_TRUE(contains(s.message(), "node 1 (I/O node): 0x1000 device type = 0x00020192")) << s.message();
}

// ---------------------------------------------------------------------------------------------------
// Interoperability rules (CiA 301)
// ---------------------------------------------------------------------------------------------------
// Rule 1: a mapping that cannot be written is read back and accepted when it carries what we need.
TEST(Interop, IoModuleWithFixedMappingIsReadBackAndAccepted) {
  sim_can::SimIoConfig ic;
  ic.fixed_mapping = true;
  IoRig r(ic);
  const drivers::Status s = r.configure();
  ASSERT_TRUE(s) << s.message();
  EXPECT_TRUE(any_note(r.port.notes(), "0x1A00 mapping is fixed"));
  r.enable_all();
  EXPECT_TRUE(r.in.io.estop_ok);
  EXPECT_TRUE(r.in.analog.beat_force_valid);
}

// Rule 1, refusal: the fixed mapping lacks an object the wiring needs → refused, naming node, object.
TEST(Interop, IoModuleWithFixedMappingLackingTheLoadCellIsRefused) {
  sim_can::SimIoConfig ic;
  ic.fixed_mapping = true;  // TPDO2 carries 0x6401:01 only
  CanIoConfig pc;
  pc.wiring.load_cell_channel = 2;
  IoRig r(ic, three_drives(), {}, pc);
  const drivers::Status s = r.configure();
  ASSERT_FALSE(s);
  EXPECT_TRUE(contains(s.message(), "node 4 (I/O node): no PDO carries 0x6401:02 (load cell)"))
      << s.message();
}

// A 16-input module with a fixed TPDO1 {0x6000:01, 0x6000:02}: the default wiring's second channels
// (0x6000:03) cannot arrive, so it is refused naming the object and the signal that needs it.
sim_can::SimIoConfig fixed_16_inputs() {
  sim_can::SimIoConfig ic;
  ic.fixed_mapping = true;
  ic.tpdo1_factory_mapping = {0x60000108, 0x60000208};
  return ic;
}

TEST(Interop, IoModuleWithFixedMappingLackingTheSecondChannelsIsRefusedNamingTheSignal) {
  IoRig r(fixed_16_inputs());
  const drivers::Status s = r.configure();
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(),
            "node 4 (I/O node): no PDO carries 0x6000:03 (digital inputs, needed by "
            "io.shuttle_at_right_2_bit = 21); "
            "the module's mapping (fixed or refused) lacks it");
}

TEST(Interop, IoModuleWithFixedSixteenInputsIsAcceptedForSingleChannelSensing) {
  CanIoConfig pc;
  pc.wiring = single_channel();
  IoRig r(fixed_16_inputs(), three_drives(), {}, pc);
  const drivers::Status s = r.configure();
  ASSERT_TRUE(s) << s.message();
  r.enable_all();
  EXPECT_EQ(hal::safety_sensors(r.in.io), kAtRest);
}

// A writable 16-input module cannot map 0x6000:03: the SDO abort is explained by the signal that needs it.
TEST(Interop, IoModuleWithSixteenInputsRefusingTheThirdGroupIsExplainedByTheSignal) {
  sim_can::SimIoConfig ic;
  ic.digital_input_groups = 2;
  IoRig r(ic);
  const drivers::Status s = r.configure();
  ASSERT_FALSE(s);
  EXPECT_TRUE(contains(s.message(), "node 4 (I/O node): SDO write 0x1A00:03")) << s.message();
  EXPECT_TRUE(contains(s.message(), "0x06040041")) << s.message();
  EXPECT_TRUE(contains(s.message(),
                       "; 0x6000:03 is mapped because the wiring reads 0x6000:01..03 up to "
                       "io.shuttle_at_right_2_bit = 21 (a module with fewer digital inputs needs "
                       "that signal moved or unwired, -1)"))
      << s.message();
  // The same module serves single-channel sensing.
  CanIoConfig pc;
  pc.wiring = single_channel();
  IoRig single(ic, three_drives(), {}, pc);
  const drivers::Status ok = single.configure();
  ASSERT_TRUE(ok) << ok.message();
  single.enable_all();
  EXPECT_EQ(hal::safety_sensors(single.in.io), kAtRest);
}

// The inputs are one sample: a fixed mapping that spreads them over two TPDOs is refused.
TEST(Interop, IoModuleWithInputsSplitOverTwoTpdosIsRefused) {
  sim_can::SimIoConfig ic = fixed_16_inputs();
  ic.tpdo2_factory_mapping = {0x64010110, 0x60000308};  // load cell, then the third input byte
  IoRig r(ic);
  const drivers::Status s = r.configure();
  ASSERT_FALSE(s);
  EXPECT_EQ(
      s.message(),
      "node 4 (I/O node): 0x6000:03 (digital inputs, needed by io.shuttle_at_right_2_bit = 21) is in TPDO2, "
      "0x6000:01 in TPDO1; the master needs every digital input in one TPDO (one sample per cycle)");
}

// Rule 2: "object does not exist" while disabling an unused PDO is not an error.
TEST(Interop, IoModuleWithoutTpdo3And4AndWithoutErrorModeIsAccepted) {
  sim_can::SimIoConfig ic;
  ic.absent_objects = {0x1802, 0x1803, 0x1A02, 0x1A03, 0x1401, 0x1601};
  IoRig r(ic);
  const drivers::Status s = r.configure();
  ASSERT_TRUE(s) << s.message();
  EXPECT_TRUE(r.port.notes().empty());
}

// Rule 3: optional objects used when present, reported when absent (I/O node: 0x1016, 0x6206/0x6207).
TEST(Interop, IoModuleOptionalObjectsAbsentAreReported) {
  sim_can::SimIoConfig ic;
  ic.absent_objects = {0x1016, 0x6206, 0x6207};
  IoRig r(ic);
  const drivers::Status s = r.configure();
  ASSERT_TRUE(s) << s.message();
  EXPECT_TRUE(any_note(r.port.notes(), "0x1016 (consumer heartbeat time) absent"));
  EXPECT_TRUE(any_note(r.port.notes(), "0x6206/0x6207 (output error mode/value) absent"));
}

// The "commercial" drive personality: fixed mapping, no TPDO3/TPDO4 objects, no 0x1016, slow boot
// and slow switch to operational.
std::vector<sim_can::SimDriveConfig> fixed_drives(std::int64_t boot_us, std::int64_t op_us) {
  auto d = three_drives();
  for (auto& c : d) {
    c.fixed_mapping = true;
    c.missing_objects = {0x1802, 0x1803, 0x1A02, 0x1A03, 0x1016};
    c.boot_delay_us = boot_us;
    c.operational_delay_us = op_us;
  }
  return d;
}

TEST(Interop, FixedPersonalityDriveIsAcceptedWithNotes) {
  drivers::CanAxisPortConfig ac;
  ac.tpdo2 = true;                  // its fixed TPDO2 carries velocity + torque: used
  ac.bus_load_budget = 0.85;        // 3 drives with TPDO2 + the I/O module on one bus at 2 ms: 82.7 %
  ac.operational_timeout_s = 0.25;  // the per-node windows below are what let the slow drives in
  ac.axes[0].operational_timeout_s = 0.6;
  ac.axes[1].operational_timeout_s = 0.6;
  ac.axes[2].operational_timeout_s = 0.6;
  IoRig r({}, fixed_drives(300'000, 400'000), ac);
  const drivers::Status s = r.configure();
  ASSERT_TRUE(s) << s.message();
  const auto& notes = r.rig.port.notes();
  EXPECT_TRUE(any_note(notes, "node 1 (beat_crank): 0x1016 (consumer heartbeat time) absent"));
  EXPECT_TRUE(any_note(notes, "0x1600:00 (RPDO1 mapping) is fixed (read-only); read back and accepted") ||
              any_note(notes, "0x1600:00"));
  EXPECT_TRUE(r.rig.port.has_tpdo2(hal::index(hal::CoreAxis::kCarriage)));
  EXPECT_FALSE(r.rig.port.has_consumer(hal::index(hal::CoreAxis::kCarriage)));
  r.enable_all();
}

// Rule 4: per-node operational windows — the same slow drive fails the default window, naming it.
TEST(Interop, SlowOperationalSwitchNeedsItsPerNodeWindow) {
  drivers::CanAxisPortConfig ac;
  ac.operational_timeout_s = 0.25;  // port-wide window shorter than the drive needs
  IoRig r({}, fixed_drives(0, 400'000), ac);
  const drivers::Status s = r.configure();
  ASSERT_FALSE(s);
  EXPECT_TRUE(
      contains(s.message(), "node 1 (beat_crank): no operational heartbeat after NMT start within 0.25 s"))
      << s.message();
}

TEST(Interop, FixedMappingThatLacksThePositionIsRefusedNamingWhatIsMissing) {
  auto d = fixed_drives(0, 0);
  d[1].tpdo1_factory_mapping = {0x60410010, 0x60630020};  // position actual in increments, not 0x6064
  drivers::CanAxisPortConfig ac;
  ac.operational_timeout_s = 0.5;
  IoRig r({}, d, ac);
  const drivers::Status s = r.configure();
  ASSERT_FALSE(s);
  EXPECT_TRUE(contains(s.message(), "node 2 (carriage): 0x1A00:00")) << s.message();
  EXPECT_TRUE(contains(s.message(), "missing 0x6064")) << s.message();
}

// ---------------------------------------------------------------------------------------------------
// Fault reactions
// ---------------------------------------------------------------------------------------------------
// An EMCY while the drive's statusword still says Operation Enabled stops every axis in that tick.
TEST(FaultReaction, EmcyFromAnEnabledDriveQuickStopsEveryAxisInTheSameTick) {
  IoRig r;
  ASSERT_TRUE(r.configure());
  r.enable_all();
  r.rig.drives.send(drivers::make_emcy(2, 0x2310, 0x03));  // over-current; the drive stays enabled
  r.rig.advance(100);
  r.tick(AxisRequest::kEnable);
  // Reported as what it is (the HAL's contract: the sequencer latches drive_emcy): its kind and code; the
  // drive is not in Fault.
  EXPECT_FALSE(r.in.axes[1].fault);
  EXPECT_EQ(r.in.axes[1].fault_kind, hal::FaultKind::kEmcy);
  EXPECT_EQ(r.in.axes[1].fault_code, 0x2310);
  for (hal::CoreAxis a : {hal::CoreAxis::kBeatCrank, hal::CoreAxis::kCarriage, hal::CoreAxis::kHelix}) {
    EXPECT_EQ(r.rig.port.last_controlword(hal::index(a)), drivers::controlword::kQuickStop)
        << hal::axis_name(a);
  }
}

TEST(FaultReaction, EmcyFromTheIoNodeStopsEveryAxisAndIsALinkFault) {
  IoRig r;
  ASSERT_TRUE(r.configure());
  r.enable_all();
  r.rig.drives.send(drivers::make_emcy(4, 0x5000, 0x01));
  r.rig.advance(100);
  r.tick(AxisRequest::kEnable);
  EXPECT_TRUE(r.in.link.link_fault);
  EXPECT_EQ(r.in.link.link_fault_code, 0x5000);
  EXPECT_EQ(r.rig.port.last_controlword(hal::index(hal::CoreAxis::kHelix)), drivers::controlword::kQuickStop);
  // Latched until the operator acknowledges (fault reset request).
  for (int i = 0; i < 5; ++i) r.tick(AxisRequest::kEnable);
  EXPECT_TRUE(r.in.link.link_fault);
  r.tick(AxisRequest::kFaultReset);
  r.tick(AxisRequest::kDisable);
  EXPECT_FALSE(r.in.link.link_fault);
}

TEST(FaultReaction, SilentIoNodeIsLostWithinItsConsumerTimeAndStopsEveryAxis) {
  IoRig r;
  ASSERT_TRUE(r.configure());
  r.enable_all();
  r.rig.rack.io_controls().silent = true;
  const hal::Tick cut = r.rig.tick_index;
  int n = 0;
  bool deadline_in_the_past = false;
  while (!r.in.link.link_fault && n < 500) {
    r.tick(AxisRequest::kEnable);
    // The silent node's timers run on: a deadline left behind makes loom-sim-drive's event loop spin
    // (at real-time priority in HIL, starving the master it is testing).
    deadline_in_the_past = deadline_in_the_past || r.rig.rack.next_deadline_us() < r.rig.now_us;
    ++n;
  }
  EXPECT_FALSE(deadline_in_the_past);
  ASSERT_TRUE(r.in.link.link_fault);
  EXPECT_EQ(r.in.link.link_fault_code, drivers::fault_code::kHeartbeatLost);
  // The last heartbeat came up to one producer period (100 ms) before the cut; consumer 250 ms.
  EXPECT_LE(static_cast<double>(r.rig.tick_index - cut) * 0.002, 0.250 + 0.004);
  EXPECT_LE(r.in.io.refreshed, cut + 1);  // stale inputs keep their old tick (one frame was in flight)
  EXPECT_EQ(r.rig.port.last_controlword(hal::index(hal::CoreAxis::kCarriage)),
            drivers::controlword::kQuickStop);
  // Until it is heard again, acknowledging cannot re-arm: the link names the silent node.
  EXPECT_EQ(r.in.link.recovery, hal::LinkRecovery::kNodeSilent);
  EXPECT_EQ(r.in.link.silent_node, 4);
  r.rig.rack.io_controls().silent = false;  // the cable is back: its heartbeats resume
  for (int i = 0; i < 100 && r.in.link.recovery != hal::LinkRecovery::kReady; ++i)
    r.tick(AxisRequest::kEnable);
  EXPECT_EQ(r.in.link.recovery, hal::LinkRecovery::kReady);
  EXPECT_TRUE(r.in.link.link_fault);  // still latched: only re-arming (configure) clears it
}

// The master produces its heartbeat; the I/O module and the drives watch it (0x1016) and react by
// themselves when the master dies: valves to their safe state, drives quick stop.
TEST(FaultReaction, MasterSilenceTripsTheNodesConsumers) {
  IoRig r;
  ASSERT_TRUE(r.configure());
  r.enable_all();
  hal::DigitalOutputs out;
  out.piston_b_extend = true;
  for (int i = 0; i < 5; ++i) r.tick(AxisRequest::kEnable, out);
  EXPECT_EQ(r.io.outputs(0) & 0x03, 0x02);
  EXPECT_TRUE(r.rig.port.has_consumer(hal::index(hal::CoreAxis::kBeatCrank)));
  // The host dies: no more ticks, time goes on.
  r.rig.advance(400'000);
  EXPECT_FALSE(r.io.comm_lost());
  r.rig.advance(300'000);
  EXPECT_TRUE(r.io.comm_lost());
  EXPECT_EQ(r.io.outputs(0) & 0x03, 0x00);  // both valve coils off (0x6207)
  EXPECT_EQ(r.io.outputs(0) & 0x40, 0x40);  // red lamp on
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(r.rig.rack.node(i).master_lost());
    EXPECT_EQ(r.rig.rack.node(i).drive_state(), DriveState::kQuickStopActive);
  }
}

TEST(FaultReaction, FollowingErrorScalesWithCommandedSpeedAndKeepsAHighWaterMark) {
  drivers::CanAxisPortConfig ac;
  ac.axes[2].ferror_min = 0.5;   // rad
  ac.axes[2].ferror_k_s = 0.01;  // 5 cycles of lag at the commanded speed
  IoRig r({}, three_drives(), ac);
  ASSERT_TRUE(r.configure());
  r.enable_all();
  // Ramp the helix at 100 rad/s: the ideal drive lags one to two cycles (0.2..0.4 rad) < max(0.5, 1.0).
  hal::HalOutputs o;
  double target = r.in.axes[2].position;
  drivers::CanHal hal(r.rig.network, r.rig.port, r.port);
  for (int i = 0; i < 100; ++i) {
    hal.read(r.rig.tick_index, r.in);
    for (std::size_t k = 0; k < 3; ++k) {
      o.axes[k].request = AxisRequest::kEnable;
      o.axes[k].target_position = r.in.axes[k].position;
    }
    target += 100.0 * 0.002;
    o.axes[2].target_position = target;
    hal.write(r.rig.tick_index, o);
    ++r.rig.tick_index;
    r.rig.advance(r.rig.period_us());
  }
  EXPECT_FALSE(r.in.axes[2].fault);
  const double hw = r.rig.port.ferror_high_water(hal::index(hal::CoreAxis::kHelix));
  EXPECT_GT(hw, 0.15);
  EXPECT_LT(hw, 0.5);
  // The drive stops receiving its targets (RPDOs lost): the error grows 0.2 rad per cycle and trips
  // at max(0.5, 0.01 s × 100 rad/s) = 1.0 rad, as fault 0x8611, and every axis stops in that tick.
  r.rig.net.drop = [](const drivers::CanFrame& f) { return f.id == 0x203; };
  int n = 0;
  for (; n < 20 && !r.in.axes[2].fault; ++n) {
    hal.read(r.rig.tick_index, r.in);
    for (std::size_t k = 0; k < 3; ++k) o.axes[k].target_position = r.in.axes[k].position;
    target += 100.0 * 0.002;
    o.axes[2].target_position = target;
    hal.write(r.rig.tick_index, o);
    ++r.rig.tick_index;
    r.rig.advance(r.rig.period_us());
  }
  ASSERT_TRUE(r.in.axes[2].fault);
  EXPECT_EQ(r.in.axes[2].fault_code, drivers::fault_code::kFollowingError);
  EXPECT_GE(n, 4);
  EXPECT_LE(n, 8);
  EXPECT_EQ(r.rig.port.last_controlword(hal::index(hal::CoreAxis::kBeatCrank)),
            drivers::controlword::kQuickStop);
  EXPECT_GT(r.rig.port.ferror_high_water(hal::index(hal::CoreAxis::kHelix)), 0.99);
}

}  // namespace
}  // namespace loom::test

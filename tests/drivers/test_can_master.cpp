// The bus owner and the per-node supervision (drivers/can_master.hpp, node_supervisor.hpp):
//  - NodeSupervisor against frames written out by hand from CiA 301 (heartbeat 0x700+id with the NMT
//    state byte, EMCY 0x080+id with the error code little-endian), not through the master's codec;
//  - a loom with its fourth axis on a second bus: one master per bus, each bus with its own SYNC and
//    RPDOs, node ids per bus, a fault on either bus stopping every axis, load counted per bus.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <span>
#include <vector>

#include "drive_rig.hpp"
#include "fake_can_network.hpp"
#include "loom/drivers/can_axis_port.hpp"
#include "loom/drivers/can_io_config.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/node_supervisor.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/sim_can/sim_drive_rack.hpp"

namespace loom {
namespace {

using drivers::CanFrame;
using drivers::NodeSupervisor;
using hal::AxisRequest;
using hal::DriveState;

CanFrame heartbeat(std::uint8_t node, std::uint8_t state) {
  CanFrame f;
  f.id = 0x700U + node;
  f.dlc = 1;
  f.data[0] =
      state;  // CiA 301 7.2.8.3.2.2: 0x00 boot-up, 0x04 stopped, 0x05 operational, 0x7F pre-operational
  return f;
}
CanFrame emcy(std::uint8_t node, std::uint16_t code) {
  CanFrame f;
  f.id = 0x080U + node;
  f.dlc = 8;
  f.data[0] = static_cast<std::uint8_t>(code & 0xFF);
  f.data[1] = static_cast<std::uint8_t>(code >> 8);
  f.data[2] = code != 0 ? 0x01 : 0x00;  // error register: generic error
  return f;
}

TEST(NodeSupervisor, HeartbeatConsumerTripsOneTickAfterTheConsumerTime) {
  NodeSupervisor s;
  s.arm(125);         // 250 ms at 2 ms
  s.supervise(1000);  // starts counting here
  ASSERT_TRUE(s.on_heartbeat(1050, heartbeat(3, 0x05)));
  s.supervise(1175);
  EXPECT_EQ(s.link_fault(), 0);
  s.supervise(1176);
  EXPECT_EQ(s.link_fault(), 0x8130);  // CiA 301: heartbeat consumer time-out
  EXPECT_FALSE(s.heard_again(1176));
  ASSERT_TRUE(s.on_heartbeat(1200, heartbeat(3, 0x05)));
  EXPECT_TRUE(s.heard_again(1200));
  EXPECT_EQ(s.link_fault(), 0x8130);  // latched until the next bring-up
  s.arm(125);
  EXPECT_EQ(s.link_fault(), 0);
}

TEST(NodeSupervisor, BootUpAndNotOperationalAreLinkFaultsAndMalformedFramesAreRefused) {
  NodeSupervisor a;
  a.arm(10);
  ASSERT_TRUE(a.on_heartbeat(5, heartbeat(1, 0x00)));
  EXPECT_EQ(a.link_fault(), drivers::fault_code::kNodeRebooted);
  EXPECT_TRUE(a.heard_again(1000));  // a boot-up counts as heard, however long ago
  NodeSupervisor b;
  b.arm(10);
  ASSERT_TRUE(b.on_heartbeat(5, heartbeat(1, 0x7F)));
  EXPECT_EQ(b.link_fault(), drivers::fault_code::kNodeNotOperational);
  EXPECT_EQ(drivers::link_fault_kind(b.link_fault()), hal::FaultKind::kNodeLost);
  CanFrame bad = heartbeat(1, 0x05);
  bad.dlc = 2;
  EXPECT_FALSE(b.on_heartbeat(6, bad));
  CanFrame short_emcy = emcy(1, 0x2310);
  short_emcy.dlc = 4;
  EXPECT_FALSE(b.on_emcy(short_emcy));
  EXPECT_EQ(b.emcy_code(), 0);
}

TEST(NodeSupervisor, EmcyLatchesUntilAcknowledgedAndTheNodesErrorReset) {
  NodeSupervisor s;
  s.arm(10);
  ASSERT_TRUE(s.on_emcy(emcy(2, 0x2310)));  // continuous over-current
  ASSERT_TRUE(s.on_emcy(emcy(2, 0x0000)));  // the node's own reset, not acknowledged: still latched
  EXPECT_EQ(s.emcy_code(), 0x2310);
  s.acknowledge(/*still_in_fault=*/true);  // the drive still says Fault: wait for its error reset
  EXPECT_EQ(s.emcy_code(), 0x2310);
  ASSERT_TRUE(s.on_emcy(emcy(2, 0x0000)));
  EXPECT_EQ(s.emcy_code(), 0);
  ASSERT_TRUE(s.on_emcy(emcy(2, 0x4210)));  // a new one after the acknowledgement latches again
  EXPECT_EQ(s.emcy_code(), 0x4210);
  s.acknowledge(false);
  EXPECT_EQ(s.emcy_code(), 0);
}

// ---------------------------------------------------------------------------------------------------
// Two buses
// ---------------------------------------------------------------------------------------------------
// The core three on bus 0 (nodes 1..3) and a take-up roller on bus 1 with node id 1 again: ids are per bus.
drivers::CanAxisPortConfig four_axes_two_buses() {
  drivers::CanAxisPortConfig c;
  c.axes.push_back({"take_up", 1, 1, 4096.0 / (2.0 * 3.141592653589793), 0.0});
  return c;
}

struct Bus {
  test::FakeCanNetwork net;
  test::FakeCanNetwork::Endpoint& master = net.add_endpoint();
  test::FakeCanNetwork::Endpoint& drives = net.add_endpoint();
  sim_can::SimDriveRack rack;
  explicit Bus(const std::vector<sim_can::SimDriveConfig>& nodes) : rack(drives, nodes) {}
  std::size_t frames_from_master(std::uint32_t id, std::size_t from = 0) const {
    std::size_t n = 0;
    for (std::size_t i = from; i < net.log().size(); ++i) {
      n += net.log()[i].from == 0 && net.log()[i].frame.id == id && !net.log()[i].frame.is_error() ? 1 : 0;
    }
    return n;
  }
};

struct TwoBusRig final : drivers::ConfigureClock {
  std::vector<std::unique_ptr<Bus>> buses;
  drivers::CanNetwork network;
  drivers::CanAxisPort port;
  std::int64_t now = 0;
  hal::Tick tick_index = 0;
  hal::AxisFeedbacks fb{};
  hal::LinkStatus link{};
  hal::AxisCommands cmd{};

  explicit TwoBusRig(drivers::CanAxisPortConfig c = four_axes_two_buses())
      : network(drivers::can_master_config(c), drivers::bus_count(c)), port(network, std::move(c)) {
    std::vector<sim_can::SimDriveConfig> b0(3), b1(1);
    for (std::size_t i = 0; i < 3; ++i) b0[i].node_id = static_cast<std::uint8_t>(i + 1);
    b0[0].initial_position = 1000;
    b1[0].node_id = 1;
    b1[0].initial_position = -777;
    buses.push_back(std::make_unique<Bus>(b0));
    buses.push_back(std::make_unique<Bus>(b1));
  }
  std::int64_t now_us() override { return now; }
  void idle() override { advance(100); }
  void advance(std::int64_t dt) {
    const std::int64_t end = now + dt;
    while (now < end) {
      now = std::min(end, now + 100);
      for (auto& b : buses) {
        b->net.set_time(now);
        b->rack.step(now);
      }
    }
  }
  drivers::Status configure() {
    for (auto& b : buses) b->rack.power_on(now);
    drivers::CanBus* const list[] = {&buses[0]->master, &buses[1]->master};
    return drivers::bring_up(network, port, std::span<drivers::CanBus* const>(list), *this);
  }
  void tick(AxisRequest r, double take_up_offset = 0.0) {
    network.poll(tick_index);
    port.read_axes(tick_index, fb, link);
    for (std::size_t i = 0; i < port.axis_count(); ++i) {
      cmd[i].request = r;
      cmd[i].target_position = fb[i].position + (i == 3 ? take_up_offset : 0.0);
    }
    network.start_cycle(tick_index);
    port.write_axes(tick_index, cmd);
    ++tick_index;
    advance(2000);
  }
  bool all_in(DriveState s) const {
    for (std::size_t i = 0; i < port.axis_count(); ++i) {
      if (fb[i].state != s) return false;
    }
    return true;
  }
};

TEST(CanMasterTwoBuses, EachBusCarriesItsOwnCycleAndNodeIdsArePerBus) {
  TwoBusRig r;
  ASSERT_EQ(r.port.bus_count(), 2u);
  const drivers::Status s = r.configure();
  ASSERT_TRUE(s) << s.message();
  for (int i = 0; i < 50 && !r.all_in(DriveState::kOperationEnabled); ++i) r.tick(AxisRequest::kEnable);
  ASSERT_TRUE(r.all_in(DriveState::kOperationEnabled));
  // Node 1 of bus 0 is the crank, node 1 of bus 1 the take-up: each reports its own drive's position.
  EXPECT_NEAR(r.fb[0].position * drivers::kDefaultCountsPerRad, 1000.0, 0.5);
  EXPECT_NEAR(r.fb[3].position * 4096.0 / (2.0 * 3.141592653589793), -777.0, 0.5);

  const std::size_t m0 = r.buses[0]->net.log().size(), m1 = r.buses[1]->net.log().size();
  for (int i = 0; i < 20; ++i) r.tick(AxisRequest::kEnable, 0.01);  // the take-up turns, the rest hold
  // One SYNC per tick on each bus, and each drive's RPDO1 on its own bus only.
  EXPECT_EQ(r.buses[0]->frames_from_master(0x080, m0), 20u);
  EXPECT_EQ(r.buses[1]->frames_from_master(0x080, m1), 20u);
  for (std::uint32_t node = 1; node <= 3; ++node)
    EXPECT_EQ(r.buses[0]->frames_from_master(0x200 + node, m0), 20u);
  EXPECT_EQ(r.buses[1]->frames_from_master(0x201, m1), 20u);
  EXPECT_EQ(r.buses[1]->frames_from_master(0x202, m1), 0u);
  // Each target is 0.01 rad (6.5 counts) past the last feedback, which lags the drive by up to two ticks.
  EXPECT_GT(r.buses[1]->rack.node(0).position() + 777, 30);
  EXPECT_NEAR(r.buses[0]->rack.node(0).position(), 1000, 1);
  EXPECT_FALSE(r.link.link_fault);
}

TEST(CanMasterTwoBuses, ANodeLostOnTheSecondBusStopsEveryAxisOnBoth) {
  TwoBusRig r;
  ASSERT_TRUE(r.configure());
  for (int i = 0; i < 50 && !r.all_in(DriveState::kOperationEnabled); ++i) r.tick(AxisRequest::kEnable);
  ASSERT_TRUE(r.all_in(DriveState::kOperationEnabled));
  r.buses[1]->rack.node(0).power_off();
  for (int i = 0; i < 200 && !r.fb[3].fault; ++i) r.tick(AxisRequest::kEnable);
  ASSERT_TRUE(r.fb[3].fault);
  EXPECT_EQ(r.fb[3].fault_kind, hal::FaultKind::kNodeLost);
  EXPECT_TRUE(r.link.link_fault);
  EXPECT_EQ(r.link.link_fault_kind, hal::FaultKind::kNodeLost);
  EXPECT_EQ(r.link.recovery, hal::LinkRecovery::kNodeSilent);
  EXPECT_EQ(r.link.silent_node, 1);
  // The drives on bus 0 are healthy but quick-stopped in the same tick, whatever the sequencer asks.
  for (int i = 0; i < 10; ++i) r.tick(AxisRequest::kEnable);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_FALSE(r.fb[i].fault) << i;
    EXPECT_EQ(r.port.last_controlword(i), drivers::controlword::kQuickStop) << i;
    EXPECT_EQ(r.buses[0]->rack.node(i).drive_state(), DriveState::kQuickStopActive) << i;
  }
  // Back on the bus and re-armed: both buses are brought up again.
  r.buses[1]->rack.node(0).power_on(r.now);
  r.tick(AxisRequest::kDisable);
  EXPECT_EQ(r.link.recovery, hal::LinkRecovery::kReady);
  ASSERT_TRUE(r.configure());
  r.tick(AxisRequest::kDisable);
  EXPECT_FALSE(r.link.link_fault);
}

TEST(CanMasterTwoBuses, BusOffOnOneBusIsReportedAndStopsAll) {
  TwoBusRig r;
  ASSERT_TRUE(r.configure());
  for (int i = 0; i < 50 && !r.all_in(DriveState::kOperationEnabled); ++i) r.tick(AxisRequest::kEnable);
  r.buses[1]->net.bus_off();
  r.tick(AxisRequest::kEnable);
  r.tick(AxisRequest::kEnable);
  EXPECT_TRUE(r.link.link_fault);
  EXPECT_EQ(r.link.link_fault_kind, hal::FaultKind::kBusOff);
  EXPECT_EQ(r.link.recovery, hal::LinkRecovery::kBusOff);
  EXPECT_EQ(r.fb[3].fault_kind, hal::FaultKind::kBusOff);
  EXPECT_FALSE(r.fb[0].fault);
  EXPECT_EQ(r.port.last_controlword(0), drivers::controlword::kQuickStop);
}

TEST(CanMasterTwoBuses, TheNumberOfInterfacesMustMatchTheBuses) {
  TwoBusRig r;
  for (auto& b : r.buses) b->rack.power_on(0);
  drivers::CanBus* const one[] = {&r.buses[0]->master};
  const drivers::Status s = drivers::bring_up(r.network, r.port, std::span<drivers::CanBus* const>(one), r);
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find("2 CAN bus(es)"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("1 interface(s)"), std::string::npos) << s.message();
}

TEST(CanMasterTwoBuses, NodeIdsAreUniquePerBusAndBusesAreBounded) {
  drivers::CanAxisPortConfig c = four_axes_two_buses();
  EXPECT_TRUE(drivers::validate(c));
  c.axes[3].bus = 0;  // node 1 twice on bus 0
  drivers::Status s = drivers::validate(c);
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find("axes.take_up.node_id = 1 is already used by another axis on bus 0"),
            std::string::npos)
      << s.message();
  c.axes[3].bus = 4;
  s = drivers::validate(c);
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find("axes.take_up.bus = 4 is outside 0..3"), std::string::npos) << s.message();
}

TEST(CanMasterTwoBuses, LoadIsCountedPerBus) {
  drivers::CanAxisPortConfig c = four_axes_two_buses();
  c.other_frames_per_cycle[0] = drivers::io_frames_per_cycle(drivers::IoWiring{});
  // Bus 0: SYNC + 3 × (RPDO1 + TPDO1) + the I/O node's 3 PDOs + master heartbeat = 11 frames.
  EXPECT_EQ(drivers::planned_bus_load(c, 0).frames, 11u);
  // Bus 1: SYNC + RPDO1 + TPDO1 + master heartbeat = 4 frames (the I/O node lives on bus 0).
  EXPECT_EQ(drivers::planned_bus_load(c, 1).frames, 4u);
  EXPECT_LT(drivers::planned_bus_load(c, 1).utilisation_worst,
            drivers::planned_bus_load(c, 0).utilisation_worst);
  ::testing::Test::RecordProperty("bus0_load",
                                  std::to_string(drivers::planned_bus_load(c, 0).utilisation_worst));
  ::testing::Test::RecordProperty("bus1_load",
                                  std::to_string(drivers::planned_bus_load(c, 1).utilisation_worst));
}

}  // namespace
}  // namespace loom

// ---------------------------------------------------------------------------------------------------
// CiA 402 homing over CAN, against the simulated drive (its own homing, its own random power-up count)
// ---------------------------------------------------------------------------------------------------
namespace loom {
namespace {

std::uint64_t run_seed() {
  static const std::uint64_t seed = [] {
    const std::uint64_t s = std::random_device{}() | 1U;
    std::printf("homing tests: power-up seed %llu\n", static_cast<unsigned long long>(s));
    return s;
  }();
  return seed;
}

// The helix (node 3) on an incremental encoder: index-pulse homing (34) to a home offset of 0.5 rad.
struct HomingRig {
  static constexpr std::int32_t kIndexEvery = 65536;
  test::DriveRig rig;
  explicit HomingRig(std::int8_t method = 34, bool switch_missing = false, bool drive_homes = true)
      : rig(drives(switch_missing, drive_homes), config(method)) {}
  static std::vector<sim_can::SimDriveConfig> drives(bool switch_missing, bool drive_homes) {
    std::vector<sim_can::SimDriveConfig> v = test::three_drives(100, 200, 300);
    v[2].power_up_seed = run_seed();
    v[2].index_every = kIndexEvery;
    v[2].home_switch_at = 12345;
    v[2].home_switch_missing = switch_missing;
    v[2].supports_homing = drive_homes;
    return v;
  }
  static drivers::CanAxisPortConfig config(std::int8_t method) {
    drivers::CanAxisPortConfig c;
    c.axes[2].homing_method = method;
    c.axes[2].home_offset = 0.5;
    c.axes[2].homing_speed = 20.0;  // rad/s: 6675 counts per 2 ms SYNC
    c.axes[2].homing_accel = 200.0;
    return c;
  }
  // The helix homes, the others are enabled and held.
  void tick_homing() {
    rig.tick([](const hal::AxisFeedbacks& fb, hal::AxisCommands& cmd) {
      for (std::size_t i = 0; i < 3; ++i) {
        cmd[i].request = i == 2 ? AxisRequest::kHome : AxisRequest::kEnable;
        cmd[i].target_position = fb[i].position;
      }
    });
  }
  const sim_can::SimDriveNode& helix() const { return rig.rack.node(2); }
};

TEST(CanHoming, AnIncrementalAxisIsUnreferencedAfterBringUpAndHomesToItsIndexPulse) {
  HomingRig h;
  const drivers::Status s = h.rig.configure();
  ASSERT_TRUE(s) << s.message();
  h.rig.tick(test::DriveRig::hold(AxisRequest::kDisable));
  EXPECT_TRUE(h.rig.feedback[0].referenced);  // absolute encoders
  EXPECT_FALSE(h.rig.feedback[2].referenced);
  int n = 0;
  while (!h.rig.feedback[2].referenced && n < 400) {
    h.tick_homing();
    ++n;
  }
  ASSERT_TRUE(h.rig.feedback[2].referenced) << "not referenced after " << n << " ticks";
  EXPECT_FALSE(h.rig.feedback[2].homing_error);
  // Independent truth: the simulated axis stands on an index pulse and its count is the home offset.
  EXPECT_EQ(h.helix().physical_position() % HomingRig::kIndexEvery, 0) << h.helix().physical_position();
  EXPECT_NEAR(h.rig.feedback[2].position, 0.5, 1.0 / drivers::kDefaultCountsPerRad);
  EXPECT_EQ(h.helix().position(),
            static_cast<std::int32_t>(std::llround(0.5 * drivers::kDefaultCountsPerRad)));
  // The mode travelled in the PDOs: 7-byte RPDO1s to node 3 with 0x6060 = 6, then back to 8.
  bool saw_homing = false;
  for (const auto& l : h.rig.net.log()) {
    if (l.from == 0 && l.frame.id == 0x203) {
      EXPECT_EQ(l.frame.dlc, 7);
      saw_homing = saw_homing || static_cast<std::int8_t>(l.frame.data[6]) == 6;
    }
    if (l.from == 0 && l.frame.id == 0x201) {
      EXPECT_EQ(l.frame.dlc, 6);
    }
  }
  EXPECT_TRUE(saw_homing);
  for (int i = 0; i < 5; ++i) h.rig.tick(test::DriveRig::hold(AxisRequest::kEnable));
  EXPECT_EQ(h.helix().mode(), 8);
  EXPECT_EQ(h.rig.feedback[2].state, DriveState::kOperationEnabled);
  // Referenced, it follows targets in CSP like every axis.
  h.rig.tick([](const hal::AxisFeedbacks& fb, hal::AxisCommands& cmd) {
    for (std::size_t i = 0; i < 3; ++i) {
      cmd[i].request = AxisRequest::kEnable;
      cmd[i].target_position = fb[i].position + (i == 2 ? 0.001 : 0.0);
    }
  });
  h.rig.tick(test::DriveRig::hold(AxisRequest::kEnable));
  EXPECT_NEAR(h.helix().position(), std::llround(0.501 * drivers::kDefaultCountsPerRad), 2);
}

TEST(CanHoming, AnUnreferencedAxisIsNeverMovedAndABootUpUnreferencesIt) {
  HomingRig h(37);
  ASSERT_TRUE(h.rig.configure());
  h.rig.tick(test::DriveRig::hold(AxisRequest::kDisable));
  ASSERT_FALSE(h.rig.feedback[2].referenced);
  const std::int32_t count = h.helix().position();
  for (int i = 0; i < 30; ++i) {
    h.rig.tick([](const hal::AxisFeedbacks& fb, hal::AxisCommands& cmd) {
      for (std::size_t k = 0; k < 3; ++k) {
        cmd[k].request = AxisRequest::kEnable;
        cmd[k].target_position = fb[k].position + 0.01;  // asks it to move
      }
    });
  }
  EXPECT_EQ(h.rig.feedback[2].state, DriveState::kOperationEnabled);
  EXPECT_EQ(h.helix().position(), count);         // held: its count means nothing yet
  EXPECT_NE(h.rig.rack.node(0).position(), 100);  // a referenced axis did move
  // Method 37: the current position is the home point.
  for (int i = 0; i < 10 && !h.rig.feedback[2].referenced; ++i) h.tick_homing();
  ASSERT_TRUE(h.rig.feedback[2].referenced);
  EXPECT_EQ(h.helix().position(),
            static_cast<std::int32_t>(std::llround(0.5 * drivers::kDefaultCountsPerRad)));
  // A power cycle: a new random count; the master sees the boot-up, and after re-arming the axis is
  // unreferenced again.
  h.rig.rack.node(2).power_off();
  h.rig.rack.node(2).power_on(h.rig.now_us);
  h.rig.tick(test::DriveRig::hold(AxisRequest::kQuickStop));
  EXPECT_TRUE(h.rig.feedback[2].fault);
  EXPECT_EQ(h.rig.feedback[2].fault_kind, hal::FaultKind::kNodeLost);
  ASSERT_TRUE(h.rig.configure());
  h.rig.tick(test::DriveRig::hold(AxisRequest::kDisable));
  EXPECT_FALSE(h.rig.feedback[2].referenced);
}

TEST(CanHoming, ASwitchNeverFoundIsAHomingErrorUntilAcknowledged) {
  HomingRig h(19, /*switch_missing=*/true);
  ASSERT_TRUE(h.rig.configure());
  h.rig.tick(test::DriveRig::hold(AxisRequest::kDisable));
  for (int i = 0; i < 400 && !h.rig.feedback[2].homing_error; ++i) h.tick_homing();
  EXPECT_TRUE(h.rig.feedback[2].homing_error);
  EXPECT_FALSE(h.rig.feedback[2].referenced);
  h.rig.tick(test::DriveRig::hold(AxisRequest::kFaultReset));
  h.rig.tick(test::DriveRig::hold(AxisRequest::kDisable));
  EXPECT_FALSE(h.rig.feedback[2].homing_error);
}

// A homing statusword with "homing error" (bit 13) is never a success, even beside "attained" (bit 12,
// with target reached): the two together are reserved in CiA 402. Found by the CAN fuzzer.
TEST(CanHoming, AHomingErrorBesideAttainedIsNotReferenced) {
  HomingRig h(19, /*switch_missing=*/true);  // a long search: the run stays under way
  ASSERT_TRUE(h.rig.configure());
  h.rig.tick(test::DriveRig::hold(AxisRequest::kDisable));
  for (int i = 0; i < 20; ++i) h.tick_homing();
  ASSERT_FALSE(h.rig.feedback[2].referenced);
  ASSERT_FALSE(h.rig.feedback[2].homing_error);
  drivers::Tpdo1Mode bad;
  bad.statusword = 0x0027 | drivers::statusword::kTargetReached | drivers::statusword::kHomingAttained |
                   drivers::statusword::kHomingError;  // operation enabled, reached, attained AND error
  bad.position_actual = 0;
  bad.mode_display = drivers::od::kModeHoming;
  ASSERT_EQ(h.rig.drives.send(drivers::pack_tpdo1_mode(3, bad)), drivers::SendResult::kOk);
  // The drive's own TPDOs go on: the error stays latched, the axis unreferenced.
  for (int i = 0; i < 50; ++i) {
    h.tick_homing();
    ASSERT_TRUE(h.rig.feedback[2].homing_error) << "tick " << i;
    ASSERT_FALSE(h.rig.feedback[2].referenced) << "tick " << i;
  }
}

TEST(CanHoming, TheHomeSwitchMethodStopsOnTheSwitch) {
  HomingRig h(19);
  ASSERT_TRUE(h.rig.configure());
  h.rig.tick(test::DriveRig::hold(AxisRequest::kDisable));
  ASSERT_FALSE(h.rig.feedback[2].referenced);
  for (int i = 0; i < 2000 && !h.rig.feedback[2].referenced; ++i) h.tick_homing();
  ASSERT_TRUE(h.rig.feedback[2].referenced);
  EXPECT_EQ(h.helix().physical_position(), 12345);
}

TEST(CanHoming, ADriveWithoutHomingModeIsRefusedNamingTheObject) {
  HomingRig h(34, false, /*drive_homes=*/false);
  const drivers::Status s = h.rig.configure();
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find(
                "node 3 (helix): referencing = \"homing\" but the drive does not offer homing mode (0x6502"),
            std::string::npos)
      << s.message();
}

TEST(CanHoming, HomedAxesCountTheirLongerPdosInTheBusLoad) {
  drivers::CanAxisPortConfig c;
  const drivers::BusLoad absolute = drivers::planned_bus_load(c);
  c.axes[2].homing_method = 34;
  c.axes[2].homing_speed = 1.0;
  c.axes[2].homing_accel = 1.0;
  const drivers::BusLoad homed = drivers::planned_bus_load(c);
  EXPECT_EQ(homed.frames, absolute.frames);
  EXPECT_EQ(homed.bits_nominal, absolute.bits_nominal + 16);  // one more byte in RPDO1 and in TPDO1
}

}  // namespace
}  // namespace loom

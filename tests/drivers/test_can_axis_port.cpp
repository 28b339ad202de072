// CanAxisPort end to end against simulated CiA 402 drives over the fault-injecting in-memory bus:
// bring-up order and content, reaching Operation Enabled, tracking, no jump on enable, heartbeat loss,
// drive faults and reset, quick stop, state timeouts, bus-off, dropped/delayed frames, and
// configuration errors that name the node, the object and the step.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <span>

#include "drive_rig.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/drivers/sdo.hpp"

namespace loom::test {
namespace {

using drivers::CanAxisPortConfig;
using hal::AxisRequest;
using hal::DriveState;

constexpr auto kEnable = AxisRequest::kEnable;

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

void enable_all(DriveRig& rig) {
  const int n = rig.run_until(
      DriveRig::hold(kEnable), [&] { return rig.all_in(DriveState::kOperationEnabled); }, 50);
  ASSERT_TRUE(rig.all_in(DriveState::kOperationEnabled)) << "after " << n << " ticks";
}

TEST(CanAxisPort, ConfigureBringsEveryDriveUpInOrder) {
  DriveRig rig(three_drives());
  const drivers::Status s = rig.configure();
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_TRUE(rig.port.configured());

  for (std::size_t i = 0; i < 3; ++i) {
    const auto& n = rig.rack.node(i);
    EXPECT_EQ(n.nmt_state(), drivers::NmtState::kOperational);
    EXPECT_EQ(n.mode(), 8);
    EXPECT_EQ(n.heartbeat_ms(), 100);
  }
  // Order on the wire: 3 × reset-node first, 3 × start last, SDO requests in between.
  std::vector<drivers::CanFrame> sent;
  for (const auto& l : rig.net.log()) {
    if (l.from == 0) sent.push_back(l.frame);
  }
  ASSERT_GT(sent.size(), 6u);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto first = drivers::parse_nmt(sent[i]);
    ASSERT_TRUE(first);
    EXPECT_EQ(first->command, drivers::NmtCommand::kResetNode);
    EXPECT_EQ(first->node, i + 1);
    const auto last = drivers::parse_nmt(sent[sent.size() - 3 + i]);
    ASSERT_TRUE(last);
    EXPECT_EQ(last->command, drivers::NmtCommand::kStart);
  }
  for (std::size_t i = 3; i < sent.size() - 3; ++i) {
    EXPECT_EQ(drivers::decode_cob_id(sent[i].id).function, drivers::CobFunction::kSdoRx) << i;
  }
  // 0x6060 = 8 is written before 0x6061 is read, for every node.
  for (std::uint8_t node = 1; node <= 3; ++node) {
    std::size_t write_mode = 0, read_display = 0;
    for (std::size_t i = 0; i < sent.size(); ++i) {
      if (sent[i].id != drivers::cob::sdo_rx(node)) continue;
      const auto r = drivers::parse_sdo_request(sent[i]);
      if (r.index == 0x6060 && r.kind == drivers::SdoRequestKind::kDownloadExpedited) write_mode = i;
      if (r.index == 0x6061 && r.kind == drivers::SdoRequestKind::kUpload) read_display = i;
    }
    EXPECT_GT(write_mode, 0u);
    EXPECT_GT(read_display, write_mode);
  }
  EXPECT_EQ(rig.port.bus_load().frames, 8u);  // SYNC, 3 RPDO, 3 TPDO, the master heartbeat
}

TEST(CanAxisPort, OnlyTheMappedPdosFlowAtFourFramesOutPerTick) {
  DriveRig rig(three_drives());
  ASSERT_TRUE(rig.configure().is_ok());
  const std::size_t start = rig.net.log().size();
  for (int i = 0; i < 20; ++i) rig.tick(DriveRig::hold(kEnable));
  int from_master = 0, tpdo1 = 0, other_pdo = 0, master_heartbeats = 0;
  for (std::size_t i = start; i < rig.net.log().size(); ++i) {
    const auto& l = rig.net.log()[i];
    const auto fn = drivers::decode_cob_id(l.frame.id).function;
    if (l.from == 0 && fn == drivers::CobFunction::kHeartbeat) ++master_heartbeats;
    if (l.from == 0 && fn != drivers::CobFunction::kHeartbeat) ++from_master;
    if (fn == drivers::CobFunction::kTpdo1) ++tpdo1;
    if (fn == drivers::CobFunction::kTpdo2 || fn == drivers::CobFunction::kTpdo3 ||
        fn == drivers::CobFunction::kTpdo4) {
      ++other_pdo;  // the drives' factory TPDO2 must have been switched off
    }
  }
  EXPECT_EQ(from_master, 20 * 4);   // SYNC + 3 RPDO
  EXPECT_EQ(master_heartbeats, 1);  // every 100 ms = 50 ticks
  EXPECT_EQ(tpdo1, 20 * 3);
  EXPECT_EQ(other_pdo, 0);
}

TEST(CanAxisPort, ReachesOperationEnabledAndTracksWithTwoTickLatency) {
  DriveRig rig(three_drives(1000, -2000, 3000));
  ASSERT_TRUE(rig.configure().is_ok());
  enable_all(rig);
  EXPECT_EQ(rig.link.link_fault, false);

  // Sinusoids on every axis; the drive reaches the target at the next SYNC and reports it one SYNC
  // later, so the feedback at tick k+2 equals the target commanded at tick k (to one count).
  std::array<double, 3> p0{};
  for (std::size_t i = 0; i < 3; ++i) p0[i] = rig.feedback[i].position;
  const double amp[] = {0.5, 0.02, 3.0};  // rad, m, rad
  std::vector<std::array<double, 3>> commanded;
  std::vector<std::array<double, 3>> measured;
  const double dt = rig.port.config().cycle_period_s;
  for (int k = 0; k < 300; ++k) {
    rig.tick([&](const hal::AxisFeedbacks& fb, hal::AxisCommands& cmd) {
      std::array<double, 3> m{}, c{};
      for (std::size_t i = 0; i < 3; ++i) {
        m[i] = fb[i].position;
        c[i] = p0[i] + amp[i] * std::sin(2.0 * std::numbers::pi * 2.0 * k * dt);
        cmd[i] = {kEnable, c[i]};
      }
      measured.push_back(m);
      commanded.push_back(c);
    });
  }
  for (std::size_t k = 0; k + 2 < commanded.size(); ++k) {
    for (std::size_t i = 0; i < 3; ++i) {
      const double count = 1.0 / rig.port.config().axes[i].counts_per_unit;
      ASSERT_NEAR(measured[k + 2][i], commanded[k][i], 0.5 * count + 1e-15) << "k=" << k << " axis " << i;
    }
  }
  for (const auto& f : std::span(rig.feedback.data(), rig.port.axis_count())) {
    EXPECT_FALSE(f.fault);
    EXPECT_EQ(f.refreshed, rig.tick_index - 1);  // fresh every tick
  }
}

TEST(CanAxisPort, FirstTargetIsTheActualPositionSoEnablingNeverJumps) {
  // The drives trip on any target step above 2000 counts, and the "sequencer" naively commands 0
  // until it sees Operation Enabled: the port must hold the targets at the actual position.
  auto nodes = three_drives(123456, -98765, 2147480000);
  for (auto& n : nodes) n.max_step_counts = 2000;
  DriveRig rig(nodes);
  ASSERT_TRUE(rig.configure().is_ok());
  std::array<bool, 3> seeded{};
  std::array<double, 3> hold_at{};
  const auto policy = [&](const hal::AxisFeedbacks& fb, hal::AxisCommands& cmd) {
    for (std::size_t i = 0; i < 3; ++i) {
      if (fb[i].state == DriveState::kOperationEnabled && !seeded[i]) {
        seeded[i] = true;
        hold_at[i] = fb[i].position;
      }
      cmd[i] = {kEnable, seeded[i] ? hold_at[i] : 0.0};
    }
  };
  rig.run_until(
      policy, [&] { return rig.all_in(DriveState::kOperationEnabled); }, 50);
  ASSERT_TRUE(rig.all_in(DriveState::kOperationEnabled));
  for (int i = 0; i < 10; ++i) rig.tick(policy);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto rpdos = rig.rpdos_to(static_cast<std::uint8_t>(i + 1));
    ASSERT_FALSE(rpdos.empty());
    for (const auto& r : rpdos) EXPECT_EQ(r.target_position, nodes[i].initial_position) << "axis " << i;
    EXPECT_EQ(rig.rack.node(i).drive_state(), DriveState::kOperationEnabled);
    EXPECT_FALSE(rig.feedback[i].fault);
    EXPECT_EQ(rig.rack.node(i).position(), nodes[i].initial_position);
  }
}

TEST(CanAxisPort, HeartbeatLossFaultsWithinThreeProducerPeriodsAndStopsEnabling) {
  DriveRig rig(three_drives());
  ASSERT_TRUE(rig.configure().is_ok());
  enable_all(rig);
  // Steady operation for 4 producer periods: heartbeats keep every axis healthy.
  for (int i = 0; i < 200; ++i) rig.tick(DriveRig::hold(kEnable));
  for (const auto& f : std::span(rig.feedback.data(), rig.port.axis_count())) ASSERT_FALSE(f.fault);
  ASSERT_FALSE(rig.link.link_fault);
  EXPECT_EQ(rig.link.recovery, hal::LinkRecovery::kHealthy);

  const std::int64_t t_off = rig.now_us;
  rig.rack.node(1).power_off();  // carriage drive disappears
  const auto& carriage = rig.feedback[hal::index(hal::CoreAxis::kCarriage)];
  rig.run_until(
      DriveRig::hold(kEnable), [&] { return carriage.fault; }, 1000);
  const std::int64_t detected_after_us = rig.now_us - t_off;
  ASSERT_TRUE(carriage.fault);
  EXPECT_EQ(carriage.fault_code, drivers::fault_code::kHeartbeatLost);
  EXPECT_TRUE(rig.link.link_fault);
  EXPECT_EQ(rig.link.link_fault_code, 0x8130);
  ::testing::Test::RecordProperty("heartbeat_loss_detected_after_us", std::to_string(detected_after_us));
  EXPECT_LE(detected_after_us, 3 * 100'000) << "producer time 100 ms";
  EXPECT_GT(detected_after_us, 250'000 - 100'000);  // not before the consumer time can have elapsed
  EXPECT_FALSE(rig.feedback[0].fault);
  EXPECT_FALSE(rig.feedback[2].fault);

  // The sequencer keeps asking for Enable (worst case); the lost node gets quick stop only, even after
  // it comes back (a reboot lost its configuration: it needs configure() again).
  const std::size_t mark = rig.net.log().size();
  for (int i = 0; i < 100; ++i) rig.tick(DriveRig::hold(kEnable));
  // Until the node is heard again an acknowledgement could not re-arm it: the link says which node.
  EXPECT_EQ(rig.link.recovery, hal::LinkRecovery::kNodeSilent);
  EXPECT_EQ(rig.link.silent_node, 2);
  rig.rack.node(1).power_on(rig.now_us);
  for (int i = 0; i < 100; ++i) rig.tick(DriveRig::hold(kEnable));
  const auto after = rig.rpdos_to(2, mark);
  ASSERT_EQ(after.size(), 200u);
  for (const auto& r : after) {
    EXPECT_TRUE(r.controlword == drivers::controlword::kQuickStop ||
                r.controlword == drivers::controlword::kDisableVoltage)
        << std::hex << r.controlword;
  }
  EXPECT_TRUE(carriage.fault);
  EXPECT_NE(rig.rack.node(1).drive_state(), DriveState::kOperationEnabled);
  // Its boot-up was heard (a rebooted node sends no heartbeat until configured): ready to re-arm.
  EXPECT_EQ(rig.link.recovery, hal::LinkRecovery::kReady);

  // Recovery is configure() from the non-RT side.
  ASSERT_TRUE(rig.configure().is_ok());
  rig.tick(DriveRig::hold(AxisRequest::kDisable));
  EXPECT_FALSE(rig.link.link_fault);
  enable_all(rig);
}

TEST(CanAxisPort, UnexpectedRebootIsALinkFault) {
  DriveRig rig(three_drives());
  ASSERT_TRUE(rig.configure().is_ok());
  enable_all(rig);
  // Power blip shorter than the consumer time: the heartbeat never lapses, but the boot-up says the
  // drive lost its mapping and mode.
  rig.rack.node(0).power_off();
  rig.advance(20'000);
  rig.rack.node(0).power_on(rig.now_us);
  rig.tick(DriveRig::hold(kEnable));
  EXPECT_TRUE(rig.feedback[0].fault);
  EXPECT_EQ(rig.feedback[0].fault_code, drivers::fault_code::kNodeRebooted);
  EXPECT_TRUE(rig.link.link_fault);
  EXPECT_EQ(rig.link.link_fault_code, drivers::fault_code::kNodeRebooted);
}

TEST(CanAxisPort, DriveLeavingOperationalIsALinkFault) {
  DriveRig rig(three_drives());
  auto& tool = rig.net.add_endpoint();  // e.g. a technician's tool on the same bus
  ASSERT_TRUE(rig.configure().is_ok());
  enable_all(rig);
  tool.send(drivers::make_nmt(drivers::NmtCommand::kEnterPreOperational, 3));
  const auto& helix = rig.feedback[2];
  rig.run_until(
      DriveRig::hold(kEnable), [&] { return helix.fault; }, 100);  // next heartbeat ≤ 100 ms
  EXPECT_TRUE(helix.fault);
  EXPECT_EQ(helix.fault_code, drivers::fault_code::kNodeNotOperational);
  EXPECT_TRUE(rig.link.link_fault);
}

TEST(CanAxisPort, DriveFaultReportsEmcyCodeAndResetsOnRequest) {
  DriveRig rig(three_drives(0, 0, 777));
  ASSERT_TRUE(rig.configure().is_ok());
  enable_all(rig);
  rig.rack.node(2).inject_fault(0x2310);  // continuous over-current
  const auto& helix = rig.feedback[2];
  rig.run_until(
      DriveRig::hold(kEnable), [&] { return helix.state == DriveState::kFault; }, 10);
  ASSERT_EQ(helix.state, DriveState::kFault);
  EXPECT_TRUE(helix.fault);
  EXPECT_EQ(helix.fault_code, 0x2310);
  EXPECT_FALSE(rig.link.link_fault);  // a drive fault is not a link fault
  // Enable requests never reset the fault.
  for (int i = 0; i < 20; ++i) rig.tick(DriveRig::hold(kEnable));
  EXPECT_EQ(helix.state, DriveState::kFault);

  rig.run_until(
      DriveRig::hold(AxisRequest::kFaultReset), [&] { return helix.state == DriveState::kSwitchOnDisabled; },
      10);
  ASSERT_EQ(helix.state, DriveState::kSwitchOnDisabled);
  EXPECT_FALSE(helix.fault);
  EXPECT_EQ(helix.fault_code, 0);  // EMCY 0x0000 cleared it
  enable_all(rig);
  EXPECT_EQ(rig.rack.node(2).position(), 777);
}

TEST(CanAxisPort, QuickStopThenDisable) {
  DriveRig rig(three_drives());
  ASSERT_TRUE(rig.configure().is_ok());
  enable_all(rig);
  rig.run_until(
      DriveRig::hold(AxisRequest::kQuickStop), [&] { return rig.all_in(DriveState::kQuickStopActive); }, 10);
  EXPECT_TRUE(rig.all_in(DriveState::kQuickStopActive));
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(rig.rack.node(i).drive_state(), DriveState::kQuickStopActive);
  rig.run_until(
      DriveRig::hold(AxisRequest::kDisable), [&] { return rig.all_in(DriveState::kSwitchOnDisabled); }, 10);
  EXPECT_TRUE(rig.all_in(DriveState::kSwitchOnDisabled));
}

TEST(CanAxisPort, UnconfirmedTransitionTimesOutIntoAFault) {
  DriveRig rig(three_drives());
  ASSERT_TRUE(rig.configure().is_ok());
  rig.net.drop = [](const drivers::CanFrame& f) { return f.id == drivers::cob::rpdo(1, 3); };
  const std::uint32_t limit = 250;  // 0.5 s at 2 ms
  const auto& helix = rig.feedback[2];
  for (std::uint32_t i = 0; i < limit; ++i) rig.tick(DriveRig::hold(kEnable));
  EXPECT_FALSE(helix.fault);
  // Tick `limit` (the 251st) latches the timeout in write_axes; the next read reports it.
  const int more = rig.run_until(
      DriveRig::hold(kEnable), [&] { return helix.fault; }, 5);
  EXPECT_EQ(more, 2);
  EXPECT_TRUE(helix.fault);
  EXPECT_EQ(helix.fault_code, drivers::fault_code::kStateTimeout);
  EXPECT_EQ(rig.port.last_controlword(hal::index(hal::CoreAxis::kHelix)),
            drivers::controlword::kDisableVoltage);
  EXPECT_TRUE(rig.feedback[0].state == DriveState::kOperationEnabled);

  // The bus heals; a fault-reset request clears the latch and the axis enables.
  rig.net.drop = nullptr;
  rig.tick(DriveRig::hold(AxisRequest::kFaultReset));  // the request reaches the tracker in write_axes
  rig.tick(DriveRig::hold(AxisRequest::kFaultReset));
  EXPECT_FALSE(helix.fault);
  enable_all(rig);
}

TEST(CanAxisPort, BusOffLatchesALinkFaultAndCountsDroppedFrames) {
  DriveRig rig(three_drives());
  ASSERT_TRUE(rig.configure().is_ok());
  enable_all(rig);
  rig.net.bus_off();
  rig.tick(DriveRig::hold(kEnable));
  EXPECT_TRUE(rig.link.link_fault);
  EXPECT_EQ(rig.link.link_fault_code, drivers::fault_code::kCommunication);
  EXPECT_EQ(rig.link.rx_errors, 1u);
  for (const auto& f : std::span(rig.feedback.data(), rig.port.axis_count())) EXPECT_TRUE(f.fault);
  EXPECT_EQ(rig.link.tx_dropped, 0u);
  rig.tick(DriveRig::hold(kEnable));
  EXPECT_EQ(rig.link.tx_dropped, 4u);  // the previous tick's SYNC + 3 RPDO were refused by the bus
  EXPECT_EQ(rig.link.recovery, hal::LinkRecovery::kBusOff);  // an acknowledgement cannot help yet
  rig.net.restart();
  for (int i = 0; i < 5; ++i) rig.tick(DriveRig::hold(kEnable));
  EXPECT_TRUE(rig.link.link_fault);                         // latched until configure()
  EXPECT_EQ(rig.link.recovery, hal::LinkRecovery::kReady);  // the controller is back: re-arming can work
  EXPECT_EQ(rig.port.last_controlword(hal::index(hal::CoreAxis::kBeatCrank)),
            drivers::controlword::kQuickStop);
}

TEST(CanAxisPort, FullTransmitQueueDropsAndCountsWithoutFault) {
  DriveRig rig(three_drives());
  ASSERT_TRUE(rig.configure().is_ok());
  enable_all(rig);
  rig.net.fill_tx_queue(3);
  rig.tick(DriveRig::hold(kEnable));
  rig.tick(DriveRig::hold(kEnable));
  EXPECT_EQ(rig.link.tx_dropped, 3u);
  EXPECT_FALSE(rig.link.link_fault);
}

TEST(CanAxisPort, LostAndLateFramesAreTolerated) {
  DriveRig rig(three_drives());
  ASSERT_TRUE(rig.configure().is_ok());
  rig.net.latency_us = 600;
  int n = 0;
  rig.net.drop = [&n](const drivers::CanFrame& f) {
    return f.id == drivers::cob::tpdo(1, 1) && (++n % 3 == 0);  // every third crank TPDO lost
  };
  enable_all(rig);
  int stale = 0;
  for (int i = 0; i < 60; ++i) {
    rig.tick(DriveRig::hold(kEnable));
    if (rig.feedback[0].refreshed != rig.tick_index - 1) ++stale;
    EXPECT_GE(rig.feedback[0].refreshed, rig.tick_index - 2);
    EXPECT_FALSE(rig.feedback[0].fault);
  }
  EXPECT_EQ(stale, 20);
}

TEST(CanAxisPort, UnwrappedPositionAcrossTheInt32Wrap) {
  DriveRig rig(three_drives(2147483647 - 5000, 0, 0));
  ASSERT_TRUE(rig.configure().is_ok());
  enable_all(rig);
  const double cpu = rig.port.config().axes[0].counts_per_unit;
  const double start = rig.feedback[0].position;
  EXPECT_NEAR(start, (2147483647.0 - 5000.0) / cpu, 1e-9);
  double last = start;
  for (int k = 1; k <= 120; ++k) {
    rig.tick([&](const hal::AxisFeedbacks&, hal::AxisCommands& cmd) {
      cmd = {};
      cmd[0] = {kEnable, start + 100.0 * k / cpu};
      cmd[1] = {kEnable, rig.feedback[1].position};
      cmd[2] = {kEnable, rig.feedback[2].position};
    });
    EXPECT_GE(rig.feedback[0].position, last);
    last = rig.feedback[0].position;
  }
  EXPECT_NEAR(last, start + 11800.0 / cpu, 0.5 / cpu);  // two ticks behind the last command
  EXPECT_LT(rig.rack.node(0).position(), 0);            // the drive's own counter wrapped
}

TEST(CanAxisPort, VelocityFromTpdo2OrFromFiniteDifferences) {
  for (bool tpdo2 : {false, true}) {
    CanAxisPortConfig cfg;
    cfg.tpdo2 = tpdo2;
    cfg.bus_load_budget = 0.75;  // three drives with TPDO2 on one bus at 2 ms: 71.5 % (test_bus_load.cpp)
    cfg.axes[2].rated_effort = 2.0;
    DriveRig rig(three_drives(), cfg);
    ASSERT_TRUE(rig.configure().is_ok());
    enable_all(rig);
    const double v = 12.5;  // rad/s on the helix shaft
    const double dt = cfg.cycle_period_s;
    const double p0 = rig.feedback[2].position;
    for (int k = 1; k <= 50; ++k) {
      rig.tick([&](const hal::AxisFeedbacks& fb, hal::AxisCommands& cmd) {
        for (std::size_t i = 0; i < 2; ++i) cmd[i] = {kEnable, fb[i].position};
        cmd[2] = {kEnable, p0 + v * k * dt};
      });
    }
    // One count per cycle of quantisation in the per-cycle difference.
    const double tol = 1.0 / (cfg.axes[2].counts_per_unit * dt);
    EXPECT_NEAR(rig.feedback[2].velocity, v, tol) << "tpdo2=" << tpdo2;
    EXPECT_EQ(rig.feedback[2].effort, 0.0);                   // the ideal drive needs no torque
    EXPECT_EQ(rig.port.bus_load().frames, tpdo2 ? 11u : 8u);  // incl. the master heartbeat
  }
}

// ---- configuration errors -------------------------------------------------------------------------
TEST(CanAxisPortConfigure, SdoAbortNamesNodeObjectAndCode) {
  auto nodes = three_drives();
  nodes[1].missing_objects = {0x60C2};
  DriveRig rig(nodes);
  const drivers::Status s = rig.configure();
  ASSERT_FALSE(s.is_ok());
  EXPECT_TRUE(contains(s.message(), "node 2 (carriage)")) << s.message();
  EXPECT_TRUE(contains(s.message(), "0x60C2:01 (interpolation time period)")) << s.message();
  EXPECT_TRUE(contains(s.message(), "0x06020000")) << s.message();
  EXPECT_TRUE(contains(s.message(), "object does not exist")) << s.message();
  EXPECT_FALSE(rig.port.configured());
}

TEST(CanAxisPortConfigure, DriveWithoutCspIsRefused) {
  auto nodes = three_drives();
  nodes[0].supports_csp = false;
  DriveRig rig(nodes);
  const drivers::Status s = rig.configure();
  ASSERT_FALSE(s.is_ok());
  EXPECT_TRUE(contains(s.message(), "node 1 (beat_crank)")) << s.message();
  EXPECT_TRUE(contains(s.message(), "cyclic synchronous position")) << s.message();
  EXPECT_TRUE(contains(s.message(), "0x6502")) << s.message();
}

TEST(CanAxisPortConfigure, MissingDriveIsNamedAfterTheBootTimeout) {
  auto nodes = three_drives();
  nodes.pop_back();
  DriveRig rig(nodes);
  const drivers::Status s = rig.configure();
  ASSERT_FALSE(s.is_ok());
  EXPECT_TRUE(contains(s.message(), "node 3 (helix): no boot-up")) << s.message();
  EXPECT_GE(rig.now_us, 2'000'000);
  EXPECT_LT(rig.now_us, 2'100'000);
}

TEST(CanAxisPortConfigure, SdoTimeoutSendsAbortAndSaysSo) {
  DriveRig rig(three_drives());
  rig.net.drop = [](const drivers::CanFrame& f) { return f.id == drivers::cob::sdo_tx(3); };
  const drivers::Status s = rig.configure();
  ASSERT_FALSE(s.is_ok());
  EXPECT_TRUE(contains(s.message(),
                       "node 3 (helix): SDO read 0x6502:00 (supported drive modes): no reply "
                       "within 100 ms (sent abort 0x05040000)"))
      << s.message();
  const auto& last = rig.net.log().back().frame;
  EXPECT_EQ(last.id, drivers::cob::sdo_rx(3));
  const auto abort = drivers::parse_sdo_request(last);
  EXPECT_EQ(abort.kind, drivers::SdoRequestKind::kAbort);
  EXPECT_EQ(abort.value, drivers::sdo_abort::kTimeout);
}

TEST(CanAxisPortConfigure, OverloadedBusIsRefusedBeforeAnyFrame) {
  CanAxisPortConfig cfg;
  cfg.cycle_period_s = 0.001;
  cfg.tpdo2 = true;
  cfg.state_timeout_s = 0.5;
  DriveRig rig(three_drives(), cfg);
  const drivers::Status s = rig.configure();
  ASSERT_FALSE(s.is_ok());
  // SYNC + 9 × 6 B + master heartbeat (1 B) at 1 ms: 55 + 9·115 + 65 = 1155 bits; + blocking 135 + EMCY 135
  // + the three drives' heartbeats (100 ms) ⌈3 · 65 / 100⌉ = 2: 1427 worst-case bits = 142.7 %.
  EXPECT_TRUE(contains(s.message(), "11 frames/cycle incl. blocking, EMCY headroom, 3 heartbeats"))
      << s.message();
  EXPECT_TRUE(contains(s.message(), "1427 worst-case")) << s.message();
  EXPECT_TRUE(contains(s.message(), "142.7 %")) << s.message();
  EXPECT_TRUE(contains(s.message(), "budget of 70 %")) << s.message();
  for (const auto& l : rig.net.log()) EXPECT_NE(l.from, 0u) << "the master sent a frame";
}

TEST(CanAxisPortConfigure, OtherNodesCountTowardTheBudget) {
  CanAxisPortConfig cfg;
  cfg.other_frames_per_cycle[0] = {{8, 8}};  // an I/O node that chatters: 8 × 135 bits more
  DriveRig rig(three_drives(), cfg);
  const drivers::Status s = rig.configure();
  ASSERT_FALSE(s.is_ok());
  // 745 + 65 + 1080 + blocking 135 + EMCY 135 + the drives' heartbeats ⌈3 · 65 · 2 / 100⌉ = 4.
  EXPECT_TRUE(contains(s.message(), "2164 worst-case")) << s.message();
}

TEST(CanAxisPortConfigure, InvalidFieldsAreNamed) {
  const auto error_of = [](const std::function<void(CanAxisPortConfig&)>& edit) {
    CanAxisPortConfig c;
    edit(c);
    return drivers::validate(c).message();
  };
  EXPECT_TRUE(
      contains(error_of([](auto& c) { c.heartbeat_consumer_s = 0.35; }), "heartbeat_consumer_s = 0.35"));
  EXPECT_TRUE(contains(error_of([](auto& c) { c.heartbeat_consumer_s = 0.05; }), "must exceed"));
  EXPECT_TRUE(contains(error_of([](auto& c) { c.axes[2].node_id = 1; }), "axes.helix.node_id = 1"));
  EXPECT_TRUE(contains(error_of([](auto& c) { c.axes[0].node_id = 0; }), "outside 1..127"));
  EXPECT_TRUE(
      contains(error_of([](auto& c) { c.axes[1].counts_per_unit = -1; }), "axes.carriage.counts_per_unit"));
  EXPECT_TRUE(contains(error_of([](auto& c) { c.cycle_period_s = 0.3; }), "cycle_period_s = 0.3"));
  EXPECT_TRUE(contains(error_of([](auto& c) { c.heartbeat_producer_s = 0.1005; }), "heartbeat_producer_s"));
  EXPECT_TRUE(contains(error_of([](auto& c) { c.tpdo2_every_n_sync = 0; }), "tpdo2_every_n_sync = 0"));
  EXPECT_TRUE(contains(error_of([](auto& c) { c.state_timeout_s = 0.004; }), "state_timeout_s"));
  EXPECT_TRUE(drivers::validate(CanAxisPortConfig{}).is_ok());
}

TEST(CanAxisPortConfigure, UnconfiguredPortSendsNothingAndReportsALinkFault) {
  DriveRig rig(three_drives());
  rig.tick(DriveRig::hold(kEnable));
  EXPECT_TRUE(rig.link.link_fault);
  for (const auto& f : std::span(rig.feedback.data(), rig.port.axis_count())) EXPECT_TRUE(f.fault);
  for (const auto& l : rig.net.log()) EXPECT_NE(l.from, 0u);
}

}  // namespace
}  // namespace loom::test

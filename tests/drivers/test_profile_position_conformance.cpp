// Profile position (CiA 402 mode 1) end to end: drivers::CanAxisPort with one cyclic (CSP) and one
// profile-position axis against the simulated drives of sim_hal/can_drive (their own dictionary, state
// machine, handshake and profile: a peer that shares none of the master's code), on the in-memory bus.
// Judged from the frames on the wire and the simulated drive: the PP axis' RPDO1 goes out only on change
// (one set-point and one release per move, none while idle), its event-driven TPDO1 never comes closer
// than the inhibit time and comes at least once per event timer, and the drive ends where it was sent.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "drive_rig.hpp"
#include "loom/drivers/cia402.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/drivers/sdo.hpp"

namespace loom::test {
namespace {

using drivers::CanAxisPortConfig;
using hal::AxisRequest;
using hal::DriveState;

constexpr std::uint8_t kPpNode = 2;
constexpr double kSpeed = 10.0;   // rad/s
constexpr double kAccel = 200.0;  // rad/s²

CanAxisPortConfig csp_and_pp() {
  CanAxisPortConfig c;
  c.axes.resize(2);
  c.axes[0] = drivers::CanAxisConfig{.name = "knotter_1", .node_id = 1};
  c.axes[1] = drivers::CanAxisConfig{.name = "selector_1", .node_id = kPpNode};
  c.axes[1].mode = drivers::DriveMode::kProfilePosition;
  c.axes[1].profile_velocity = kSpeed;
  c.axes[1].profile_acceleration = kAccel;
  c.axes[1].profile_jerk = 5000.0;
  return c;
}

std::vector<sim_can::SimDriveConfig> two_drives(bool pp_offered = true) {
  std::vector<sim_can::SimDriveConfig> v(2);
  v[0].node_id = 1;
  v[1].node_id = kPpNode;
  v[1].initial_position = 5000;
  v[1].supports_pp = pp_offered;
  return v;
}

// The SDO downloads the master made to `node`'s (index, sub), in order.
std::vector<std::uint32_t> written(const DriveRig& rig, std::uint8_t node, std::uint16_t index,
                                   std::uint8_t sub) {
  std::vector<std::uint32_t> out;
  for (const auto& l : rig.net.log()) {
    if (l.from != 0 || l.frame.id != drivers::cob::sdo_rx(node)) continue;
    const auto r = drivers::parse_sdo_request(l.frame);
    if (r.kind == drivers::SdoRequestKind::kDownloadExpedited && r.index == index && r.sub == sub)
      out.push_back(r.value);
  }
  return out;
}

std::vector<std::int64_t> tpdo1_times(const DriveRig& rig, std::uint8_t node, std::size_t from) {
  std::vector<std::int64_t> t;
  for (std::size_t i = from; i < rig.net.log().size(); ++i) {
    const auto& l = rig.net.log()[i];
    if (l.from != 0 && l.frame.id == drivers::cob::tpdo(1, node)) t.push_back(l.time_us);
  }
  return t;
}

void hold_all(const hal::AxisFeedbacks& fb, hal::AxisCommands& cmd) {
  for (std::size_t i = 0; i < 2; ++i) {
    cmd[i].request = AxisRequest::kEnable;
    cmd[i].target_position = fb[i].position;
    cmd[i].move_end = std::numeric_limits<double>::quiet_NaN();
  }
}

TEST(ProfilePosition, BringUpSelectsModeOneWithEventDrivenPdosAndTheProfileInCounts) {
  DriveRig rig(two_drives(), csp_and_pp());
  const drivers::Status s = rig.configure();
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_EQ(rig.rack.node(0).mode(), 8);
  EXPECT_EQ(rig.rack.node(1).mode(), 1);
  const double cpr = drivers::kDefaultCountsPerRad;
  EXPECT_EQ(written(rig, kPpNode, 0x6081, 0),
            std::vector<std::uint32_t>{static_cast<std::uint32_t>(std::llround(kSpeed * cpr))});
  EXPECT_EQ(written(rig, kPpNode, 0x6083, 0),
            std::vector<std::uint32_t>{static_cast<std::uint32_t>(std::llround(kAccel * cpr))});
  EXPECT_EQ(written(rig, kPpNode, 0x6084, 0), written(rig, kPpNode, 0x6083, 0));
  // Jerk-limited asked first; the simulated drive has only the linear ramp: 0 written, and a note.
  EXPECT_EQ(written(rig, kPpNode, 0x6086, 0), (std::vector<std::uint32_t>{3, 0}));
  bool noted = false;
  for (const auto& n : rig.port.notes())
    noted |= n.find("node 2") != std::string::npos && n.find("linear ramp") != std::string::npos;
  EXPECT_TRUE(noted);
  EXPECT_EQ(written(rig, kPpNode, 0x1400, 2), std::vector<std::uint32_t>{255});
  EXPECT_EQ(written(rig, kPpNode, 0x1800, 2), std::vector<std::uint32_t>{255});
  EXPECT_EQ(written(rig, kPpNode, 0x1800, 3),  // the port's inhibit time (30 ms) in 100 µs
            std::vector<std::uint32_t>{
                static_cast<std::uint32_t>(std::lround(rig.port.config().profile_tpdo_inhibit_s * 1e4))});
  EXPECT_EQ(written(rig, kPpNode, 0x1800, 3), std::vector<std::uint32_t>{300});
  EXPECT_EQ(written(rig, kPpNode, 0x1800, 5), std::vector<std::uint32_t>{100});  // ms
  // The CSP axis is as before: synchronous.
  EXPECT_EQ(written(rig, 1, 0x1400, 2), std::vector<std::uint32_t>{1});
  EXPECT_TRUE(written(rig, 1, 0x6081, 0).empty());
}

TEST(ProfilePosition, ADriveWithoutProfilePositionIsRefusedNamingNodeAndBit) {
  DriveRig rig(two_drives(false), csp_and_pp());
  const drivers::Status s = rig.configure();
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(s.message().find("node 2 (selector_1)"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("0x6502"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("bit 0 clear"), std::string::npos) << s.message();
}

TEST(ProfilePosition, OneSetPointAndOneReleasePerMoveNoneWhileIdleAndTheDriveArrives) {
  DriveRig rig(two_drives(), csp_and_pp());
  ASSERT_TRUE(rig.configure().is_ok());
  rig.run_until(
      hold_all, [&] { return rig.all_in(DriveState::kOperationEnabled); }, 50);
  ASSERT_TRUE(rig.all_in(DriveState::kOperationEnabled));
  for (int k = 0; k < 20; ++k) rig.tick(hold_all);  // the enable's last frames

  // Idle: the CSP axis gets an RPDO1 every tick, the PP axis none; its TPDO1 comes by the event timer.
  std::size_t mark = rig.net.log().size();
  for (int k = 0; k < 250; ++k) rig.tick(hold_all);  // 0.5 s
  EXPECT_EQ(rig.rpdos_to(1, mark).size(), 250u);
  EXPECT_EQ(rig.rpdos_to(kPpNode, mark).size(), 0u);
  const auto idle = tpdo1_times(rig, kPpNode, mark);
  ASSERT_GE(idle.size(), 4u);
  for (std::size_t k = 1; k < idle.size(); ++k)
    EXPECT_NEAR(static_cast<double>(idle[k] - idle[k - 1]), 100000.0, 200.0) << k;
  // Its data is current all along (a still axis' last TPDO holds until the event timer is overdue).
  EXPECT_EQ(rig.feedback[1].refreshed, rig.tick_index - 1);
  EXPECT_FALSE(rig.feedback[1].fault);

  // A move of 1.5 rad as the sequencer plays it: a per-tick target along a ramp, the end given.
  const double from = rig.feedback[1].position, to = from + 1.5;
  const int ramp = 200;
  mark = rig.net.log().size();
  for (int k = 1; k <= ramp + 150; ++k) {
    rig.tick([&](const hal::AxisFeedbacks& fb, hal::AxisCommands& cmd) {
      hold_all(fb, cmd);
      cmd[1].target_position = from + (to - from) * std::min(1.0, static_cast<double>(k) / ramp);
      cmd[1].move_end = to;
    });
    ASSERT_FALSE(rig.feedback[1].fault) << "tick " << k << " code " << rig.feedback[1].fault_code;
  }
  const auto rpdos = rig.rpdos_to(kPpNode, mark);
  ASSERT_EQ(rpdos.size(), 2u);
  const auto goal = static_cast<std::int32_t>(std::llround(to * drivers::kDefaultCountsPerRad));
  EXPECT_EQ(rpdos[0].controlword & 0x10, 0x10);  // bit 4: new set-point
  EXPECT_EQ(rpdos[0].target_position, goal);
  EXPECT_EQ(rpdos[1].controlword & 0x10, 0);  // released after the acknowledge
  EXPECT_EQ(rpdos[1].controlword & 0x0F, 0x0F);
  EXPECT_EQ(rpdos[1].target_position, goal);
  EXPECT_EQ(rig.rack.node(1).setpoints_latched(), 1u);
  EXPECT_EQ(rig.rack.node(1).position(), goal);
  EXPECT_NEAR(rig.feedback[1].position, to, 1e-5);
  EXPECT_NE(rig.rack.node(1).statusword() & drivers::statusword::kTargetReached, 0);
  // The TPDOs never closer than the inhibit time (10 ms), moving or not.
  const auto moving = tpdo1_times(rig, kPpNode, mark);
  ASSERT_GE(moving.size(), 5u);
  for (std::size_t k = 1; k < moving.size(); ++k) EXPECT_GE(moving[k] - moving[k - 1], 10000) << k;
}

TEST(ProfilePosition, AQuickStopAbandonsTheMoveAndANewMoveAfterReEnablingIsOneSetPoint) {
  DriveRig rig(two_drives(), csp_and_pp());
  ASSERT_TRUE(rig.configure().is_ok());
  rig.run_until(
      hold_all, [&] { return rig.all_in(DriveState::kOperationEnabled); }, 50);
  for (int k = 0; k < 20; ++k) rig.tick(hold_all);
  const double from = rig.feedback[1].position, to = from + 3.0;
  for (int k = 1; k <= 60; ++k) {  // part of the way
    rig.tick([&](const hal::AxisFeedbacks& fb, hal::AxisCommands& cmd) {
      hold_all(fb, cmd);
      cmd[1].target_position = from + (to - from) * k / 400.0;
      cmd[1].move_end = to;
    });
  }
  // Quick stop, the sequencer holding the measured position (the move's end still in the command).
  for (int k = 0; k < 50; ++k) {
    rig.tick([&](const hal::AxisFeedbacks& fb, hal::AxisCommands& cmd) {
      hold_all(fb, cmd);
      for (auto& c : cmd) c.request = AxisRequest::kQuickStop;
      cmd[1].move_end = to;
    });
  }
  const std::int32_t stopped = rig.rack.node(1).position();
  EXPECT_LT(stopped, static_cast<std::int32_t>(std::llround(to * drivers::kDefaultCountsPerRad)));
  // Enabled again and holding: the drive stays where it stopped (no stale move end is resumed).
  const std::size_t mark = rig.net.log().size();
  for (int k = 0; k < 200; ++k) {
    rig.tick([&](const hal::AxisFeedbacks& fb, hal::AxisCommands& cmd) {
      hold_all(fb, cmd);
      cmd[1].move_end = to;  // left over: the per-tick target holds, so it is not the set-point
    });
  }
  EXPECT_EQ(rig.feedback[1].state, DriveState::kOperationEnabled);
  EXPECT_EQ(rig.rack.node(1).position(), stopped);
  EXPECT_EQ(rig.rack.node(1).setpoints_latched(), 1u);
  for (const auto& r : rig.rpdos_to(kPpNode, mark)) EXPECT_EQ(r.controlword & 0x10, 0);
}

// Enabled and settled, ready for a move.
void enable(DriveRig& rig) {
  ASSERT_TRUE(rig.configure().is_ok());
  rig.run_until(
      hold_all, [&] { return rig.all_in(DriveState::kOperationEnabled); }, 50);
  ASSERT_TRUE(rig.all_in(DriveState::kOperationEnabled));
  for (int k = 0; k < 20; ++k) rig.tick(hold_all);
}

// Tick with a move of `distance` to the PP axis under way (its end given) until `done` or `max_ticks`.
int move_until(DriveRig& rig, double distance, const std::function<bool()>& done, int max_ticks) {
  const double from = rig.feedback[1].position;
  return rig.run_until(
      [&](const hal::AxisFeedbacks& fb, hal::AxisCommands& cmd) {
        hold_all(fb, cmd);
        cmd[1].target_position = from + distance;  // (a move of one tick: its end at once)
        cmd[1].move_end = from + distance;
      },
      done, max_ticks);
}

TEST(ProfilePosition, ASetPointTheDriveNeverAcknowledgesIsANamedFaultWithinTheStateTimeout) {
  DriveRig rig(two_drives(), csp_and_pp());
  enable(rig);
  // The drive's TPDO1 no longer reaches the master: no acknowledge is ever seen.
  rig.net.drop = [](const drivers::CanFrame& f) { return f.id == drivers::cob::tpdo(1, kPpNode); };
  const int n = move_until(
      rig, 1.0, [&] { return rig.feedback[1].fault; }, 400);
  ASSERT_TRUE(rig.feedback[1].fault);
  EXPECT_EQ(rig.feedback[1].fault_code, drivers::fault_code::kSetpointNotAcknowledged);
  EXPECT_EQ(rig.feedback[1].fault_kind, hal::FaultKind::kDrive);
  // state_timeout_s = 0.5 s = 250 ticks after the set-point (sent in the first tick of the move).
  EXPECT_GE(n, 250);
  EXPECT_LE(n, 255);
}

TEST(ProfilePosition, ATargetNeverReportedReachedIsANamedFaultAfterTheMovesTimeAndMargin) {
  DriveRig rig(two_drives(), csp_and_pp());
  enable(rig);
  // Every TPDO1 that says "target reached" (bit 10) is lost: the arrival is never seen.
  rig.net.drop = [](const drivers::CanFrame& f) {
    return f.id == drivers::cob::tpdo(1, kPpNode) && (f.data[1] & 0x04) != 0;
  };
  const int n = move_until(
      rig, 1.0, [&] { return rig.feedback[1].fault; }, 1000);
  ASSERT_TRUE(rig.feedback[1].fault);
  EXPECT_EQ(rig.feedback[1].fault_code, drivers::fault_code::kTargetNotReached);
  // 1 rad at 10 rad/s and 200 rad/s² (a linear ramp: the simulated drive has no jerk-limited profile):
  // d/v + v/a = 0.15 s; × 1.25 + the 0.5 s state timeout = 0.6875 s = 344 ticks after the acknowledge.
  EXPECT_GE(n, 344);
  EXPECT_LE(n, 352);
  // Every axis is stopped with it.
  rig.tick(hold_all);
  EXPECT_NE(rig.port.last_controlword(0), 0x000F);
}

TEST(ProfilePosition, AStillAxisWhoseTpdoStopsGoesStaleAfterTheEventTimerAndItsMargin) {
  DriveRig rig(two_drives(), csp_and_pp());
  enable(rig);
  EXPECT_EQ(rig.feedback[1].refreshed, rig.tick_index - 1);
  rig.net.drop = [](const drivers::CanFrame& f) { return f.id == drivers::cob::tpdo(1, kPpNode); };
  for (int k = 0; k < 150; ++k) rig.tick(hold_all);
  // Current for 1.5 event timer periods (150 ms = 75 ticks) after the last TPDO, then as old as that TPDO,
  // which came at most one event period (50 ticks) before the cut.
  const hal::Tick age = rig.tick_index - 1 - rig.feedback[1].refreshed;
  EXPECT_GE(age, 150);
  EXPECT_LE(age, 201);
  EXPECT_EQ(rig.feedback[0].refreshed, rig.tick_index - 1);  // the CSP axis is fresh every tick
}

}  // namespace
}  // namespace loom::test

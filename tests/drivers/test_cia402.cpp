// The master's CiA 402 step function, transition by transition (CiA 402-2 numbering), its timeout and
// fault-reset edge rules, and a closed loop against the independently written drive-side state machine
// with the two-SYNC confirmation delay of the real exchange.
#include <gtest/gtest.h>

#include <deque>

#include "loom/drivers/cia402.hpp"
#include "loom/sim_can/drive_fsa.hpp"

namespace loom::drivers {
namespace {

using hal::AxisRequest;
using hal::DriveState;
namespace cw = controlword;

constexpr std::uint32_t kTimeout = 10;

// One step from a tracker that already saw `state` with `request` (so no edge effects).
Cia402Step steady(DriveState state, AxisRequest request) {
  Cia402Tracker t;
  t.last_state = state;
  t.last_request = request;
  return cia402_step(state, request, t, kTimeout);
}

TEST(Cia402Statusword, DecodesEveryStateFromItsMask) {
  EXPECT_EQ(decode_statusword(0x0000), DriveState::kNotReadyToSwitchOn);
  EXPECT_EQ(decode_statusword(0x0040), DriveState::kSwitchOnDisabled);
  EXPECT_EQ(decode_statusword(0x0060), DriveState::kSwitchOnDisabled);  // bit 5 is don't-care there
  EXPECT_EQ(decode_statusword(0x0021), DriveState::kReadyToSwitchOn);
  EXPECT_EQ(decode_statusword(0x0023), DriveState::kSwitchedOn);
  EXPECT_EQ(decode_statusword(0x0027), DriveState::kOperationEnabled);
  EXPECT_EQ(decode_statusword(0x0007), DriveState::kQuickStopActive);
  EXPECT_EQ(decode_statusword(0x000F), DriveState::kFaultReactionActive);
  EXPECT_EQ(decode_statusword(0x002F), DriveState::kFaultReactionActive);
  EXPECT_EQ(decode_statusword(0x0008), DriveState::kFault);
  EXPECT_EQ(decode_statusword(0x0028), DriveState::kFault);
  // Bits outside the masks (voltage enabled 4, warning 7, remote 9, target reached 10, CSP 12/13).
  EXPECT_EQ(decode_statusword(0x3637), DriveState::kOperationEnabled);
  EXPECT_EQ(decode_statusword(0x0231), DriveState::kReadyToSwitchOn);
  EXPECT_EQ(decode_statusword(0x0297), DriveState::kQuickStopActive);
  // 0x0041 matches no state (switch-on-disabled and ready-to-switch-on bits together).
  EXPECT_EQ(decode_statusword(0x0041), DriveState::kUnknown);
}

TEST(Cia402Step, EnablePathOneConfirmedTransitionAtATime) {
  EXPECT_EQ(steady(DriveState::kSwitchOnDisabled, AxisRequest::kEnable).controlword, cw::kShutdown);   // 2
  EXPECT_EQ(steady(DriveState::kReadyToSwitchOn, AxisRequest::kEnable).controlword, cw::kSwitchOn);    // 3
  EXPECT_EQ(steady(DriveState::kSwitchedOn, AxisRequest::kEnable).controlword, cw::kEnableOperation);  // 4
  const Cia402Step hold = steady(DriveState::kOperationEnabled, AxisRequest::kEnable);
  EXPECT_EQ(hold.controlword, cw::kEnableOperation);
  EXPECT_FALSE(hold.awaiting_transition);
}

TEST(Cia402Step, NoBlindSequenceWithoutConfirmation) {
  // The drive keeps reporting Switch On Disabled: the master repeats Shutdown, never runs ahead.
  Cia402Tracker t;
  for (int i = 0; i < 5; ++i) {
    const Cia402Step s = cia402_step(DriveState::kSwitchOnDisabled, AxisRequest::kEnable, t, kTimeout);
    EXPECT_EQ(s.controlword, cw::kShutdown) << i;
    EXPECT_TRUE(s.awaiting_transition);
    t = s.next;
  }
}

TEST(Cia402Step, DisableAndQuickStopFromEveryPoweredState) {
  EXPECT_EQ(steady(DriveState::kOperationEnabled, AxisRequest::kDisable).controlword,
            cw::kDisableVoltage);                                                                      // 9
  EXPECT_EQ(steady(DriveState::kSwitchedOn, AxisRequest::kDisable).controlword, cw::kDisableVoltage);  // 10
  EXPECT_EQ(steady(DriveState::kReadyToSwitchOn, AxisRequest::kDisable).controlword,
            cw::kDisableVoltage);  // 7
  EXPECT_EQ(steady(DriveState::kOperationEnabled, AxisRequest::kQuickStop).controlword,
            cw::kQuickStop);                                                                             // 11
  EXPECT_EQ(steady(DriveState::kSwitchedOn, AxisRequest::kQuickStop).controlword, cw::kQuickStop);       // 10
  EXPECT_EQ(steady(DriveState::kReadyToSwitchOn, AxisRequest::kQuickStop).controlword, cw::kQuickStop);  // 7
  const Cia402Step qs_hold = steady(DriveState::kQuickStopActive, AxisRequest::kQuickStop);
  EXPECT_EQ(qs_hold.controlword, cw::kQuickStop);
  EXPECT_FALSE(qs_hold.awaiting_transition);
  // Leaving quick stop always goes down to Switch On Disabled first (12), even when enabling.
  EXPECT_EQ(steady(DriveState::kQuickStopActive, AxisRequest::kEnable).controlword, cw::kDisableVoltage);
  EXPECT_EQ(steady(DriveState::kQuickStopActive, AxisRequest::kDisable).controlword, cw::kDisableVoltage);
  EXPECT_FALSE(steady(DriveState::kSwitchOnDisabled, AxisRequest::kDisable).awaiting_transition);
  EXPECT_FALSE(steady(DriveState::kSwitchOnDisabled, AxisRequest::kQuickStop).awaiting_transition);
}

TEST(Cia402Step, FaultIsNeverResetUnlessAsked) {
  Cia402Tracker t;
  for (int i = 0; i < 1000; ++i) {
    const Cia402Step s = cia402_step(DriveState::kFault, AxisRequest::kEnable, t, kTimeout);
    EXPECT_EQ(s.controlword & cw::kFaultResetBit, 0);
    EXPECT_FALSE(s.next.timed_out);  // nothing was commanded, so nothing can time out
    t = s.next;
  }
  EXPECT_EQ(steady(DriveState::kFaultReactionActive, AxisRequest::kFaultReset).controlword,
            cw::kDisableVoltage);
}

TEST(Cia402Step, FaultResetRisingEdgeOncePerRequest) {
  Cia402Tracker t;
  t = cia402_step(DriveState::kFault, AxisRequest::kDisable, t, kTimeout).next;
  // Rising edge of the request → bit 7 rises, and is held while the drive is still in Fault.
  Cia402Step s = cia402_step(DriveState::kFault, AxisRequest::kFaultReset, t, kTimeout);
  EXPECT_EQ(s.controlword, cw::kFaultReset);
  s = cia402_step(DriveState::kFault, AxisRequest::kFaultReset, s.next, kTimeout);
  EXPECT_EQ(s.controlword, cw::kFaultReset);
  // Transition 15 confirmed: bit 7 falls.
  s = cia402_step(DriveState::kSwitchOnDisabled, AxisRequest::kFaultReset, s.next, kTimeout);
  EXPECT_EQ(s.controlword, cw::kDisableVoltage);
  EXPECT_FALSE(s.awaiting_transition);
  // The drive faults again while the request is still FaultReset: no second, automatic reset.
  s = cia402_step(DriveState::kFault, AxisRequest::kFaultReset, s.next, kTimeout);
  EXPECT_EQ(s.controlword, cw::kDisableVoltage);
  // The sequencer asks again (request edge) → a new rising edge.
  s = cia402_step(DriveState::kFault, AxisRequest::kDisable, s.next, kTimeout);
  EXPECT_EQ(s.controlword & cw::kFaultResetBit, 0);
  s = cia402_step(DriveState::kFault, AxisRequest::kFaultReset, s.next, kTimeout);
  EXPECT_EQ(s.controlword, cw::kFaultReset);
}

TEST(Cia402Step, UnconfirmedTransitionTimesOutAfterExactlyTimeoutTicks) {
  Cia402Tracker t;
  for (std::uint32_t i = 1; i <= kTimeout; ++i) {
    const Cia402Step s = cia402_step(DriveState::kReadyToSwitchOn, AxisRequest::kEnable, t, kTimeout);
    EXPECT_FALSE(s.next.timed_out) << i;
    EXPECT_EQ(s.controlword, cw::kSwitchOn);
    t = s.next;
  }
  Cia402Step s = cia402_step(DriveState::kReadyToSwitchOn, AxisRequest::kEnable, t, kTimeout);
  EXPECT_TRUE(s.next.timed_out);
  EXPECT_EQ(s.controlword, cw::kDisableVoltage);
  // Latched: even if the drive now reports Switched On, no enable command follows.
  s = cia402_step(DriveState::kSwitchedOn, AxisRequest::kEnable, s.next, kTimeout);
  EXPECT_TRUE(s.next.timed_out);
  EXPECT_EQ(s.controlword, cw::kDisableVoltage);
  // Quick stop is still honoured while latched.
  s = cia402_step(DriveState::kSwitchedOn, AxisRequest::kQuickStop, s.next, kTimeout);
  EXPECT_EQ(s.controlword, cw::kQuickStop);
  // A fault-reset request clears the latch; enabling works again.
  s = cia402_step(DriveState::kSwitchOnDisabled, AxisRequest::kFaultReset, s.next, kTimeout);
  EXPECT_FALSE(s.next.timed_out);
  s = cia402_step(DriveState::kSwitchOnDisabled, AxisRequest::kEnable, s.next, kTimeout);
  EXPECT_EQ(s.controlword, cw::kShutdown);
}

TEST(Cia402Step, ProgressResetsTheTimeout) {
  // Each state lasts kTimeout ticks (just inside the limit): the climb never times out.
  Cia402Tracker t;
  for (DriveState st :
       {DriveState::kSwitchOnDisabled, DriveState::kReadyToSwitchOn, DriveState::kSwitchedOn}) {
    for (std::uint32_t i = 0; i < kTimeout; ++i) t = cia402_step(st, AxisRequest::kEnable, t, kTimeout).next;
    EXPECT_FALSE(t.timed_out);
  }
}

TEST(Cia402Step, NoStatuswordYetIsSupervisedToo) {
  Cia402Tracker t;
  for (std::uint32_t i = 0; i <= kTimeout; ++i) {
    const Cia402Step s = cia402_step(DriveState::kUnknown, AxisRequest::kEnable, t, kTimeout);
    EXPECT_EQ(s.controlword, cw::kDisableVoltage);
    t = s.next;
  }
  EXPECT_TRUE(t.timed_out);
}

// Closed loop: master step → (controlword reaches the drive one SYNC later) → drive FSA → (statusword
// back one SYNC later). From every start state, every request reaches its goal without a timeout.
struct Loop {
  DriveState drive;
  std::uint16_t drive_cw = 0;
  std::deque<std::uint16_t> cw_pipe{0};
  std::deque<DriveState> sw_pipe;
  Cia402Tracker tracker;

  explicit Loop(DriveState start) : drive(start), sw_pipe{start} {}
  Cia402Step tick(AxisRequest request) {
    const Cia402Step s = cia402_step(sw_pipe.front(), request, tracker, 50);
    tracker = s.next;
    cw_pipe.push_back(s.controlword);
    const std::uint16_t cw_now = cw_pipe.front();
    cw_pipe.pop_front();
    drive = sim_can::drive_settle(sim_can::drive_apply_controlword(drive, cw_now, drive_cw));
    drive_cw = cw_now;
    sw_pipe.push_back(drive);
    sw_pipe.pop_front();
    return s;
  }
};

TEST(Cia402ClosedLoop, EveryRequestReachesItsGoalFromEveryState) {
  const DriveState starts[] = {DriveState::kSwitchOnDisabled, DriveState::kReadyToSwitchOn,
                               DriveState::kSwitchedOn,       DriveState::kOperationEnabled,
                               DriveState::kQuickStopActive,  DriveState::kNotReadyToSwitchOn};
  const AxisRequest requests[] = {AxisRequest::kEnable, AxisRequest::kDisable, AxisRequest::kQuickStop,
                                  AxisRequest::kFaultReset};
  for (DriveState start : starts) {
    for (AxisRequest req : requests) {
      Loop loop(start);
      int ticks = 0;
      while (!cia402_goal_reached(loop.sw_pipe.front(), req) && ticks < 40) {
        loop.tick(req);
        ++ticks;
      }
      EXPECT_TRUE(cia402_goal_reached(loop.sw_pipe.front(), req))
          << hal::drive_state_name(start) << " → request " << static_cast<int>(req);
      EXPECT_FALSE(loop.tracker.timed_out);
      // Worst case: quick stop active → disabled → ready → switched on → enabled, 2 ticks each.
      EXPECT_LE(ticks, 10);
    }
  }
}

TEST(Cia402ClosedLoop, FaultResetThenEnable) {
  Loop loop(DriveState::kFault);
  for (int i = 0; i < 5; ++i) loop.tick(AxisRequest::kEnable);
  EXPECT_EQ(loop.drive, DriveState::kFault);  // not reset without a request
  int ticks = 0;
  while (loop.sw_pipe.front() != DriveState::kSwitchOnDisabled && ticks++ < 10)
    loop.tick(AxisRequest::kFaultReset);
  EXPECT_EQ(loop.sw_pipe.front(), DriveState::kSwitchOnDisabled);
  ticks = 0;
  while (loop.sw_pipe.front() != DriveState::kOperationEnabled && ticks++ < 20)
    loop.tick(AxisRequest::kEnable);
  EXPECT_EQ(loop.sw_pipe.front(), DriveState::kOperationEnabled);
}

TEST(InterpolationPeriod, EncodesValueTimesPowerOfTen) {
  const auto two_ms = encode_interpolation_period(0.002);
  ASSERT_TRUE(two_ms);
  EXPECT_EQ(two_ms->value, 2);
  EXPECT_EQ(two_ms->index, -3);
  const auto four_ms = encode_interpolation_period(0.004);
  EXPECT_EQ(four_ms->value, 4);
  const auto one_and_half = encode_interpolation_period(0.0015);
  ASSERT_TRUE(one_and_half);
  EXPECT_EQ(one_and_half->value, 15);
  EXPECT_EQ(one_and_half->index, -4);
  const auto quarter = encode_interpolation_period(250e-6);
  ASSERT_TRUE(quarter);
  EXPECT_EQ(quarter->value, 25);
  EXPECT_EQ(quarter->index, -5);
  EXPECT_FALSE(encode_interpolation_period(0.3));  // 300 ms does not fit value ≤ 255 at index ≤ −3
  EXPECT_FALSE(encode_interpolation_period(0.0));
}

}  // namespace
}  // namespace loom::drivers

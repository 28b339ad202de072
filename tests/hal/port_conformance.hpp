// The conformance suite every HAL port must pass: what hal/README.md ("Writing a HAL port") and the loop
// (ControlLoop::cycle: read → decide → write) promise of any hal::AxisPort / hal::IoPort, written against
// those interfaces alone. A port's test supplies a rig (PortRig: build the port and its plant, let a period
// pass, strike a fault at the plant, read the plant's ground truth) and instantiates the suite with it:
//
//   INSTANTIATE_TYPED_TEST_SUITE_P(PortConformance, PortConformance, ::testing::Types<MyPortRig>);
//
// (ctest then names each case PortConformance.<case><MyPortRig's full name>.)
//
// Each check asserts only what every port promises. Where a check cannot apply to a port (its plant cannot
// fail that way, or the promise is optional in the README), the rig says why and the case is skipped with
// that reason (GTEST_SKIP), never passed silently. The executable must link tests/support's allocation
// counter (it replaces the global operator new), which the no-allocation check reads.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "alloc_counter.hpp"
#include "loom/hal/fault_events.hpp"
#include "loom/hal/hal.hpp"

namespace loom::test {

// What a rig can make its plant do, at the start of a given tick.
enum class PlantEvent : std::uint8_t {
  kNone,
  kDriveFault,  // the drive of the planned axis goes to Fault and reports the planned code
  kEmcy,        // the drive of the planned axis sends an EMCY with the planned code and stays enabled
  kAxisSilent,  // the drive of the planned axis stops answering (power lost, cable pulled)
  kIoSilent,    // the I/O device stops answering
  kIoEmcy,      // the I/O device reports a fault (EMCY with the planned code)
  // The I/O device's heartbeat stops reaching the port while the device still hears the port: the port
  // can no longer supervise it, and the device still applies what the port writes.
  kIoUnsupervised,
};

// The checks a port may legitimately not be able to take; PortRig::skip_reason says why.
enum class Check : std::uint8_t {
  kDriveFault,
  kEmcy,
  kAxisSilent,
  kIoSilent,
  kIoEmcy,
  kIoFaultSafeOutputs,       // the port writes the safe outputs to an I/O device it cannot supervise
  kHoldsTargetUntilEnabled,  // a target written before the drive is enabled is not followed
};

struct PortPlan {
  // Where the plant's three core axes stand at power-up (SI: rad, m, rad): off zero, so a reading in
  // counts, or a port that commands zero on enable, shows.
  std::array<double, hal::kCoreAxisCount> start{0.5, 0.125, -1.5};
  PlantEvent event = PlantEvent::kNone;
  hal::Tick at = 0;             // the event is in effect from this tick's read on
  std::size_t axis = 1;         // the axis a drive event strikes
  std::uint16_t code = 0x2310;  // CiA 301 EMCY code: continuous over-current
};

// What a port's test implements. Ground truth (plant_*) is read from the plant, never through the port.
class PortRig {
 public:
  virtual ~PortRig() = default;
  // Configure time: build the plant as `plan` says and the port over it, configured and ready to tick.
  virtual void make(const PortPlan& plan) = 0;
  // The port's axis and I/O sides as the machine assembles them into its HAL (for CAN, with the network
  // polled before they read and its cycle started before they write).
  virtual hal::Hal& hal() = 0;
  virtual std::size_t axis_count() const = 0;
  // After tick `now`'s write: one period of plant time passes (frames travel, drives and valves move), and
  // the planned event strikes when its tick comes. Not part of the measured RT path.
  virtual void between_ticks(hal::Tick now) = 0;
  // The plant's true position of core axis `slot` (SI), and how far each heald frame's piston stands
  // (0 retracted … 1 extended).
  virtual double plant_position(std::size_t slot) const = 0;
  virtual std::array<double, 2> plant_pistons() const = 0;
  // Ticks within which a port reports an axis that stopped answering as lost (its heartbeat time).
  virtual int node_lost_within_ticks() const = 0;
  // nullptr when this port and its plant can take `check`; otherwise why not (the skip's message).
  virtual const char* skip_reason(Check check) const = 0;
};

template <class Rig>
class PortConformance : public ::testing::Test {
 protected:
  static constexpr int kEnableTicks = 50;       // a CiA 402 drive walks its state machine in a few SYNCs
  static constexpr int kFaultTicks = 5;         // a fault reaches the feedback within a few frames
  static constexpr int kStrokeTicks = 250;      // a heald frame's stroke (0.25 s) at 2 ms, with margin
  static constexpr double kPositionTol = 1e-5;  // a few counts of a 2^20-count encoder, in rad or m

  void make(const PortPlan& plan = PortPlan{}) {
    plan_ = plan;
    rig_.make(plan);
  }
  bool skipped(Check c) const { return rig_.skip_reason(c) != nullptr; }

  // One tick as ControlLoop::cycle runs it: read, decide, write; the port's calls counted for allocations.
  template <class Decide>
  void tick(Decide&& decide) {
    hal::Hal& hal = rig_.hal();
    count_allocations(true);
    hal.read(now_, in_);
    count_allocations(false);
    tally_fault_events();
    decide();
    count_allocations(true);
    hal.write(now_, out_);
    count_allocations(false);
    rig_.between_ticks(now_);
    ++now_;
  }
  // Every axis asked for `r` with its target held where the port reads it (what the sequencer does).
  void hold(hal::AxisRequest r) {
    tick([&] {
      for (std::size_t i = 0; i < rig_.axis_count(); ++i) out_.axes[i] = {r, in_.axes[i].position};
    });
  }
  bool all_enabled() const {
    for (std::size_t i = 0; i < rig_.axis_count(); ++i) {
      if (in_.axes[i].state != hal::DriveState::kOperationEnabled) return false;
    }
    return true;
  }
  // Enable every axis, holding; then `settle` more ticks. Fails the test when a drive does not enable.
  void enable(int settle = 10) {
    for (int i = 0; i < kEnableTicks && !all_enabled(); ++i) hold(hal::AxisRequest::kEnable);
    ASSERT_TRUE(all_enabled()) << "the drives did not reach Operation Enabled in " << kEnableTicks
                               << " ticks";
    for (int i = 0; i < settle; ++i) hold(hal::AxisRequest::kEnable);
  }
  // A tick for a planned event: `ahead` ticks after the latest tick enable() can return at (every drive
  // enabled and settled), so the event always strikes an enabled machine.
  static constexpr hal::Tick after_enabling(int ahead) { return kEnableTicks + 10 + ahead; }

  // The read's fault events (hal/fault_events.hpp), counted per axis and for the link; an event always
  // comes with the fault it reports.
  void tally_fault_events() {
    for (std::size_t i = 0; i < rig_.axis_count(); ++i) {
      if (!in_.axes[i].fault_raised) continue;
      ++axis_events_[i];
      EXPECT_TRUE(hal::axis_faulted(in_.axes[i]))
          << "axis " << i << ": an event without a fault, tick " << now_;
    }
    if (in_.link.fault_raised) {
      ++link_events_;
      EXPECT_TRUE(in_.link.link_fault) << "a link event without a link fault, tick " << now_;
    }
  }

  Rig rig_;
  PortPlan plan_;
  std::array<int, hal::kMaxAxes> axis_events_{};
  int link_events_ = 0;
  hal::HalInputs in_{};
  hal::HalOutputs out_{};
  hal::Tick now_ = 0;
};

TYPED_TEST_SUITE_P(PortConformance);

// 1. Fresh feedback, stamped with this tick, in SI: the plant's true position, not counts.
TYPED_TEST_P(PortConformance, ReadStampsEveryValueWithThisTickInSiUnits) {
  this->make();
  this->enable();
  for (int k = 0; k < 20; ++k) {
    this->hold(hal::AxisRequest::kEnable);
    const hal::Tick read_at = this->now_ - 1;
    for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i) {
      const hal::AxisFeedback& a = this->in_.axes[i];
      EXPECT_EQ(a.refreshed, read_at) << "axis " << i;
      EXPECT_TRUE(std::isfinite(a.position) && std::isfinite(a.velocity)) << "axis " << i;
      EXPECT_NEAR(a.position, this->rig_.plant_position(i), this->kPositionTol) << "axis " << i;
      EXPECT_NEAR(a.position, this->plan_.start[i], this->kPositionTol) << "axis " << i;
      EXPECT_EQ(a.fault_kind, hal::FaultKind::kNone) << "axis " << i;
    }
    EXPECT_EQ(this->in_.io.refreshed, read_at);
    EXPECT_TRUE(this->in_.io.estop_ok);
    EXPECT_FALSE(this->in_.link.link_fault);
  }
}

// 1. A target written is followed: every core axis reaches a step away from where it stood, and the
// feedback says so.
TYPED_TEST_P(PortConformance, AWrittenTargetIsFollowedByThePlant) {
  this->make();
  this->enable();
  const std::array<double, hal::kCoreAxisCount> step{0.02, -0.01, 0.05};  // rad, m, rad
  std::array<double, hal::kCoreAxisCount> goal{};
  for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i) goal[i] = this->plan_.start[i] + step[i];
  for (int k = 0; k < 10; ++k) {
    this->tick([&] {
      for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i)
        this->out_.axes[i] = {hal::AxisRequest::kEnable, goal[i]};
    });
  }
  for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i) {
    EXPECT_NEAR(this->rig_.plant_position(i), goal[i], this->kPositionTol) << "axis " << i;
    EXPECT_NEAR(this->in_.axes[i].position, goal[i], this->kPositionTol) << "axis " << i;
    EXPECT_EQ(this->in_.axes[i].state, hal::DriveState::kOperationEnabled) << "axis " << i;
  }
}

// 1. No jump on enable: a loop that enables while holding the read position leaves the plant where it
// stood, through every tick of the enabling.
TYPED_TEST_P(PortConformance, EnablingWhileHoldingTheReadPositionNeverMovesThePlant) {
  this->make();
  for (int k = 0; k < this->kEnableTicks + 10; ++k) {
    this->hold(hal::AxisRequest::kEnable);
    for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i) {
      ASSERT_NEAR(this->rig_.plant_position(i), this->plan_.start[i], this->kPositionTol)
          << "axis " << i << " moved at tick " << this->now_ - 1;
    }
  }
  EXPECT_TRUE(this->all_enabled());
}

// 1. No jump on enable, the stronger promise: a naive loop that writes target 0 until it sees the drive
// enabled does not move the plant (the port holds the target at the actual position until then).
TYPED_TEST_P(PortConformance, ATargetWrittenBeforeTheDriveIsEnabledIsNotFollowed) {
  if (const char* why = this->rig_.skip_reason(Check::kHoldsTargetUntilEnabled)) GTEST_SKIP() << why;
  this->make();
  std::array<bool, hal::kCoreAxisCount> seen{};
  std::array<double, hal::kCoreAxisCount> hold_at{};
  for (int k = 0; k < this->kEnableTicks + 10; ++k) {
    this->tick([&] {
      for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i) {
        if (!seen[i] && this->in_.axes[i].state == hal::DriveState::kOperationEnabled) {
          seen[i] = true;
          hold_at[i] = this->in_.axes[i].position;
        }
        this->out_.axes[i] = {hal::AxisRequest::kEnable, seen[i] ? hold_at[i] : 0.0};
      }
    });
    for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i) {
      ASSERT_NEAR(this->rig_.plant_position(i), this->plan_.start[i], this->kPositionTol) << "axis " << i;
    }
  }
  EXPECT_TRUE(this->all_enabled());
}

// 2. A drive that stops answering: its feedback keeps the tick of its last frame (so the sequencer's
// staleness check can fire) and its old values (nothing invented); the others stay fresh; within the
// heartbeat time it is reported lost (heartbeat_lost in the sequencer).
TYPED_TEST_P(PortConformance, ASilentAxisGoesStaleKeepsItsLastValuesAndIsReportedLost) {
  if (const char* why = this->rig_.skip_reason(Check::kAxisSilent)) GTEST_SKIP() << why;
  PortPlan plan;
  plan.event = PlantEvent::kAxisSilent;
  plan.at = this->after_enabling(10);
  plan.axis = 1;
  this->make(plan);
  this->enable();
  while (this->now_ < plan.at + 2) this->hold(hal::AxisRequest::kEnable);
  const hal::AxisFeedback last = this->in_.axes[plan.axis];
  EXPECT_LE(last.refreshed, plan.at) << "one frame may have been on the wire when it fell silent";
  bool lost = false;
  for (int k = 0; k < this->rig_.node_lost_within_ticks() && !lost; ++k) {
    this->hold(hal::AxisRequest::kEnable);
    const hal::AxisFeedback& a = this->in_.axes[plan.axis];
    ASSERT_EQ(a.refreshed, last.refreshed) << "a silent drive's feedback was stamped fresh";
    EXPECT_EQ(a.position, last.position) << "a silent drive's position changed";
    for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i) {
      if (i != plan.axis) {
        EXPECT_EQ(this->in_.axes[i].refreshed, this->now_ - 1) << "axis " << i;
      }
    }
    lost = (a.fault && a.fault_kind == hal::FaultKind::kNodeLost) ||
           (this->in_.link.link_fault && this->in_.link.link_fault_kind == hal::FaultKind::kNodeLost);
  }
  EXPECT_TRUE(lost) << "not reported lost within " << this->rig_.node_lost_within_ticks() << " ticks";
  EXPECT_TRUE(this->in_.axes[plan.axis].fault);
}

// 2. The I/O device stops answering: the inputs keep the tick of their last frame; within the heartbeat
// time the port reports the device lost.
TYPED_TEST_P(PortConformance, ASilentIoDeviceGoesStaleAndIsReportedLost) {
  if (const char* why = this->rig_.skip_reason(Check::kIoSilent)) GTEST_SKIP() << why;
  PortPlan plan;
  plan.event = PlantEvent::kIoSilent;
  plan.at = this->after_enabling(10);
  this->make(plan);
  this->enable();
  while (this->now_ < plan.at + 3) this->hold(hal::AxisRequest::kEnable);
  const hal::Tick last = this->in_.io.refreshed;
  // A plant may take a period to fall silent: the frame answering the tick before may still arrive.
  EXPECT_LE(last, plan.at + 1);
  bool lost = false;
  for (int k = 0; k < this->rig_.node_lost_within_ticks() && !lost; ++k) {
    this->hold(hal::AxisRequest::kEnable);
    ASSERT_EQ(this->in_.io.refreshed, last) << "a silent I/O device's inputs were stamped fresh";
    lost = this->in_.link.link_fault && this->in_.link.link_fault_kind == hal::FaultKind::kNodeLost;
  }
  EXPECT_TRUE(lost) << "not reported lost within " << this->rig_.node_lost_within_ticks() << " ticks";
}

// 3. A drive fault arrives as FaultKind::kDrive on that axis with the device's code (drive_fault); the
// link and the other axes stay clean.
TYPED_TEST_P(PortConformance, ADriveFaultArrivesAsADriveFaultWithItsCode) {
  if (const char* why = this->rig_.skip_reason(Check::kDriveFault)) GTEST_SKIP() << why;
  PortPlan plan;
  plan.event = PlantEvent::kDriveFault;
  plan.at = this->after_enabling(5);
  plan.axis = 2;
  plan.code = 0x2310;
  this->make(plan);
  this->enable();
  EXPECT_EQ(this->axis_events_[plan.axis], 0) << "a fault event before the fault";
  while (this->now_ < plan.at + this->kFaultTicks) this->hold(hal::AxisRequest::kEnable);
  const hal::AxisFeedback& a = this->in_.axes[plan.axis];
  EXPECT_TRUE(a.fault);
  EXPECT_EQ(a.state, hal::DriveState::kFault);
  // One event when the report begins, and one more at most when the device's code follows its state.
  const int events = this->axis_events_[plan.axis];
  EXPECT_GE(events, 1);
  EXPECT_LE(events, 2);
  EXPECT_EQ(a.fault_kind, hal::FaultKind::kDrive);
  EXPECT_EQ(a.fault_code, plan.code);
  EXPECT_FALSE(this->in_.link.link_fault) << "a drive fault is not a link fault";
  for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i) {
    if (i != plan.axis) {
      EXPECT_EQ(this->in_.axes[i].fault_kind, hal::FaultKind::kNone) << "axis " << i;
    }
  }
  // Asking for enable never clears it; the standing report raises no further event.
  for (int k = 0; k < 20; ++k) this->hold(hal::AxisRequest::kEnable);
  EXPECT_EQ(this->in_.axes[plan.axis].state, hal::DriveState::kFault);
  EXPECT_EQ(this->axis_events_[plan.axis], events);
  EXPECT_EQ(this->link_events_, 0);
  for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i) {
    if (i != plan.axis) {
      EXPECT_EQ(this->axis_events_[i], 0) << "axis " << i;
    }
  }
}

// 3. An EMCY from a drive that stays enabled arrives as FaultKind::kEmcy with its code, without `fault`
// (the drive is not in Fault): the sequencer latches drive_emcy, whichever port.
TYPED_TEST_P(PortConformance, AnEmcyFromAnEnabledDriveArrivesAsEmcyWithItsCode) {
  if (const char* why = this->rig_.skip_reason(Check::kEmcy)) GTEST_SKIP() << why;
  PortPlan plan;
  plan.event = PlantEvent::kEmcy;
  plan.at = this->after_enabling(5);
  plan.axis = 1;
  plan.code = 0x8611;  // following error
  this->make(plan);
  this->enable();
  while (this->now_ < plan.at + this->kFaultTicks) this->hold(hal::AxisRequest::kEnable);
  const hal::AxisFeedback& a = this->in_.axes[plan.axis];
  EXPECT_EQ(a.fault_kind, hal::FaultKind::kEmcy);
  EXPECT_EQ(a.fault_code, plan.code);
  EXPECT_NE(a.state, hal::DriveState::kFault) << "an EMCY alone does not put the drive in Fault";
  EXPECT_FALSE(a.fault) << "an EMCY from an enabled drive is its kind and code, not `fault` (drive_emcy)";
  EXPECT_FALSE(this->in_.link.link_fault) << "a drive's EMCY is not a link fault";
}

// 3. A fault the I/O device reports (EMCY) arrives on the link, as FaultKind::kEmcy with its code
// (link_fault in the sequencer): the device's faults stop every axis, not one.
TYPED_TEST_P(PortConformance, AnIoDeviceFaultArrivesOnTheLinkWithItsCode) {
  if (const char* why = this->rig_.skip_reason(Check::kIoEmcy)) GTEST_SKIP() << why;
  PortPlan plan;
  plan.event = PlantEvent::kIoEmcy;
  plan.at = this->after_enabling(5);
  plan.code = 0x5000;  // device hardware
  this->make(plan);
  this->enable();
  while (this->now_ < plan.at + this->kFaultTicks) this->hold(hal::AxisRequest::kEnable);
  EXPECT_TRUE(this->in_.link.link_fault);
  EXPECT_EQ(this->in_.link.link_fault_kind, hal::FaultKind::kEmcy);
  EXPECT_EQ(this->in_.link.link_fault_code, plan.code);
  // One event for the link's report, however long it stands.
  for (int k = 0; k < 20; ++k) this->hold(hal::AxisRequest::kEnable);
  EXPECT_EQ(this->link_events_, 1);
}

// 4. The stop path's outputs (DigitalOutputs{}: both valve coils off) reach the plant: extended frames
// retract.
TYPED_TEST_P(PortConformance, TheSafeOutputsRetractBothFrames) {
  this->make();
  this->enable();
  this->out_.io.piston_a_extend = this->out_.io.piston_b_extend = true;
  for (int k = 0; k < this->kStrokeTicks; ++k) this->hold(hal::AxisRequest::kEnable);
  ASSERT_EQ(this->rig_.plant_pistons(), (std::array<double, 2>{1.0, 1.0})) << "the valves did not extend";
  EXPECT_TRUE(this->in_.io.piston_a_extended && this->in_.io.piston_b_extended);
  this->out_.io = hal::DigitalOutputs{};
  for (int k = 0; k < this->kStrokeTicks; ++k) this->hold(hal::AxisRequest::kQuickStop);
  EXPECT_EQ(this->rig_.plant_pistons(), (std::array<double, 2>{0.0, 0.0}));
  EXPECT_TRUE(this->in_.io.piston_a_retracted && this->in_.io.piston_b_retracted);
}

// 4. A port that can no longer supervise its I/O device writes the safe outputs whatever the loop still
// asks (hal/README: io_safe_outputs()): the extended frame retracts, and the device is reported lost.
TYPED_TEST_P(PortConformance, AnUnsupervisedIoDeviceGetsTheSafeOutputsWhateverTheLoopAsks) {
  if (const char* why = this->rig_.skip_reason(Check::kIoFaultSafeOutputs)) GTEST_SKIP() << why;
  PortPlan plan;
  plan.event = PlantEvent::kIoUnsupervised;
  plan.at = this->after_enabling(this->kStrokeTicks);
  this->make(plan);
  this->enable();
  this->out_.io.piston_a_extend = true;
  while (this->now_ < plan.at) this->hold(hal::AxisRequest::kEnable);
  ASSERT_EQ(this->rig_.plant_pistons()[0], 1.0) << "valve A did not extend";
  for (int k = 0; k < this->rig_.node_lost_within_ticks() + this->kStrokeTicks; ++k) {
    this->hold(hal::AxisRequest::kEnable);
  }
  EXPECT_TRUE(this->in_.link.link_fault);
  EXPECT_EQ(this->in_.link.link_fault_kind, hal::FaultKind::kNodeLost);
  EXPECT_EQ(this->rig_.plant_pistons()[0], 0.0) << "the port kept energising valve A";
  EXPECT_EQ(this->in_.io.refreshed, this->now_ - 1) << "the device still answers: its inputs are fresh";
}

// 5. Read and write allocate nothing, over an eventful run: enabling, motion, valves, a drive fault and
// its reset (or, for a plant that cannot fault a drive, without it).
TYPED_TEST_P(PortConformance, ReadAndWriteAllocateNothing) {
  PortPlan plan;
  if (!this->skipped(Check::kDriveFault)) {
    plan.event = PlantEvent::kDriveFault;
    plan.at = this->after_enabling(100);
    plan.axis = 0;
  }
  this->make(plan);
  reset_allocations();
  for (int k = 0; k < 600; ++k) {
    this->tick([&] {
      for (std::size_t i = 0; i < this->rig_.axis_count(); ++i) {
        const hal::AxisFeedback& a = this->in_.axes[i];
        const bool enabled = a.state == hal::DriveState::kOperationEnabled;
        this->out_.axes[i] = {a.fault ? hal::AxisRequest::kFaultReset : hal::AxisRequest::kEnable,
                              a.position + (enabled ? 1e-4 : 0.0)};
      }
      this->out_.io.piston_a_extend = (k / 100) % 2 == 1;
      this->out_.io.lamp_green = !this->out_.io.piston_a_extend;
    });
  }
  EXPECT_EQ(allocations(), 0u);
}

REGISTER_TYPED_TEST_SUITE_P(
    PortConformance, ReadStampsEveryValueWithThisTickInSiUnits, AWrittenTargetIsFollowedByThePlant,
    EnablingWhileHoldingTheReadPositionNeverMovesThePlant, ATargetWrittenBeforeTheDriveIsEnabledIsNotFollowed,
    ASilentAxisGoesStaleKeepsItsLastValuesAndIsReportedLost, ASilentIoDeviceGoesStaleAndIsReportedLost,
    ADriveFaultArrivesAsADriveFaultWithItsCode, AnEmcyFromAnEnabledDriveArrivesAsEmcyWithItsCode,
    AnIoDeviceFaultArrivesOnTheLinkWithItsCode, TheSafeOutputsRetractBothFrames,
    AnUnsupervisedIoDeviceGetsTheSafeOutputsWhateverTheLoopAsks, ReadAndWriteAllocateNothing);

}  // namespace loom::test

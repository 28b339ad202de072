// Each interlock trips on exactly the motion it forbids and allows holding still.
#include "loom/sequencer/interlocks.hpp"

#include <gtest/gtest.h>

#include "loom/motion/angles.hpp"
#include "loom/motion/beatup.hpp"

using namespace loom;
using namespace loom::sequencer;

namespace {
struct Fixture {
  motion::BeatUp beatup{motion::default_beatup_geometry()};
  InterlockContext ctx{&beatup.warp(), 0.0, {}};
  hal::HalInputs in{};
  hal::HalOutputs prev{}, next{};
  Fixture() {
    in.io.piston_a_extended = true;
    in.io.piston_b_retracted = true;
    in.io.shuttle_at_left = true;
    in.io.estop_ok = true;
  }
};
}  // namespace

TEST(Interlocks, CarriageMayNotMoveWhileTheBeaterIsInTheWarp) {
  Fixture f;
  f.in.axes[hal::index(hal::CoreAxis::kBeatCrank)].position = f.beatup.warp().fell;  // beater at the fell
  f.next.axes[hal::index(hal::CoreAxis::kCarriage)].target_position = 0.001;
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kCarriageInWarp);
  f.in.axes[hal::index(hal::CoreAxis::kBeatCrank)].position = 0.0;  // park: clear
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kNone);
  // Several turns later at the fell again: still in the warp (phase is taken modulo a turn).
  f.in.axes[hal::index(hal::CoreAxis::kBeatCrank)].position = f.beatup.warp().fell + 40 * motion::kTwoPi;
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kCarriageInWarp);
}

TEST(Interlocks, NoPickUnlessTheShedIsConfirmedOpen) {
  Fixture f;
  f.next.axes[hal::index(hal::CoreAxis::kHelix)].target_position = 0.1;
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kNone);
  f.in.io.piston_b_retracted = false;  // frame B between end sensors
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kPickWithoutShed);
  f.in.io.piston_b_extended = true;  // both up: not a shed
  f.in.io.piston_b_retracted = false;
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kPickWithoutShed);
}

TEST(Interlocks, NoShedChangeWhileTheShuttleIsInTheShed) {
  Fixture f;
  f.next.io.piston_a_extend = true;
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kNone);
  f.in.io.shuttle_at_left = false;
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kShedWithShuttle);
  // Holding everything still is always allowed.
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.prev), Fault::kNone);
}

// ---------------------------------------------------------------------------------------------------
// The knotting heads' interlocks (KnotGuard): one head, knotting servo on slot 3, selector on slot 4,
// its gripper in the warp between 1.0 and 2.0 rad from TAKE (a cycle that swings back).
// ---------------------------------------------------------------------------------------------------
namespace {
struct KnotFixture : Fixture {
  static constexpr std::size_t kKnotter = 3, kSelector = 4;
  KnotFixture() {
    ctx.knot.heads = 1;
    ctx.knot.knotter[0] = kKnotter;
    ctx.knot.selector[0] = kSelector;
    ctx.knot.in_warp_from_rad = 1.0;
    ctx.knot.in_warp_to_rad = 2.0;
  }
  void gripper_at(double rad) { in.axes[kKnotter].position = rad; }
};
}  // namespace

TEST(KnotInterlocks, NothingCrossesAGripperInTheWarp) {
  KnotFixture f;
  f.gripper_at(1.5);  // inside
  f.next.axes[hal::index(hal::CoreAxis::kCarriage)].target_position = 0.001;
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kGripperInWarp);
  f.next = f.prev;
  f.next.axes[hal::index(hal::CoreAxis::kBeatCrank)].target_position = 0.01;
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kGripperInWarp);
  f.next = f.prev;
  f.next.io.piston_a_extend =
      true;  // a shed change (the shuttle is at a selvedge: only the gripper forbids it)
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kGripperInWarp);
  // Out of the warp (at TAKE, or past the far end), all three may move.
  for (const double clear : {0.0, 0.99, 2.01}) {
    f.gripper_at(clear);
    EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kNone) << clear;
  }
  // The TAKE pose is commissioned: the guard measures from it.
  f.ctx.knot.take_position_rad = 10.0;
  f.gripper_at(11.5);
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kGripperInWarp);
}

TEST(KnotInterlocks, AFullTurnCycleWrapsTheAngle) {
  KnotFixture f;
  f.ctx.knot.full_turn = true;
  f.gripper_at(1.5 + 7 * motion::kTwoPi);  // seven knots later, inside again
  f.next.axes[hal::index(hal::CoreAxis::kCarriage)].target_position = 0.001;
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kGripperInWarp);
  f.gripper_at(7 * motion::kTwoPi);
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kNone);
}

TEST(KnotInterlocks, NoKnotUnlessTheBeaterIsClearAndTheShedStill) {
  KnotFixture f;
  f.next.axes[KnotFixture::kKnotter].target_position = 0.01;
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kNone);
  f.in.axes[hal::index(hal::CoreAxis::kBeatCrank)].position = f.beatup.warp().fell;
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kKnotNotClear);
  f.in.axes[hal::index(hal::CoreAxis::kBeatCrank)].position = 0.0;
  f.in.io.piston_b_retracted = false;  // frame B between its ends: the warp moves
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kKnotNotClear);
  f.in.io.piston_a_extended = false;  // both frames down, each at an end: still
  f.in.io.piston_a_retracted = true;
  f.in.io.piston_b_retracted = true;
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kNone);
  EXPECT_TRUE(shed_still(f.in.io));
  f.in.io.piston_a_extended = true;  // A reads both ends: a stuck switch, not a still shed
  EXPECT_FALSE(shed_still(f.in.io));
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kKnotNotClear);
}

TEST(KnotInterlocks, NoSelectorTurnsUnderAClosedGripper) {
  KnotFixture f;
  f.next.axes[KnotFixture::kSelector].target_position = 0.5;
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kNone);
  f.next.io.gripper_close[0] = true;  // closing this tick
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kSelectorWithYarn);
  f.next.io.gripper_close[0] = false;
  f.prev.io.gripper_close[0] = true;  // opening this tick: it still held yarn
  EXPECT_EQ(check_interlocks(f.ctx, f.in, f.prev, f.next), Fault::kSelectorWithYarn);
}

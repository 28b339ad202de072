// Each interlock trips on exactly the motion it forbids and allows holding still.
#include <gtest/gtest.h>

#include "loom/motion/angles.hpp"
#include "loom/motion/beatup.hpp"
#include "loom/sequencer/interlocks.hpp"

using namespace loom;
using namespace loom::sequencer;

namespace {
struct Fixture {
  motion::BeatUp beatup{motion::default_beatup_geometry()};
  InterlockContext ctx{&beatup.warp(), 0.0};
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

// ProfileSlot: a new recipe reaches the loop only at a row boundary, the old set comes back to the
// non-RT side to be deleted there, and under a publisher thread racing a loop thread every set the
// loop reads is whole (run under ASan/TSan to see use-after-free or races).
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <thread>

#include "loom/motion/errors.hpp"
#include "loom/motion/profile_slot.hpp"

using namespace loom::motion;

namespace {
std::unique_ptr<const ProfileSet> set_with_width(double width_m) {
  ProfileSpec s;
  s.width_m = width_m;
  return std::make_unique<const ProfileSet>(s);
}
}  // namespace

TEST(ProfileSlot, SwapsOnlyAtTheBoundaryAndHandsTheOldSetBack) {
  ProfileSlot slot(set_with_width(1.2));
  EXPECT_FALSE(slot.swap_at_row_boundary());  // nothing published
  EXPECT_FALSE(slot.collect());
  slot.publish(set_with_width(1.5));
  EXPECT_TRUE(slot.pending());
  EXPECT_EQ(slot.active().spec().width_m, 1.2);  // still the old recipe until the row ends
  EXPECT_TRUE(slot.swap_at_row_boundary());
  EXPECT_EQ(slot.active().spec().width_m, 1.5);
  EXPECT_FALSE(slot.pending());
  // The retired 1.2 m set has not been collected: a newer recipe waits rather than lose it.
  slot.publish(set_with_width(1.8));
  EXPECT_FALSE(slot.swap_at_row_boundary());
  EXPECT_EQ(slot.active().spec().width_m, 1.5);
  EXPECT_TRUE(slot.collect());
  EXPECT_TRUE(slot.swap_at_row_boundary());
  EXPECT_EQ(slot.active().spec().width_m, 1.8);
}

TEST(ProfileSlot, NewestPublishedRecipeWins) {
  ProfileSlot slot(set_with_width(1.0));
  slot.publish(set_with_width(1.1));
  slot.publish(set_with_width(1.3));  // replaces (and deletes) the 1.1 m set the loop never saw
  EXPECT_TRUE(slot.swap_at_row_boundary());
  EXPECT_EQ(slot.active().spec().width_m, 1.3);
}

TEST(ProfileSlot, RejectsNullSets) {
  EXPECT_THROW(ProfileSlot(nullptr), MotionError);
  ProfileSlot slot(set_with_width(1.0));
  EXPECT_THROW(slot.publish(nullptr), MotionError);
}

TEST(ProfileSlot, PublisherRacingTheLoopNeverShowsAPartialSet) {
  ProfileSlot slot(set_with_width(1.0));
  constexpr int kRecipes = 60;
  std::atomic<bool> done{false};
  std::thread publisher([&] {
    for (int i = 1; i <= kRecipes; ++i) {
      slot.publish(set_with_width(1.0 + 0.01 * i));
      while (slot.pending()) {
        slot.collect();
        std::this_thread::yield();
      }
    }
    while (slot.collect()) {
    }
    done.store(true);
  });
  double last = 1.0;
  int swaps = 0;
  while (!done.load()) {
    if (slot.swap_at_row_boundary()) ++swaps;
    const ProfileSet& p = slot.active();
    // A whole set: its width is one of the recipes, never decreasing, and its tables answer.
    const double w = p.spec().width_m;
    EXPECT_GE(w, last);
    last = w;
    EXPECT_TRUE(std::isfinite(p.rocker().at(Phase{0, 12345}).value));
    EXPECT_GE(p.beats_per_row(), 1);
  }
  publisher.join();
  while (slot.swap_at_row_boundary()) ++swaps;
  EXPECT_NEAR(slot.active().spec().width_m, 1.0 + 0.01 * kRecipes, 1e-12);
  EXPECT_GE(swaps, 1);
}

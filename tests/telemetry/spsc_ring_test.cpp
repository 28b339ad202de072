// SpscRing: FIFO order, full/empty edges, index wrap-around, drop counting, batch pops, and a
// two-thread stress run checking that every element arrives exactly once, in order, untorn.
// The same file is built a second time with ThreadSanitizer (telemetry_ring_tsan).
#include "loom/telemetry/spsc_ring.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace {

using loom::telemetry::SpscRing;

TEST(SpscRing, PopsInPushOrderAndRefusesWhenFull) {
  SpscRing<int, 8> ring;
  for (int i = 0; i < 8; ++i) ASSERT_TRUE(ring.try_push(i)) << i;
  EXPECT_FALSE(ring.try_push(99));
  EXPECT_EQ(ring.size_approx(), 8u);
  for (int i = 0; i < 8; ++i) {
    int v = -1;
    ASSERT_TRUE(ring.try_pop(v));
    EXPECT_EQ(v, i);
  }
  int v = -1;
  EXPECT_FALSE(ring.try_pop(v));
  EXPECT_EQ(v, -1) << "a failed pop must not touch the output";
  EXPECT_EQ(ring.size_approx(), 0u);
}

TEST(SpscRing, KeepsOrderAcrossManyWrapArounds) {
  // Interleave pushes and pops with a fill level that keeps changing so the indices cross the
  // capacity boundary at every offset.
  SpscRing<std::uint32_t, 4> ring;
  std::uint32_t next_in = 0, next_out = 0;
  for (int round = 0; round < 1000; ++round) {
    const int pushes = 1 + round % 4;
    for (int i = 0; i < pushes; ++i) {
      if (ring.try_push(next_in)) ++next_in;
    }
    const int pops = 1 + (round * 7) % 4;
    for (int i = 0; i < pops; ++i) {
      std::uint32_t v = 0;
      if (!ring.try_pop(v)) break;
      ASSERT_EQ(v, next_out++);
    }
    ASSERT_LE(next_in - next_out, 4u);
    ASSERT_EQ(ring.size_approx(), next_in - next_out);
  }
  EXPECT_GT(next_in, 1000u * 4 / 2);
}

TEST(SpscRing, PushOrDropCountsOnlyRefusals) {
  SpscRing<int, 4> ring;
  for (int i = 0; i < 10; ++i) ring.push_or_drop(i);
  EXPECT_EQ(ring.dropped(), 6u);
  int v = 0;
  ASSERT_TRUE(ring.try_pop(v));
  EXPECT_EQ(v, 0) << "the oldest are kept, the newest refused";
  EXPECT_TRUE(ring.push_or_drop(42));
  EXPECT_EQ(ring.dropped(), 6u);
  // try_push never counts: a retrying caller is not losing anything.
  EXPECT_FALSE(ring.try_push(43));
  EXPECT_EQ(ring.dropped(), 6u);
}

TEST(SpscRing, APushWithACopyFunctionFillsTheSlotItsWay) {
  // The copy writes only the first two of four values: the rest of the slot keeps what it held.
  using Rec = std::array<int, 4>;
  SpscRing<Rec, 2> ring;
  const auto first_two = [](Rec& slot, const Rec& v) { slot[0] = v[0], slot[1] = v[1]; };
  ASSERT_TRUE(ring.try_push(Rec{1, 2, 3, 4}, first_two));
  ASSERT_TRUE(ring.push_or_drop(Rec{5, 6, 7, 8}, first_two));
  EXPECT_FALSE(ring.push_or_drop(Rec{9, 9, 9, 9}, first_two));
  EXPECT_EQ(ring.dropped(), 1u);
  Rec out{};
  ASSERT_TRUE(ring.try_pop(out));
  EXPECT_EQ(out, (Rec{1, 2, 0, 0}));
  ASSERT_TRUE(ring.try_pop(out));
  EXPECT_EQ(out, (Rec{5, 6, 0, 0}));
}

TEST(SpscRing, PopManyTakesAtMostWhatIsThereInOrder) {
  SpscRing<int, 16> ring;
  std::array<int, 8> out{};
  EXPECT_EQ(ring.try_pop_many(out), 0u);
  for (int i = 0; i < 11; ++i) ASSERT_TRUE(ring.try_push(100 + i));
  ASSERT_EQ(ring.try_pop_many(out), 8u);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(out[static_cast<std::size_t>(i)], 100 + i);
  ASSERT_EQ(ring.try_pop_many(out), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(out[static_cast<std::size_t>(i)], 108 + i);
  // Freed slots are reusable right away: a full ring's worth fits again.
  for (int i = 0; i < 16; ++i) ASSERT_TRUE(ring.try_push(i));
  EXPECT_FALSE(ring.try_push(16));
}

TEST(SpscRing, IndicesAreOnSeparateCacheLines) {
  // False sharing between the producer's and the consumer's index is what the alignment prevents;
  // a smaller object would mean the fields were packed together.
  EXPECT_GE(sizeof(SpscRing<char, 2>), 3 * loom::telemetry::kCacheLineBytes);
  EXPECT_EQ(alignof(SpscRing<char, 2>), loom::telemetry::kCacheLineBytes);
}

// A record large enough that a torn copy (consumer reading a slot the producer is still writing)
// would show up as words that disagree with each other.
struct Record {
  std::uint64_t seq = 0;
  std::array<std::uint64_t, 7> copies{};
};

Record make_record(std::uint64_t seq) {
  Record r;
  r.seq = seq;
  for (std::size_t i = 0; i < r.copies.size(); ++i) r.copies[i] = seq * 0x9E3779B97F4A7C15ull + i;
  return r;
}

class SpscRingStress : public ::testing::TestWithParam<bool> {};

TEST_P(SpscRingStress, TwoThreadsLoseNothingDuplicateNothingKeepOrder) {
  const bool batched = GetParam();
  constexpr std::uint64_t kItems = 400'000;
  auto ring = std::make_unique<SpscRing<Record, 64>>();  // small: forces constant full/empty edges

  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kItems; ++i) {
      const Record r = make_record(i);
      while (!ring->try_push(r)) std::this_thread::yield();
    }
  });

  std::uint64_t expected = 0, bad = 0;
  std::vector<Record> batch(17);
  while (expected < kItems) {
    std::size_t n = 0;
    if (batched) {
      n = ring->try_pop_many(batch);
    } else if (ring->try_pop(batch[0])) {
      n = 1;
    }
    if (n == 0) {
      std::this_thread::yield();
      continue;
    }
    for (std::size_t k = 0; k < n; ++k) {
      const Record want = make_record(expected);
      if (batch[k].seq != want.seq || batch[k].copies != want.copies) ++bad;
      ++expected;
    }
  }
  producer.join();
  EXPECT_EQ(bad, 0u) << "out-of-order, duplicated, lost or torn records";
  Record extra;
  EXPECT_FALSE(ring->try_pop(extra)) << "more records came out than went in";
  EXPECT_EQ(ring->dropped(), 0u);
}

std::string pop_style_name(const ::testing::TestParamInfo<bool>& p) {
  return p.param ? "Batched" : "OneByOne";
}
INSTANTIATE_TEST_SUITE_P(PopStyles, SpscRingStress, ::testing::Values(false, true), pop_style_name);

}  // namespace

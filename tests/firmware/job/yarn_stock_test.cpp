// The magazines' levels on disk (round trip, refusals with file:line, field and value) and the forecast of
// the slot that empties, checked against a peer that walks every knot of every row one by one (no design
// periods, no per-row sums) on random designs and levels (seed printed; LOOM_TEST_SEED replays).
#include "loom/job/yarn_stock.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include "loom/job/job_queue.hpp"

using loom::job::JobError;
using loom::job::SlotEmpty;
using loom::job::YarnStock;
using loom::sequencer::KnotProgram;
using loom::sequencer::KnottingSpec;

namespace {

template <typename F>
std::string error_of(F f) {
  try {
    f();
  } catch (const JobError& e) {
    return e.what();
  }
  return "(no error)";
}

// A loom 0.2 m wide at 30 knots/dm: 60 knots per row; two heads 0.1 m apart tie stripes of 30.
KnottingSpec small_spec(int knots_per_slot) {
  KnottingSpec s;
  s.mode = loom::sequencer::KnottingMode::kHeads;
  s.heads = 2;
  s.head_spacing_m = 0.1;
  s.slot_colours = {"R", "I", "B"};
  s.knots_per_slot = knots_per_slot;
  return s;
}
constexpr double kWidth = 0.2;

// The peer: knot by knot, in the order the heads tie them (cycle j: every head's knot j), the first
// knot that finds its slot empty.
std::vector<SlotEmpty> walk(const YarnStock& stock, const KnotProgram& p, std::uint32_t next,
                            std::uint64_t rows) {
  std::vector<std::vector<std::int64_t>> left(static_cast<std::size_t>(p.heads()));
  for (int h = 0; h < p.heads(); ++h) {
    for (int s = 0; s < p.slots(); ++s) left[static_cast<std::size_t>(h)].push_back(stock.knots(h, s));
  }
  std::vector<SlotEmpty> out;
  std::vector<std::vector<bool>> seen(static_cast<std::size_t>(p.heads()),
                                      std::vector<bool>(static_cast<std::size_t>(p.slots())));
  for (std::uint64_t r = 0; r < rows; ++r) {
    const auto row = static_cast<std::uint32_t>(next + r);
    std::vector<SlotEmpty> this_row;
    for (int j = 0; j < p.stripe(); ++j) {
      for (int h = 0; h < p.heads(); ++h) {
        const int k = p.knot_of(h, j);
        if (k < 0) continue;
        const int s = p.slot(row, k);
        auto& l = left[static_cast<std::size_t>(h)][static_cast<std::size_t>(s)];
        if (seen[static_cast<std::size_t>(h)][static_cast<std::size_t>(s)]) continue;
        if (l == 0) {
          seen[static_cast<std::size_t>(h)][static_cast<std::size_t>(s)] = true;
          this_row.push_back({h, s, p.slot_colour(s), stock.knots(h, s), r, row, j});
        } else {
          --l;
        }
      }
    }
    std::sort(this_row.begin(), this_row.end(), [](const SlotEmpty& a, const SlotEmpty& b) {
      return a.head != b.head ? a.head < b.head : a.slot < b.slot;
    });
    out.insert(out.end(), this_row.begin(), this_row.end());
  }
  return out;
}

}  // namespace

TEST(YarnStock, RoundTripsAndReloads) {
  YarnStock s(2, 3, 2000);
  s.set(0, 1, 1873);
  s.set(1, 2, 0);
  EXPECT_EQ(YarnStock::format(s),
            "# loomctl's magazines: knots of yarn left per head (head.1 = head 1) and slot (0, 1, ...)\n"
            "format = loomctl-magazines 1\nknots_per_slot = 2000\nhead.1 = 2000 1873 2000\n"
            "head.2 = 2000 2000 0\n");
  char tmpl[] = "/tmp/loom_yarn_test.XXXXXX";
  const std::string dir = mkdtemp(tmpl);
  const std::string path = YarnStock::path_in(dir);
  EXPECT_FALSE(YarnStock::load(path).has_value());  // the first start
  s.save(path);
  YarnStock back = *YarnStock::load(path);
  EXPECT_EQ(back.knots(0, 1), 1873);
  EXPECT_EQ(back.knots(1, 2), 0);
  back.reload(1, 2);
  EXPECT_EQ(back.knots(1, 2), 2000);
  back.reload(1, 2, 500);
  EXPECT_EQ(back.knots(1, 2), 500);
  EXPECT_NE(
      error_of([&] { back.reload(1, 2, 2001); }).find("head 2 slot 2: 2001 knots: a slot holds 0..2000"),
      std::string::npos);
  EXPECT_NE(error_of([&] { back.reload(2, 0); }).find("heads 1..2"), std::string::npos);
  EXPECT_EQ(back.mismatch(2, 3, 2000), "");
  EXPECT_NE(back.mismatch(6, 3, 2000), "");
  std::filesystem::remove_all(dir);
}

TEST(YarnStock, ABadFileIsRefusedWithLineFieldAndValue) {
  const std::string good = YarnStock::format(YarnStock(2, 3, 2000));
  struct Case {
    std::string from, to, want;
  };
  const std::vector<Case> cases = {
      {"head.2 = 2000 2000 2000", "head.2 = 2000 2001 2000",
       "m.txt:5: field \"head.2\" = \"2001\": slot 1 holds more"},
      {"head.2 = 2000 2000 2000", "head.2 = 2000 -1 2000",
       "m.txt:5: field \"head.2\" = \"2000 -1 2000\": slot 1 = \"-1\""},
      {"head.2 = 2000 2000 2000", "head.2 = 2000 2000",
       "m.txt:5: field \"head.2\" = \"2000 2000\": 2 slots; head.1 has 3"},
      {"head.2 =", "head.3 =", "m.txt:5: field \"head.3\": want head.1, head.2"},
      {"knots_per_slot = 2000", "knots_per_slot = 2e3", "m.txt:3: field \"knots_per_slot\" = \"2e3\""},
      {"format = loomctl-magazines 1", "format = x", "m.txt:2: field \"format\" = \"x\""},
      {"head.1 = 2000 2000 2000", "head.1 = 2000 2000 2000\nhead.1 = 1 1 1",
       "m.txt:5: field \"head.1\" given twice"},
  };
  for (const Case& c : cases) {
    std::string bad = good;
    bad.replace(bad.find(c.from), c.from.size(), c.to);
    const std::string e = error_of([&] { YarnStock::parse(bad, "m.txt"); });
    EXPECT_NE(e.find(c.want), std::string::npos) << "want: " << c.want << "\ngot:  " << e;
  }
}

TEST(YarnForecast, AStripeOfOneColourEmptiesAtTheRowTheArithmeticSays) {
  // Head 0's stripe all R (30 knots a row), head 1's all I. 100 knots of R: rows 0, 1, 2 take 90, row 3
  // finds 10 and runs out at its cycle 10.
  const int w = 60, h = 4;
  std::vector<std::uint16_t> knots(static_cast<std::size_t>(w * h));
  for (int r = 0; r < h; ++r) {
    for (int k = 0; k < w; ++k) knots[static_cast<std::size_t>(r * w + k)] = k < 30 ? 0 : 1;
  }
  const std::vector<std::string> codes = {"R", "I"};
  const KnotProgram p = KnotProgram::build(small_spec(100), kWidth, w, h, knots, codes, 0, 0);
  const YarnStock stock(2, 3, 100);
  const auto f = loom::job::forecast_empty_slots(stock, p, 0, 10);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].head, 0);
  EXPECT_EQ(f[0].slot, 0);
  EXPECT_EQ(f[0].colour, "R");
  EXPECT_EQ(f[0].rows_from_now, 3u);
  EXPECT_EQ(f[0].cycle, 10);
  EXPECT_EQ(f[1].head, 1);
  EXPECT_EQ(f[1].colour, "I");
  // Only 3 rows to go: nothing empties.
  EXPECT_TRUE(loom::job::forecast_empty_slots(stock, p, 0, 3).empty());
  // A stock for another loom is refused.
  EXPECT_NE(error_of([&] { loom::job::forecast_empty_slots(YarnStock(6, 3, 100), p, 0, 1); }).find("6 heads"),
            std::string::npos);
}

TEST(YarnForecast, AgreesWithAKnotByKnotWalk) {
  const char* env = std::getenv("LOOM_TEST_SEED");
  const unsigned seed =
      env != nullptr ? static_cast<unsigned>(std::strtoul(env, nullptr, 10)) : std::random_device{}();
  std::printf("seed %u (LOOM_TEST_SEED replays)\n", seed);
  std::mt19937 rng(seed);
  std::size_t empties = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int w = 60, h = 1 + static_cast<int>(rng() % 12);
    const int cap = 1 + static_cast<int>(rng() % 400);
    std::vector<std::uint16_t> knots(static_cast<std::size_t>(w * h));
    const int colours = 1 + static_cast<int>(rng() % 3);
    for (auto& k : knots) k = static_cast<std::uint16_t>(rng() % static_cast<unsigned>(colours));
    const std::vector<std::string> codes = {"R", "I", "B"};
    const auto start_row = static_cast<std::uint32_t>(rng() % 50);
    const KnotProgram p =
        KnotProgram::build(small_spec(cap), kWidth, w, h, knots,
                           std::span(codes).first(static_cast<std::size_t>(colours)), rng() % 7, start_row);
    YarnStock stock(2, 3, cap);
    for (int hh = 0; hh < 2; ++hh) {
      for (int s = 0; s < 3; ++s)
        stock.set(hh, s, static_cast<std::int32_t>(rng() % static_cast<unsigned>(cap + 1)));
    }
    const std::uint32_t next = start_row + static_cast<std::uint32_t>(rng() % 20);
    const std::uint64_t rows = rng() % 200;
    const auto got = loom::job::forecast_empty_slots(stock, p, next, rows);
    const auto want = walk(stock, p, next, rows);
    ASSERT_EQ(got.size(), want.size()) << "trial " << trial;
    empties += got.size();
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].head, want[i].head) << "trial " << trial << " #" << i;
      EXPECT_EQ(got[i].slot, want[i].slot) << "trial " << trial << " #" << i;
      EXPECT_EQ(got[i].rows_from_now, want[i].rows_from_now) << "trial " << trial << " #" << i;
      EXPECT_EQ(got[i].counter_row, want[i].counter_row) << "trial " << trial << " #" << i;
      EXPECT_EQ(got[i].cycle, want[i].cycle) << "trial " << trial << " #" << i;
      EXPECT_EQ(got[i].knots_left, want[i].knots_left) << "trial " << trial << " #" << i;
    }
  }
  // The draws make slots run out (levels 0..capacity, up to 200 rows of up to 30 knots a head): a
  // comparison of two empty lists would prove nothing.
  EXPECT_GT(empties, 20u);
}

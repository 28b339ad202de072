// The JOB and CARPET channels (issue 29: the panel's carpet view): the messages encoded by the generated
// LCM code and decoded again carry the queue, the progress, the ETA (rows left x mean whole-row time, a
// closed form worked here) and the yarn; the knot map is cut into bands of whole rows that each stay under
// LCM's 64 KB small message and put back together give the design knot for knot; JobEvents writes both
// on the channel names written out here (LCM's file:// provider, read back with lcm::LogFile).
#include "loom/telemetry/job_events.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <string>
#include <vector>

namespace {

using loom::design::Colour;
using loom::design::Design;
using loom::telemetry::JobReport;

template <typename Msg>
Msg round_trip(const Msg& m) {
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  Msg out;
  EXPECT_EQ(out.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  return out;
}

JobReport two_heads_report() {
  JobReport r;
  r.job_id = 2;
  r.state = "current";
  r.design_name = "rug.csv";
  r.design_hash = "0123456789ab";
  r.width = 360;
  r.design_rows = 540;
  r.rows_done = 537;
  r.rows_total = 540;
  r.stripe = 60;
  r.cycles_done = 17;
  r.row_mean_s = 40.0;
  r.slot_colours = {"R", "I", "B"};
  r.knots_per_slot = 2000;
  r.stock = {{1999, 12, 0}, {-1, 2000, 300}};
  r.queue = {{1, "old.csv", "carpet_done", 20, 20},
             {2, "rug.csv", "current", 537, 540},
             {3, "next.csv", "queued", 0, 40}};
  return r;
}

TEST(JobMessage, CarriesTheQueueProgressEtaAndYarnThroughEncodeAndDecode) {
  const loomlcm::job_t m =
      round_trip(loom::telemetry::to_job(two_heads_report(), "hall-3", 1'700'000'000'000'000));
  EXPECT_EQ(m.loom_id, "hall-3");
  EXPECT_EQ(m.utime, 1'700'000'000'000'000);
  EXPECT_EQ(m.job_id, 2);
  EXPECT_EQ(m.state, "current");
  EXPECT_EQ(m.design_name, "rug.csv");
  EXPECT_EQ(m.design_hash, "0123456789ab");
  EXPECT_EQ(m.width, 360);
  EXPECT_EQ(m.design_rows, 540);
  EXPECT_EQ(m.rows_done, 537);
  EXPECT_EQ(m.rows_total, 540);
  EXPECT_EQ(m.stripe, 60);
  EXPECT_EQ(m.cycles_done, 17);
  EXPECT_DOUBLE_EQ(m.row_mean_s, 40.0);
  EXPECT_DOUBLE_EQ(m.eta_s, 120.0);  // 3 rows left x 40 s
  ASSERT_EQ(m.heads, 2);
  ASSERT_EQ(m.slots, 3);
  EXPECT_EQ(m.slot_colour, (std::vector<std::string>{"R", "I", "B"}));
  EXPECT_EQ(m.knots_per_slot, 2000);
  EXPECT_EQ(m.stock, (std::vector<std::vector<std::int32_t>>{{1999, 12, 0}, {-1, 2000, 300}}));
  ASSERT_EQ(m.n_jobs, 3);
  EXPECT_EQ(m.queue_id, (std::vector<std::int32_t>{1, 2, 3}));
  EXPECT_EQ(m.queue_design, (std::vector<std::string>{"old.csv", "rug.csv", "next.csv"}));
  EXPECT_EQ(m.queue_state, (std::vector<std::string>{"carpet_done", "current", "queued"}));
  EXPECT_EQ(m.queue_rows_done, (std::vector<std::int64_t>{20, 537, 0}));
  EXPECT_EQ(m.queue_rows_total, (std::vector<std::int64_t>{20, 540, 40}));
}

TEST(JobMessage, NoEtaUntilARowIsTimedAndNoHeadsWithoutKnottingHeads) {
  JobReport r = two_heads_report();
  r.row_mean_s = -1.0;
  r.stock.clear();
  r.slot_colours.clear();
  const loomlcm::job_t m = round_trip(loom::telemetry::to_job(r, "l1", 1));
  EXPECT_LT(m.eta_s, 0.0);
  EXPECT_EQ(m.heads, 0);
  EXPECT_EQ(m.slots, 0);
  EXPECT_TRUE(m.stock.empty());
  JobReport none;
  const loomlcm::job_t n = round_trip(loom::telemetry::to_job(none, "l1", 1));
  EXPECT_EQ(n.job_id, 0);
  EXPECT_EQ(n.n_jobs, 0);
}

// A design whose knot (r, k) has palette index (r * 7 + k) % 3.
Design striped(int width, int height, int colours = 3) {
  std::vector<Colour> palette;
  for (int c = 0; c < colours; ++c)
    palette.push_back({"c" + std::to_string(c), (0x102030u * static_cast<unsigned>(c + 1)) & 0xFFFFFFu, ""});
  std::vector<std::uint16_t> knots;
  for (int r = 0; r < height; ++r)
    for (int k = 0; k < width; ++k) knots.push_back(static_cast<std::uint16_t>((r * 7 + k) % colours));
  return Design("/tmp/striped.csv", width, palette, knots);
}

TEST(CarpetMessage, BandsOfWholeRowsUnder64KbThatGiveBackTheDesign) {
  const Design d = striped(360, 100);
  const auto bands = loom::telemetry::to_carpet(d, 4, "abcdefabcdef", "l1", 5);
  // 16384 knots / 360 per row = 45 rows a band: 45 + 45 + 10.
  ASSERT_EQ(bands.size(), 3u);
  std::vector<int> firsts, counts;
  std::vector<std::uint8_t> all;
  for (const auto& b0 : bands) {
    const loomlcm::carpet_t b = round_trip(b0);
    EXPECT_LT(b.getEncodedSize(), 60000);  // LCM sends up to ~65,400 bytes unfragmented
    EXPECT_EQ(b.job_id, 4);
    EXPECT_EQ(b.design_hash, "abcdefabcdef");
    EXPECT_EQ(b.design_name, "striped.csv");
    EXPECT_EQ(b.width, 360);
    EXPECT_EQ(b.height, 100);
    EXPECT_EQ(b.code, (std::vector<std::string>{"c0", "c1", "c2"}));
    EXPECT_EQ(b.rgb, (std::vector<std::int32_t>{0x102030, 0x204060, 0x306090}));
    EXPECT_EQ(b.n_knots, b.n_rows * 360);
    firsts.push_back(b.first_row);
    counts.push_back(b.n_rows);
    all.insert(all.end(), b.knots.begin(), b.knots.end());
  }
  EXPECT_EQ(firsts, (std::vector<int>{0, 45, 90}));
  EXPECT_EQ(counts, (std::vector<int>{45, 45, 10}));
  ASSERT_EQ(all.size(), 36000u);
  for (int r = 0; r < 100; ++r)
    for (int k = 0; k < 360; ++k)
      ASSERT_EQ(all[static_cast<std::size_t>(r * 360 + k)], (r * 7 + k) % 3) << r << "," << k;
}

TEST(CarpetMessage, TheWidestDesignStillFitsAndTooManyColoursAreRefused) {
  // 4000 knots (design::kMaxWidth): 16384 / 4000 = 4 rows a band.
  const auto bands = loom::telemetry::to_carpet(striped(4000, 10), 1, "h", "l1", 1);
  ASSERT_EQ(bands.size(), 3u);
  EXPECT_EQ(bands[2].n_rows, 2);
  for (const auto& b : bands) EXPECT_LT(b.getEncodedSize(), 60000);
  EXPECT_THROW(loom::telemetry::to_carpet(striped(4, 2, 257), 1, "h", "l1", 1), std::invalid_argument);
}

TEST(JobEvents, PublishesJobAndEveryBandOnTheLoomsChannels) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("job_events_" + std::to_string(::getpid()) + ".lcmlog"))
          .string();
  {
    loom::telemetry::JobEvents ev("file://" + path + "?mode=w", "LOOM", "hall-3");
    ev.publish_job(two_heads_report());
    ev.set_carpet(std::make_shared<const Design>(striped(360, 100)), 2, "0123456789ab");
    ev.repeat_carpet();  // within 10 s: nothing again
    EXPECT_EQ(ev.published(), 4u);
    EXPECT_EQ(ev.failures(), 0u);
  }
  lcm::LogFile log(path, "r");
  ASSERT_TRUE(log.good());
  std::vector<std::string> channels;
  int rows = 0;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    channels.push_back(e->channel);
    if (e->channel == "LOOM.hall-3.CARPET") {
      loomlcm::carpet_t c;
      ASSERT_GE(c.decode(e->data, 0, static_cast<int>(e->datalen)), 0);
      rows += c.n_rows;
    } else {
      loomlcm::job_t j;
      ASSERT_GE(j.decode(e->data, 0, static_cast<int>(e->datalen)), 0);
      EXPECT_EQ(j.rows_done, 537);
    }
  }
  EXPECT_EQ(channels, (std::vector<std::string>{"LOOM.hall-3.JOB", "LOOM.hall-3.CARPET", "LOOM.hall-3.CARPET",
                                                "LOOM.hall-3.CARPET"}));
  EXPECT_EQ(rows, 100);
  std::filesystem::remove(path);
}

}  // namespace

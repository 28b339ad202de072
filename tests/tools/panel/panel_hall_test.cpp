// loom-panel's model of the hall: bounded per loom (rows, faults, beats), the current row's beats
// become the previous row's when the next row starts, a restarted loop starts its loom afresh, JSON
// never carries NaN; and its udpm receiver reads what a real LCM publisher sends. The job queue's POSTs
// become well-formed socket lines or are refused, and the loom's own `job list` text reads back as rows.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <map>
#include <optional>
#include <vector>

#include "fault_history.hpp"
#include "hall.hpp"
#include "job_request.hpp"
#include "loom/job/job_text.hpp"
#include "recorder.hpp"
#include "synthetic_loom.hpp"
#include "udpm_receiver.hpp"

using namespace loom::panel;

namespace {

loomlcm::beat_t beat(const std::string& id, int row, int index, double force) {
  loomlcm::beat_t m{};
  m.loom_id = id;
  m.row = row;
  m.index = static_cast<std::int16_t>(index);
  m.x_m = 0.1 * index;
  m.peak_force_n = force;
  m.force_measured = 1;
  m.in_band = force >= 80 && force <= 100;
  m.band_min_n = 80;
  m.band_max_n = 100;
  return m;
}

loomlcm::status_t status(const std::string& id, std::int64_t tick, int row) {
  loomlcm::status_t m{};
  m.loom_id = id;
  m.tick = tick;
  m.state = "beat_sweep";
  m.row = row;
  m.rows_done = row - 1;
  return m;
}

}  // namespace

TEST(PanelHall, CurrentRowBecomesPreviousWhenTheNextRowBeats) {
  Hall h;
  for (int k = 0; k < 3; ++k) h.on_beat(beat("A", 1, k, 89.0 + k));
  h.on_beat(beat("A", 2, 0, 75.0));
  const auto j = h.loom_json("A").value();
  EXPECT_EQ(j["current_row"]["row"], 2);
  ASSERT_EQ(j["current_row"]["beats"].size(), 1u);
  EXPECT_FALSE(j["current_row"]["beats"][0]["in_band"].get<bool>());
  EXPECT_EQ(j["previous_row"]["row"], 1);
  EXPECT_EQ(j["previous_row"]["beats"].size(), 3u);
  EXPECT_EQ(j["beats_seen"], 4);
  EXPECT_EQ(j["beats_in_band"], 3);
  // A row that is not the next one (a restart elsewhere) leaves no "previous" row.
  h.on_beat(beat("A", 7, 0, 90.0));
  EXPECT_EQ(h.loom_json("A").value()["previous_row"]["beats"].size(), 0u);
}

TEST(PanelHall, EverythingKeptIsBounded) {
  HallLimits lim;
  lim.looms = 2;
  lim.rows_kept = 3;
  lim.faults_kept = 2;
  lim.beats_per_row = 4;
  Hall h(lim);
  for (int r = 1; r <= 10; ++r) {
    loomlcm::row_t row{};
    row.loom_id = "A";
    row.row = r;
    h.on_row(row);
    loomlcm::fault_t f{};
    f.loom_id = "A";
    f.name = "estop";
    f.row = r;
    h.on_fault(f);
  }
  for (int k = 0; k < 10; ++k) h.on_beat(beat("A", 1, k, 90));
  h.on_status(status("B", 1, 1));
  h.on_status(status("C", 1, 1));  // a third loom: over the limit, counted, not kept
  const auto j = h.loom_json("A").value();
  ASSERT_EQ(j["rows"].size(), 3u);
  EXPECT_EQ(j["rows"][0]["row"], 8);
  ASSERT_EQ(j["faults"].size(), 2u);
  EXPECT_EQ(j["faults"][1]["row"], 10);
  EXPECT_EQ(j["faults_seen"], 10);
  EXPECT_EQ(j["current_row"]["beats"].size(), 4u);
  EXPECT_FALSE(h.loom_json("C").has_value());
  EXPECT_EQ(h.ignored_looms(), 1u);
  EXPECT_EQ(h.hall_json()["looms"].size(), 2u);
}

TEST(PanelHall, RestartedLoopStartsAfreshAndNaNIsNull) {
  Hall h;
  h.on_status(status("A", 5000, 3));
  h.on_beat(beat("A", 3, 0, 90));
  h.on_status(status("A", 10, 1));  // tick went back: a new run
  auto j = h.loom_json("A").value();
  EXPECT_EQ(j["beats_seen"], 0);
  EXPECT_EQ(j["status"]["row"], 1);
  loomlcm::axes_t a{};
  a.loom_id = "A";
  a.num_axes = 1;
  a.axes.resize(1);
  a.axes[0].name = "carriage";
  a.axes[0].following_error = std::numeric_limits<double>::quiet_NaN();
  h.on_axes(a);
  j = h.loom_json("A").value();
  EXPECT_TRUE(j["axes"]["axes"][0]["following_error"].is_null());
  EXPECT_FALSE(nlohmann::json::parse(j.dump()).is_discarded());
  const auto v = h.version();
  h.on_rt(loomlcm::rt_stats_t{});
  EXPECT_GT(h.wait_for_change(v, std::chrono::milliseconds(10)), v);
}

TEST(PanelHall, DesignShowsTheNextRowAndOnlyANewRowIsAChange) {
  Hall hall;
  // 7: beyond the palette (a corrupt message) is shown as unknown.
  auto d = loom::telemetry::test_support::design_message("L1", {{0, 1}, {1, 7}});
  hall.on_design(d);
  const auto v = hall.version();
  hall.on_design(d);  // the periodic repeat of the same row
  EXPECT_EQ(hall.version(), v);
  const auto j = *hall.loom_json("L1");
  EXPECT_EQ(j["design"]["next_row"], 2);
  EXPECT_EQ(j["design"]["palette"][0]["rgb"], "#9b1b30");
  EXPECT_EQ(j["design"]["rows"][1]["next"], true);
  EXPECT_EQ(j["design"]["rows"][0]["next"], false);
  EXPECT_TRUE(j["design"]["rows"][1]["knots"][1].is_null());
  EXPECT_EQ(hall.hall_json()["looms"][0]["design"]["next_row"], 2);
  d.rows_done = 2;
  d.next_row = 3;
  hall.on_design(d);
  EXPECT_GT(hall.version(), v);
}

// Issue 29: the carpet job's knot map comes in CARPET bands; the panel puts them together, drops a band
// that contradicts itself, starts afresh for another design, keeps nothing beyond its bound, and pushes
// only a band that brought new rows (the 10 s repeat of a whole map changes nothing).
loomlcm::carpet_t band(const std::string& hash, int first, int rows, int width, int height) {
  loomlcm::carpet_t m{};
  m.loom_id = "L1";
  m.job_id = 3;
  m.design_hash = hash;
  m.design_name = "rug.csv";
  m.width = width;
  m.height = height;
  m.n_colours = 2;
  m.code = {"R", "B"};
  m.rgb = {0xa52a2a, 0x1f3a6e};
  m.first_row = first;
  m.n_rows = rows;
  for (int r = first; r < first + rows; ++r)
    for (int k = 0; k < width; ++k) m.knots.push_back(static_cast<std::uint8_t>((r + k) % 2));
  m.n_knots = static_cast<std::int32_t>(m.knots.size());
  return m;
}

TEST(PanelHall, CarpetBandsMakeTheKnotMap) {
  Hall hall;
  hall.on_carpet(band("aaa", 2, 2, 3, 4));
  auto j = *hall.carpet_json("L1");
  EXPECT_EQ(j["rows_heard"], 2);
  EXPECT_EQ(j["knots"], "ffffffffffff000100010001");  // rows 0-1 not heard yet; (r + k) % 2 from row 2
  hall.on_carpet(band("aaa", 0, 2, 3, 4));
  j = *hall.carpet_json("L1");
  EXPECT_EQ(j["knots"], "000100010001000100010001");
  EXPECT_EQ(j["palette"][1]["rgb"], "#1f3a6e");
  EXPECT_EQ(j["width"], 3);
  EXPECT_EQ(j["height"], 4);
  const auto v = hall.version();
  hall.on_carpet(band("aaa", 0, 2, 3, 4));  // the repeat
  EXPECT_EQ(hall.version(), v);
  auto bad = band("aaa", 3, 2, 3, 4);  // beyond the design's height
  hall.on_carpet(bad);
  bad = band("aaa", 0, 1, 3, 4);
  bad.n_knots = 2;  // contradicts its rows x width
  hall.on_carpet(bad);
  EXPECT_EQ(hall.version(), v);
  EXPECT_EQ((*hall.carpet_json("L1"))["knots"], "000100010001000100010001");
  EXPECT_EQ((*hall.loom_json("L1"))["carpet"]["rows_heard"], 4);
  hall.on_carpet(band("bbb", 0, 1, 3, 4));  // another design: afresh
  EXPECT_EQ((*hall.carpet_json("L1"))["rows_heard"], 1);
  HallLimits small;
  small.carpet_knots = 11;
  Hall bounded(small);
  bounded.on_carpet(band("aaa", 0, 2, 3, 4));  // 12 knots
  EXPECT_EQ((*bounded.carpet_json("L1"))["too_big"], true);
  EXPECT_EQ((*bounded.carpet_json("L1"))["knots"], "");
}

TEST(PanelHall, JobShowsTheQueueEtaAndYarn) {
  Hall hall;
  loomlcm::job_t m{};
  m.loom_id = "L1";
  m.job_id = 1;
  m.state = "current";
  m.rows_done = 2;
  m.rows_total = 6;
  m.row_mean_s = -1;
  m.eta_s = -1;
  m.heads = 2;
  m.slots = 2;
  m.slot_colour = {"R", "B"};
  m.stock = {{40, 3}, {-1, 12}};
  m.n_jobs = 3;  // more than the arrays hold: only what is there is listed
  m.queue_id = {1, 2};
  m.queue_design = {"a.csv", "b.csv"};
  m.queue_state = {"current", "queued"};
  m.queue_rows_done = {2, 0};
  m.queue_rows_total = {6, 2};
  hall.on_job(m);
  auto j = (*hall.loom_json("L1"))["job"];
  EXPECT_TRUE(j["eta_s"].is_null());
  EXPECT_EQ(j["stock"], nlohmann::json::parse("[[40,3],[-1,12]]"));
  ASSERT_EQ(j["queue"].size(), 2u);
  EXPECT_EQ(j["queue"][1]["design"], "b.csv");
  m.eta_s = 120.0;
  m.row_mean_s = 30.0;
  hall.on_job(m);
  j = (*hall.loom_json("L1"))["job"];
  EXPECT_EQ(j["eta_s"], 120.0);
}

// Issue 22: one FAULT packet or palette name that is not UTF-8 aborted the panel (type_error 316).
TEST(PanelHall, TextThatIsNotUtf8IsReplacedNeverThrown) {
  Hall hall;
  auto d = loom::telemetry::test_support::design_message("L1", {{0, 1}});
  d.colour_name[0] = "rot\xe9 (cp1252)";
  d.name = "teppich\xfc.csv";
  hall.on_design(d);
  loomlcm::fault_t f{};
  f.loom_id = "L1";
  f.kind = "fault";
  f.name = "drive_fault";
  f.text = "spoofed \xff\xfe\xc3";
  hall.on_fault(f);
  std::string loom, all;
  ASSERT_NO_THROW(loom = loom::panel::json_text(*hall.loom_json("L1")));
  ASSERT_NO_THROW(all = loom::panel::json_text(hall.hall_json()));
  EXPECT_NE(loom.find("rot\xef\xbf\xbd (cp1252)"), std::string::npos) << loom;  // U+FFFD for the bad byte
  EXPECT_NE(loom.find("spoofed \xef\xbf\xbd"), std::string::npos);
  EXPECT_TRUE(nlohmann::json::accept(loom));  // what a browser gets parses
  EXPECT_TRUE(nlohmann::json::accept(all));
}

// Item 7: a fault the panel heard carries its wall-clock stamp (the page shows it beside loop time).
TEST(PanelHall, FaultsCarryTheirWallClockStamp) {
  Hall hall;
  loomlcm::fault_t f{};
  f.loom_id = "L1";
  f.kind = "first";
  f.name = "drive_fault";
  f.utime = 1'790'000'000'123'456;
  f.time_s = 12.5;
  hall.on_fault(f);
  const auto j = hall.loom_json("L1").value();
  ASSERT_EQ(j["faults"].size(), 1u);
  EXPECT_EQ(j["faults"][0]["utime"].get<std::int64_t>(), 1'790'000'000'123'456);
  EXPECT_EQ(j["faults"][0]["time_s"].get<double>(), 12.5);
}

TEST(PanelHall, RowsCarryTheKnottingTime) {
  Hall hall;
  loomlcm::row_t r{};
  r.loom_id = "L1";
  r.row = 1;
  r.knotting_s = 42.5;
  hall.on_row(r);
  EXPECT_EQ((*hall.loom_json("L1"))["rows"][0]["knotting_s"], 42.5);
}

// The knotting heads: the latest KNOTS as the page draws it (each head's knot and magazine, the row's
// slots, the open request), every WEAVER request kept up to the limit; counts a corrupt message claims
// beyond its arrays are never trusted.
TEST(PanelHall, KnotsShowTheRowPerHeadAndTheOpenRequest) {
  HallLimits lim;
  lim.weaver_requests_kept = 2;
  lim.knots_per_row = 4;
  Hall hall(lim);
  loomlcm::knots_t k{};
  k.loom_id = "L1";
  k.state = "knotting";
  k.knotting = 1;
  k.row = 3;
  k.heads = 2;
  k.stripe = 3;
  k.knots_per_row = 6;
  k.slots = 2;
  k.knots_per_slot = 100;
  k.cycle = 1;
  k.head_knot = {1, 4};
  k.head_slot = {0, 1};
  k.head_colour = {"R", "B"};
  k.slot_colour = {"R", "B"};
  k.knot_slot = {0, 0, 1, 1, 1, 7};  // 7: no such slot
  k.stock = {{90, -1}, {100, 5}};
  k.ask = "tie_by_hand";
  k.ask_knot = 4;
  k.ask_head = 1;
  k.ask_text = "tie knot 5";
  hall.on_knots(k);
  for (int n = 1; n <= 3; ++n) {
    loomlcm::weaver_request_t w{};
    w.loom_id = "L1";
    w.number = n;
    w.ask = "reload";
    w.text = "request " + std::to_string(n);
    hall.on_weaver(w);
  }
  const auto j = *hall.loom_json("L1");
  const auto& kj = j["knots"];
  ASSERT_EQ(kj["heads"].size(), 2u);
  EXPECT_EQ(kj["heads"][1]["knot"], 4);
  EXPECT_EQ(kj["heads"][1]["colour"], "B");
  EXPECT_EQ(kj["heads"][0]["stock"], nlohmann::json({90, -1}));
  EXPECT_EQ(kj["row_slots"], nlohmann::json({0, 0, 1, 1}));  // cut at the limit of 4
  EXPECT_TRUE(kj["cut"]);
  EXPECT_EQ(kj["request"]["text"], "tie knot 5");
  EXPECT_EQ(kj["request"]["knot"], 4);
  ASSERT_EQ(j["weaver_requests"].size(), 2u);
  EXPECT_EQ(j["weaver_requests"][0]["number"], 2);
  EXPECT_EQ(j["weaver_requests"][1]["text"], "request 3");

  k.heads = 12;  // claims more heads than it carries
  k.ask = "";
  k.knot_slot = {0, 9};
  k.knots_per_row = 2;
  hall.on_knots(k);
  const auto j2 = *hall.loom_json("L1");
  EXPECT_EQ(j2["knots"]["heads"].size(), 2u);
  EXPECT_TRUE(j2["knots"]["request"].is_null());
  EXPECT_EQ(j2["knots"]["row_slots"], nlohmann::json({0, nullptr}));  // slot 9 is not a slot
}

TEST(PanelUdpm, UrlsAndPackets) {
  const auto a = parse_udpm_url("udpm://239.255.76.67:7771?ttl=0");
  ASSERT_TRUE(a.has_value());
  EXPECT_EQ(a->group, "239.255.76.67");
  EXPECT_EQ(a->port, 7771);
  EXPECT_FALSE(parse_udpm_url("file:///tmp/x.lcmlog?mode=r").has_value());
  EXPECT_FALSE(parse_udpm_url("udpm://10.0.0.1:7667").has_value());  // not a multicast group
  EXPECT_FALSE(parse_udpm_url("udpm://239.255.76.67:0").has_value());
  EXPECT_FALSE(parse_udpm_url("udpm://239.255.76.67:70000").has_value());
  // "LC02", sequence number, channel, NUL, payload.
  const std::uint8_t pkt[] = {0x4c, 0x43, 0x30, 0x32, 0, 0, 0, 7, 'A', '.', 'B', 0, 1, 2, 3};
  const auto p = parse_lcm_packet(pkt, sizeof pkt);
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->channel, "A.B");
  EXPECT_EQ(p->size, 3u);
  EXPECT_EQ(p->data[2], 3);
  EXPECT_FALSE(parse_lcm_packet(pkt, 10).has_value());  // channel not terminated
  const std::uint8_t fragment[] = {0x4c, 0x43, 0x30, 0x33, 0, 0, 0, 7, 'A', 0, 1};
  EXPECT_FALSE(parse_lcm_packet(fragment, sizeof fragment).has_value());
}

TEST(PanelUdpm, ReceivesWhatLcmPublishes) {
  const std::string url = "udpm://239.255.76.67:7793?ttl=0";
  UdpmReceiver rx(parse_udpm_url(url).value());
  lcm::LCM tx(url);
  ASSERT_TRUE(tx.good());
  loomlcm::beat_t b = beat("L9", 4, 2, 88.5);
  ASSERT_EQ(tx.publish("LOOM.L9.BEAT", &b), 0);
  int got = 0;
  for (int i = 0; i < 20 && got == 0; ++i) {
    rx.poll(100, [&](const LcmPacket& p) {
      if (p.channel != "LOOM.L9.BEAT") return;
      loomlcm::beat_t m;
      ASSERT_GT(m.decode(p.data, 0, static_cast<int>(p.size)), 0);
      EXPECT_EQ(m.row, 4);
      EXPECT_DOUBLE_EQ(m.peak_force_n, 88.5);
      ++got;
    });
  }
  EXPECT_EQ(got, 1);
}

// Issue 22: a recording replayed onto the live group never mixes with the live loom of the same id.
// A message stamped longer ago than replay_after_s is a replay: it is kept apart under "<id>~replay"
// (which no live loom id can be) and marked; the live loom's picture is untouched by it.
TEST(PanelHall, AReplayedRecordingIsKeptApartFromTheLiveLoomAndMarked) {
  HallLimits lim;
  lim.replay_after_s = 10.0;
  const std::int64_t now_us = 1'800'000'000'000'000;
  Hall h(lim, [now_us] { return now_us; });
  loomlcm::status_t live = status("A", 5000, 7);
  live.utime = now_us - 200'000;  // 0.2 s old: live
  h.on_status(live);
  loomlcm::status_t old = status("A", 100, 2);  // an earlier run: a lower tick would reset the live loom
  old.utime = now_us - 3'600'000'000;           // recorded an hour ago
  old.state = "paused";
  h.on_status(old);
  loomlcm::beat_t b = beat("A", 2, 0, 90.0);
  b.utime = now_us - 3'599'000'000;
  h.on_beat(b);
  const auto a = h.loom_json("A").value();
  EXPECT_EQ(a["status"]["row"], 7);
  EXPECT_EQ(a["status"]["state"], "beat_sweep");
  EXPECT_EQ(a["beats_seen"], 0);
  EXPECT_FALSE(a["replay"].get<bool>());
  EXPECT_TRUE(a["recorded_s_ago"].is_null());
  EXPECT_EQ(a["loom"], "A");
  const auto r = h.loom_json("A~replay").value();
  EXPECT_TRUE(r["replay"].get<bool>());
  EXPECT_EQ(r["loom"], "A");
  EXPECT_EQ(r["status"]["row"], 2);
  EXPECT_EQ(r["status"]["state"], "paused");
  EXPECT_EQ(r["beats_seen"], 1);
  EXPECT_NEAR(r["recorded_s_ago"].get<double>(), 3599.0, 1e-9);  // the latest replayed message's age
  const auto hall = h.hall_json();
  ASSERT_EQ(hall["looms"].size(), 2u);
  EXPECT_EQ(hall["looms"][0]["id"], "A");
  EXPECT_EQ(hall["looms"][1]["id"], "A~replay");
  EXPECT_TRUE(hall["looms"][1]["replay"].get<bool>());
  // Off (0): every message is taken as live, whatever its stamp (a log read through file://).
  Hall off;
  off.on_status(old);
  EXPECT_FALSE(off.loom_json("A~replay").has_value());
  EXPECT_FALSE(off.loom_json("A").value()["replay"].get<bool>());
}

// Item 7: the persisted fault history (serve's `faults` reply) as the panel's JSON, newest lines kept.
// The lines are written out here as FaultHistory's documented format, not produced by it.
TEST(PanelFaultHistory, LinesAreSplitAndTheNewestKept) {
  const std::string reply =
      "2026-11-23T20:15:03Z fault loom1 drive_fault 0x1002 axis=carriage device=0x7310 rows=3 picks=3 "
      "beats=45: "
      "a servo drive reported a fault\n"
      "2026-11-23T20:16:10Z ack loom1 drive_fault 0x1002 device=0x0000 rows=3 picks=3 beats=45: acknowledged "
      "by local "
      "user anna (uid 1000, pid 42); re-arming from the measured positions\n"
      "2026-11-23T20:17:00Z command loom1 start 0x0000 device=0x0000 rows=0 picks=0 beats=0: by local user "
      "anna: ok start\n"
      "garbage \xff\xfe line\n";
  const auto j = fault_history_json(reply, 3);
  EXPECT_EQ(j["total"], 4);
  EXPECT_EQ(j["shown"], 3);
  ASSERT_EQ(j["lines"].size(), 3u);
  EXPECT_EQ(j["lines"][0]["time"], "2026-11-23T20:16:10Z");
  EXPECT_EQ(j["lines"][0]["kind"], "ack");
  EXPECT_EQ(j["lines"][0]["name"], "drive_fault");
  EXPECT_EQ(j["lines"][1]["kind"], "command");
  EXPECT_EQ(j["lines"][1]["name"], "start");
  EXPECT_EQ(j["lines"][1]["detail"],
            "0x0000 device=0x0000 rows=0 picks=0 beats=0: by local user anna: ok start");
  EXPECT_FALSE(j["lines"][2].contains("kind"));  // not a history line: kept whole, not trusted
  EXPECT_EQ(json_text(j["lines"][2]["line"]),
            "\"garbage \xEF\xBF\xBD\xEF\xBF\xBD line\"");  // U+FFFD, never thrown
  const auto none = fault_history_json("no faults recorded in /var/lib/loomctl/faults.log\n", 50);
  EXPECT_EQ(none["total"], 0);
  EXPECT_EQ(none["note"], "no faults recorded in /var/lib/loomctl/faults.log");
}

namespace {
loomlcm::axes_t axes_at(const std::string& id, double t, const std::vector<std::string>& names) {
  loomlcm::axes_t m{};
  m.loom_id = id;
  m.time_s = t;
  for (std::size_t i = 0; i < names.size(); ++i) {
    loomlcm::axis_t a{};
    a.name = names[i];
    // Written out so the test knows each value: position = t + i, velocity = 1, following error = 1e-4 * (i +
    // 1).
    a.position = t + static_cast<double>(i);
    a.velocity = 1.0;
    a.following_error = 1e-4 * static_cast<double>(i + 1);
    m.axes.push_back(a);
  }
  m.num_axes = static_cast<decltype(m.num_axes)>(m.axes.size());
  return m;
}
}  // namespace

// Item 7: a scope strip of any axis over the last N seconds of loop time, bounded in samples and time.
TEST(PanelScope, EachAxisKeepsTheLastWindowOfSamples) {
  HallLimits lim;
  lim.scope_window_s = 2.0;
  lim.scope_samples = 15;
  Hall h(lim);
  const std::vector<std::string> names{"beat_crank", "carriage", "helix"};
  for (int k = 0; k <= 40; ++k) h.on_axes(axes_at("A", 0.1 * k, names));  // 0.0 .. 4.0 s at 10 Hz
  const auto c = h.scope_json("A", "carriage").value();
  EXPECT_EQ(c["axes"], nlohmann::json(names));
  // The window is 2 s (21 samples at 10 Hz), the count 15: the count binds — t = 2.6 .. 4.0 s.
  ASSERT_EQ(c["t"].size(), 15u);
  EXPECT_NEAR(c["t"][0].get<double>(), 2.6, 1e-12);
  EXPECT_NEAR(c["t"][14].get<double>(), 4.0, 1e-12);
  EXPECT_NEAR(c["position"][14].get<double>(), 5.0, 1e-6);          // t + 1 (float storage)
  EXPECT_NEAR(c["following_error"][0].get<double>(), 2e-4, 1e-10);  // axis 1
  EXPECT_NEAR(c["velocity"][7].get<double>(), 1.0, 0.0);
  // A looser count: the 2 s window binds — 4.0 - 2.0 .. 4.0 s.
  HallLimits wide = lim;
  wide.scope_samples = 1000;
  Hall w(wide);
  for (int k = 0; k <= 40; ++k) w.on_axes(axes_at("A", 0.1 * k, names));
  const auto hw = w.scope_json("A", "helix").value();
  EXPECT_EQ(hw["t"].size(), 21u);
  EXPECT_NEAR(hw["t"][0].get<double>(), 2.0, 1e-12);
  // The loop restarted (time went back): the strip starts afresh.
  w.on_axes(axes_at("A", 0.5, names));
  EXPECT_EQ(w.scope_json("A", "helix").value()["t"].size(), 1u);
  // An unknown axis: empty traces; an unknown loom: nothing.
  EXPECT_EQ(w.scope_json("A", "nosuch").value()["t"].size(), 0u);
  EXPECT_FALSE(w.scope_json("B", "helix").has_value());
  // NaN from the wire is sent as null, never as invalid JSON.
  auto bad = axes_at("A", 0.6, names);
  bad.axes[2].position = std::numeric_limits<double>::quiet_NaN();
  w.on_axes(bad);
  EXPECT_TRUE(w.scope_json("A", "helix").value()["position"][1].is_null());
}

// Item 7: the row report as a download — every row kept (more than the page's table), CSV, wall-clock
// time and loop time, fixed notation. The expected lines are written out here.
TEST(PanelHall, TheRowReportIsCsvOfEveryRowKept) {
  HallLimits lim;
  lim.rows_kept = 2;
  lim.rows_report = 3;
  Hall h(lim);
  for (int r = 1; r <= 4; ++r) {
    loomlcm::row_t m{};
    m.loom_id = "A";
    m.row = r;
    m.utime = 1'790'000'000'000'000 + r * 1'000'000;  // 2026-09-21T14:13:2{1..4}Z (date -u -d @1790000001)
    m.time_s = 10.0 * r;
    m.row_s = 9.5;
    m.shed_s = 0.5;
    m.pick_s = 1.25;
    m.beat_s = 7.75;
    m.beats = 15;
    m.carriage_steps = 14;
    m.force_measured = r != 3;
    m.force_min_n = 0.00001;  // printed fixed, never 1e-05
    m.force_mean_n = 89.5;
    m.force_max_n = 91;
    m.beats_in_band = 15;
    m.band_min_n = 80;
    m.band_max_n = 100;
    h.on_row(m);
  }
  EXPECT_EQ(h.loom_json("A").value()["rows"].size(), 2u);  // the page's table
  const std::string csv = h.rows_csv("A").value();
  const std::string want =
      "utc,loop_time_s,row,row_s,shed_s,pick_s,beat_s,beats,carriage_steps,force_min_n,force_mean_n,force_"
      "max_n,"
      "beats_in_band,band_min_n,band_max_n,knotting_s,knot_s,weaver_s,knots_tied,knots_retried,knots_by_"
      "hand\n"
      "2026-09-21T14:13:22Z,20.000000,2,9.500000,0.500000,1.250000,7.750000,15,14,0.000010,89.500000,91."
      "000000,15,"
      "80.000000,100.000000,0.000000,0.000000,0.000000,0,0,0\n"
      "2026-09-21T14:13:23Z,30.000000,3,9.500000,0.500000,1.250000,7.750000,15,14,,,,15,"
      "80.000000,100.000000,0.000000,0.000000,0.000000,0,0,0\n"
      "2026-09-21T14:13:24Z,40.000000,4,9.500000,0.500000,1.250000,7.750000,15,14,0.000010,89.500000,91."
      "000000,15,"
      "80.000000,100.000000,0.000000,0.000000,0.000000,0,0,0\n";
  EXPECT_EQ(csv, want);
  EXPECT_FALSE(h.rows_csv("B").has_value());
}

// Item 7: an lcmlog of the last minutes. What the recorder writes is read back by LCM's own log reader;
// the window and the byte budget bound it.
TEST(PanelRecorder, TheLastMinutesAreAnLcmLogLcmReads) {
  Recorder rec(60.0, 1 << 20);
  const std::int64_t t0 = 1'790'000'000'000'000;
  for (int k = 0; k < 130; ++k) {  // one message a second for 130 s, payload "m<k>"
    const std::string payload = "m" + std::to_string(k);
    rec.add("A", k % 2 ? "LOOM.A.STATUS" : "LOOM.A.AXES", payload.data(), payload.size(),
            t0 + k * 1'000'000LL);
  }
  rec.add("B", "LOOM.B.STATUS", "b", 1, t0);
  const auto bytes = rec.lcmlog("A", t0 + 129 * 1'000'000LL);
  ASSERT_TRUE(bytes.has_value());
  const std::string path =
      (std::filesystem::temp_directory_path() / ("panel_rec_" + std::to_string(::getpid()))).string();
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    std::fwrite(bytes->data(), 1, bytes->size(), f);
    std::fclose(f);
  }
  lcm::LogFile log(path, "r");
  ASSERT_TRUE(log.good());
  std::vector<std::string> got;
  std::int64_t first_us = 0, last_us = 0;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    got.push_back(ev->channel + "=" +
                  std::string(static_cast<const char*>(ev->data), static_cast<std::size_t>(ev->datalen)));
    if (got.size() == 1) first_us = ev->timestamp;
    last_us = ev->timestamp;
  }
  std::remove(path.c_str());
  // The last 60 s before t = 129 s: messages 69..129 (61 of them).
  ASSERT_EQ(got.size(), 61u);
  EXPECT_EQ(got.front(), "LOOM.A.STATUS=m69");
  EXPECT_EQ(got.back(), "LOOM.A.STATUS=m129");
  EXPECT_EQ(got[1], "LOOM.A.AXES=m70");
  EXPECT_EQ(first_us, t0 + 69'000'000);
  EXPECT_EQ(last_us, t0 + 129'000'000);
  EXPECT_FALSE(rec.lcmlog("C", t0).has_value());
  // The byte budget for all looms: the loom holding the most gives up its oldest messages.
  Recorder small(600.0, 10 * (64 + 16));
  for (int k = 0; k < 20; ++k)
    small.add("A", "LOOM.A.AXES", "0123456789abcdef", 0, t0 + k);  // 11 + 0 + 64 each
  EXPECT_LE(small.bytes(), 10u * (64 + 16));
  small.add("B", "LOOM.B.AXES", "x", 1, t0 + 30);
  EXPECT_TRUE(small.lcmlog("B", t0 + 30).has_value());  // B kept: A, the largest, gave way
  EXPECT_LE(small.bytes(), 10u * (64 + 16));
  Recorder off(0.0, 1 << 20);
  off.add("A", "LOOM.A.AXES", "x", 1, t0);
  EXPECT_FALSE(off.lcmlog("A", t0).has_value());
}

namespace {
// The request parameters of a POST, as the route gives them to job_line.
ParamOf params(std::map<std::string, std::string> m) {
  return [m](const char* name) -> std::optional<std::string> {
    const auto it = m.find(name);
    return it == m.end() ? std::nullopt : std::optional<std::string>(it->second);
  };
}
}  // namespace

TEST(PanelJobRequest, WellFormedRequestsBecomeTheLoomsSocketLines) {
  std::string why;
  EXPECT_EQ(job_line(JobVerb::kAdd, params({{"design", "/srv/designs/rug.csv"}}), why),
            "job add design=/srv/designs/rug.csv");
  EXPECT_EQ(job_line(JobVerb::kAdd, params({{"design", "/d/a.png"}, {"rows", "540"}}), why),
            "job add design=/d/a.png rows=540");
  EXPECT_EQ(job_line(JobVerb::kAdd, params({{"design", "/d/a.png"}, {"metres", "1.8"}}), why),
            "job add design=/d/a.png metres=1.8");
  EXPECT_EQ(job_line(JobVerb::kAdd, params({{"design", "/d/a.png"}, {"repeat", "3"}}), why),
            "job add design=/d/a.png repeat=3");
  EXPECT_EQ(job_line(JobVerb::kRemove, params({{"id", "2"}}), why), "job remove id=2");
  EXPECT_EQ(job_line(JobVerb::kStartOver, params({{"id", "4294967295"}}), why),
            "job start-over id=4294967295");
  EXPECT_EQ(why, "");
  EXPECT_EQ(job_verb("start-over"), JobVerb::kStartOver);
  EXPECT_EQ(job_verb("start"), JobVerb::kUnknown);  // a job is started at the machine only
  EXPECT_EQ(job_verb("list"), JobVerb::kUnknown);   // read with GET
}

TEST(PanelJobRequest, MalformedRequestsAreRefusedWithTheReasonAndNoLine) {
  const std::vector<std::pair<JobVerb, std::map<std::string, std::string>>> bad = {
      {JobVerb::kAdd, {}},
      {JobVerb::kAdd, {{"design", "rug.csv"}}},                      // relative
      {JobVerb::kAdd, {{"design", "/a b.csv"}}},                     // a space ends the field
      {JobVerb::kAdd, {{"design", "/a.csv token=0123"}}},            // ... and would smuggle another
      {JobVerb::kAdd, {{"design", "/a\n.csv"}}},                     // not printable
      {JobVerb::kAdd, {{"design", "/" + std::string(256, 'a')}}},    // too long
      {JobVerb::kAdd, {{"design", "/a.csv"}, {"rows", "-1"}}},       // not digits
      {JobVerb::kAdd, {{"design", "/a.csv"}, {"rows", "1e3"}}},      // not digits
      {JobVerb::kAdd, {{"design", "/a.csv"}, {"metres", "1.2.3"}}},  // two points
      {JobVerb::kAdd, {{"design", "/a.csv"}, {"metres", "."}}},      // no digit
      {JobVerb::kAdd, {{"design", "/a.csv"}, {"rows", "2"}, {"repeat", "2"}}},  // two lengths
      {JobVerb::kAdd, {{"design", "/a.csv"}, {"id", "1"}}},
      {JobVerb::kRemove, {}},
      {JobVerb::kRemove, {{"id", "0"}}},
      {JobVerb::kRemove, {{"id", "4294967296"}}},
      {JobVerb::kRemove, {{"id", "1 "}}},
      {JobVerb::kStartOver, {{"id", "1"}, {"rows", "2"}}},
      {JobVerb::kUnknown, {{"id", "1"}}},
  };
  for (const auto& [verb, m] : bad) {
    std::string why;
    EXPECT_EQ(job_line(verb, params(m), why), "") << (m.count("design") ? m.at("design") : "");
    EXPECT_NE(why, "");
  }
}

TEST(PanelJobRequest, TheLoomsJobListReadsBackAsRows) {
  // The text is the loom's own (loom::job::list_text, what serve answers to `job list`).
  loom::job::Job a;
  a.id = 1;
  a.state = loom::job::JobState::kCarpetDone;
  a.design_name = "knot sample.csv";  // a name with a space: the columns are found by the hash
  a.sha256 = "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";
  a.design_rows = 4;
  a.length_rows = 2;
  a.progress.rows_done = 2;
  loom::job::Job b = a;
  b.id = 12;
  b.state = loom::job::JobState::kQueued;
  b.design_name = "rug.csv";
  b.sha256 = "fedcba9876543210fedcba9876543210fedcba9876543210fedcba9876543210";
  b.length_rows = 540;
  b.progress.rows_done = 0;
  const std::string text = loom::job::list_text({a, b}, "this loom's job queue");
  const auto j = job_list_json(text);
  ASSERT_EQ(j["jobs"].size(), 2u) << text;
  EXPECT_EQ(j["jobs"][0]["id"], 1);
  EXPECT_EQ(j["jobs"][0]["state"], "carpet_done");
  EXPECT_EQ(j["jobs"][0]["design"], "knot sample.csv");
  EXPECT_EQ(j["jobs"][0]["sha256"], "0123456789ab");
  EXPECT_EQ(j["jobs"][0]["progress"], "all 2 rows woven");
  EXPECT_EQ(j["jobs"][1]["id"], 12);
  EXPECT_EQ(j["jobs"][1]["state"], "queued");
  EXPECT_EQ(j["jobs"][1]["design"], "rug.csv");
  EXPECT_EQ(j["jobs"][1]["progress"], "row 1 of 540 next");
  EXPECT_EQ(j["text"], text);
  EXPECT_EQ(job_list_json(loom::job::list_text({}, "this loom's job queue"))["jobs"].size(), 0u);
}

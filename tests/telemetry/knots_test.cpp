// The knotting heads' telemetry: the snapshot's knot part reaches a ring slot (magazines of the heads in
// use only), KNOTS and WEAVER carry the knots, colours and requests the machine's KnotProgram gives and
// survive LCM's encode/decode, STATUS (and with it KNOTS) goes out on every new knot cycle and request,
// ROW carries the row's knot counts, and loom-monitor prints them in its documented format.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "lines.hpp"
#include "loom/sequencer/knot_program.hpp"
#include "loom/sequencer/row_knotter.hpp"
#include "loom/sequencer/sequencer.hpp"
#include "loom/telemetry/encode.hpp"
#include "loom/telemetry/schedule.hpp"

namespace {

using namespace loom::telemetry;
namespace seq = loom::sequencer;

// Two heads on a 1.2 m loom at 10 knots/dm: 120 knots, head 0 ties knots 0..59 and head 1 knots
// 60..119 (knot h·60 + j in cycle j). Slots R, B, W. Design row 0 is red but knot 7 (blue) and knot 67
// (white); design row 1 is all white.
seq::KnotProgram program() {
  seq::KnottingSpec s;
  s.mode = seq::KnottingMode::kHeads;
  s.knots_per_dm = 10.0;
  s.rows_per_dm = 30.0;
  s.heads = 2;
  s.head_spacing_m = 0.6;
  s.slot_colours = {"R", "B", "W"};
  s.knots_per_slot = 500;
  std::vector<std::uint16_t> knots(240, 0);
  knots[7] = 1;
  knots[67] = 2;
  for (std::size_t k = 120; k < 240; ++k) knots[k] = 2;
  const std::vector<std::string> palette{"R", "B", "W"};
  return seq::KnotProgram::build(s, 1.2, 120, 2, knots, palette, 0, 0);
}

template <typename M>
M round_trip(const M& m) {
  std::vector<unsigned char> buf(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  M out;
  EXPECT_EQ(out.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  return out;
}

Snapshot knotting_sample() {
  Snapshot s;
  s.tick = 1000;
  s.period_ns = 2'000'000;
  s.state = static_cast<std::uint8_t>(seq::State::kKnotting);
  s.row = 0;  // no row done: production row 1, design row 0
  KnotSample& k = s.knots;
  k.heads = 2;
  k.slots = 3;
  k.knotting = true;
  k.cycle = 7;
  k.cycles_started = 8;
  k.cycles_done = 7;
  k.tied = 14, k.retried = 2, k.by_hand = 1;
  k.row_tied = 13, k.row_retried = 1, k.row_by_hand = 1;
  k.requests = 3;
  k.ask = static_cast<std::uint8_t>(seq::WeaverAsk::kTieByHand);
  k.ask_knot = 67, k.ask_head = 1, k.ask_slot = 2, k.ask_row = 1;
  for (std::size_t h = 0; h < 2; ++h) {
    for (std::size_t sl = 0; sl < 3; ++sl) k.stock[h][sl] = static_cast<std::int32_t>(100 * h + 10 * sl + 1);
  }
  return s;
}

TEST(Knots, CopyInUseCopiesTheKnotPartAndOnlyTheHeadsMagazines) {
  Snapshot from = knotting_sample();
  from.knots.stock[2][0] = 77;  // a head the loom does not have: never copied
  Snapshot to{};
  copy_in_use(to, from);
  EXPECT_EQ(to.knots.heads, 2);
  EXPECT_EQ(to.knots.slots, 3);
  EXPECT_TRUE(to.knots.knotting);
  EXPECT_EQ(to.knots.cycle, 7);
  EXPECT_EQ(to.knots.tied, 14u);
  EXPECT_EQ(to.knots.ask_knot, 67);
  EXPECT_EQ(to.knots.ask_row, 1u);
  EXPECT_EQ(to.knots.stock[0][2], 21);
  EXPECT_EQ(to.knots.stock[1][0], 101);
  EXPECT_EQ(to.knots.stock[1][2], 121);
  EXPECT_EQ(to.knots.stock[2][0], 0);
}

TEST(Knots, KnotsMessageNamesEachHeadsKnotColourAndMagazine) {
  const seq::KnotProgram p = program();
  const auto m = round_trip(to_knots(knotting_sample(), p, "L7", 42));
  EXPECT_EQ(m.loom_id, "L7");
  EXPECT_EQ(m.utime, 42);
  EXPECT_EQ(m.tick, 1000);
  EXPECT_DOUBLE_EQ(m.time_s, 2.0);
  EXPECT_EQ(m.state, "knotting");
  EXPECT_TRUE(m.knotting);
  EXPECT_EQ(m.row, 1);
  EXPECT_EQ(m.design_row, 0);
  EXPECT_EQ(m.heads, 2);
  EXPECT_EQ(m.stripe, 60);
  EXPECT_EQ(m.knots_per_row, 120);
  EXPECT_EQ(m.slots, 3);
  EXPECT_EQ(m.knots_per_slot, 500);
  EXPECT_EQ(m.cycle, 7);
  EXPECT_EQ(m.cycles_started, 8);
  EXPECT_EQ(m.cycles_done, 7);
  EXPECT_EQ(m.tied, 14);
  EXPECT_EQ(m.retried, 2);
  EXPECT_EQ(m.by_hand, 1);
  EXPECT_EQ(m.row_tied, 13);
  EXPECT_EQ(m.row_retried, 1);
  EXPECT_EQ(m.row_by_hand, 1);
  // Cycle 7: head 0 ties knot 7 (blue, slot 1), head 1 knot 60 + 7 = 67 (white, slot 2).
  EXPECT_EQ(m.head_knot, (std::vector<std::int16_t>{7, 67}));
  EXPECT_EQ(m.head_slot, (std::vector<std::int16_t>{1, 2}));
  EXPECT_EQ(m.head_colour, (std::vector<std::string>{"B", "W"}));
  EXPECT_EQ(m.slot_colour, (std::vector<std::string>{"R", "B", "W"}));
  ASSERT_EQ(m.knot_slot.size(), 120u);
  EXPECT_EQ(m.knot_slot[0], 0);
  EXPECT_EQ(m.knot_slot[7], 1);
  EXPECT_EQ(m.knot_slot[67], 2);
  EXPECT_EQ(m.knot_slot[119], 0);
  EXPECT_EQ(m.stock, (std::vector<std::vector<std::int32_t>>{{1, 11, 21}, {101, 111, 121}}));
  EXPECT_EQ(m.requests, 3);
  EXPECT_EQ(m.ask, "tie_by_hand");
  EXPECT_EQ(m.ask_knot, 67);
  EXPECT_EQ(m.ask_head, 1);
  EXPECT_EQ(m.ask_slot, 2);
  EXPECT_EQ(
      m.ask_text,
      "row 1 (design row 1): tie knot 68 (head 2) by hand in colour W (the head missed it twice: look at "
      "slot 2's yarn and the gripper)");
}

TEST(Knots, OutsideKnottingNoHeadTiesAndNothingIsAsked) {
  const seq::KnotProgram p = program();
  Snapshot s = knotting_sample();
  s.knots.knotting = false;
  s.knots.cycle = -1;
  s.knots.ask = 0;
  s.row = 1;  // row 1 done: production row 2 ties design row 1, all white
  const auto m = to_knots(s, p, "L7", 0);
  EXPECT_EQ(m.row, 2);
  EXPECT_EQ(m.design_row, 1);
  EXPECT_EQ(m.head_knot, (std::vector<std::int16_t>{-1, -1}));
  EXPECT_EQ(m.head_colour, (std::vector<std::string>{"", ""}));
  EXPECT_EQ(m.knot_slot[7], 2);
  EXPECT_EQ(m.ask, "");
  EXPECT_EQ(m.ask_text, "");
}

Event weaver_event() {
  Event e;
  e.kind = Event::Kind::kWeaver;
  e.tick = 5000;
  e.period_ns = 2'000'000;
  e.row = 4;
  e.ask = static_cast<std::uint8_t>(seq::WeaverAsk::kReload);
  e.request = 2;
  e.design_row = 1;
  e.knot = -1;
  e.head = 0;
  e.slot = 1;
  return e;
}

TEST(Knots, WeaverRequestIsWordedWithTheSlotsColour) {
  const seq::KnotProgram p = program();
  const auto m = round_trip(to_weaver_request(weaver_event(), &p, "L7", 9));
  EXPECT_EQ(m.loom_id, "L7");
  EXPECT_EQ(m.tick, 5000);
  EXPECT_DOUBLE_EQ(m.time_s, 10.0);
  EXPECT_EQ(m.number, 2);
  EXPECT_EQ(m.ask, "reload");
  EXPECT_EQ(m.row, 4);
  EXPECT_EQ(m.design_row, 1);
  EXPECT_EQ(m.knot, -1);
  EXPECT_EQ(m.head, 0);
  EXPECT_EQ(m.slot, 1);
  EXPECT_EQ(m.colour, "B");
  EXPECT_EQ(m.text, "row 4 (design row 2): reload colour B into slot 1 of head 1");
  // Without the program the request still goes out, without a colour.
  const auto bare = to_weaver_request(weaver_event(), nullptr, "L7", 9);
  EXPECT_EQ(bare.colour, "");
  EXPECT_FALSE(bare.text.empty());
}

TEST(Knots, RowCarriesTheRowsKnots) {
  Event e;
  e.kind = Event::Kind::kRow;
  e.period_ns = 2'000'000;
  e.row = 2;
  e.row_ticks = 50'000;
  e.knot_ticks = 30'000;
  e.weaver_ticks = 7'500;
  e.knots_tied = 358, e.knots_retried = 23, e.knots_by_hand = 2;
  const auto m = round_trip(to_row(e, "L7", 0));
  EXPECT_DOUBLE_EQ(m.row_s, 100.0);
  EXPECT_DOUBLE_EQ(m.knot_s, 60.0);
  EXPECT_DOUBLE_EQ(m.weaver_s, 15.0);
  EXPECT_EQ(m.knots_tied, 358);
  EXPECT_EQ(m.knots_retried, 23);
  EXPECT_EQ(m.knots_by_hand, 2);
}

TEST(Knots, ANewKnotCycleOrRequestSendsStatusAtOnce) {
  Decimation d;
  d.status_every_n_ticks = 1000;
  ChannelSchedule sched(d);
  Snapshot s = knotting_sample();
  EXPECT_TRUE(sched.decide(s).status);  // the first
  s.tick += 1;
  EXPECT_FALSE(sched.decide(s).status);  // nothing changed
  s.tick += 1;
  s.knots.cycle = 8;
  EXPECT_TRUE(sched.decide(s).status);
  s.tick += 1;
  EXPECT_FALSE(sched.decide(s).status);
  s.tick += 1;
  s.knots.ask = 0;  // the weaver answered
  EXPECT_TRUE(sched.decide(s).status);
  s.tick += 1;
  s.knots.requests = 4;
  EXPECT_TRUE(sched.decide(s).status);
}

TEST(Knots, MonitorPrintsRowKnotsAndEachRequest) {
  loomlcm::row_t r{};
  r.loom_id = "L7";
  r.time_s = 188.34;
  r.row = 2;
  r.row_s = 105.35;
  r.shed_s = 0.27;
  r.pick_s = 1.29;
  r.beat_s = 5.93;
  r.beats = 15;
  r.knot_s = 67.84;
  r.weaver_s = 30.01;
  r.knots_tied = 358;
  r.knots_retried = 23;
  r.knots_by_hand = 2;
  EXPECT_EQ(loom::monitor::row_line(r),
            "row loom=L7 t=188.340s row=2 time=105.35s shed=0.27s pick=1.29s beat=5.93s beats=15 steps=0 "
            "force_min=- force_mean=- force_max=- in_band=- knotting=0.00s knots_tied=358 knots_retried=23 "
            "knots_by_hand=2 knot_time=67.84s weaver_time=30.01s");
  loom::monitor::EventView v;
  EXPECT_EQ(
      v.on_row(r).at(0),
      "L7 t=188.340s row 2 done in 105.35 s (shed 0.27, pick 1.29, beat 5.93 s), 15 beats, knots 358 tied, "
      "23 retried, 2 by hand (heads 67.8 s, weaver 30.0 s)");

  const seq::KnotProgram p = program();
  const auto w = to_weaver_request(weaver_event(), &p, "L7", 0);
  EXPECT_EQ(loom::monitor::weaver_line(w),
            "weaver loom=L7 t=10.000s n=2 ask=reload row=4 design_row=1 knot=-1 head=0 slot=1 colour=B "
            "text=\"row 4 (design row 2): reload colour B into slot 1 of head 1\"");
  EXPECT_EQ(v.on_weaver(w).at(0),
            "L7 t=10.000s WEAVER reload: row 4 (design row 2): reload colour B into slot 1 of head 1");

  const auto k = to_knots(knotting_sample(), p, "L7", 0);
  EXPECT_EQ(
      loom::monitor::knots_line(k),
      "knots loom=L7 tick=1000 t=2.000s state=knotting row=1 design_row=0 cycle=7/60 cycles_done=7 tied=14 "
      "retried=2 by_hand=1 row_tied=13 row_retried=1 row_by_hand=1 requests=3 ask=tie_by_hand"
      " | head0 knot=7 colour=B stock=1,11,21 | head1 knot=67 colour=W stock=101,111,121");
}

}  // namespace

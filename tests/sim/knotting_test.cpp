// The loom ties its own knots: the knotting heads tie the design on the narrow knotting loom
// (tests/sim/knotting_sample_loom.toml), through misses, an empty slot and the weaver's hand, and the
// carpet the simulated machine actually knotted — read back from its PNG with libpng, compared with the
// design file read here on its own — equals the design knot for knot.
#include <gtest/gtest.h>
#include <png.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/firmware/carpet_png.hpp"
#include "loom/firmware/machine.hpp"
#include "loom/firmware/runner.hpp"
#include "loom/hal/motion_outputs.hpp"

using namespace loom;

namespace {
const std::string kDir = std::string(LOOM_SOURCE_DIR) + "/tests/sim/";

firmware::LoomConfig knotting_loom() {
  return firmware::load_loom_config(kDir + "knotting_sample_loom.toml");
}

firmware::Scene scene(const std::string& knotter, const std::string& faults = "") {
  return firmware::parse_scene(
      "name = \"knots\"\nseed = 3\neffects = [\"ideal\", \"knotter\"]\n[knotter]\n" + knotter + faults,
      "knots.toml");
}

// The design file as a weaver reads it: palette codes to colours, rows top line first.
struct Picture {
  std::vector<std::vector<std::uint32_t>> rows_top_down;
};
Picture read_design_csv(const std::string& path) {
  std::ifstream in(path);
  std::map<std::string, std::uint32_t> palette;
  Picture p;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    if (cells[0] == "palette") {
      palette[cells[1]] = static_cast<std::uint32_t>(std::stoul(cells[2].substr(1), nullptr, 16));
      continue;
    }
    std::vector<std::uint32_t> row;
    for (const auto& c : cells) row.push_back(palette.at(c));
    p.rows_top_down.push_back(row);
  }
  return p;
}

struct Rgba {
  int w = 0, h = 0;
  std::vector<png_byte> px;
};
Rgba read_png(const std::string& path) {
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  Rgba r;
  if (png_image_begin_read_from_file(&img, path.c_str()) == 0) return r;
  img.format = PNG_FORMAT_RGBA;
  r.w = static_cast<int>(img.width);
  r.h = static_cast<int>(img.height);
  r.px.resize(PNG_IMAGE_SIZE(img));
  if (png_image_finish_read(&img, nullptr, r.px.data(), 0, nullptr) == 0) r.w = r.h = 0;
  return r;
}

struct Woven {
  sequencer::State state{};
  sequencer::Fault fault{};
  int fault_axis = -1;
  sequencer::Counters counters{};
  std::vector<sequencer::WeaverRequest> requests;
  std::vector<std::uint32_t> request_cycles;  // the row's knot cycles done when each request was made
  firmware::CarpetCheck check{};
  Rgba png;
};

Woven weave(const firmware::LoomConfig& cfg, const firmware::Scene& sc, std::uint32_t rows) {
  firmware::MachineOptions opt;
  opt.telemetry = false;
  opt.rows = rows;
  firmware::Machine m(cfg, sc, opt, {});
  m.sequencer().request_start();
  firmware::RunOptions ro;
  ro.period_s = cfg.sequencer.period_s;
  ro.max_ticks = 400000;
  ro.sim_weaver = m.sim_weaver();
  Woven w;
  firmware::run_loop(m.loop(), m.sequencer(), ro, [&](const firmware::RunEvent& e) {
    if (e.kind == firmware::RunEvent::Kind::kWeaverRequest) {
      w.requests.push_back(e.request);
      w.request_cycles.push_back(e.counters.knot.cycles_done);
    }
  });
  w.state = m.sequencer().state();
  w.fault = m.sequencer().first_fault();
  w.fault_axis = m.sequencer().fault_axis();
  w.counters = m.sequencer().counters();
  const std::string png = testing::TempDir() + "/carpet_" + std::to_string(::getpid()) + ".png";
  w.check = firmware::write_carpet_png(*m.sim().knotter(), *m.knot_program(), *cfg.recipe.design, 0, png);
  w.png = read_png(png);
  std::filesystem::remove(png);
  return w;
}

// Every knot of the first `rows` rows has the design's colour; returns the knots whose alpha says "by hand".
int expect_equals_design(const Woven& w, int rows) {
  const Picture d = read_design_csv(kDir + "knot_sample.csv");
  const int h = static_cast<int>(d.rows_top_down.size());
  EXPECT_EQ(w.png.w, 90);
  EXPECT_EQ(w.png.h, rows);
  int by_hand = 0;
  for (int r = 0; r < rows && w.png.w == 90 && w.png.h == rows; ++r) {
    // Carpet row r (woven r-th) is design row r from the bottom; both pictures draw it from the bottom.
    const auto& want = d.rows_top_down[static_cast<std::size_t>(h - 1 - r)];
    for (int k = 0; k < 90; ++k) {
      const png_byte* p =
          &w.png.px[(static_cast<std::size_t>(rows - 1 - r) * 90 + static_cast<std::size_t>(k)) * 4];
      const std::uint32_t rgb =
          static_cast<std::uint32_t>(p[0]) << 16 | static_cast<std::uint32_t>(p[1]) << 8 | p[2];
      EXPECT_EQ(rgb, want[static_cast<std::size_t>(k)]) << "row " << r + 1 << " knot " << k + 1;
      EXPECT_NE(p[3], 0) << "row " << r + 1 << " knot " << k + 1 << " not tied";
      by_hand += p[3] == 128;
    }
  }
  return by_hand;
}
}  // namespace

TEST(Knotting, TheHeadsTieTheDesignKnotForKnot) {
  const Woven w = weave(knotting_loom(), scene("miss_probability = 0.0\nweaver_s = 1.0\n"), 2);
  EXPECT_EQ(w.state, sequencer::State::kDone) << sequencer::fault_name(w.fault);
  EXPECT_EQ(w.counters.rows, 2u);
  EXPECT_EQ(w.counters.knot.tied, 180u);
  EXPECT_EQ(w.counters.knot.by_hand, 0u);
  EXPECT_TRUE(w.requests.empty() ||
              w.requests[0].ask == sequencer::WeaverAsk::kReload);  // 40-knot slots: reloads only
  EXPECT_TRUE(w.check.equal());
  EXPECT_EQ(expect_equals_design(w, 2), 0);
}

TEST(Knotting, MissedKnotsAndAnEmptySlotEndWithTheDesignAndTheWeaversKnotsMarked) {
  // Knots slip off one time in six; slot 2 (indigo) of head 1 runs dry early.
  const Woven w = weave(knotting_loom(),
                        scene("miss_probability = 0.17\nweaver_s = 2.0\n",
                              "[[fault]]\nkind = \"yarn_out\"\nat_s = 5.0\nhead = 1\nslot = 2\n"),
                        3);
  EXPECT_EQ(w.state, sequencer::State::kDone) << sequencer::fault_name(w.fault);
  EXPECT_GT(w.counters.knot.retried, 0u);
  EXPECT_GT(w.counters.knot.by_hand, 0u);
  EXPECT_EQ(w.counters.knot.tied + w.counters.knot.by_hand,
            270u);  // every knot once: none skipped, none twice
  int asked_by_hand = 0, reloads = 0;
  for (const auto& r : w.requests) {
    asked_by_hand += r.ask == sequencer::WeaverAsk::kTieByHand;
    reloads += r.ask == sequencer::WeaverAsk::kReload;
    EXPECT_GE(r.slot, 0);
  }
  EXPECT_EQ(static_cast<std::uint32_t>(asked_by_hand), w.counters.knot.by_hand);
  EXPECT_GT(reloads, 0);
  EXPECT_TRUE(w.check.equal()) << w.check.missing << " missing, " << w.check.wrong << " wrong, "
                               << w.check.doubled << " doubled";
  EXPECT_EQ(expect_equals_design(w, 3), static_cast<int>(w.counters.knot.by_hand));
}

// The yarn forecast: a slot that cannot give the rest of a row its knots is reloaded before the row's
// first knot cycle, the heads at rest — never when it runs dry in the middle of the row. With no misses
// (no knot takes yarn twice) the forecast is exact: every reload comes before a row, none mid-row.
TEST(Knotting, AReloadIsAskedBeforeTheRowThatNeedsItNeverInItsMiddle) {
  const firmware::LoomConfig cfg = knotting_loom();  // 40-knot slots, 30 knots per head and row
  const Woven w = weave(cfg, scene("miss_probability = 0.0\nweaver_s = 1.0\n"), 6);
  EXPECT_EQ(w.state, sequencer::State::kDone) << sequencer::fault_name(w.fault);
  ASSERT_FALSE(w.requests.empty());
  for (std::size_t i = 0; i < w.requests.size(); ++i) {
    const sequencer::WeaverRequest& r = w.requests[i];
    EXPECT_EQ(r.ask, sequencer::WeaverAsk::kReload) << "request " << i;
    EXPECT_EQ(w.request_cycles[i], 0u) << "request " << i << " came in the middle of row " << r.row;
    EXPECT_GT(r.knots_needed, r.knots_left) << "request " << i;
    EXPECT_LT(r.knots_left, cfg.knotting.knots_per_slot) << "request " << i;
  }
  EXPECT_EQ(w.counters.knot.by_hand, 0u);
  EXPECT_TRUE(w.check.equal());
}

TEST(Knotting, AJammedSelectorIsANamedFault) {
  const firmware::LoomConfig cfg = knotting_loom();
  const Woven w =
      weave(cfg, scene("weaver_s = 1.0\n", "[[fault]]\nkind = \"selector_jam\"\nat_s = 3.0\nhead = 2\n"), 2);
  EXPECT_EQ(w.state, sequencer::State::kFault);
  EXPECT_EQ(w.fault, sequencer::Fault::kSelectorJam);
  EXPECT_EQ(w.fault_axis, cfg.sequencer.heads.selector_axis[1]);
}

// Stepping the machine tick by tick (no simulated weaver: the loom's requests stay open).
struct Stepped {
  firmware::Machine m;
  hal::Tick t = 0;
  Stepped(const firmware::LoomConfig& cfg, const firmware::Scene& sc, std::uint32_t rows)
      : m(cfg, sc, options(rows), {}) {
    m.sequencer().request_start();
  }
  static firmware::MachineOptions options(std::uint32_t rows) {
    firmware::MachineOptions o;
    o.telemetry = false;
    o.rows = rows;
    return o;
  }
  // Runs until `until` holds (true) or `limit` ticks pass (false).
  template <class Pred>
  bool run(Pred until, hal::Tick limit) {
    for (const hal::Tick end = t + limit; t < end; ++t) {
      if (until()) return true;
      m.loop().cycle(t);
    }
    return until();
  }
};

// A stop (ctl stop, SIGTERM to serve) while the heads wait for the weaver ends the run there, as it does
// while the weaver knots a row in weaver mode; it does not wait for a row end that needs the weaver.
TEST(Knotting, AStopWhileTheHeadsWaitForTheWeaverEndsTheRun) {
  Stepped s(knotting_loom(), scene("miss_probability = 1.0\n"), 2);  // every knot slips: the weaver is asked
  ASSERT_TRUE(s.run([&] { return s.m.sequencer().weaver_request().ask == sequencer::WeaverAsk::kTieByHand; },
                    100000));
  EXPECT_EQ(s.m.sequencer().state(), sequencer::State::kKnotting);
  s.m.sequencer().request_stop();
  ASSERT_TRUE(s.run([&] { return s.m.sequencer().state() == sequencer::State::kDone; }, 10));
  EXPECT_EQ(s.m.sequencer().counters().rows, 0u);  // the row is not woven: the next run resumes its knots
}

// A pause asked for while the heads tie holds after the knot cycle in progress, before the next one starts
// (nothing taken, nothing written ahead): the heads stand at rest, no heald frame has moved, and resume goes
// on knotting the same row from the next knot — the row is then tied in full, every knot once.
TEST(Knotting, APauseWhileTheHeadsTieHoldsAfterTheKnotCycleInProgress) {
  Stepped s(knotting_loom(), scene(""), 2);
  ASSERT_TRUE(s.run(
      [&] {
        return s.m.sequencer().state() == sequencer::State::kKnotting && s.m.sequencer().knot_cycle() == 2;
      },
      100000));
  s.m.sequencer().request_pause();
  const auto pistons = s.m.sim().pistons();
  ASSERT_TRUE(s.run([&] { return s.m.sequencer().state() != sequencer::State::kKnotting; }, 100000));
  EXPECT_EQ(s.m.sequencer().state(), sequencer::State::kPaused);
  const sequencer::KnotCounters held = s.m.sequencer().counters().knot;
  // Asked as cycle 2's carriage step and selectors travelled: cycles 0 and 1 tied, cycle 2 not begun (not
  // written ahead: the next run would begin it afresh).
  EXPECT_EQ(held.cycles_done, 2u);
  EXPECT_EQ(held.cycles_started, 2u);
  EXPECT_EQ(s.m.sim().pistons(), pistons);  // no shed
  // Standing: nothing moves while paused.
  const hal::HalOutputs before = s.m.loop().outputs();
  ASSERT_FALSE(s.run([&] { return s.m.sequencer().state() != sequencer::State::kPaused; }, 2000));
  EXPECT_FALSE(hal::motion_started(before, s.m.loop().outputs(), s.m.sequencer().axes().count,
                                   s.m.knot_program()->heads()));
  s.m.sequencer().request_resume();
  ASSERT_TRUE(s.run([&] { return s.m.sequencer().counters().picks > 0; }, 100000));
  EXPECT_EQ(s.m.sequencer().counters().knot.tied + s.m.sequencer().counters().knot.by_hand,
            static_cast<std::uint32_t>(s.m.knot_program()->knots_per_row()));
}

// `ctl reload HEAD SLOT [KNOTS]`: the weaver's count is the slot's level; a reload of the slot the heads
// ask for answers their request (they go on), a reload of another slot only sets that slot's level, and a
// reload short of what the row needs is asked again for the rest.
TEST(Knotting, AReloadAnswersTheHeadsRequestWithTheWeaversCount) {
  Stepped s(knotting_loom(), scene("miss_probability = 0.0\n"), 6);
  sequencer::Sequencer& seq = s.m.sequencer();
  const auto asked = [&] { return seq.weaver_request().ask == sequencer::WeaverAsk::kReload; };
  ASSERT_TRUE(s.run(asked, 400000));
  const sequencer::WeaverRequest r = seq.weaver_request();
  ASSERT_GT(r.knots_needed, 1);
  const int other = (r.slot + 1) % 3;
  EXPECT_TRUE(seq.reload_magazine(r.head, other, 7));
  s.run([] { return false; }, 5);
  EXPECT_TRUE(asked());
  EXPECT_EQ(seq.knotter().stock(r.head, other), 7);
  EXPECT_FALSE(seq.reload_magazine(3, 0, 5));  // the sample loom has heads 0..2
  EXPECT_FALSE(seq.reload_magazine(0, 3, 5));  // ... and slots 0..2
  EXPECT_FALSE(seq.reload_magazine(-1, 0, 5));
  const std::uint32_t requests = seq.knotter().requests();
  EXPECT_TRUE(seq.reload_magazine(r.head, r.slot, r.knots_needed - 1));  // one knot short
  ASSERT_TRUE(s.run([&] { return seq.knotter().requests() != requests; }, 10));
  EXPECT_TRUE(asked());
  EXPECT_EQ(seq.weaver_request().head, r.head);
  EXPECT_EQ(seq.weaver_request().slot, r.slot);
  EXPECT_EQ(seq.weaver_request().knots_left, r.knots_needed - 1);
  EXPECT_TRUE(seq.reload_magazine(r.head, r.slot, 1000));  // more than a slot holds: full
  s.run([] { return false; }, 1);
  EXPECT_EQ(seq.knotter().stock(r.head, r.slot), s.m.knot_program()->knots_per_slot());
  EXPECT_FALSE(asked() && seq.weaver_request().head == r.head && seq.weaver_request().slot == r.slot);
}

TEST(Knotting, AScenelessHeadsLoomAndAHeadlessKnotterAreRefused) {
  firmware::MachineOptions opt;
  opt.telemetry = false;
  const auto error = [&](const firmware::LoomConfig& cfg, const firmware::Scene& sc) -> std::string {
    try {
      firmware::Machine m(cfg, sc, opt, {});
    } catch (const firmware::ConfigError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error(knotting_loom(), firmware::parse_scene("name = \"t\"\neffects = [\"ideal\"]\n", "t.toml"))
                .find("the scene must name the effect \"knotter\""),
            std::string::npos);
  EXPECT_NE(error(firmware::default_loom_config(), scene("weaver_s = 1.0\n"))
                .find("has none (knotting.mode = \"none\")"),
            std::string::npos);
}

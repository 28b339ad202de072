// The shipped twelve-head loom (firmware/config/knotting_loom_12_heads.toml): twelve heads across the
// default 1.2 m width, on at most four buses at the default 2 ms, every bus within the default 70 % budget
// with every term of the bus load counted — its figures against the closed forms of drivers/bus_load.cpp's
// terms. The selectors run profile position (axes.<name>.drive_mode = "profile"); cyclic, they would not fit.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "loom/config/config.hpp"
#include "loom/drivers/bus_load.hpp"
#include "loom/drivers/can_axis_config.hpp"
#include "loom/sequencer/knot_plan.hpp"
#include "text_file.hpp"

using namespace loom;
using namespace loom::firmware;

namespace {

using loom::test::read_text_file;

const std::string kPath = std::string(LOOM_SOURCE_DIR) + "/firmware/config/knotting_loom_12_heads.toml";

// The file as the loom reads it, and the CAN master's config derived from it.
struct Loaded {
  LoomConfig config;
  drivers::CanAxisPortConfig can;
  int profile_lines = 0;  // lines that set drive_mode = "profile"
};

Loaded load() {
  const std::string text = read_text_file(kPath);
  Loaded l;
  const std::string line = "\ndrive_mode = \"profile\"";  // a key at the start of its line
  for (std::size_t at = text.find(line); at != std::string::npos; at = text.find(line, at + 1))
    ++l.profile_lines;
  EXPECT_EQ(text.find("bus_load_budget"), std::string::npos)
      << "the shipped file must keep the default budget";
  EXPECT_EQ(text.find("period_ms"), std::string::npos) << "the shipped file must keep the default period";
  l.config = load_loom_config(kPath);  // throws (the test fails) if any bus were over its budget
  l.can = can_axis_config(l.config);
  return l;
}

TEST(TwelveHeads, TwelveHeadsCoverTheDefaultWidth) {
  const Loaded l = load();
  const LoomConfig& c = l.config;
  EXPECT_EQ(c.knotting.heads, 12);
  EXPECT_EQ(l.profile_lines, 12);  // every selector, nothing else
  int knotters = 0, selectors = 0;
  for (const AxisSpec& a : c.axes) {
    knotters += a.role == hal::AxisRole::kKnotter ? 1 : 0;
    selectors += a.role == hal::AxisRole::kSelector ? 1 : 0;
  }
  EXPECT_EQ(knotters, 12);
  EXPECT_EQ(selectors, 12);
  // 360 knots a row at 30 knots/dm on 1.2 m; each head's stripe is the spacing, 30 whole pitches.
  const int knots = sequencer::knots_per_row(c.knotting, 1.2);
  EXPECT_EQ(knots, 360);
  const double pitches = c.knotting.head_spacing_m / sequencer::knot_pitch_m(c.knotting);
  EXPECT_NEAR(pitches, 30.0, 1e-9);
  EXPECT_EQ(12 * static_cast<int>(std::lround(pitches)), knots);
}

TEST(TwelveHeads, EveryBusIsWithinTheDefaultBudgetAtTwoMilliseconds) {
  const Loaded l = load();
  ASSERT_TRUE(drivers::validate(l.can).is_ok()) << drivers::validate(l.can).message();
  EXPECT_NEAR(l.can.bus_load_budget, 0.70, 1e-12);
  EXPECT_NEAR(l.can.cycle_period_s, 0.002, 1e-12);
  int profile = 0;
  for (std::size_t i = 0; i < l.config.axes.size(); ++i) {
    const bool selector = l.config.axes[i].role == hal::AxisRole::kSelector;
    EXPECT_EQ(l.can.axes[i].mode == drivers::DriveMode::kProfilePosition, selector) << l.config.axes[i].name;
    profile += selector ? 1 : 0;
  }
  EXPECT_EQ(profile, 12);
  ASSERT_EQ(drivers::bus_count(l.can), 4u);
  for (std::size_t b = 0; b < 4; ++b) {
    const drivers::BusLoad load = drivers::planned_bus_load(l.can, b);
    EXPECT_TRUE(drivers::check_bus_load(load, l.can.bus_load_budget).is_ok())
        << drivers::describe_bus_load(load);
  }
  // Bus 0: SYNC 55 + 3 drives · 230 + the I/O module's outputs (4 B) 95, inputs (5 B) 105 and load cell
  // (2 B) 75 + master heartbeat 65 = 1085; blocking 135, EMCY 135; 4 heartbeats ⌈4 · 65 · 2 / 100⌉ = 6:
  // 1361 bits of 2000 = 68.05 %.
  const drivers::BusLoad bus0 = drivers::planned_bus_load(l.can, 0);
  EXPECT_EQ(bus0.synchronous_bits_worst, 1085u);
  EXPECT_EQ(bus0.bits_worst, 1361u);
  // Buses 1..3: SYNC 55 + 4 knotters · 230 + master heartbeat 65 = 1040; blocking 135, EMCY 135; 8
  // heartbeats ⌈8 · 65 · 2 / 100⌉ = 11; 4 selectors' RPDO1 and TPDO1 at one per 30 ms inhibit,
  // ⌈4 · 115 · 2 / 30⌉ = 31 each: 1383 bits of 2000 = 69.15 %.
  for (std::size_t b = 1; b < 4; ++b) {
    const drivers::BusLoad load = drivers::planned_bus_load(l.can, b);
    EXPECT_EQ(load.synchronous_bits_worst, 1040u) << b;
    EXPECT_EQ(load.heartbeat_bits_worst, 11u) << b;
    EXPECT_EQ(load.event_bits_worst, 62u) << b;
    EXPECT_EQ(load.bits_worst, 1383u) << b;
    EXPECT_NEAR(load.utilisation_worst, 0.6915, 1e-12) << b;
  }
}

TEST(TwelveHeads, CyclicSelectorsOrAShortInhibitWouldNotFit) {
  // The selectors cyclic as well: 1040 + 8 · 115 = 1960 synchronous + 270 + 11 = 2241 of 2000 (112 %).
  Loaded cyclic = load();
  for (drivers::CanAxisConfig& a : cyclic.can.axes) a.mode = drivers::DriveMode::kCyclicPosition;
  EXPECT_EQ(drivers::planned_bus_load(cyclic.can, 1).bits_worst, 2241u);
  EXPECT_FALSE(drivers::check_bus_load(drivers::planned_bus_load(cyclic.can, 1), 0.70).is_ok());
  // Profile position with a 10 ms TPDO inhibit: 2 · ⌈460 · 0.2⌉ = 184 event bits, 1505 of 2000 (75.25 %).
  Loaded fast = load();
  fast.can.profile_tpdo_inhibit_s = 0.010;
  for (std::size_t b = 1; b < 4; ++b) {
    EXPECT_EQ(drivers::planned_bus_load(fast.can, b).bits_worst, 1505u) << b;
    EXPECT_FALSE(drivers::check_bus_load(drivers::planned_bus_load(fast.can, b), 0.70).is_ok()) << b;
  }
}

}  // namespace

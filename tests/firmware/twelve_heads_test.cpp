// The shipped twelve-head loom (firmware/config/knotting_loom_12_heads.toml): twelve heads across the
// default 1.2 m width, on at most four buses, every bus within the default 70 % budget with every term of
// the bus load counted — its figures against the closed forms of drivers/bus_load.cpp's terms.
//
// The selectors' `drive_mode = "profile"` key is read by the loom config once the profile-position
// selectors land (axes.<name>.drive_mode); until then this test reads the file without those lines, at a
// budget the all-cyclic wiring passes, and sets the selectors' mode on the CAN master's config itself.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "loom/config/config.hpp"
#include "loom/drivers/bus_load.hpp"
#include "loom/drivers/can_axis_config.hpp"
#include "loom/sequencer/knot_plan.hpp"

using namespace loom;
using namespace loom::firmware;

namespace {

const std::string kPath = std::string(LOOM_SOURCE_DIR) + "/firmware/config/knotting_loom_12_heads.toml";

std::string read(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// The file, its selectors' drive_mode lines taken out (counted), the budget raised for the parse-time
// check of the all-cyclic wiring; the CAN master's config with the selectors in profile position.
struct Loaded {
  LoomConfig config;
  drivers::CanAxisPortConfig can;
  int profile_lines = 0;
};

Loaded load() {
  std::string text = read(kPath);
  Loaded l;
  const std::string line = "\ndrive_mode = \"profile\"";  // a key at the start of its line
  for (std::size_t at = text.find(line); at != std::string::npos; at = text.find(line, at)) {
    text.erase(at + 1, text.find('\n', at + 1) - at - 1);
    ++l.profile_lines;
  }
  EXPECT_EQ(text.find("bus_load_budget"), std::string::npos)
      << "the shipped file must keep the default budget";
  l.config = parse_loom_config(text + "\n[can]\nbus_load_budget = 1.0\n", kPath);
  l.can = can_axis_config(l.config);
  for (std::size_t i = 0; i < l.config.axes.size(); ++i) {
    if (l.config.axes[i].role == hal::AxisRole::kSelector)
      l.can.axes[i].mode = drivers::DriveMode::kProfilePosition;
  }
  l.can.bus_load_budget = LoomConfig{}.can.bus_load_budget;  // the default, 70 %
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

TEST(TwelveHeads, EveryBusIsWithinTheDefaultBudget) {
  const Loaded l = load();
  ASSERT_TRUE(drivers::validate(l.can).is_ok()) << drivers::validate(l.can).message();
  EXPECT_NEAR(l.can.bus_load_budget, 0.70, 1e-12);
  EXPECT_NEAR(l.can.cycle_period_s, 0.0025, 1e-12);
  ASSERT_EQ(drivers::bus_count(l.can), 4u);
  for (std::size_t b = 0; b < 4; ++b) {
    const drivers::BusLoad load = drivers::planned_bus_load(l.can, b);
    EXPECT_TRUE(drivers::check_bus_load(load, l.can.bus_load_budget).is_ok())
        << drivers::describe_bus_load(load);
  }
  // Bus 0, at 2.5 ms: SYNC 55 + 3 drives · 230 + the I/O module's outputs (4 B) 95, inputs (5 B) 105 and load
  // cell (2 B) 75 + master heartbeat 65 = 1085; blocking 135, EMCY 135; 4 heartbeats ⌈4 · 65 · 2.5 / 100⌉ =
  // 7: 1362 bits of 2500 = 54.5 %.
  const drivers::BusLoad bus0 = drivers::planned_bus_load(l.can, 0);
  EXPECT_EQ(bus0.synchronous_bits_worst, 1085u);
  EXPECT_EQ(bus0.bits_worst, 1362u);
  // Buses 1..3: SYNC 55 + 4 knotters · 230 + master heartbeat 65 = 1040; blocking 135, EMCY 135; 8 heartbeats
  // ⌈8 · 65 · 2.5 / 100⌉ = 13; 4 selectors' RPDO1 and TPDO1 at one per 10 ms, ⌈4 · 115 · 2.5 / 10⌉ = 115
  // each: 1553 bits of 2500 = 62.1 %.
  for (std::size_t b = 1; b < 4; ++b) {
    const drivers::BusLoad load = drivers::planned_bus_load(l.can, b);
    EXPECT_EQ(load.synchronous_bits_worst, 1040u) << b;
    EXPECT_EQ(load.heartbeat_bits_worst, 13u) << b;
    EXPECT_EQ(load.event_bits_worst, 230u) << b;
    EXPECT_EQ(load.bits_worst, 1553u) << b;
    EXPECT_NEAR(load.utilisation_worst, 0.6212, 1e-12) << b;
  }
}

TEST(TwelveHeads, AtTwoMillisecondsTheHeadBusesAreOverTheBudget) {
  // Why the file runs at 2.5 ms: the same wiring at 2 ms. Bus 0: 1085 + 270 + ⌈5.2⌉ = 1361 of 2000
  // (68.05 %); buses 1..3: 1040 + 270 + ⌈10.4⌉ + 2 · ⌈460 · 0.2⌉ = 1505 of 2000 (75.25 %).
  Loaded l = load();
  l.can.cycle_period_s = 0.002;
  EXPECT_EQ(drivers::planned_bus_load(l.can, 0).bits_worst, 1361u);
  EXPECT_TRUE(drivers::check_bus_load(drivers::planned_bus_load(l.can, 0), 0.70).is_ok());
  for (std::size_t b = 1; b < 4; ++b) {
    EXPECT_EQ(drivers::planned_bus_load(l.can, b).bits_worst, 1505u) << b;
    EXPECT_FALSE(drivers::check_bus_load(drivers::planned_bus_load(l.can, b), 0.70).is_ok()) << b;
  }
  // With the selectors cyclic as well, even 2.5 ms is not enough: 1960 + 270 + 13 = 2243 of 2500 (89.7 %).
  Loaded cyclic = load();
  for (drivers::CanAxisConfig& a : cyclic.can.axes) a.mode = drivers::DriveMode::kCyclicPosition;
  EXPECT_EQ(drivers::planned_bus_load(cyclic.can, 1).bits_worst, 2243u);
}

}  // namespace

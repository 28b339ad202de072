// What a whole knotted row takes on the default loom's width (1.2 m), by carpet class and head count:
// each configuration is the default loom with N knotting heads — their I/O bits derived from N as the
// default loom's six heads have theirs (grippers on outputs 8.., cutters on 20.., yarn-present switches on
// inputs 24..: the shipped twelve-head loom's bits) —
// woven three rows on the simulated machine (the knotter effect, no misses) in virtual time. A cell is the
// steady state: the mean of rows 2 and 3 (row 1 carries the shed test; every row is knotted from the left
// selvedge and swept back to it, so rows differ only by their design rows), each row's
// machine time read from its RowStats — knotting, shed, pick and beat — against the weaver's ~600 s whole
// row (thesis, ch. 6). Machine time, not CPU time: the numbers are the same on every host. The heads'
// spacing is the smallest whole number of knot pitches whose stripes cover the width (the last head's
// stripe may be shorter). A cell the loom refuses (or that does not finish its rows) makes the exit 1.
//
// The heads are wired as the shipped looms are (knotting_loom.toml, knotting_loom_12_heads.toml): spread
// evenly over buses 1..3 (at most four heads a bus), knotters cyclic, selectors in profile position, held to
// the loom's own 70 % bus-load budget. At 2 ms that takes up to 8 heads; 12 heads need 2.5 ms
// (--period-ms 2.5: four knotters, four selectors and the bus' fixed terms are 75.3 % at 2 ms).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/firmware/machine.hpp"
#include "loom/firmware/runner.hpp"
#include "loom/sequencer/knot_plan.hpp"

using namespace loom;

namespace {
struct Class {
  const char* name;
  double knots_per_dm;  // across and along (a square knot grid)
};
constexpr Class kClasses[] = {
    {"coarse", 20.0}, {"medium", 30.0}, {"fine", 40.0}, {"extra fine", 45.0}, {"extra extra fine", 60.0}};

struct RowTime {
  bool ok = false;
  double whole_s = 0.0, knot_s = 0.0;
  int cycles = 0;
  std::string why;
};

std::string exact(double v) {  // round-trips: the spacing stays a whole number of pitches
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

RowTime one_row(const std::string& dir, const Class& c, int heads, double period_ms) {
  const double width = 1.2;
  sequencer::KnottingSpec k;
  k.knots_per_dm = c.knots_per_dm;
  const int knots = sequencer::knots_per_row(k, width);
  const int stripe = (knots + heads - 1) / heads;
  const double spacing = stripe * sequencer::knot_pitch_m(k);
  // A one-row design in three colours, drawn with a fixed seed: a selector moves about every other knot.
  std::mt19937 rng(7);
  std::ofstream design(dir + "/row.csv");
  design << "palette,R,#a52a2a\npalette,I,#f3ead6\npalette,B,#1f3a6e\n";
  const char* codes[] = {"R", "I", "B"};
  for (int i = 0; i < knots; ++i) design << (i ? "," : "") << codes[rng() % 3];
  design << "\n";
  design.close();
  // Each head's gripper, cutter and yarn-present switch on its own bit, derived from the head count.
  const auto bits = [heads](int first) {
    std::string list = "[";
    for (int h = 0; h < heads; ++h) list += (h ? ", " : "") + std::to_string(first + h);
    return list + "]";
  };
  std::string cfg =
      "extends = \"default\"\n[io]\ngripper_close_bits = " + bits(8) + "\ncutter_bits = " + bits(20) +
      "\nyarn_present_bits = " + bits(24) + "\n[timing]\nperiod_ms = " + std::to_string(period_ms) +
      "\n[knotting]\nmode = \"heads\"\nknots_per_dm = " + std::to_string(c.knots_per_dm) +
      "\nrows_per_dm = " + std::to_string(c.knots_per_dm) + "\nheads = " + std::to_string(heads) +
      "\nhead_spacing_m = " + exact(spacing) + "\nslot_colours = [\"R\", \"I\", \"B\"]\n";
  for (int h = 1; h <= heads; ++h) {
    const int bus = 1 + (h - 1) * 3 / heads;  // buses 1..3, the heads spread evenly (≤ 4 a bus)
    for (const char* role : {"knotter", "selector"}) {
      cfg +=
          std::string("[axes.") + role + "_" + (h < 10 ? "0" : "") + std::to_string(h) + "]\nrole = \"" +
          role + "\"\nbus = " + std::to_string(bus) +
          "\nnode = " + std::to_string((role[0] == 'k' ? 20 : 50) + h) + "\ncounts_per_rev = 4096\n" +
          (role[0] == 'k' ? "drive = \"servo_100w_10to1\"" : "max_speed = 20.0\ndrive_mode = \"profile\"") +
          "\nferror_min = 0.2\nreferencing = \"absolute\"\n";
    }
  }
  cfg += "[recipe]\ndesign = \"row.csv\"\n";
  std::ofstream(dir + "/loom.toml") << cfg;
  RowTime t;
  try {
    const firmware::LoomConfig lc = firmware::load_loom_config(dir + "/loom.toml");
    const firmware::Scene scene = firmware::parse_scene(
        "name = \"bench\"\nseed = 1\neffects = [\"ideal\", \"knotter\"]\n", "bench.toml");
    firmware::MachineOptions opt;
    opt.telemetry = false;
    opt.rows = 3;
    firmware::Machine m(lc, scene, opt, {});
    m.sequencer().request_start();
    firmware::RunOptions ro;
    ro.period_s = lc.sequencer.period_s;
    ro.max_ticks = 5'000'000;
    ro.sim_weaver = m.sim_weaver();
    int rows = 0;
    firmware::run_loop(m.loop(), m.sequencer(), ro, [&](const firmware::RunEvent& e) {
      if (e.kind != firmware::RunEvent::Kind::kRowDone || ++rows < 2) return;  // row 1: the shed test
      t.whole_s += static_cast<double>(e.row.total_ticks) * ro.period_s / 2.0;
      t.knot_s += static_cast<double>(e.row.knot_ticks) * ro.period_s / 2.0;
    });
    t.ok = rows == 3;
    t.cycles = std::min(stripe, knots);
    if (!t.ok) t.why = sequencer::fault_name(m.sequencer().first_fault());
  } catch (const std::exception& e) {
    t.why = e.what();
  }
  return t;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Whole-row machine time of the default loom's width by carpet class and knotting-head count"};
  double period_ms = 2.0;
  bool smoke = false;
  std::vector<int> heads{1, 2, 4, 8, 12};
  app.add_option("--period-ms", period_ms, "control period (ms)")->check(CLI::Range(1.0, 10.0));
  app.add_option("--heads", heads, "head counts (columns)")->check(CLI::Range(1, 12));
  app.add_flag("--smoke", smoke,
               "the medium class only, at every head count asked for: proves each configuration is built");
  CLI11_PARSE(app, argc, argv);
  const std::string dir =
      std::filesystem::temp_directory_path() / ("loom_knot_bench_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::printf("| class (knots/dm²) | knots/row |");
  for (int h : heads) std::printf(" %d head%s |", h, h == 1 ? "" : "s");
  std::printf("\n|---|---|");
  for (std::size_t i = 0; i < heads.size(); ++i) std::printf("---|");
  std::printf("\n");
  int status = 0;
  for (const Class& c : kClasses) {
    if (smoke && std::string(c.name) != "medium") continue;
    sequencer::KnottingSpec k;
    k.knots_per_dm = c.knots_per_dm;
    std::printf("| %s (%.0f) | %d |", c.name, c.knots_per_dm * c.knots_per_dm,
                sequencer::knots_per_row(k, 1.2));
    for (int h : heads) {
      const RowTime t = one_row(dir, c, h, period_ms);
      if (!t.ok) {
        std::printf(" failed: %s |", t.why.c_str());
        status = 1;
        continue;
      }
      std::printf(" %.1f s (%.0fx) |", t.whole_s, 600.0 / t.whole_s);
    }
    std::printf("\n");
    std::fflush(stdout);
  }
  std::printf(
      "\nwhole row = knotting + shed + pick + beat, the mean of rows 2 and 3, machine time at a %.3g ms "
      "period; (Nx) = ~600 s for the weaver's whole row / the loom's\n",
      period_ms);
  std::filesystem::remove_all(dir);
  return status;
}

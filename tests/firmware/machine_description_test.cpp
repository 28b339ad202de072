// One machine description: every reproduction of "a config that parses but does harm" is refused at
// parse time with file:line:col, key and value; each fact is stated once and derived everywhere; a
// recipe reload may change the recipe only.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "config_error.hpp"
#include "loom/config/config.hpp"
#include "loom/sequencer/sequencer.hpp"
#include "loom/sim_heads/sim_heads.hpp"

using namespace loom::firmware;

namespace {

using loom::test::config_error;

std::string ext(const std::string& body) {
  return "extends = \"default\"\n" + body;
}

std::string load_error(const std::string& path) {
  try {
    (void)load_loom_config(path);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("loom_md_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

}  // namespace

TEST(MachineDescription, EmptyOrCommentsOnlyFileIsNotTheDefaultLoom) {
  EXPECT_EQ(config_error(""),
            "loom.toml:1:1: loom.id: missing: a config file must be complete, or begin with extends = "
            "\"default\" to take what it does not say from the embedded default loom");
  EXPECT_NE(config_error("# just a comment\n").find("loom.id: missing"), std::string::npos);
  // A partial file without `extends` names the first key it lacks, at its section's header.
  EXPECT_EQ(config_error("[loom]\nid = \"x\"\n").rfind("loom.toml:1:1: [loom] width_m: missing", 0), 0u)
      << config_error("[loom]\nid = \"x\"\n");
  EXPECT_NE(config_error("extends = \"mine\"\n").find("extends = \"mine\": only \"default\""),
            std::string::npos);
}

TEST(MachineDescription, TheDefaultFileIsCompleteAndExtendingItChangesNothing) {
  const LoomConfig a = default_loom_config();
  const LoomConfig b = parse_loom_config("extends = \"default\"\n", "x.toml");
  EXPECT_EQ(restart_only_changes(a, b), "");
  EXPECT_EQ(a.profile.crank.velocity, b.profile.crank.velocity);
  // Every key the parser knows is written in the shipped file (so a copy of it is complete); a node's EDS
  // and the input groups it decides, which have no default, as commented examples.
  for (const KeyInfo& k : config_keys()) {
    if (std::string(k.path) == "io.input_group_bits") {
      EXPECT_NE(std::string(kDefaultLoomToml).find("\n# input_group_bits = "), std::string::npos) << k.path;
      continue;
    }
    if (std::string(k.path).size() > 4 &&
        std::string(k.path).substr(std::string(k.path).size() - 4) == ".eds") {
      EXPECT_NE(std::string(kDefaultLoomToml).find("\n# eds = "), std::string::npos) << k.path;
      continue;
    }
    if (std::string(k.path).rfind("axes.<name>.", 0) == 0) {  // per-axis keys: in the axis tables
      const std::string key = std::string(k.path).substr(12);
      if (key == "max_speed" || key == "drive" || key.rfind("hom", 0) == 0)
        continue;  // added axes / homed axes only
      EXPECT_NE(std::string(kDefaultLoomToml).find("\n" + key + " "), std::string::npos) << k.path;
      continue;
    }
    if (std::string(k.path).rfind("drives.<model>.", 0) == 0) {  // the shipped drive's table
      const std::string key = std::string(k.path).substr(15);
      EXPECT_NE(std::string(kDefaultLoomToml).find("\n" + key + " "), std::string::npos) << k.path;
      continue;
    }
    if (std::string(k.path).rfind("io_modules.<name>.", 0) ==
        0) {  // further I/O modules: a commented example
      const std::string key = std::string(k.path).substr(18);
      EXPECT_NE(std::string(kDefaultLoomToml).find("\n# " + key + " = "), std::string::npos) << k.path;
      continue;
    }
    // The key is the last part of the path, its table the rest ([knotting.linkage] holds take_x_m).
    const std::string key = std::string(k.path).substr(std::string(k.path).rfind('.') + 1);
    const std::string section = std::string(k.path).substr(0, std::string(k.path).rfind('.'));
    if (std::string(k.path) == "recipe.crank_speed_rad_s") continue;  // the alternative to the force target
    if (std::string(k.path) == "knotting.placement_tolerance_m") {    // derived from the pitch when not given
      EXPECT_NE(std::string(kDefaultLoomToml).find("\n# " + key + " = "), std::string::npos) << k.path;
      continue;
    }
    EXPECT_NE(std::string(kDefaultLoomToml).find("\n" + key + " "), std::string::npos) << k.path;
    EXPECT_NE(std::string(kDefaultLoomToml).find("[" + section + "]"), std::string::npos) << k.path;
  }
}

TEST(MachineDescription, NonRegularOrHugeFilesAreRefusedWithoutReading) {
  EXPECT_EQ(load_error("/dev/null"), "/dev/null: not a regular file");
  EXPECT_EQ(load_error("/dev/zero"), "/dev/zero: not a regular file");
  const std::string fifo = temp_path("fifo");
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(load_error(fifo), fifo + ": not a regular file");  // returns at once: no writer needed
  std::filesystem::remove(fifo);
  const std::string big = temp_path("big.toml");
  std::ofstream(big) << std::string(2 << 20, '#');
  EXPECT_NE(load_error(big).find("larger than any config"), std::string::npos);
  std::filesystem::remove(big);
  EXPECT_NE(load_error(temp_path("absent.toml")).find("cannot open"), std::string::npos);
}

TEST(MachineDescription, DeeplyNestedKeysAreRefusedBeforeTheParserRecurses) {
  std::string deep = "a";
  for (int i = 0; i < 40000; ++i) deep += ".a";
  EXPECT_EQ(config_error(deep + " = 1\n"), "loom.toml:1:32: key nested deeper than 16 levels");
  std::string arrays = "x = ";
  for (int i = 0; i < 40000; ++i) arrays += "[";
  EXPECT_NE(config_error(arrays + "\n").find("nested deeper than 32 levels"), std::string::npos);
  EXPECT_NE(config_error(std::string("a = 1\0b", 7)).find("NUL"), std::string::npos);
}

TEST(MachineDescription, BeatsPerRowBeyondTheSequencerCapacityAreRefused) {
  const std::string e = config_error(ext("[loom]\nwidth_m = 3.0\n[recipe]\nbeats_per_position = 8\n"));
  EXPECT_EQ(
      e,
      "loom.toml:5:22: recipe.beats_per_position = 8: gives 304 beats per row on a 3 m loom; the sequencer "
      "holds at most " +
          std::to_string(loom::sequencer::kMaxBeatsPerRow));
}

TEST(MachineDescription, CalibrationOffsetsMustBeFiniteAndPlausible) {
  for (const char* v : {"nan", "inf", "-inf", "1e308"}) {
    for (const char* key :
         {"[beatup]\ncrank_park_position_rad", "[carriage]\nhome_position_m", "[helix]\nleft_position_rad"}) {
      const std::string e = config_error(ext(std::string(key) + " = " + v + "\n"));
      EXPECT_EQ(e.rfind("loom.toml:3:", 0), 0u) << key << " = " << v << ": " << e;
      EXPECT_TRUE(e.find("must be finite") != std::string::npos ||
                  e.find("must be in [") != std::string::npos)
          << e;
    }
  }
}

TEST(MachineDescription, AbsurdPositiveValuesAreRefusedByPlausibleRanges) {
  EXPECT_EQ(config_error(ext("[recipe]\ncrank_jerk_rad_s3 = 1e-320\n")),
            "loom.toml:3:21: recipe.crank_jerk_rad_s3 = 1e-320: must be in [10, 1e+07]");
  EXPECT_EQ(config_error(ext("[helix]\nlead_m = 1e-320\n")),
            "loom.toml:3:10: helix.lead_m = 1e-320: must be in [0.005, 1]");
  EXPECT_EQ(config_error(ext("[beatup]\nbeater_mass_kg = 1e308\n")),
            "loom.toml:3:18: beatup.beater_mass_kg = 1e308: must be in [0.1, 50]");
  EXPECT_EQ(config_error(ext("[helix]\nshuttle_mass_kg = 1e308\n")),
            "loom.toml:3:19: helix.shuttle_mass_kg = 1e308: must be in [0.01, 10]");
  EXPECT_NE(config_error(ext("[timing]\nenable_timeout_s = 1e300\n")).find("must be in [0.05, 60]"),
            std::string::npos);
  EXPECT_NE(config_error(ext("[can]\nbitrate = 123456\n")).find("must be a CiA 301 bit rate"),
            std::string::npos);
}

TEST(MachineDescription, EachCrossFieldErrorPointsAtTheLineThatIsWrong) {
  // A duplicated node id at its second use, whichever key that is.
  EXPECT_EQ(config_error(ext("[axes.helix]\nnode = 7\n[axes.carriage]\nnode = 7\n")),
            "loom.toml:5:8: axes.carriage.node = 7: node id already used by axes.helix.node");
  // A non-Grashof linkage at the link lengths.
  EXPECT_NE(config_error(ext("[beatup]\ncrank_m = 0.3\n"))
                .find("loom.toml:3:11: beatup.crank_m = 0.3: the linkage"),
            std::string::npos);
  // A misspelled section is an unknown section, with the near miss suggested.
  EXPECT_EQ(config_error(ext("[carriag]\nmax_speed_m_s = 1\n")),
            "loom.toml:2:1: [carriag] = {...}: unknown section (did you mean [carriage]?)");
  // A force target that cannot be met names the limit and the speed it asks for, at the target.
  const std::string force =
      config_error(ext("[recipe]\nbeat_force_target_n = 400\nbeat_force_max_n = 500\n"));
  EXPECT_EQ(force.rfind("loom.toml:3:23: recipe.beat_force_target_n = 400:", 0), 0u) << force;
  EXPECT_NE(force.find("crank speed of"), std::string::npos) << force;
  // A target outside the band the beats must hit.
  EXPECT_NE(config_error(ext("[recipe]\nbeat_force_target_n = 120\n"))
                .find("must lie in the band [beat_force_min_n"),
            std::string::npos);
  // The CAN master's own rule, at parse time (exit 2), not when the bus is opened (exit 4).
  EXPECT_EQ(config_error(ext("[can]\nheartbeat_timeout_ms = 400\n"))
                .rfind("loom.toml:3:24: can.heartbeat_timeout_ms = 400", 0),
            0u);
  EXPECT_NE(config_error(ext("[beatup]\nbeater_width_m = 0.05\n[recipe]\noverlap_m = 0.05\n"))
                .find("loom.toml:5:13: recipe.overlap_m"),
            std::string::npos);
}

TEST(MachineDescription, EveryModuleConfigIsDerivedFromOneFact) {
  LoomConfig c =
      parse_loom_config(ext("[timing]\nperiod_ms = 4\n[beatup]\ncrank_park_position_rad = 0.5\n"), "x.toml");
  EXPECT_EQ(c.sequencer.period_s, 0.004);
  EXPECT_EQ(c.machine.period_s, 0.004);
  EXPECT_EQ(can_axis_config(c).cycle_period_s, 0.004);
  EXPECT_EQ(c.sequencer.crank_park_position_rad, 0.5);
  EXPECT_EQ(c.machine.crank_park_position_rad, 0.5);
  EXPECT_EQ(c.machine.width_m, c.profile.width_m);
  EXPECT_EQ(c.machine.beatup.bar.crank, c.profile.beatup.bar.crank);
  // An override changes the fact once; the derivation carries it everywhere.
  c.run.period_s = 0.001;
  derive_module_configs(c);
  EXPECT_EQ(c.sequencer.period_s, 0.001);
  EXPECT_EQ(c.machine.period_s, 0.001);
  EXPECT_EQ(can_axis_config(c).cycle_period_s, 0.001);
  // The loop's clocks take the period in nanoseconds and the CAN diagnosis window from the same derivation.
  EXPECT_EQ(c.timing.period_ns, 1'000'000);
  EXPECT_DOUBLE_EQ(c.timing.can_diagnosis_window_s, c.can.heartbeat_timeout_ms * 1e-3 + 10 * 0.001);
}

TEST(MachineDescription, AReloadMayChangeOnlyTheRecipe) {
  const LoomConfig running = default_loom_config();
  const LoomConfig recipe = parse_loom_config(
      ext("[recipe]\nbeats_per_position = 2\n[profiles]\ninterp = \"quintic\"\n"), "r.toml");
  EXPECT_EQ(restart_only_changes(running, recipe), "");
  const LoomConfig geometry = parse_loom_config(ext("[beatup]\ncoupler_m = 0.19\n"), "g.toml");
  EXPECT_EQ(restart_only_changes(running, geometry), "beatup.coupler_m 0.189 -> 0.19");
  const LoomConfig run =
      parse_loom_config(ext("[timing]\ndebounce_ticks = 5\n[loom]\nwidth_m = 1.0\n"), "w.toml");
  EXPECT_EQ(restart_only_changes(running, run), "loom.width_m 1.2 -> 1, timing.debounce_ticks 3 -> 5");
}

TEST(MachineDescription, EveryKeyHasAClassAndARange) {
  int machine = 0, recipe = 0, run = 0;
  for (const KeyInfo& k : config_keys()) {
    const std::string klass = k.klass;
    machine += klass == "machine";
    recipe += klass == "recipe";
    run += klass == "run";
    EXPECT_FALSE(k.range.empty()) << k.path;
  }
  EXPECT_GT(machine, 30);
  EXPECT_GT(recipe, 10);
  EXPECT_GT(run, 5);
}

// ---------------------------------------------------------------------------------------------------
// Axes are the machine's: [axes.<name>] tables, the core three in every loom, more up to the capacity.
// ---------------------------------------------------------------------------------------------------
namespace {
// An auxiliary take-up roller on node 5, added to the default loom.
const char* const kTakeUp =
    "[axes.take_up]\nrole = \"auxiliary\"\nnode = 5\ncounts_per_rev = 4096\nmax_speed = 2.0\n"
    "ferror_min = 0.1\nreferencing = \"absolute\"\n";
}  // namespace

TEST(MachineAxes, TheDefaultLoomHasTheThreeCoreAxesInSlotOrder) {
  const LoomConfig c = default_loom_config();
  ASSERT_EQ(c.axes.size(), 3u);
  const loom::hal::AxisLayout l = axis_layout(c);
  EXPECT_EQ(std::string(l.name(0)), "beat_crank");
  EXPECT_EQ(std::string(l.name(1)), "carriage");
  EXPECT_EQ(std::string(l.name(2)), "helix");
  EXPECT_EQ(c.sequencer.axes.count, 3u);
  EXPECT_EQ(c.machine.axis_count, 3u);
  EXPECT_EQ(can_axis_config(c).axes.size(), 3u);
  EXPECT_EQ(can_axis_config(c).axes[2].node_id, 3);
}

TEST(MachineAxes, AnAddedAxisIsDerivedIntoEveryModule) {
  const LoomConfig c =
      parse_loom_config(ext(std::string("[can]\nbus_load_budget = 0.8\n") + kTakeUp), "loom.toml");
  ASSERT_EQ(c.axes.size(), 4u);
  EXPECT_EQ(c.axes[3].name, "take_up");
  EXPECT_EQ(c.sequencer.axes.count, 4u);
  EXPECT_EQ(std::string(c.sequencer.axes.name(3)), "take_up");
  EXPECT_DOUBLE_EQ(c.sequencer.axis_max_speed[3], 2.0);
  EXPECT_EQ(c.machine.axis_count, 4u);
  const auto can = can_axis_config(c);
  ASSERT_EQ(can.axes.size(), 4u);
  EXPECT_EQ(can.axes[3].node_id, 5);
  EXPECT_NEAR(can.axes[3].counts_per_unit, 4096.0 / (2.0 * M_PI), 1e-9);
  // One more drive on the bus: one more RPDO1 and TPDO1 per cycle than the default loom.
  EXPECT_EQ(can_bus_load(c).frames, can_bus_load(default_loom_config()).frames + 2);
  // An added axis is a restart-only change.
  EXPECT_NE(restart_only_changes(default_loom_config(), c).find("axes"), std::string::npos);
  // Slot order does not follow the file: the core axes come first, the others by name.
  const LoomConfig d = parse_loom_config(
      ext(std::string("[can]\nbus_load_budget = 1.0\n") + kTakeUp +
          "[axes.a_roll]\nrole = \"auxiliary\"\nnode = 6\n"
          "counts_per_rev = 4096\nmax_speed = 1\nferror_min = 0\nreferencing = \"absolute\"\n"),
      "loom.toml");
  ASSERT_EQ(d.axes.size(), 5u);
  EXPECT_EQ(d.axes[0].name, "beat_crank");
  EXPECT_EQ(d.axes[3].name, "a_roll");
  EXPECT_EQ(d.axes[4].name, "take_up");
}

TEST(MachineAxes, BadAxisTablesAreRefusedAtTheirLine) {
  // The old three-axis keys name where the fact lives now.
  EXPECT_EQ(config_error(ext("[can]\nnode_helix = 7\n")),
            "loom.toml:3:14: can.node_helix = 7: moved: this fact is axes.helix.node "
            "(loomctl check --keys lists every key)");
  EXPECT_NE(config_error(ext("[can]\ncarriage_counts_per_m = 1e6\n")).find("axes.carriage.lead_m"),
            std::string::npos);
  // A new axis says what it is, which drive moves it and how fast it may go.
  EXPECT_NE(config_error(ext("[axes.x]\nnode = 5\n")).find("axes.x.role = (missing): missing"),
            std::string::npos)
      << config_error(ext("[axes.x]\nnode = 5\n"));
  EXPECT_NE(
      config_error(ext("[axes.x]\nrole = \"auxiliary\"\nnode = 5\ncounts_per_rev = 4096\nferror_min = 0\n"))
          .find("axes.x.max_speed = (missing)"),
      std::string::npos);
  EXPECT_NE(config_error(ext("[axes.x]\nrole = \"spindle\"\n")).find("axes.x.role = \"spindle\""),
            std::string::npos);
  // Facts that belong elsewhere are refused where they are written.
  EXPECT_NE(config_error(ext("[axes.helix]\nmax_speed = 5\n")).find("[helix] max_speed_rad_s"),
            std::string::npos);
  EXPECT_NE(config_error(ext("[axes.helix]\nlead_m = 0.01\n")).find("only a linear axis"), std::string::npos);
  // Names are identifiers; the set holds one axis per core role and at most the capacity.
  EXPECT_NE(config_error(ext("[axes.Take-Up]\nrole = \"auxiliary\"\n")).find("a-z, 0-9 and _"),
            std::string::npos);
  EXPECT_NE(config_error(ext("[axes.second_crank]\nrole = \"beat_crank\"\nnode = 9\ncounts_per_rev = "
                             "4096\nferror_min = 0\nreferencing = \"absolute\"\n"))
                .find("the loom has one beat_crank axis (axes.beat_crank)"),
            std::string::npos);
  EXPECT_NE(config_error(ext("[axes.helix]\nrole = \"auxiliary\"\nmax_speed = 1\n"))
                .find("no axis has role = \"helix\""),
            std::string::npos);
  std::string many;
  for (int i = 0; i < 30; ++i) {
    many += "[axes.k" + std::to_string(10 + i) + "]\nrole = \"knotter\"\nnode = " + std::to_string(10 + i) +
            "\ncounts_per_rev = 4096\nmax_speed = 10\nferror_min = 0\nreferencing = \"absolute\"\n";
  }
  EXPECT_NE(config_error(ext(many)).find("33 axes; the controller holds at most 32"), std::string::npos)
      << config_error(ext(many));
  // A duplicated node id between an axis and the I/O module.
  EXPECT_NE(config_error(ext("[io]\nnode = 2\n")).find("node id already used by axes.carriage.node"),
            std::string::npos);
}

// ---------------------------------------------------------------------------------------------------
// [knotting]: the pile, as the machine ties it
// ---------------------------------------------------------------------------------------------------
TEST(MachineKnotting, TheOldRecipeFlagNamesItsNewHome) {
  EXPECT_NE(config_error(ext("[recipe]\nknotting = true\n"))
                .find("loom.toml:3:12: recipe.knotting = true: moved: this fact is knotting.mode"),
            std::string::npos)
      << config_error(ext("[recipe]\nknotting = true\n"));
  EXPECT_TRUE(parse_loom_config(ext("[knotting]\nmode = \"weaver\"\n"), "x.toml").sequencer.knotting);
  EXPECT_FALSE(default_loom_config().sequencer.knotting);
}

TEST(MachineKnotting, HeadsNeedAMagazineThatHoldsEveryColourOfTheDesign) {
  const std::string dir = temp_path("knots");
  std::filesystem::create_directories(dir);
  // 1.2 m at 10 knots/dm: 120 knots per row; the design uses R and B, the magazine holds R and W.
  std::ofstream design(dir + "/rug.csv");
  design << "palette,R,#aa0000\npalette,B,#0000aa\npalette,W,#ffffff\n";
  for (int row = 0; row < 2; ++row) {
    for (int k = 0; k < 120; ++k) design << (k ? "," : "") << (row == 1 && k == 70 ? "B" : "R");
    design << "\n";
  }
  design.close();
  const std::string heads =
      "[knotting]\nmode = \"heads\"\nknots_per_dm = 10\nheads = 2\nhead_spacing_m = 0.6\n";
  // Each head's knotting servo and colour selector, on a bus of their own.
  std::string head_axes =
      "[io]\ngripper_close_bits = [8, 9]\ncutter_bits = [20, 21]\nyarn_present_bits = [24, 25]\n";
  for (const char* a : {"knotter_1", "knotter_2", "selector_1", "selector_2"}) {
    static int node = 10;
    head_axes += std::string("[axes.") + a + "]\nrole = \"" + (a[0] == 'k' ? "knotter" : "selector") +
                 "\"\nbus = 1\nnode = " + std::to_string(++node) +
                 "\ncounts_per_rev = 4096\nmax_speed = 20.0\nferror_min = 0.2\nreferencing = \"absolute\"\n" +
                 (a[0] == 'k' ? "drive = \"servo_100w_10to1\"\n" : "");
  }
  std::ofstream(dir + "/bad.toml") << ext(heads + "slot_colours = [\"R\", \"W\"]\n" + head_axes +
                                          "[recipe]\ndesign = \"rug.csv\"\n");
  // Design row 1 is the file's last line (woven bottom up): its knot 71 is the blue one, head 2's.
  EXPECT_NE(load_error(dir + "/bad.toml")
                .find("recipe.design = \"rug.csv\": design row 1: colour \"B\" (knot 71, head 2) is in no "
                      "magazine slot"),
            std::string::npos)
      << load_error(dir + "/bad.toml");
  std::ofstream(dir + "/good.toml") << ext(heads + "slot_colours = [\"R\", \"W\", \"B\"]\n" + head_axes +
                                           "[recipe]\ndesign = \"rug.csv\"\n");
  EXPECT_EQ(load_error(dir + "/good.toml"), "");
  // Heads without a design to tie: the config loads (a carpet job brings the design), and building the
  // heads without one — weave or serve with no job — is refused where the file says heads (issue 30: it was
  // said without a line).
  std::ofstream(dir + "/no_design.toml") << ext(heads + "slot_colours = [\"R\", \"W\", \"B\"]\n" + head_axes);
  EXPECT_EQ(load_error(dir + "/no_design.toml"), "");
  {
    const LoomConfig no_design = load_loom_config(dir + "/no_design.toml");
    EXPECT_EQ(no_design.recipe.design, nullptr);
    std::string why;
    try {
      (void)build_heads(no_design, 0, 0);
    } catch (const ConfigError& e) {
      why = e.what();
    }
    EXPECT_NE(
        why.find(
            "no_design.toml:3:8: knotting.mode = heads: the heads tie a design's knots: set recipe.design"),
        std::string::npos)
        << why;
    EXPECT_NE(why.find("or give the loom a carpet job (loomctl job add DESIGN"), std::string::npos) << why;
  }
  // The heads' signals on the I/O module: one bit per head, refused at the list's own line otherwise.
  const auto with_io = [&](const std::string& from, const std::string& to) {
    std::string axes = head_axes;
    axes.replace(axes.find(from), from.size(), to);
    return ext(heads + "slot_colours = [\"R\", \"W\", \"B\"]\n" + axes + "[recipe]\ndesign = \"rug.csv\"\n");
  };
  std::ofstream(dir + "/short.toml") << with_io("yarn_present_bits = [24, 25]", "yarn_present_bits = [24]");
  EXPECT_NE(load_error(dir + "/short.toml").find("short.toml:"), std::string::npos)
      << load_error(dir + "/short.toml");
  EXPECT_NE(load_error(dir + "/short.toml")
                .find("io.yarn_present_bits = [24]: 1 bits for knotting.heads = 2: one per head"),
            std::string::npos)
      << load_error(dir + "/short.toml");
  std::ofstream(dir + "/clash.toml") << with_io("cutter_bits = [20, 21]", "cutter_bits = [20, 5]");
  EXPECT_NE(load_error(dir + "/clash.toml")
                .find("io.cutter_bits = 20,5: the I/O module refuses it: io.outputs.cutter.head2.bit = 5 is "
                      "already used by "
                      "io.outputs.lamp_amber"),
            std::string::npos)
      << load_error(dir + "/clash.toml");
  std::ofstream(dir + "/range.toml") << with_io("gripper_close_bits = [8, 9]",
                                                "gripper_close_bits = [8, 64]");
  EXPECT_NE(load_error(dir + "/range.toml").find("io.gripper_close_bits"), std::string::npos)
      << load_error(dir + "/range.toml");
  EXPECT_NE(load_error(dir + "/range.toml").find("outside 0..63"), std::string::npos)
      << load_error(dir + "/range.toml");
  // Without its axes a head cannot tie: refused at the head count, naming the role.
  std::ofstream(dir + "/no_axes.toml")
      << ext(heads + "slot_colours = [\"R\", \"W\", \"B\"]\n[recipe]\ndesign = \"rug.csv\"\n");
  EXPECT_NE(load_error(dir + "/no_axes.toml")
                .find("knotting.heads = 2: the loom has 0 axes with role = \"knotter\""),
            std::string::npos)
      << load_error(dir + "/no_axes.toml");
  // Stripes that do not reach the right selvedge, at the spacing's line.
  EXPECT_NE(
      config_error(
          ext("[knotting]\nmode = \"heads\"\nheads = 2\nhead_spacing_m = 0.5\nslot_colours = [\"R\"]\n"))
          .find("knotting.head_spacing_m = 0.5: knotting.head_spacing_m: 2 heads x 150 knots per stripe "
                "cover 300"),
      std::string::npos)
      << config_error(
             ext("[knotting]\nmode = \"heads\"\nheads = 2\nhead_spacing_m = 0.5\nslot_colours = [\"R\"]\n"));
  // A spacing that is not a whole number of knot pitches would put head 2 between two knots.
  EXPECT_NE(
      config_error(
          ext("[knotting]\nmode = \"heads\"\nheads = 2\nhead_spacing_m = 0.6015\nslot_colours = [\"R\"]\n"))
          .find("is not a whole number of knot pitches"),
      std::string::npos);
  std::filesystem::remove_all(dir);
}

// A drive on the controller's own node id: the refusal points at whichever of the two the file says.
TEST(MachineDescription, ADriveOnTheMastersNodeIdIsRefusedAtTheLineThatSaysIt) {
  EXPECT_EQ(config_error(ext("[can]\nmaster_node = 3\n")),
            "loom.toml:3:15: can.master_node = 3: the CAN master refuses it: axes.helix.node_id = 3 is the "
            "master's own "
            "node id");
  EXPECT_EQ(config_error(ext("[axes.helix]\nnode = 127\n")),
            "loom.toml:3:8: axes.helix.node = 127: the CAN master refuses it: axes.helix.node_id = 127 is "
            "the master's "
            "own node id");
}

// The modules' refusals reach the file by their typed field (no key read back from a message): at the
// key that sets it, at knotting.mode when the file takes that key from the embedded default, and the
// sequencer's own at parse time, before anything is armed.
TEST(MachineDescription, ModuleRefusalsArePinnedToTheKeyOfTheirField) {
  EXPECT_EQ(
      config_error(ext("[knotting]\nmode = \"heads\"\n")),
      "loom.toml:3:8: knotting.mode = heads: knotting.slot_colours must name 1..16 colours (one per magazine "
      "slot)");
  EXPECT_EQ(
      config_error(ext("[knotting]\nmode = \"heads\"\nslot_colours = []\n")),
      "loom.toml:4:16: knotting.slot_colours = : knotting.slot_colours must name 1..16 colours (one per "
      "magazine slot)");
  EXPECT_EQ(config_error(ext(
                "[knotting]\nmode = \"heads\"\nheads = 2\nhead_spacing_m = 0.5\nslot_colours = [\"R\"]\n")),
            "loom.toml:5:18: knotting.head_spacing_m = 0.5: knotting.head_spacing_m: 2 heads x 150 knots per "
            "stripe "
            "cover 300 of the row's 360 knots (loom.width_m / knotting.heads is the spacing that covers the "
            "width)");
  EXPECT_EQ(
      config_error(ext("[timing]\nsensor_discrepancy_ms = 1\n")),
      "loom.toml:3:25: timing.sensor_discrepancy_ms = 1: timing.sensor_discrepancy_ms must be between one "
      "period and 1000 ms");
}

// [io_modules.<name>]: a loom's signals over several CiA 401 modules. What the file says becomes each
// module's CanIoConfig (node, bus, its signals), the buses' load and count, and the restart-only check;
// every mistake is refused at its line with key and value.
#include <gtest/gtest.h>

#include <string>

#include "config_error.hpp"
#include "loom/config/config.hpp"
#include "loom/drivers/bus_load.hpp"

using namespace loom::firmware;
namespace drivers = loom::drivers;

namespace {

using loom::test::config_error;

std::string ext(const std::string& body) {
  return "extends = \"default\"\n" + body;
}

// The stack light, the buzzer and the operator buttons on a panel module on a second bus.
const std::string kPanel =
    "[io_modules.panel]\n"
    "node = 6\n"
    "bus = 1\n"
    "signals = [\"lamp_green\", \"lamp_amber\", \"lamp_red\", \"buzzer\", \"button_start\", "
    "\"button_pause\", "
    "\"button_ack\"]\n";

}  // namespace

TEST(IoModules, ASecondModuleCarriesTheSignalsItListsOnItsBus) {
  const LoomConfig c = parse_loom_config(ext(kPanel), "panel.toml");
  ASSERT_EQ(c.io.modules.size(), 1u);
  EXPECT_EQ(c.io.wiring.lamp_green.module, 1);
  EXPECT_EQ(c.io.wiring.button_ack.module, 1);
  EXPECT_EQ(c.io.wiring.estop_ok.module, 0);
  EXPECT_EQ(c.io.wiring.piston_a_extend.module, 0);
  const auto configs = can_io_configs(c);
  ASSERT_EQ(configs.size(), 2u);
  EXPECT_EQ(configs[0].node_id, 4);
  EXPECT_EQ(configs[1].node_id, 6);
  EXPECT_EQ(configs[1].module, 1);
  EXPECT_EQ(configs[1].name, "panel");
  EXPECT_EQ(can_io_buses(c), (std::vector<std::size_t>{0, 1}));
  // Each module maps only its own signals: the panel one output and one input byte, no load cell.
  const drivers::IoWiring panel = drivers::module_wiring(configs[1].wiring, 1);
  EXPECT_EQ(panel.piston_a_extend.bit, -1);
  EXPECT_EQ(panel.lamp_green.bit, 4);
  EXPECT_EQ(panel.load_cell_channel, 0);
  EXPECT_EQ(drivers::io_output_subs(panel), 1);
  EXPECT_EQ(drivers::io_input_subs(panel), 2);  // buttons on bits 8..10
  // A bus that carries only an I/O module is one of the loom's buses, loaded by that module's frames.
  const drivers::CanAxisPortConfig cc = can_axis_config(c);
  EXPECT_EQ(drivers::bus_count(cc), 2u);
  EXPECT_EQ(cc.other_frames_per_cycle[1].size(), 2u);  // RPDO outputs, TPDO inputs
  const drivers::BusLoad one_bus = can_bus_load(default_loom_config(), 0);
  // Bus 0's [io] module still reads three input groups (second channels on 16..21) and writes one.
  EXPECT_EQ(can_bus_load(c, 0).utilisation_worst, one_bus.utilisation_worst);
  EXPECT_GT(can_bus_load(c, 1).utilisation_worst, 0.0);
}

TEST(IoModules, TheHeadsAndTheLoadCellMoveAsAGroup) {
  // On bus 1: a second module beside the default loom's three drives and I/O module on bus 0 would be over
  // the 70 % budget (72.1 % with blocking, EMCY headroom and the heartbeats).
  const LoomConfig c =
      parse_loom_config(ext("[io_modules.heads]\nnode = 9\nbus = 1\nsignals = [\"gripper_close\", "
                            "\"cutter\", \"yarn_present\", \"load_cell\"]\n"),
                        "heads.toml");
  EXPECT_EQ(c.io.gripper_close.module, 1);
  EXPECT_EQ(c.io.cutter.module, 1);
  EXPECT_EQ(c.io.yarn_present.module, 1);
  EXPECT_EQ(c.io.wiring.load_cell_module, 1);
  EXPECT_EQ(can_io_buses(c), (std::vector<std::size_t>{0, 1}));
}

TEST(IoModules, ModulesAreNumberedByNameWhateverTheFileOrder) {
  const LoomConfig c =
      parse_loom_config(ext("[io_modules.zeta]\nnode = 8\nbus = 1\nsignals = [\"buzzer\"]\n"
                            "[io_modules.alpha]\nnode = 7\nbus = 1\nsignals = [\"lamp_red\"]\n"),
                        "two.toml");
  ASSERT_EQ(c.io.modules.size(), 2u);
  EXPECT_EQ(c.io.modules[0].name, "alpha");
  EXPECT_EQ(c.io.wiring.lamp_red.module, 1);
  EXPECT_EQ(c.io.wiring.buzzer.module, 2);
}

TEST(IoModules, MistakesAreRefusedAtTheirLine) {
  // An unknown signal, with the known ones.
  const std::string unknown = config_error(ext("[io_modules.p]\nnode = 6\nsignals = [\"lamp_blue\"]\n"));
  EXPECT_NE(unknown.find("loom.toml:4:"), std::string::npos) << unknown;
  EXPECT_NE(
      unknown.find("io_modules.p.signals = [lamp_blue]: \"lamp_blue\" is not an I/O signal; the signals are "
                   "piston_a_extended"),
      std::string::npos)
      << unknown;
  // One signal on two modules.
  const std::string twice =
      config_error(ext("[io_modules.a]\nnode = 6\nsignals = [\"buzzer\"]\n"
                       "[io_modules.b]\nnode = 7\nsignals = [\"lamp_red\", \"buzzer\"]\n"));
  EXPECT_NE(twice.find("io_modules.b.signals = [lamp_red, buzzer]: \"buzzer\" is already on io_modules.a"),
            std::string::npos)
      << twice;
  EXPECT_NE(config_error(ext("[io_modules.a]\nnode = 6\nsignals = [\"buzzer\", \"buzzer\"]\n"))
                .find("listed twice"),
            std::string::npos);
  EXPECT_NE(config_error(ext("[io_modules.a]\nnode = 6\nsignals = []\n")).find("at least one signal"),
            std::string::npos);
  EXPECT_NE(
      config_error(ext("[io_modules.a]\nsignals = [\"buzzer\"]\n")).find("io_modules.a.node = (missing)"),
      std::string::npos)
      << config_error(ext("[io_modules.a]\nsignals = [\"buzzer\"]\n"));
  EXPECT_NE(config_error(ext("[io_modules.a]\nnode = 6\n")).find("io_modules.a.signals = (missing)"),
            std::string::npos);
  EXPECT_NE(config_error(ext("[io_modules.a]\nnode = 6\nbus = 4\nsignals = [\"buzzer\"]\n"))
                .find("io_modules.a.bus"),
            std::string::npos);
  EXPECT_NE(
      config_error(ext("[io_modules.Panel]\nnode = 6\nsignals = [\"buzzer\"]\n")).find("a module name is"),
      std::string::npos);
  EXPECT_NE(config_error(ext("[io_modules.a]\nnode = 6\ncolour = 3\nsignals = [\"buzzer\"]\n"))
                .find("io_modules.a.colour"),
            std::string::npos)
      << config_error(ext("[io_modules.a]\nnode = 6\ncolour = 3\nsignals = [\"buzzer\"]\n"));
  // Node ids are unique per bus: against an axis, the [io] module and another module.
  const std::string axis = config_error(ext("[io_modules.a]\nnode = 2\nsignals = [\"buzzer\"]\n"));
  EXPECT_NE(axis.find("loom.toml:3:8: io_modules.a.node = 2: node id already used by axes.carriage.node"),
            std::string::npos)
      << axis;
  EXPECT_NE(config_error(ext("[io_modules.a]\nnode = 4\nsignals = [\"buzzer\"]\n"))
                .find("io_modules.a.node = 4: node id already used by io.node on bus 0"),
            std::string::npos);
  EXPECT_EQ(config_error(ext("[io_modules.a]\nnode = 2\nbus = 1\nsignals = [\"buzzer\"]\n")),
            "");  // another bus
  // Two signals on one bit of one module: named by module.
  const std::string clash = config_error(
      ext("[io]\nbuzzer_bit = 4\n[io_modules.a]\nnode = 6\nsignals = [\"buzzer\", \"lamp_green\"]\n"));
  EXPECT_NE(
      clash.find("io.buzzer_bit = 4: the I/O module refuses it: io.outputs.buzzer.bit = 4 is already used by "
                 "io.outputs.lamp_green (both on io_modules.a)"),
      std::string::npos)
      << clash;
  // ...while the same bit on two modules is two terminals.
  EXPECT_EQ(
      config_error(ext("[io]\nbuzzer_bit = 0\n[io_modules.a]\nnode = 6\nbus = 1\nsignals = [\"buzzer\"]\n")),
      "");
  // A required signal unwired stays refused whatever module it is on.
  EXPECT_NE(config_error(ext("[io]\nestop_ok_bit = -1\n[io_modules.a]\nnode = 6\nsignals = [\"estop_ok\"]\n"))
                .find("io.inputs.estop_ok.bit = -1: this signal must be wired"),
            std::string::npos);
  // At most three further modules.
  std::string four;
  for (const char* n : {"a", "b", "c", "d"}) {
    four += "[io_modules." + std::string(n) + "]\nnode = " + std::to_string(10 + (n[0] - 'a')) +
            "\nsignals = [\"" +
            std::string(n[0] == 'a'   ? "buzzer"
                        : n[0] == 'b' ? "lamp_red"
                        : n[0] == 'c' ? "lamp_amber"
                                      : "lamp_green") +
            "\"]\n";
  }
  EXPECT_NE(config_error(ext(four)).find("at most 4 I/O modules"), std::string::npos)
      << config_error(ext(four));
}

TEST(IoModules, MovingASignalOrAModuleNeedsARestart) {
  const LoomConfig a = parse_loom_config(ext(kPanel), "a.toml");
  LoomConfig b = parse_loom_config(ext(kPanel), "b.toml");
  EXPECT_EQ(restart_only_changes(a, b), "");
  b = parse_loom_config(ext("[io_modules.panel]\nnode = 7\nbus = 1\nsignals = [\"buzzer\"]\n"), "b.toml");
  EXPECT_NE(restart_only_changes(a, b).find("io_modules [panel node 6 bus 1"), std::string::npos)
      << restart_only_changes(a, b);
}

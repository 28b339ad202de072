// No silent simulation on hardware: the CAN HAL with simulated I/O is refused (ConfigError, before any
// bus is opened) unless the command line asked for it, and then the machine carries the banner the
// caller prints on every start. Needs no CAN: the refusal comes first, and an interface that does not
// exist shows how far assembly got.
#include <gtest/gtest.h>

#include <string>

#include "loom/config/config.hpp"
#include "loom/firmware/machine.hpp"

namespace loom::firmware {
namespace {

MachineOptions can_options(std::optional<IoKind> io) {
  MachineOptions o;
  o.hal = HalKind::kSocketCan;
  o.iface = "nosuchcan7";
  o.telemetry = false;
  o.io = io;
  return o;
}

TEST(IoKind, SimulatedIoBesideCanDrivesIsRefusedUnlessAskedOnTheCommandLine) {
  LoomConfig cfg = default_loom_config();
  cfg.io.kind = IoKind::kSimulated;
  try {
    Machine m(cfg, default_scene(), can_options(std::nullopt), {});
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("io.kind = \"simulated\" with the CAN HAL"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--io simulated"), std::string::npos) << msg;
  }
  // --io can overrides the config the safe way: assembly goes on to the interface (which is missing).
  try {
    Machine m(cfg, default_scene(), can_options(IoKind::kCan), {});
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    FAIL() << "refused as config: " << e.what();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "CAN interface 'nosuchcan7' does not exist");
  }
}

TEST(IoKind, ExplicitSimulatedIoGetsPastTheRefusal) {
  LoomConfig cfg = default_loom_config();
  cfg.io.kind = IoKind::kCan;
  try {
    Machine m(cfg, default_scene(), can_options(IoKind::kSimulated), {});
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    FAIL() << "refused as config: " << e.what();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "CAN interface 'nosuchcan7' does not exist");
  }
  EXPECT_NE(std::string(kSimulatedIoBanner).find("SIMULATED I/O"), std::string::npos);
  EXPECT_NE(std::string(kSimulatedIoBanner).find("interlocks are not protecting anything"),
            std::string::npos);
}

// --iface names one interface per bus, bus 0 first; a count that does not match the machine's buses is
// refused before any interface is opened, and the second name is the one opened for bus 1.
TEST(Iface, OneInterfacePerBusCommaSeparated) {
  const LoomConfig four = parse_loom_config(
      "extends = \"default\"\n[axes.take_up]\nrole = \"auxiliary\"\nbus = 1\nnode = 5\ncounts_per_rev = "
      "4096\n"
      "max_speed = 2.0\nferror_min = 0.1\nreferencing = \"absolute\"\n",
      "four.toml");
  const auto error_of = [&](const std::string& iface) -> std::string {
    MachineOptions o = can_options(IoKind::kCan);
    o.iface = iface;
    try {
      Machine m(four, default_scene(), o, {});
    } catch (const std::exception& e) {
      return e.what();
    }
    return "accepted";
  };
  std::string e = error_of("nosuchcan7");
  EXPECT_NE(e.find("--iface \"nosuchcan7\" names 1 interface(s), but four.toml puts its axes and I/O modules "
                   "on 2 CAN bus(es)"),
            std::string::npos)
      << e;
  e = error_of("nosuchcan7,nosuchcan7");
  EXPECT_NE(e.find("nosuchcan7 is named twice"), std::string::npos) << e;
  e = error_of("nosuchcan7,");
  EXPECT_NE(e.find("interface 1 has no name"), std::string::npos) << e;
  e = error_of("nosuchcan7,nosuchcan8");  // the right count: assembly goes on to the first interface
  EXPECT_EQ(e, "CAN interface 'nosuchcan7' does not exist");
}

TEST(IoKind, BadWiringIsAConfigErrorAtTheLineThatIsWrong) {
  // Checked when the file is read (exit 2), not when the bus is opened.
  const auto error_of = [](const std::string& text) {
    try {
      (void)parse_loom_config(text, "loom.toml");
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string e = error_of("extends = \"default\"\n[io]\nbutton_ack_bit = 6\n");
  EXPECT_EQ(e.rfind("loom.toml:3:18: io.button_ack_bit = 6:", 0), 0u) << e;
  EXPECT_NE(e.find("io.inputs.button_ack.bit = 6 is already used by io.inputs.estop_ok"), std::string::npos)
      << e;
  EXPECT_EQ(error_of("extends = \"default\"\n[io]\nnode = 2\n"),
            "loom.toml:3:8: io.node = 2: node id already used by axes.carriage.node");
}

}  // namespace
}  // namespace loom::firmware

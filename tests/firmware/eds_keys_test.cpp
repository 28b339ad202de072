// The machine description names each node's EDS (axes.<name>.eds, io.eds, io_modules.<name>.eds): the
// path relative to the loom file, a file that cannot be used refused at its key with the EDS's
// file:line, a key the EDS contradicts refused at that key's line with the EDS's file:line, and each
// node's DCF read back by the project's own reader to the same configuration. On the hand-written
// vendor-style files of tests/drivers/eds (their facts read off the files, not off the reader).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "config_error.hpp"
#include "loom/config/config.hpp"
#include "loom/config/eds_nodes.hpp"
#include "loom/drivers/eds.hpp"
#include "loom/drivers/eds_dcf.hpp"
#include "loom/drivers/node_description.hpp"

using namespace loom::firmware;
namespace eds = loom::drivers::eds;
using loom::test::config_error;

namespace {

const std::string kDir = LOOM_EDS_DIR;
// A loom file that sits beside the EDS files, so its relative paths name them.
const std::string kSource = kDir + "/loom.toml";

std::string ext(const std::string& body) {
  return "extends = \"default\"\n" + body;
}

std::string axis_eds(const std::string& axis, const std::string& file) {
  return "[axes." + axis + "]\neds = \"" + file + "\"\n";
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST(EdsKeys, ARelativePathIsTheLoomFilesFolders) {
  const LoomConfig c = parse_loom_config(ext(axis_eds("beat_crank", "acme_ax400_dynamic.eds")), kSource);
  EXPECT_EQ(c.axes[0].eds, kDir + "/acme_ax400_dynamic.eds");
  EXPECT_TRUE(c.axes[1].eds.empty());
  // An absolute path stays as it is; the module keys read the same way.
  const LoomConfig m =
      parse_loom_config(ext("[io]\neds = \"" + kDir + "/tecto_io16.eds\"\n"), "/elsewhere/x.toml");
  EXPECT_EQ(m.io.eds, kDir + "/tecto_io16.eds");
}

TEST(EdsKeys, ChangingAnEdsNeedsARestart) {
  const LoomConfig a = parse_loom_config(ext(""), kSource);
  const LoomConfig b = parse_loom_config(ext(axis_eds("helix", "brick_bx2_fixed.eds")), kSource);
  EXPECT_TRUE(has(restart_only_changes(a, b), "brick_bx2_fixed.eds"));
}

TEST(EdsKeys, AMissingOrMalformedFileIsRefusedAtItsKeyWithTheEdsLine) {
  const std::string missing = config_error(ext(axis_eds("carriage", "no_such.eds")), kSource);
  EXPECT_TRUE(has(missing, "loom.toml:3:7: axes.carriage.eds = \"" + kDir + "/no_such.eds\"")) << missing;

  const std::string path =
      (std::filesystem::path(testing::TempDir()) / "broken.eds").lexically_normal().string();
  {
    std::ofstream f(path);
    f << "[DeviceInfo]\nVendorNumber=1\n\n[1000\nDataType=0x0007\n";  // a section header without ']'
  }
  const std::string broken = config_error(ext(axis_eds("carriage", path)), kSource);
  EXPECT_TRUE(has(broken, "axes.carriage.eds = \"" + path + "\"")) << broken;
  EXPECT_TRUE(has(broken, path + ":4: error:")) << broken;
}

TEST(EdsKeys, AHeartbeatOutsideTheDrivesLimitsIsRefusedAtTheHeartbeatKey) {
  // stepwise_sd7_no_csp.eds line 66: LowLimit=500 of 0x1017.
  const std::string e = config_error(ext("[can]\nheartbeat_ms = 100\nheartbeat_timeout_ms = 250\n" +
                                         axis_eds("carriage", "stepwise_sd7_no_csp.eds")),
                                     kSource);
  EXPECT_TRUE(has(e, "loom.toml:3:16: can.heartbeat_ms = 100")) << e;
  EXPECT_TRUE(has(e, kDir + "/stepwise_sd7_no_csp.eds:66")) << e;
}

TEST(EdsKeys, HomingOnADriveWithoutAHomingModeIsRefusedAtReferencing) {
  // brick_bx2_fixed.eds line 393: 0x6502 = 128 (CSP only).
  const std::string e = config_error(ext("[axes.carriage]\n"
                                         "eds = \"brick_bx2_fixed.eds\"\n"
                                         "referencing = \"homing\"\n"
                                         "homing_method = 37\n"
                                         "home_offset = 0.0\n"
                                         "homing_speed = 0.01\n"
                                         "homing_accel = 0.1\n"
                                         "homing_timeout_s = 10\n"),
                                     kSource);
  EXPECT_TRUE(has(e, "loom.toml:4:15: axes.carriage.referencing = \"homing\"")) << e;
  EXPECT_TRUE(has(e, kDir + "/brick_bx2_fixed.eds:393")) << e;
  EXPECT_TRUE(has(e, "(CSP)")) << e;
  // The same axis on a drive with HM is accepted.
  EXPECT_EQ(config_error(ext("[axes.carriage]\n"
                             "eds = \"acme_ax400_dynamic.eds\"\n"
                             "referencing = \"homing\"\n"
                             "homing_method = 37\n"
                             "home_offset = 0.0\n"
                             "homing_speed = 0.01\n"
                             "homing_accel = 0.1\n"
                             "homing_timeout_s = 10\n"),
                         kSource),
            "");
}

TEST(EdsKeys, ADrivesFileForTheModuleAndTheOtherWayRoundAreRefused) {
  const std::string io = config_error(ext("[io]\neds = \"acme_ax400_dynamic.eds\"\n"), kSource);
  EXPECT_TRUE(has(io, "io.eds = \"" + kDir + "/acme_ax400_dynamic.eds\"")) << io;
  EXPECT_TRUE(has(io, "is CiA 402 (a drive), not an I/O module")) << io;
  const std::string axis = config_error(ext(axis_eds("helix", "tecto_io16.eds")), kSource);
  EXPECT_TRUE(has(axis, "axes.helix.eds")) << axis;
  EXPECT_TRUE(has(axis, "is CiA 401 (an I/O module), not a drive")) << axis;
}

TEST(EdsKeys, ALoadCellChannelTheModuleLacksIsRefused) {
  // tecto_io16.eds: 0x6401 CompactSubObj=2 (line 487).
  const std::string e = config_error(ext("[io]\neds = \"tecto_io16.eds\"\nload_cell_channel = 3\n"), kSource);
  EXPECT_TRUE(has(e, "io.load_cell_channel = 3")) << e;
  EXPECT_TRUE(has(e, kDir + "/tecto_io16.eds:487")) << e;
  EXPECT_EQ(config_error(ext("[io]\neds = \"tecto_io16.eds\"\nload_cell_channel = 2\n"), kSource), "");
}

TEST(EdsNodes, CheckReportsWhatTheModuleLacksWithTheEdsLine) {
  const LoomConfig c = parse_loom_config(ext("[io]\neds = \"tecto_io16.eds\"\n"), kSource);
  const std::vector<EdsNode> nodes = eds_nodes(c);
  ASSERT_EQ(nodes.size(), 1u);
  EXPECT_EQ(nodes[0].key, "io");
  EXPECT_FALSE(nodes[0].check.ok());  // the default wiring's second channels need 0x6000:03
  bool named = false;
  for (const eds::Finding& f : nodes[0].check.findings) {
    const std::string line = eds::format(nodes[0].eds, nodes[0].needs, f);
    if (f.level == eds::Level::kError && has(line, "0x6000:03")) named = has(line, "tecto_io16.eds:");
  }
  EXPECT_TRUE(named);
  EXPECT_TRUE(nodes[0].writes.empty());
}

// What `loomctl dcf` writes, read back strictly by the project's reader: the same node id and the same
// configuration (every write the loom makes on a writable entry), for a dynamic and a fixed mapping.
TEST(EdsNodes, EachNodesDcfReadsBackToTheSameConfiguration) {
  const LoomConfig c = parse_loom_config(
      ext(axis_eds("beat_crank", "acme_ax400_dynamic.eds") + axis_eds("helix", "brick_bx2_fixed.eds")),
      kSource);
  const std::vector<EdsNode> nodes = eds_nodes(c);
  ASSERT_EQ(nodes.size(), 2u);
  for (const EdsNode& n : nodes) {
    SCOPED_TRACE(n.key);
    ASSERT_TRUE(n.check.ok());
    ASSERT_FALSE(n.writes.empty());
    const eds::Description dcf = eds::read_eds(dcf_text(c, n), n.key + ".dcf", eds::ReadOptions{true});
    // None of the EDS's deviations in form; a DefaultValue outside its own limits (acme's 0x1017 = 0 under
    // LowLimit 10, as the vendor wrote it) is the only thing a DCF carries over.
    for (const eds::Diagnostic& d : dcf.diagnostics) {
      if (!has(d.message, "DefaultValue") || !has(d.message, "outside LowLimit..HighLimit"))
        ADD_FAILURE() << eds::format(dcf.file, d);
    }
    EXPECT_EQ(dcf.commissioning.node_id, n.node_id);
    EXPECT_EQ(dcf.commissioning.baud_rate_kbit, c.can.bitrate / 1000u);
    std::vector<eds::SdoWrite> expected;
    for (const eds::SdoWrite& w : n.writes) {
      const eds::Entry* e = n.eds.entry(w.index, w.sub);
      if (e != nullptr && eds::writable(e->access)) expected.push_back(w);
    }
    EXPECT_EQ(eds::parameter_writes(dcf, n.node_id), expected);
    // And the node the DCF describes is the EDS's node.
    EXPECT_EQ(eds::profile_of(dcf).fixed_mapping, n.check.profile.fixed_mapping);
  }
}

TEST(EdsKeys, SixteenBitInputGroupsComeFromTheModulesEdsAndAKeyItContradictsIsRefused) {
  // kordis_dio32w.eds: inputs as 0x6100:01..02 only ([6100], CompactSubObj=2).
  const LoomConfig c = parse_loom_config(ext("[io]\neds = \"kordis_dio32w.eds\"\n"), kSource);
  EXPECT_EQ(c.io.input_group_bits, 0);  // not said: the EDS decides
  const std::vector<loom::drivers::CanIoConfig> modules = can_io_configs(c);
  EXPECT_EQ(modules[0].input_group_bits, 16);
  const std::vector<EdsNode> nodes = eds_nodes(c);
  ASSERT_EQ(nodes.size(), 1u);
  EXPECT_TRUE(nodes[0].check.ok());
  // 0x6100:03 (bits 32..47) is not in the file: a yarn-present switch on bit 40 cannot be read.
  const std::string e = config_error(
      ext("[io]\neds = \"kordis_dio32w.eds\"\ninput_group_bits = 16\nrow_knotted_bit = 40\n"), kSource);
  EXPECT_TRUE(has(e, "io.input_group_bits = 16")) << e;
  EXPECT_TRUE(has(e, "kordis_dio32w.eds:")) << e;
  EXPECT_TRUE(has(e, "0x6100:03")) << e;
  // 8-bit groups asked of a module that has none.
  const std::string eight =
      config_error(ext("[io]\neds = \"kordis_dio32w.eds\"\ninput_group_bits = 8\n"), kSource);
  EXPECT_TRUE(has(eight, "io.input_group_bits = 8")) << eight;
  EXPECT_TRUE(has(eight, "has no 0x6000")) << eight;
  // Without an EDS the key says it; 12 is no CiA 401 form.
  const LoomConfig k = parse_loom_config(ext("[io]\ninput_group_bits = 16\n"), kSource);
  EXPECT_EQ(can_io_configs(k)[0].input_group_bits, 16);
  EXPECT_TRUE(has(config_error(ext("[io]\ninput_group_bits = 12\n"), kSource), "io.input_group_bits = 12"));
}

TEST(EdsKeys, StoreConfigNeedsAnEdsWithAWritable1010) {
  const LoomConfig c =
      parse_loom_config(ext("[io]\neds = \"kordis_dio32w.eds\"\nstore_config = true\n"), kSource);
  ASSERT_NE(can_io_configs(c)[0].description, nullptr);
  EXPECT_TRUE(can_io_configs(c)[0].description->store);
  // tecto_io16.eds has no 0x1010; no EDS at all cannot say so either.
  const std::string none =
      config_error(ext("[io]\neds = \"tecto_io16.eds\"\nstore_config = true\n"), kSource);
  EXPECT_TRUE(has(none, "io.store_config = true")) << none;
  EXPECT_TRUE(has(none, "tecto_io16.eds: the node has no 0x1010 store parameters")) << none;
  const std::string bare = config_error(ext("[axes.helix]\nstore_config = true\n"), kSource);
  EXPECT_TRUE(has(bare, "axes.helix.store_config = true")) << bare;
  EXPECT_TRUE(has(bare, "needs axes.helix.eds")) << bare;
}

// The comparison of an EDS with what the loom needs of a node (tests/drivers/eds/, written by hand from
// CiA 306/301/402/401): which findings each file gets and at which line. The expectations come from
// reading the files: which objects, limits, mappings and 0x6502 bits each was written with.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>

#include "loom/drivers/eds_check.hpp"
#include "text_file.hpp"

namespace loom::drivers::eds {
namespace {

std::string path_of(const std::string& name) {
  return std::string(LOOM_EDS_DIR) + "/" + name;
}

std::string text_of(const std::string& name) {
  return loom::test::read_text_file(path_of(name));
}

int line_of(const std::string& text, const std::string& needle, const std::string& after = "") {
  const std::size_t from = after.empty() ? 0 : text.find(after);
  const std::size_t at = text.find(needle, from);
  if (at == std::string::npos) return -1;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

std::vector<Finding> of_level(const NodeCheck& c, Level level) {
  std::vector<Finding> out;
  std::copy_if(c.findings.begin(), c.findings.end(), std::back_inserter(out),
               [&](const Finding& f) { return f.level == level; });
  return out;
}

std::string all(const Description& d, const NodeNeeds& n, const NodeCheck& c) {
  std::string s;
  for (const Finding& f : c.findings) s += format(d, n, f) + "\n";
  return s;
}

CanAxisPortConfig port() {
  CanAxisPortConfig p;  // 2 ms cycle, 100 ms heartbeat, master node 127
  return p;
}

TEST(EdsCheck, TheDynamicDriveOffersEverythingEvenHomingAndTpdo2) {
  const Description d = read_eds_file(path_of("acme_ax400_dynamic.eds"));
  CanAxisPortConfig p = port();
  p.tpdo2 = true;
  CanAxisConfig axis = p.axes[1];
  axis.homing_method = 34;  // index pulse; 0x6098 limits are -4..37
  const NodeNeeds needs = drive_needs(axis, p);
  const NodeCheck c = check_node(d, needs);
  EXPECT_TRUE(c.ok()) << all(d, needs, c);
  EXPECT_TRUE(of_level(c, Level::kError).empty());
  // The profile the config would otherwise have to state.
  EXPECT_EQ(c.profile.rpdos, 4);
  EXPECT_EQ(c.profile.tpdos, 4);
  EXPECT_EQ(c.profile.rpdo1, MappingKind::kDynamic);
  EXPECT_FALSE(c.profile.fixed_mapping);
  EXPECT_TRUE(c.profile.consumer_heartbeat);
  EXPECT_TRUE(c.profile.csp);
  EXPECT_TRUE(c.profile.homing);
  EXPECT_EQ(c.profile.device_type, 0x00020192u);
  EXPECT_EQ(c.profile.vendor, 0x4A2u);
  EXPECT_EQ(c.profile.product, 0x401234u);
  EXPECT_EQ(c.profile.revision, 0x20001u);
  // The loom says what it will use: the modes note is at 0x6502's DefaultValue line.
  const std::string text = text_of("acme_ax400_dynamic.eds");
  const auto modes = std::find_if(c.findings.begin(), c.findings.end(),
                                  [](const Finding& f) { return f.message.rfind("0x6502 offers", 0) == 0; });
  ASSERT_NE(modes, c.findings.end());
  EXPECT_EQ(modes->message, "0x6502 offers PP, PV, HM, CSP");
  EXPECT_EQ(modes->line, line_of(text, "DefaultValue=0x000000A5"));
}

TEST(EdsCheck, AHomingMethodOutsideTheDrivesLimitsIsRefusedAtTheLimitsLine) {
  const Description d = read_eds_file(path_of("acme_ax400_dynamic.eds"));
  CanAxisConfig axis = port().axes[0];
  axis.homing_method = 35 + 3;  // 38 > HighLimit 37
  const NodeNeeds needs = drive_needs(axis, port());
  const NodeCheck c = check_node(d, needs);
  const std::vector<Finding> errors = of_level(c, Level::kError);
  ASSERT_EQ(errors.size(), 1u) << all(d, needs, c);
  const std::string text = text_of("acme_ax400_dynamic.eds");
  EXPECT_EQ(errors[0].line, line_of(text, "HighLimit=37"));
  EXPECT_EQ(
      format(d, needs, errors[0]),
      d.file + ":" + std::to_string(errors[0].line) +
          ": error: axes.beat_crank (node 1): 0x6098 homing method: the loom writes 38, outside the EDS's "
          "limits -4..37 — choose a homing method the drive offers");
}

TEST(EdsCheck, TheFixedDriveCarriesTheLoomsLayoutButNotTheHomingOne) {
  const std::string name = "brick_bx2_fixed.eds";
  const std::string text = text_of(name);
  const Description d = read_eds_file(path_of(name));
  CanAxisPortConfig p = port();
  p.tpdo2 = true;
  {
    const NodeNeeds needs = drive_needs(p.axes[2], p);
    const NodeCheck c = check_node(d, needs);
    EXPECT_TRUE(c.ok()) << all(d, needs, c);
    EXPECT_TRUE(c.profile.fixed_mapping);
    EXPECT_EQ(c.profile.rpdo1, MappingKind::kFixed);
    EXPECT_EQ(c.profile.tpdo2, MappingKind::kFixed);
    EXPECT_FALSE(c.profile.consumer_heartbeat);
    EXPECT_FALSE(c.profile.homing);
    // The absent 0x1016 is a warning (optional), at no line: the file does not have it.
    const std::vector<Finding> w = of_level(c, Level::kWarning);
    EXPECT_TRUE(std::any_of(w.begin(), w.end(), [](const Finding& f) {
      return f.message.rfind("0x1016:01 consumer heartbeat time is not in the file", 0) == 0 && f.line == 0;
    })) << all(d, needs, c);
  }
  // referencing by homing: 0x6502 = 128 (CSP only), no homing objects, and the 7-byte layouts do not fit
  // the fixed 6-byte mapping.
  CanAxisConfig axis = p.axes[2];
  axis.homing_method = 37;
  const NodeNeeds needs = drive_needs(axis, p);
  const NodeCheck c = check_node(d, needs);
  EXPECT_FALSE(c.ok());
  std::vector<std::string> errors;
  for (const Finding& f : of_level(c, Level::kError)) errors.push_back(f.message);
  const std::vector<std::string> expected{
      "0x607C home offset is not in the file (th", "0x6098 homing method is not in the file (",
      "0x6099:01 homing speeds is not in the fil", "0x6099:02 homing speeds is not in the fil",
      "0x609A homing acceleration is not in the ", "RPDO1 {0x6040:00/16, 0x607A:00/32, 0x606",
      "TPDO1 {0x6041:00/16, 0x6064:00/32, 0x606",  "0x6502 supported drive modes 0x00000080 ",
  };
  ASSERT_EQ(errors.size(), expected.size()) << all(d, needs, c);
  for (std::size_t k = 0; k < expected.size(); ++k)
    EXPECT_EQ(errors[k].rfind(expected[k], 0), 0u) << errors[k];
  const std::vector<Finding> e = of_level(c, Level::kError);
  EXPECT_EQ(e[5].line, line_of(text, "[1600]"));
  EXPECT_EQ(e[5].remedy, "use an absolute encoder (no homing: 6-byte PDOs) or a drive with dynamic mapping");
  EXPECT_EQ(e[7].line, line_of(text, "DefaultValue=128"));
  EXPECT_EQ(e[7].message, "0x6502 supported drive modes 0x00000080 (CSP) lacks HM");
}

TEST(EdsCheck, ADriveWithoutCspIsRefusedWithEveryReason) {
  const std::string name = "stepwise_sd7_no_csp.eds";
  const std::string text = text_of(name);
  const Description d = read_eds_file(path_of(name));
  ASSERT_FALSE(d.has_errors());
  const NodeNeeds needs = drive_needs(port().axes[1], port());
  const NodeCheck c = check_node(d, needs);
  const std::vector<Finding> e = of_level(c, Level::kError);
  ASSERT_EQ(e.size(), 6u) << all(d, needs, c);
  // 0x1017 LowLimit=500 > the loom's 100 ms.
  EXPECT_EQ(e[0].line, line_of(text, "LowLimit=500"));
  EXPECT_EQ(e[0].message,
            "0x1017 producer heartbeat time: the loom writes 100, outside the EDS's limits 500..65535");
  EXPECT_EQ(e[1].message.substr(0, 56), "0x60C2:01 interpolation time period is not in the file (");
  EXPECT_EQ(e[2].message.substr(0, 56), "0x60C2:02 interpolation time period is not in the file (");
  EXPECT_EQ(e[3].line, line_of(text, "[1600]"));
  EXPECT_EQ(
      e[3].message,
      "RPDO1 {0x6040:00/16, 0x607A:00/32} (controlword + target position every SYNC): RPDO1 mapping is fixed "
      "to {0x6040:00/16, 0x60FF:00/32}");
  EXPECT_EQ(e[4].line, line_of(text, "[1A00]"));
  EXPECT_EQ(e[5].line, line_of(text, "DefaultValue=0x00000005"));
  EXPECT_EQ(e[5].message, "0x6502 supported drive modes 0x00000005 (PP, PV) lacks CSP");
  EXPECT_NE(e[5].remedy.find("CSP"), std::string::npos);
  // The 5:1 gear ratio is a warning: positions are not encoder increments.
  const std::vector<Finding> w = of_level(c, Level::kWarning);
  EXPECT_TRUE(std::any_of(w.begin(), w.end(), [&](const Finding& f) {
    return f.line == line_of(text, "[6091]") && f.message.find("gear ratio 5/1") != std::string::npos;
  })) << all(d, needs, c);
}

TEST(EdsCheck, AnIoModuleWithTwoInputGroupsServesAWiringWithinThem) {
  const std::string name = "tecto_io16.eds";
  const std::string text = text_of(name);
  const Description d = read_eds_file(path_of(name));
  CanIoConfig io;  // default wiring: second switches on bits 16..21 need 0x6000:03
  {
    const NodeNeeds needs = io_module_needs(io);
    const NodeCheck c = check_node(d, needs);
    const std::vector<Finding> e = of_level(c, Level::kError);
    ASSERT_EQ(e.size(), 1u) << all(d, needs, c);
    EXPECT_EQ(e[0].line, line_of(text, "[6000]"));
    EXPECT_EQ(e[0].message.substr(0, 55), "0x6000:03 read digital inputs, 8-bit has no sub-index 3");
    // Its 0x6100 (16-bit groups) has sub 1 only: no other form of bits 16..21 either.
    EXPECT_EQ(
        e[0].remedy,
        "the file has no 16-bit group 0x6100:02 for these inputs either: wire the signals to lower bits "
        "(fewer groups) or choose a module with more I/O");
  }
  for (IoBit& b : io.wiring.second) b = IoBit{};  // single-channel sensors: inputs 0..11, two groups
  const NodeNeeds needs = io_module_needs(io);
  const NodeCheck c = check_node(d, needs);
  EXPECT_TRUE(c.ok()) << all(d, needs, c);
  const std::vector<Finding> notes = of_level(c, Level::kInfo);
  const auto carries = [&](const std::string& what) {
    return std::any_of(notes.begin(), notes.end(), [&](const Finding& f) { return f.message == what; });
  };
  // Inputs in TPDO1 (dynamic), the load cell in the next free TPDO (TPDO2), outputs in RPDO1.
  EXPECT_TRUE(carries("TPDO1 carries {0x6000:01/8, 0x6000:02/8} (mapping written at bring-up)"))
      << all(d, needs, c);
  EXPECT_TRUE(carries("TPDO2 carries {0x6401:01/16} (mapping written at bring-up)")) << all(d, needs, c);
  EXPECT_TRUE(carries("RPDO1 carries {0x6200:01/8} (mapping written at bring-up)")) << all(d, needs, c);
}

TEST(EdsCheck, ADrivesFileGivenForTheIoModuleIsNamedAsSuch) {
  const Description d = read_eds_file(path_of("brick_bx2_fixed.eds"));
  const NodeNeeds needs = io_module_needs(CanIoConfig{});
  const NodeCheck c = check_node(d, needs);
  const std::vector<Finding> e = of_level(c, Level::kError);
  ASSERT_FALSE(e.empty());
  EXPECT_EQ(e[0].message, "0x1000 device type 0x00020192 is profile 402, not CiA 401");
  EXPECT_EQ(e[0].remedy, "give this module a CiA 401 I/O module's EDS (is this a drive's file?)");
}

TEST(EdsCheck, AnEdsWithReadErrorsIsNotCompared) {
  const Description d = read_eds("[1000]\nParameterName=x\nDataType=7\nAccessType=ro\n", "broken.eds");
  const NodeNeeds needs = drive_needs(port().axes[0], port());
  const NodeCheck c = check_node(d, needs);
  EXPECT_FALSE(c.ok());
  for (const Finding& f : c.findings) EXPECT_EQ(f.message.find("RPDO"), std::string::npos);
  EXPECT_EQ(
      format(d, needs, of_level(c, Level::kError).front()),
      "broken.eds: error: axes.beat_crank (node 1): mandatory object 0x1001 (error register) is missing "
      "(CiA 301) — correct the file (CiA 306)");
}

}  // namespace
}  // namespace loom::drivers::eds

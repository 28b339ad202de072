// axes.<name>.drive_mode: "cyclic" (default) or "profile" (CiA 402 profile position), the colour
// selectors only. Read into the CAN axis configuration with the selectors' own move limits (the ones the
// sequencer plans their moves with); anything else refused at its line naming the field and the value.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "config_error.hpp"
#include "loom/config/config.hpp"
#include "loom/drivers/can_axis_config.hpp"
#include "text_file.hpp"

using namespace loom::firmware;
using loom::test::config_error;

namespace {

const std::string kConfigDir = std::string(LOOM_SOURCE_DIR) + "/firmware/config";

std::string knotting_loom() {
  return loom::test::read_text_file(kConfigDir + "/knotting_loom.toml");
}

// The knotting loom with `line` added to axis `axis`'s table (the table's header line is followed by it).
std::string with(const std::string& axis, const std::string& line) {
  std::string s = knotting_loom();
  const std::string header = "[axes." + axis + "]\n";
  const auto at = s.find(header);
  EXPECT_NE(at, std::string::npos) << header;
  s.insert(at + header.size(), line + "\n");
  return s;
}

const std::string kSource = kConfigDir + "/knotting_loom.toml";

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST(DriveModeKey, DefaultsToCyclicAndProfileMakesTheSelectorAProfilePositionAxis) {
  const LoomConfig plain = parse_loom_config(knotting_loom(), kSource);
  for (const auto& a : can_axis_config(plain).axes)
    EXPECT_EQ(a.mode, loom::drivers::DriveMode::kCyclicPosition);
  EXPECT_EQ(plain.sequencer.heads.selector_settle_s, 0.0);

  const LoomConfig c = parse_loom_config(with("selector_1", "drive_mode = \"profile\""), kSource);
  const auto cc = can_axis_config(c);
  int profile = 0;
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    if (cc.axes[i].mode != loom::drivers::DriveMode::kProfilePosition) continue;
    ++profile;
    EXPECT_EQ(c.axes[i].name, "selector_1");
    // The drive's profile is the selectors' planned one: one fact.
    EXPECT_EQ(cc.axes[i].profile_velocity, c.sequencer.heads.selector.velocity);
    EXPECT_EQ(cc.axes[i].profile_acceleration, c.sequencer.heads.selector.acceleration);
    EXPECT_EQ(cc.axes[i].profile_jerk, c.sequencer.heads.selector.jerk);
    EXPECT_GT(cc.axes[i].profile_velocity, 0.0);
  }
  EXPECT_EQ(profile, 1);
  // The sequencer waits a little longer for a profile-position selector to be measured at its slot.
  EXPECT_GT(c.sequencer.heads.selector_settle_s, c.sequencer.heads.settle_s);
}

TEST(DriveModeKey, AnUnknownModeIsRefusedAtItsLineWithFieldAndValue) {
  const std::string e = config_error(with("selector_2", "drive_mode = \"pp\""), kSource);
  EXPECT_TRUE(has(e, "axes.selector_2.drive_mode")) << e;
  EXPECT_TRUE(has(e, "pp")) << e;
  EXPECT_TRUE(has(e, "knotting_loom.toml:")) << e;
}

TEST(DriveModeKey, ProfileOnAnAxisThatIsNotASelectorIsRefused) {
  const std::string e = config_error(with("knotter_1", "drive_mode = \"profile\""), kSource);
  EXPECT_TRUE(has(e, "axes.knotter_1.drive_mode")) << e;
  EXPECT_TRUE(has(e, "\"profile\"")) << e;
  EXPECT_TRUE(has(e, "the colour selectors")) << e;
  EXPECT_TRUE(has(e, "knotting_loom.toml:")) << e;
  // "cyclic" is fine anywhere.
  EXPECT_EQ(config_error(with("knotter_1", "drive_mode = \"cyclic\""), kSource), "");
}

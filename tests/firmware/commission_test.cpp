// The calibration writer behind `loomctl commission`: it rewrites exactly the chosen values, keeping
// every other byte (comments, spacing, line numbers) as it was, adds what is missing where TOML wants
// it, and refuses lines it cannot rewrite safely. Expected texts are written out by hand.
#include <gtest/gtest.h>

#include "loom/config/config.hpp"
#include "loom/config/toml_edit.hpp"

namespace {

using loom::firmware::set_toml_values;
using loom::firmware::TomlAssignment;

TEST(TomlEdit, ReplacesOnlyTheValueKeepingTheCommentAndEveryOtherLine) {
  const std::string in =
      "# loom 7\n[beatup]\ncrank_park_position_rad = 0.0   # at park\nother = 1\n\n[helix]\n"
      "crank_park_position_rad = 5  # same key, other section: untouched\nleft_position_rad=0.0\n";
  std::vector<std::string> changes;
  const std::string out = set_toml_values(
      in, {{"beatup", "crank_park_position_rad", "1.25"}, {"helix", "left_position_rad", "-3.5"}}, changes);
  EXPECT_EQ(out,
            "# loom 7\n[beatup]\ncrank_park_position_rad = 1.25  # at park\nother = 1\n\n[helix]\n"
            "crank_park_position_rad = 5  # same key, other section: untouched\nleft_position_rad=-3.5\n");
  // The comment keeps its column when the new value fits in the old one's room.
  EXPECT_EQ(out.find("# at park") - out.find("crank_park"), in.find("# at park") - in.find("crank_park"));
  ASSERT_EQ(changes.size(), 2u);
  EXPECT_EQ(changes[0], "3: beatup.crank_park_position_rad = 1.25 (was 0.0)");
  EXPECT_EQ(changes[1], "8: helix.left_position_rad = -3.5 (was 0.0)");
}

TEST(TomlEdit, ALongerValuePushesTheCommentOnAndAHashInAStringIsNotAComment) {
  std::vector<std::string> changes;
  EXPECT_EQ(set_toml_values("[a]\nk = 0 # c\ns = \"x#y\"\n", {{"a", "k", "123.456789"}, {"a", "s", "\"z\""}},
                            changes),
            "[a]\nk = 123.456789 # c\ns = \"z\"\n");
}

TEST(TomlEdit, MissingKeysAndSectionsAreAdded) {
  std::vector<std::string> changes;
  EXPECT_EQ(
      set_toml_values("extends = \"default\"\n[carriage]\nmax_speed_m_s = 1.0\n",
                      {{"carriage", "home_position_m", "0.5"}, {"helix", "left_position_rad", "2"}}, changes),
      "extends = \"default\"\n[carriage]\nhome_position_m = 0.5\nmax_speed_m_s = "
      "1.0\n\n[helix]\nleft_position_rad = 2\n");
  EXPECT_EQ(changes[0], "3: carriage.home_position_m = 0.5 (added)");
  EXPECT_EQ(changes[1], "7: helix.left_position_rad = 2 (added with its section)");
}

TEST(TomlEdit, ValuesItCannotRewriteOnTheirLineAreRefused) {
  std::vector<std::string> changes;
  EXPECT_THROW(set_toml_values("[a]\nk = [1,\n 2]\n", {{"a", "k", "3"}}, changes),
               loom::firmware::ConfigError);
  EXPECT_THROW(set_toml_values("[a]\nk = \"\"\"x\n\"\"\"\n", {{"a", "k", "3"}}, changes),
               loom::firmware::ConfigError);
}

TEST(TomlEdit, TheEmbeddedDefaultStaysAValidLoomWithOnlyTheCalibrationChanged) {
  std::vector<std::string> changes;
  const std::string out = set_toml_values(loom::firmware::kDefaultLoomToml,
                                          {{"beatup", "crank_park_position_rad", "0.75"},
                                           {"carriage", "home_position_m", "0.012"},
                                           {"helix", "left_position_rad", "-1.5"}},
                                          changes);
  const auto cfg = loom::firmware::parse_loom_config(out, "edited.toml");
  EXPECT_DOUBLE_EQ(cfg.machine_spec.calibration.crank_park_position_rad, 0.75);
  EXPECT_DOUBLE_EQ(cfg.machine_spec.calibration.carriage_home_m, 0.012);
  EXPECT_DOUBLE_EQ(cfg.machine_spec.calibration.helix_left_position_rad, -1.5);
  // Same number of lines: every error message's line numbers still point where they did.
  const std::string def = loom::firmware::kDefaultLoomToml;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), std::count(def.begin(), def.end(), '\n'));
}

}  // namespace

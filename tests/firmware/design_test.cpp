// Carpet designs. Truth here is what the file says, written out by hand: the CSV's last line is design
// row 1; a PNG written by libpng's encoder from a known pixel array decodes to exactly those colours,
// bottom pixel row first; every bad file is refused with its file:line:col, field and value.
#include "loom/design/design.hpp"

#include <gtest/gtest.h>
#include <png.h>

#include <filesystem>
#include <fstream>

#include "loom/config/config.hpp"
#include "loom/telemetry/encode.hpp"
#include "test_dir.hpp"

namespace {

using loom::design::Design;
using loom::design::DesignError;
using loom::design::parse_design;
using loom::design::parse_design_csv;

std::vector<std::string> codes(const Design& d, int row) {
  std::vector<std::string> out;
  for (auto k : d.row(row)) out.push_back(d.palette()[k].code);
  return out;
}

std::string error_of(const std::string& text) {
  try {
    parse_design_csv(text, "rug.csv");
  } catch (const DesignError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(DesignCsv, LastLineIsTheFirstRowWoven) {
  const Design d = parse_design_csv(
      "\xEF\xBB\xBF# a comment\r\npalette,R,#9b1b30,madder red\r\npalette , B , #1D3F8A\n\nR,B,R\n B , B "
      ",#c8a040\n",
      "/some/where/rug.csv");
  EXPECT_EQ(d.name(), "rug.csv");
  EXPECT_EQ(d.width(), 3);
  EXPECT_EQ(d.height(), 2);
  EXPECT_EQ(codes(d, 0), (std::vector<std::string>{"B", "B", "#c8a040"}));
  EXPECT_EQ(codes(d, 1), (std::vector<std::string>{"R", "B", "R"}));
  ASSERT_EQ(d.palette().size(), 3u);
  EXPECT_EQ(d.palette()[0].rgb, 0x9b1b30u);
  EXPECT_EQ(d.palette()[0].name, "madder red");
  EXPECT_EQ(d.palette()[1].rgb, 0x1d3f8au);
  EXPECT_EQ(d.palette()[2].rgb, 0xc8a040u);
}

TEST(DesignCsv, EveryRefusalNamesLineColumnAndValue) {
  EXPECT_EQ(error_of("palette,R,#ff0000\nR,R\nR,X\n"),
            "rug.csv:3:3: colour code 'X' is not in the palette (the palette has R); define it with "
            "palette,X,#RRGGBB");
  EXPECT_EQ(error_of("palette,R,#ff0000\nR,R\nR\n"),
            "rug.csv:3:1: row of 1 knots; the design's rows have 2 (every row the same width)");
  EXPECT_EQ(error_of("palette,R,#ff0000\nR,,R\n"), "rug.csv:2:3: empty cell: every knot needs a colour code");
  EXPECT_EQ(error_of("palette,R,#ff0000\npalette,R,#00ff00\n"),
            "rug.csv:2:9: palette code 'R' defined twice");
  EXPECT_EQ(error_of("palette,R,#ff0000\nR\npalette,B,#0000ff\n"),
            "rug.csv:3:1: palette line after the grid began (define every code before the first row)");
  EXPECT_EQ(error_of("palette,R,red\n"), "rug.csv:1:11: colour of 'R' = 'red': want #RRGGBB");
  EXPECT_EQ(error_of("# only a comment\n"),
            "rug.csv:2:1: no rows of knots (a design needs at least one grid line)");
  EXPECT_EQ(error_of(""), "rug.csv:1:1: no rows of knots (a design needs at least one grid line)");
  EXPECT_NE(error_of("palette,R,#ff0000\nR,R\x01\n").find("rug.csv:2:4: control character 0x01"),
            std::string::npos);
  EXPECT_NE(error_of("palette,R,#ff0000\nR,red yarn\n")
                .find("rug.csv:2:3: colour code 'red yarn': want 1..16 letters"),
            std::string::npos);
  EXPECT_NE(error_of("palette,#abcdef,#ff0000\n").find("rug.csv:1:9: palette code '#abcdef' starts with '#'"),
            std::string::npos);
}

TEST(DesignCsv, BoundsAreChecked) {
  std::string wide;
  for (int i = 0; i <= loom::design::kMaxWidth; ++i) wide += i ? ",#000000" : "#000000";
  EXPECT_NE(error_of(wide + "\n").find("4001 knots per row: more than 4000"), std::string::npos)
      << error_of(wide + "\n");
  std::string many;
  for (int i = 0; i <= loom::design::kMaxColours; ++i) {
    char cell[16];
    std::snprintf(cell, sizeof cell, "%s#%06x", i ? "," : "", i);
    many += cell;
  }
  EXPECT_NE(error_of(many + "\n").find("more than 256 colours in one design"), std::string::npos)
      << error_of(many + "\n");
}

// A PNG from libpng's encoder (independent of the decoder under test): 3 x 2 pixels, RGB.
std::string png_of(int w, int h, const std::vector<std::uint8_t>& rgb) {
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  img.width = static_cast<png_uint_32>(w);
  img.height = static_cast<png_uint_32>(h);
  img.format = PNG_FORMAT_RGB;
  png_alloc_size_t size = 0;
  EXPECT_NE(png_image_write_to_memory(&img, nullptr, &size, 0, rgb.data(), 0, nullptr), 0);
  std::string out(size, '\0');
  EXPECT_NE(png_image_write_to_memory(&img, out.data(), &size, 0, rgb.data(), 0, nullptr), 0);
  out.resize(size);
  return out;
}

TEST(DesignPng, OnePixelPerKnotBottomRowFirst) {
  // Top pixel row: red, red, white; bottom: blue, white, red.
  const std::string png =
      png_of(3, 2, {255, 0, 0, 255, 0, 0, 255, 255, 255, 0, 0, 255, 255, 255, 255, 255, 0, 0});
  const Design d = parse_design(png, "dir/medallion.PNG");
  EXPECT_EQ(d.name(), "medallion.PNG");
  EXPECT_EQ(d.width(), 3);
  EXPECT_EQ(d.height(), 2);
  EXPECT_EQ(codes(d, 0), (std::vector<std::string>{"#0000ff", "#ffffff", "#ff0000"}));
  EXPECT_EQ(codes(d, 1), (std::vector<std::string>{"#ff0000", "#ff0000", "#ffffff"}));
}

TEST(DesignPng, PhotographsAndNonPngsAreRefused) {
  std::vector<std::uint8_t> photo;
  for (int i = 0; i < 300; ++i)
    photo.insert(photo.end(), {static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(i / 256), 7});
  try {
    parse_design(png_of(300, 1, photo), "photo.png");
    FAIL() << "accepted";
  } catch (const DesignError& e) {
    EXPECT_NE(std::string(e.what()).find("photo.png: more than 256 distinct colours (pixel 256,0)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(parse_design("not a png", "x.png"), DesignError);
  EXPECT_THROW(parse_design("R\n", "x.txt"), DesignError);
}

TEST(DesignPosition, RepeatsAfterTheLastRow) {
  const Design d = parse_design_csv("palette,R,#ff0000\nR\nR\nR\n", "r.csv");
  EXPECT_EQ(loom::design::position_after(d, 0).row, 0);
  EXPECT_EQ(loom::design::position_after(d, 2).row, 2);
  EXPECT_EQ(loom::design::position_after(d, 3).row, 0);
  EXPECT_EQ(loom::design::position_after(d, 3).repeat, 2);
  // The repeat saturates, never wraps: one row and 2^64-1 rows done used to give repeat 0 (fuzz_design).
  const Design one = parse_design_csv("palette,R,#ff0000\nR\n", "one.csv");
  EXPECT_EQ(loom::design::position_after(one, UINT64_MAX).repeat, INT32_MAX);
  EXPECT_EQ(loom::design::position_after(one, UINT64_MAX).row, 0);
}

TEST(DesignTelemetry, CarriesTheRowKnottedLastTheNextAndTwoAfter) {
  const Design d =
      parse_design_csv("palette,A,#000001\npalette,B,#000002\npalette,C,#000003\nC,C\nB,B\nA,B\n", "d.csv");
  auto m = loom::telemetry::to_design(d, 0, "loom1", 5);
  EXPECT_EQ(m.next_row, 1);
  EXPECT_EQ(m.repeat, 1);
  EXPECT_EQ(m.next_index, 0);  // nothing knotted yet: no row below
  EXPECT_EQ(m.row_number, (std::vector<std::int32_t>{1, 2, 3}));
  EXPECT_EQ(m.knots[0], (std::vector<std::int16_t>{0, 1}));
  EXPECT_EQ(m.rgb, (std::vector<std::int32_t>{1, 2, 3}));
  m = loom::telemetry::to_design(d, 2, "loom1", 5);  // rows 1-2 woven: row 3 next, then the design repeats
  EXPECT_EQ(m.next_row, 3);
  EXPECT_EQ(m.next_index, 1);
  EXPECT_EQ(m.row_number, (std::vector<std::int32_t>{2, 3, 1, 2}));
  EXPECT_EQ(m.n_rows, 4);
  EXPECT_EQ(m.knots[1], (std::vector<std::int16_t>{2, 2}));
}

class DesignFiles : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = loom::test::fresh_test_dir("design_files"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(DesignFiles, ConfigLoadsTheDesignBesideItAndReportsItsLine) {
  std::ofstream(dir_ / "rug.csv") << "palette,R,#ff0000\nR,R\nR,Q\n";
  std::ofstream(dir_ / "loom.toml")
      << "extends = \"default\"\n[knotting]\nmode = \"weaver\"\n[recipe]\ndesign = \"rug.csv\"\n";
  try {
    loom::firmware::load_loom_config((dir_ / "loom.toml").string());
    FAIL() << "accepted";
  } catch (const loom::firmware::ConfigError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find((dir_ / "loom.toml").string() + ":5:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("recipe.design = \"rug.csv\""), std::string::npos) << msg;
    EXPECT_NE(msg.find((dir_ / "rug.csv").string() + ":3:3: colour code 'Q'"), std::string::npos) << msg;
  }
  std::ofstream(dir_ / "rug.csv") << "palette,R,#ff0000\nR,R\nR,R\n";
  const auto cfg = loom::firmware::load_loom_config((dir_ / "loom.toml").string());
  ASSERT_TRUE(cfg.recipe.design);
  EXPECT_EQ(cfg.recipe.design->height(), 2);
  std::ofstream(dir_ / "loom.toml") << "extends = \"default\"\n[recipe]\ndesign = \"missing.csv\"\n";
  EXPECT_THROW(loom::firmware::load_loom_config((dir_ / "loom.toml").string()), loom::firmware::ConfigError);
}

}  // namespace

// `design fit`'s parts against independent truth:
//   - CIEDE2000: all 34 pairs of Sharma, Wu & Dalal (2005), Table 1, both ways round, to their 4 decimals;
//   - sRGB → L*a*b*: the sRGB primaries, secondaries and mid grey as Lindbloom's calculator gives them (D65
//     white 0.95047, 1, 1.08883), to 0.01;
//   - the geometry in closed form: tiling is x mod w (after the centring offset), an integer scale factor n
//     shows pixel x / n, a centred picture starts at (W - w) / 2, and the rows of a scaled picture keep
//     its aspect at the knot aspect;
//   - an anti-aliased 40 x 20 drawing (rasterised here by 8 x 8 supersampling, a peer of no loom code)
//   brought
//     to 360 knots: every colour it has is mapped or listed, at once, with its knot count and a pixel of it;
//   - the CSV written reads back (design.hpp's reader) to the same knots; the preview decodes (libpng) to
//     the true aspect with each knot's colour under its centre.
#include "loom/design/design_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <set>

#include "loom/design/cielab.hpp"
#include "loom/design/design.hpp"
#include "loom/design/picture.hpp"

namespace {

using namespace loom::design;

// ---- colour science ----------------------------------------------------------------------------------

struct SharmaPair {
  Lab p, q;
  double de;
};
// Sharma, Wu & Dalal, "The CIEDE2000 color-difference formula: implementation notes, supplementary test
// data, and mathematical observations", Color Res. Appl. 30(1), 2005, Table 1.
const SharmaPair kSharma[] = {
    {{50.0000, 2.6772, -79.7751}, {50.0000, 0.0000, -82.7485}, 2.0425},
    {{50.0000, 3.1571, -77.2803}, {50.0000, 0.0000, -82.7485}, 2.8615},
    {{50.0000, 2.8361, -74.0200}, {50.0000, 0.0000, -82.7485}, 3.4412},
    {{50.0000, -1.3802, -84.2814}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, -1.1848, -84.8006}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, -0.9009, -85.5211}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, 0.0000, 0.0000}, {50.0000, -1.0000, 2.0000}, 2.3669},
    {{50.0000, -1.0000, 2.0000}, {50.0000, 0.0000, 0.0000}, 2.3669},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0009}, 7.1792},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0010}, 7.1792},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0011}, 7.2195},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0012}, 7.2195},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0009, -2.4900}, 4.8045},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0010, -2.4900}, 4.8045},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0011, -2.4900}, 4.7461},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 0.0000, -2.5000}, 4.3065},
    {{50.0000, 2.5000, 0.0000}, {73.0000, 25.0000, -18.0000}, 27.1492},
    {{50.0000, 2.5000, 0.0000}, {61.0000, -5.0000, 29.0000}, 22.8977},
    {{50.0000, 2.5000, 0.0000}, {56.0000, -27.0000, -3.0000}, 31.9030},
    {{50.0000, 2.5000, 0.0000}, {58.0000, 24.0000, 15.0000}, 19.4535},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.1736, 0.5854}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2972, 0.0000}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 1.8634, 0.5757}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2592, 0.3350}, 1.0000},
    {{60.2574, -34.0099, 36.2677}, {60.4626, -34.1751, 39.4387}, 1.2644},
    {{63.0109, -31.0961, -5.8663}, {62.8187, -29.7946, -4.0864}, 1.2630},
    {{61.2901, 3.7196, -5.3901}, {61.4292, 2.2480, -4.9620}, 1.8731},
    {{35.0831, -44.1164, 3.7933}, {35.0232, -40.0716, 1.5901}, 1.8645},
    {{22.7233, 20.0904, -46.6940}, {23.0331, 14.9730, -42.5619}, 2.0373},
    {{36.4612, 47.8580, 18.3852}, {36.2715, 50.5065, 21.2231}, 1.4146},
    {{90.8027, -2.0831, 1.4410}, {91.1528, -1.6435, 0.0447}, 1.4441},
    {{90.9257, -0.5406, -0.9208}, {88.6381, -0.8985, -0.7239}, 1.5381},
    {{6.7747, -0.2908, -2.4247}, {5.8714, -0.0985, -2.2286}, 0.6377},
    {{2.0776, 0.0795, -1.1350}, {0.9033, -0.0636, -0.5514}, 0.9082},
};

TEST(Ciede2000, SharmaWuDalalTableOne) {
  int n = 0;
  for (const SharmaPair& t : kSharma) {
    ++n;
    // The table gives 4 decimals: within 0.5e-4 of the rounded value, plus a little for its inputs' rounding.
    EXPECT_NEAR(delta_e_2000(t.p, t.q), t.de, 1e-4) << "pair " << n;
    EXPECT_NEAR(delta_e_2000(t.q, t.p), t.de, 1e-4) << "pair " << n << " reversed";
  }
  EXPECT_EQ(n, 34);
  EXPECT_EQ(delta_e_2000({50, 0, 0}, {50, 0, 0}), 0.0);  // two neutral greys: no 0/0 in the hue terms
}

TEST(SrgbToLab, LindbloomReferenceValues) {
  struct Case {
    std::uint32_t rgb;
    double L, a, b;
  };
  const Case cases[] = {
      {0xff0000, 53.2408, 80.0925, 67.2032},
      {0x00ff00, 87.7347, -86.1827, 83.1793},
      {0x0000ff, 32.2970, 79.1875, -107.8602},
      {0xffff00, 97.1393, -21.5537, 94.4780},
      {0x00ffff, 91.1132, -48.0875, -14.1312},
      {0xff00ff, 60.3242, 98.2343, -60.8249},
      {0x808080, 53.5850, 0.0, 0.0},
      {0xffffff, 100.0, 0.0, 0.0},
      {0x000000, 0.0, 0.0, 0.0},
  };
  for (const Case& c : cases) {
    const Lab lab = lab_from_srgb(c.rgb);
    EXPECT_NEAR(lab.L, c.L, 0.01) << std::hex << c.rgb;
    EXPECT_NEAR(lab.a, c.a, 0.01) << std::hex << c.rgb;
    EXPECT_NEAR(lab.b, c.b, 0.01) << std::hex << c.rgb;
  }
}

// ---- geometry ----------------------------------------------------------------------------------------

const LoomGrid kLoom{360, 30.0, 30.0};  // the default loom: 1.2 m at 30 knots/dm, 30 rows/dm

// A picture whose every pixel has its own colour (x, y coded in the RGB), so a knot names its pixel.
Picture numbered(int w, int h) {
  std::vector<std::uint32_t> rgb;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) rgb.push_back(static_cast<std::uint32_t>(y << 12 | x));
  }
  return Picture("pic.png", w, h, rgb);
}

std::int32_t knot(const FitGeometry& g, int x, int y) {
  return g
      .pixel[static_cast<std::size_t>(y) * static_cast<std::size_t>(g.width) + static_cast<std::size_t>(x)];
}

TEST(FitGeometry, TileRepeatsAcrossTheWidthCentringAPartRepeat) {
  const FitGeometry g = fit_geometry(numbered(40, 20), kLoom, FitMode::kTile);
  ASSERT_EQ(g.width, 360);
  ASSERT_EQ(g.height, 20);
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 360; ++x) ASSERT_EQ(knot(g, x, y), y * 40 + x % 40) << x << "," << y;
  }
  // 360 = 7 x 50 + 10: five knots of a part repeat on each side, so knot 5 shows pixel 0.
  const FitGeometry h = fit_geometry(numbered(50, 3), kLoom, FitMode::kTile);
  for (int x = 0; x < 360; ++x) ASSERT_EQ(knot(h, x, 1), 50 + ((x - 5) % 50 + 50) % 50) << x;
  EXPECT_NE(h.how.find("7 whole repeats"), std::string::npos) << h.how;
}

TEST(FitGeometry, ScaleByAWholeFactorRepeatsEachPixelAndKeepsTheAspectAtTheKnotAspect) {
  const FitGeometry g = fit_geometry(numbered(40, 20), kLoom, FitMode::kScale);
  ASSERT_EQ(g.width, 360);
  ASSERT_EQ(g.height, 180);  // 40 x 20 at 9 knots per pixel, square knots
  for (int y = 0; y < 180; ++y) {
    for (int x = 0; x < 360; ++x) ASSERT_EQ(knot(g, x, y), (y / 9) * 40 + x / 9) << x << "," << y;
  }
  // 40 rows per dm against 30 knots: a knot is 3/4 as tall as wide, so the same picture takes 4/3 the rows.
  const FitGeometry tall = fit_geometry(numbered(40, 20), {360, 30.0, 40.0}, FitMode::kScale);
  EXPECT_EQ(tall.height, 240);
  for (int y = 0; y < 240; ++y) ASSERT_EQ(knot(tall, 0, y), (y / 12) * 40) << y;
  // Down: 720 pixels to 360 knots shows every other pixel (the one under each knot's centre).
  const FitGeometry down = fit_geometry(numbered(720, 4), kLoom, FitMode::kScale);
  EXPECT_EQ(down.height, 2);
  for (int x = 0; x < 360; ++x) ASSERT_EQ(knot(down, x, 0), 1 * 720 + 2 * x + 1) << x;
}

TEST(FitGeometry, CentreLeavesTheGroundOnBothSides) {
  const FitGeometry g = fit_geometry(numbered(41, 2), kLoom, FitMode::kCentre);
  ASSERT_EQ(g.height, 2);
  for (int x = 0; x < 360; ++x) {
    const bool inside = x >= 159 && x < 200;  // (360 - 41) / 2 = 159 on the left, 160 on the right
    ASSERT_EQ(knot(g, x, 1), inside ? 41 + (x - 159) : -1) << x;
  }
}

std::string refusal(const std::function<void()>& f) {
  try {
    f();
  } catch (const DesignError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(FitMode, ExactlyOneWayWhenTheWidthDiffersAndNeverTwo) {
  EXPECT_EQ(fit_mode(false, false, false, "", 360, kLoom, "a.png"), FitMode::kAsIs);
  EXPECT_EQ(fit_mode(true, false, false, "", 40, kLoom, "a.png"), FitMode::kTile);
  EXPECT_EQ(fit_mode(false, false, true, "I", 40, kLoom, "a.png"), FitMode::kCentre);
  EXPECT_EQ(refusal([] { fit_mode(false, false, false, "", 40, kLoom, "a.png"); }),
            "a.png: 40 knots wide; the loom ties 360 per row: give one of --tile (9 repeats), --scale (to "
            "the width, "
            "keeping its aspect) or --centre --ground CODE (320 knots of ground)");
  EXPECT_EQ(
      refusal([] { fit_mode(false, false, false, "", 400, kLoom, "a.png"); }),
      "a.png: 400 knots wide; the loom ties 360 per row: give --scale (to the width, keeping its aspect)");
  EXPECT_EQ(refusal([] { fit_mode(true, true, false, "", 40, kLoom, "a.png"); }),
            "--tile and --scale together: give one of --tile, --scale and --centre (they fit the width "
            "differently)");
  EXPECT_EQ(refusal([] { fit_mode(false, false, true, "", 40, kLoom, "a.png"); }),
            "--centre needs --ground CODE: the yarn around the picture");
  EXPECT_EQ(refusal([] { fit_mode(true, false, false, "I", 40, kLoom, "a.png"); }),
            "--ground I without --centre: the ground is the yarn around a centred picture");
  EXPECT_EQ(refusal([] { fit_geometry(numbered(400, 2), kLoom, FitMode::kTile); }),
            "pic.png: 400 knots wide, wider than the loom's 360 per row: --tile cannot fit it; give --scale");
  EXPECT_EQ(refusal([] { fit_geometry(numbered(1, 100), kLoom, FitMode::kScale); }),
            "pic.png: scaled x360.00 to 36000 rows: more than 20000 rows (crop the picture)");
}

// ---- colours -----------------------------------------------------------------------------------------

// The knotting loom's yarns (firmware/config/designs/knot_demo.csv's palette).
const std::vector<Yarn> kYarns = {
    {"R", 0xa52a2a, "madder red"}, {"I", 0xf3ead6, "ivory"}, {"B", 0x1f3a6e, "indigo"}};

std::uint32_t mix(std::uint32_t a, std::uint32_t b, double t) {  // sRGB blend, as a drawing program does
  std::uint32_t out = 0;
  for (int s = 16; s >= 0; s -= 8) {
    const double v = (1 - t) * ((a >> s) & 0xFF) + t * ((b >> s) & 0xFF);
    out |= static_cast<std::uint32_t>(std::lround(v)) << s;
  }
  return out;
}

// A 40 x 20 drawing: an ivory ground, a red disc and an indigo bar, their edges anti-aliased by 8 x 8
// supersampling (each pixel the mean of its 64 samples' colours).
Picture antialiased_drawing() {
  std::vector<std::uint32_t> rgb;
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 40; ++x) {
      double r = 0, g = 0, b = 0;
      for (int sy = 0; sy < 8; ++sy) {
        for (int sx = 0; sx < 8; ++sx) {
          const double px = x + (sx + 0.5) / 8, py = y + (sy + 0.5) / 8;
          std::uint32_t c = kYarns[1].rgb;
          if (std::hypot(px - 12.3, py - 9.7) < 6.4) c = kYarns[0].rgb;
          if (std::abs((px - 26.0) - 0.6 * (py - 10.0)) < 2.2) c = kYarns[2].rgb;
          r += c >> 16 & 0xFF;
          g += c >> 8 & 0xFF;
          b += c & 0xFF;
        }
      }
      rgb.push_back(static_cast<std::uint32_t>(std::lround(r / 64)) << 16 |
                    static_cast<std::uint32_t>(std::lround(g / 64)) << 8 |
                    static_cast<std::uint32_t>(std::lround(b / 64)));
    }
  }
  return Picture("drawing.png", 40, 20, rgb);
}

TEST(FitColours, AnAntialiasedDrawingHasEveryColourMappedOrListedAtOnce) {
  const Picture pic = antialiased_drawing();
  std::map<std::uint32_t, long> pixels;  // the drawing's colours and their pixels, counted here
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 40; ++x) ++pixels[pic.at(x, y)];
  }
  ASSERT_GT(pixels.size(), 10u) << "the drawing should have blended edges";
  for (const double limit : {kDefaultMaxDeltaE, 2.0, 60.0}) {
    const FitResult r =
        fit_design(pic, kLoom, kYarns, {.mode = FitMode::kScale, .max_delta_e = limit}, "out.csv");
    std::set<std::uint32_t> seen;
    long knots = 0;
    for (const auto* list : {&r.mapped, &r.unmapped}) {
      for (const ColourMatch& m : *list) {
        EXPECT_TRUE(seen.insert(m.rgb).second) << "listed twice: " << std::hex << m.rgb;
        EXPECT_EQ(m.knots, pixels.at(m.rgb) * 81) << std::hex << m.rgb;  // 9 x 9 knots per pixel
        EXPECT_EQ(pic.at(m.x, m.y), m.rgb);                              // the pixel named has the colour
        knots += m.knots;
        // The nearest yarn, and on the right side of the limit.
        for (std::size_t i = 0; i < kYarns.size(); ++i) {
          EXPECT_LE(m.delta_e, delta_e_2000(lab_from_srgb(m.rgb), lab_from_srgb(kYarns[i].rgb)) + 1e-12);
        }
        EXPECT_EQ(list == &r.mapped, m.delta_e <= limit) << std::hex << m.rgb << " at " << m.delta_e;
      }
    }
    EXPECT_EQ(seen.size(), pixels.size()) << "every colour of the drawing, mapped or listed";
    EXPECT_EQ(knots, 360L * 180L);
    EXPECT_EQ(r.design != nullptr, r.unmapped.empty());
    for (std::size_t i = 1; i < r.unmapped.size(); ++i)
      EXPECT_GE(r.unmapped[i - 1].knots, r.unmapped[i].knots);
    // The yarns themselves are found exactly, with most knots.
    for (const ColourMatch& m : r.mapped) {
      if (m.rgb == kYarns[static_cast<std::size_t>(m.yarn)].rgb) {
        EXPECT_EQ(m.delta_e, 0.0);
      }
    }
    if (limit == 2.0) {
      EXPECT_FALSE(r.unmapped.empty());
    }
    if (limit == 60.0) {
      ASSERT_TRUE(r.design);
      EXPECT_EQ(r.design->width(), 360);
      EXPECT_EQ(r.design->height(), 180);
    }
  }
}

TEST(FitColours, ABlendGoesToTheNearerYarnAndAForeignColourIsUnmapped) {
  // Ivory with a near-red blend (10 % ivory), a near-ivory blend (10 % red) and a green no yarn is near.
  std::vector<std::uint32_t> rgb(360, kYarns[1].rgb);
  rgb[3] = mix(kYarns[0].rgb, kYarns[1].rgb, 0.1);
  rgb[4] = mix(kYarns[0].rgb, kYarns[1].rgb, 0.9);
  rgb[200] = 0x2e8b57;
  rgb[201] = 0x2e8b57;
  const FitResult r = fit_design(Picture("p.png", 360, 1, rgb), kLoom, kYarns, {.max_delta_e = 10}, "o.csv");
  ASSERT_EQ(r.unmapped.size(), 1u);
  EXPECT_EQ(r.unmapped[0].rgb, 0x2e8b57u);
  EXPECT_EQ(r.unmapped[0].knots, 2);
  EXPECT_EQ(r.unmapped[0].x, 200);
  ASSERT_EQ(r.mapped.size(), 3u);
  for (const ColourMatch& m : r.mapped) {
    const std::string& code = kYarns[static_cast<std::size_t>(m.yarn)].code;
    if (m.rgb == rgb[3]) {
      EXPECT_EQ(code, "R");
    }
    if (m.rgb == rgb[4]) {
      EXPECT_EQ(code, "I");
    }
  }
  EXPECT_EQ(refusal([&] {
              fit_design(Picture("p.png", 360, 1, rgb), kLoom, kYarns,
                         {.mode = FitMode::kCentre, .ground = "G"}, "o.csv");
            }),
            "--ground G: not one of the yarns (R, I, B)");
}

TEST(FitColours, CentredOnTheGroundYarn) {
  const Picture pic("p.png", 2, 1, {kYarns[0].rgb, kYarns[2].rgb});
  const FitResult r =
      fit_design(pic, kLoom, kYarns, {.mode = FitMode::kCentre, .ground = "I", .max_delta_e = 1}, "o.csv");
  ASSERT_TRUE(r.design);
  EXPECT_EQ(r.ground_knots, 358);
  std::string row;
  for (auto k : r.design->row(0)) row += r.design->palette()[k].code;
  EXPECT_EQ(row, std::string(179, 'I') + "RB" + std::string(179, 'I'));
}

// ---- outputs -----------------------------------------------------------------------------------------

TEST(FitOutputs, TheCsvReadsBackToTheSameKnotsWithTheYarnsAsPalette) {
  const FitResult r = fit_design(antialiased_drawing(), kLoom, kYarns,
                                 {.mode = FitMode::kScale, .max_delta_e = 60}, "rug.csv");
  ASSERT_TRUE(r.design);
  const std::string text = design_csv_text(*r.design, {"made by a test", "second line"});
  EXPECT_EQ(text.rfind("# made by a test\n# second line\npalette,R,#a52a2a,madder red\n", 0), 0u)
      << text.substr(0, 200);
  const Design back = parse_design_csv(text, "rug.csv");
  ASSERT_EQ(back.width(), 360);
  ASSERT_EQ(back.height(), 180);
  ASSERT_EQ(back.palette().size(), r.design->palette().size());
  for (std::size_t i = 0; i < back.palette().size(); ++i) {
    EXPECT_EQ(back.palette()[i].code, r.design->palette()[i].code);
    EXPECT_EQ(back.palette()[i].rgb, r.design->palette()[i].rgb);
  }
  for (int row = 0; row < 180; ++row) {
    const auto a = back.row(row), b = r.design->row(row);
    ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin())) << "row " << row;
  }
  // The bottom of the picture is design row 0: the drawing's bottom line, pixel (x, 19), is that row.
  const Picture pic = antialiased_drawing();
  for (int x = 0; x < 360; ++x) {
    const std::uint32_t want = pic.at(x / 9, 19);
    const std::uint32_t got = back.palette()[back.row(0)[static_cast<std::size_t>(x)]].rgb;
    if (want == kYarns[0].rgb || want == kYarns[1].rgb || want == kYarns[2].rgb) {
      ASSERT_EQ(got, want) << x;
    }
  }
}

TEST(FitOutputs, ThePreviewHasTheCarpetsTrueAspect) {
  struct Case {
    LoomGrid loom;
    int rows, w_px, h_px;
  };
  // 360 x 180 square knots: 1.2 m x 0.6 m at 4 px per knot. 40 rows/dm: 360 x 240 knots make the same
  // 1.2 m x 0.6 m, each knot 4 px wide and 3 px tall. 30 x 20 rows/dm: 360 x 40 knots, 1.2 m x 0.2 m.
  const Case cases[] = {
      {{360, 30, 30}, 180, 1440, 720}, {{360, 30, 40}, 240, 1440, 720}, {{360, 30, 20}, 40, 1440, 240}};
  for (const Case& c : cases) {
    std::vector<std::uint16_t> knots(static_cast<std::size_t>(360 * c.rows));
    for (int r = 0; r < c.rows; ++r) {
      for (int k = 0; k < 360; ++k)
        knots[static_cast<std::size_t>(r * 360 + k)] = static_cast<std::uint16_t>((k / 7 + r / 5) % 3);
    }
    const Design d("t.csv", 360, {{"R", 0xa52a2a, ""}, {"I", 0xf3ead6, ""}, {"B", 0x1f3a6e, ""}}, knots);
    const PreviewSize s = preview_size(360, c.rows, c.loom.knots_per_dm, c.loom.rows_per_dm);
    EXPECT_EQ(s.width_px, c.w_px);
    EXPECT_EQ(s.height_px, c.h_px);
    int w = 0, h = 0;
    const std::vector<std::uint32_t> px =
        decode_png_rgb(preview_png(d, c.loom.knots_per_dm, c.loom.rows_per_dm), "p.png", w, h);
    ASSERT_EQ(w, c.w_px);
    ASSERT_EQ(h, c.h_px);
    // Width over height is the carpet's: (360 / knots_per_dm) / (rows / rows_per_dm).
    EXPECT_NEAR(static_cast<double>(w) / h, (360 / c.loom.knots_per_dm) / (c.rows / c.loom.rows_per_dm),
                1e-9);
    // Under each knot's centre, its colour; the top line of the picture is the last row.
    for (int r = 0; r < c.rows; ++r) {
      for (int k = 0; k < 360; k += 13) {
        const double cx = (k + 0.5) * s.px_per_dm / c.loom.knots_per_dm;
        const double cy = (c.rows - 1 - r + 0.5) * s.px_per_dm / c.loom.rows_per_dm;
        const std::uint32_t got =
            px[static_cast<std::size_t>(cy) * static_cast<std::size_t>(w) + static_cast<std::size_t>(cx)];
        ASSERT_EQ(got, d.palette()[d.row(r)[static_cast<std::size_t>(k)]].rgb)
            << "row " << r << " knot " << k;
      }
    }
  }
}

TEST(Picture, ACsvPictureNamesItsCellsByLineAndColumn) {
  const Picture p =
      Picture::read("# rug\npalette,R,#a52a2a\npalette,I,#f3ead6\n\nR,I,R\nI, #00ff00 ,I\n", "rug.csv");
  ASSERT_EQ(p.width(), 3);
  ASSERT_EQ(p.height(), 2);
  EXPECT_EQ(p.at(1, 1), 0x00ff00u);
  EXPECT_EQ(p.at(0, 0), 0xa52a2au);
  EXPECT_EQ(p.where(1, 1), "rug.csv:6:4");
  EXPECT_EQ(p.where(2, 0), "rug.csv:5:5");
  EXPECT_EQ(Picture("a.png", 1, 1, {0}).where(0, 0), "pixel (0, 0) of a.png");
  EXPECT_EQ(refusal([] { Picture::read("x", "a.gif"); }),
            "a.gif: not a picture: want a .png or a .csv grid of colour codes");
}

}  // namespace

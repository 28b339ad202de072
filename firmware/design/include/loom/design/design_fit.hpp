// `loomctl design fit`: a picture a weaver brings made into a knot map this loom can tie.
//   1. the geometry: the picture fitted to the loom's knots per row — as it is (same width), tiled across
//      the width, scaled (nearest neighbour, keeping the picture's aspect at the loom's knot aspect), or
//      centred on a ground yarn;
//   2. the colours: each colour of the fitted map becomes the yarn nearest to it in CIELAB (CIEDE2000);
//      a colour further than the limit from every yarn is unmapped, and all of them are reported at once;
//   3. the outputs: the knot map as a design CSV and a preview PNG at the true knot aspect.
// Pure functions of their inputs (the loom's figures come from its config, read by the command).
// Configure-time only.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "loom/design/design.hpp"
#include "loom/design/picture.hpp"

namespace loom::design {

// What the loom ties: knots across a row, and the knots' size (a knot is 1/knots_per_dm dm wide and
// 1/rows_per_dm dm tall).
struct LoomGrid {
  int knots_per_row = 0;
  double knots_per_dm = 0.0;
  double rows_per_dm = 0.0;
};

enum class FitMode {
  kAsIs,  // the picture is the loom's width already: one pixel per knot
  kTile,  // repeated across the width (centred: what does not fill a whole repeat is split between the sides)
  kScale,   // resampled to the width, nearest neighbour; the rows follow from the picture's aspect
  kCentre,  // in the middle of the width on a ground yarn
};

// The mode the command line asks for, or a DesignError saying why it is ambiguous or incomplete: at
// most one of tile, scale and centre; --ground with --centre and only then; one of the three when the
// picture's width is not the loom's (`picture_width`, `knots_per_row` name the figures in the message).
FitMode fit_mode(bool tile, bool scale, bool centre, const std::string& ground, int picture_width,
                 const LoomGrid& loom, const std::string& source);

// Each knot of the fitted map (top row first, left to right): the picture pixel it shows (y * width + x),
// or -1 for the ground.
struct FitGeometry {
  int width = 0, height = 0;
  std::vector<std::int32_t> pixel;
  std::string how;  // one line for the weaver: "tiled 9 times across", "scaled x9.0 to 180 rows", ...
};
// Throws DesignError naming the picture and the figures when the mode cannot fit it (a picture wider
// than the loom cannot be tiled or centred; a scaled map beyond kMaxHeight rows).
FitGeometry fit_geometry(const Picture& picture, const LoomGrid& loom, FitMode mode);

// A yarn the knot map may use: its code in the design (a magazine slot's code, a palette code), its colour.
struct Yarn {
  std::string code;
  std::uint32_t rgb = 0;
  std::string name;  // "" when none
};

// A colour of the fitted map and the yarn it became.
struct ColourMatch {
  std::uint32_t rgb = 0;
  int yarn = -1;         // the nearest yarn (index into the yarns)
  double delta_e = 0.0;  // CIEDE2000 to that yarn
  long knots = 0;        // knots of the fitted map in this colour
  int x = 0, y = 0;      // a picture pixel of this colour that the map shows (the first, top-left first)
};

struct FitOptions {
  FitMode mode = FitMode::kAsIs;
  std::string ground{};      // the ground yarn's code (kCentre)
  double max_delta_e = 0.0;  // further than this from every yarn: unmapped
};

// A fairly strict default: CIEDE2000 10 is where two colours read as clearly different ones rather than
// shades of one; a blend of two yarns at an anti-aliased edge is further than that from both.
inline constexpr double kDefaultMaxDeltaE = 10.0;

struct FitResult {
  FitGeometry geometry;
  std::vector<ColourMatch> mapped;    // most knots first
  std::vector<ColourMatch> unmapped;  // most knots first; non-empty: no design
  long ground_knots = 0;
  std::shared_ptr<const Design> design;  // the knot map (null when a colour is unmapped)
};

// Fits `picture` to `loom` and maps its colours to `yarns`. `out_source` names the design (its file).
// Throws DesignError for a refused geometry, no yarns, or a ground that is not a yarn's code.
FitResult fit_design(const Picture& picture, const LoomGrid& loom, const std::vector<Yarn>& yarns,
                     const FitOptions& options, const std::string& out_source);

// The knot map as a design CSV (design.hpp's format): `comment` lines first (each written after "# "),
// then a palette line per colour code (literal #rrggbb codes need none), then the grid, top line first.
// parse_design_csv reads it back to the same design.
std::string design_csv_text(const Design& design, const std::vector<std::string>& comment);

// The preview's size: a knot is px_per_dm / knots_per_dm pixels wide and px_per_dm / rows_per_dm tall
// (knot edges rounded to whole pixels), so the picture has the carpet's true aspect. px_per_dm is a
// whole multiple of the finer of the two densities (every knot at least one pixel each way), chosen so
// the longer side is at most about 1600 pixels (and at most 8 times the knot grid).
struct PreviewSize {
  int width_px = 0, height_px = 0;
  double px_per_dm = 0.0;
};
PreviewSize preview_size(int knots_per_row, int rows, double knots_per_dm, double rows_per_dm);
// The preview as PNG bytes (RGB, the picture as it looks: the last row woven at the top).
std::string preview_png(const Design& design, double knots_per_dm, double rows_per_dm);

}  // namespace loom::design

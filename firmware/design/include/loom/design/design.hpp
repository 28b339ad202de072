// A carpet design: the knot map the weaver follows, one colour per knot, row by row. Loaded with the
// recipe (recipe.design) from a CSV grid of colour codes or a PNG with one pixel per knot, and shown on
// the loom panel as the row to knot next. Configure-time only: parsed once, then read-only (shared by
// the telemetry publisher and the control side; nothing here runs in the tick).
//
// Orientation: a design file is the picture as it looks, top line (top pixel row) first. A carpet is
// woven from the bottom up, so design row 1 — the first row knotted — is the file's LAST line.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace loom::design {

// A design that cannot be used: the message names the file (and line:col for a CSV), what is wrong and
// the value found.
struct DesignError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Bounds that keep every design displayable and the panel's telemetry small: a 4 m carpet at 10 knots
// per cm is 4000 knots wide; a weaver works with tens of yarn colours, not thousands (a PNG with more
// distinct colours is a photograph, not a knot map).
inline constexpr int kMaxWidth = 4000;
inline constexpr int kMaxHeight = 20000;
inline constexpr int kMaxColours = 256;
inline constexpr std::size_t kMaxCodeLength = 16;

struct Colour {
  std::string code;   // what the weaver calls it ("R", "ivory", "#a52a2a" for a PNG pixel)
  std::uint32_t rgb;  // 0xRRGGBB, for the panel's swatch
  std::string name;   // optional longer name from the palette line ("" when none)
};

class Design {
 public:
  // `source` is the file it came from; its base name becomes the design's name.
  Design(const std::string& source, int width, std::vector<Colour> palette,
         std::vector<std::uint16_t> knots_bottom_up);

  const std::string& name() const { return name_; }  // the file's name: the key of its remembered row
  int width() const { return width_; }               // knots per row
  int height() const { return height_; }             // rows
  const std::vector<Colour>& palette() const { return palette_; }
  // Palette indices of design row `r` (0 = the first row woven, the bottom of the picture), left to
  // right as the weaver faces the loom. r must be in [0, height()).
  std::span<const std::uint16_t> row(int r) const;

 private:
  std::string name_;
  int width_ = 0, height_ = 0;
  std::vector<Colour> palette_;
  std::vector<std::uint16_t> knots_;  // row-major, bottom row first
};

// Configure-time only. `source` names the file in messages; its base name becomes the design's name.
//   CSV: lines starting with '#' are comments (unless they start with a #RRGGBB cell);
//   `palette,CODE,#RRGGBB[,name]` lines define the colour codes (before the grid); every other non-empty line
//   is one row of the picture, one cell per knot, each a palette code or a literal #RRGGBB. Every row has the
//   same number of knots.
Design parse_design_csv(const std::string& text, const std::string& source);
// The same, noting the file line of each grid line, top line first (for messages that point at a knot).
Design parse_design_csv(const std::string& text, const std::string& source,
                        std::vector<std::size_t>& grid_lines);
// "source:line:col" of knot `knot` (0-based, left to right) on the grid line at file line `line` (1-based).
std::string design_csv_cell_at(const std::string& text, const std::string& source, std::size_t line,
                               int knot);
//   PNG: one pixel per knot (alpha ignored); each distinct colour becomes a code "#rrggbb".
Design parse_design_png(const std::string& bytes, const std::string& source);
// By the file's extension (.csv or .png, any case); anything else is a DesignError.
Design parse_design(const std::string& bytes, const std::string& source);

// Where design row `rows_done + 1` lies when the design repeats: 0-based row and 1-based repeat.
struct DesignPosition {
  int row = 0;     // 0-based design row to knot next
  int repeat = 1;  // 1 on the first pass through the design
};
DesignPosition position_after(const Design& d, std::uint64_t rows_done);

// Design rows woven by production row `counter_rows`, given `rows_at_start` of them woven by production
// row `counter_rows_at_start`: every production row since then was a row of this design.
constexpr std::uint64_t rows_woven(std::uint64_t rows_at_start, std::uint32_t counter_rows_at_start,
                                   std::uint32_t counter_rows) {
  return rows_at_start + (counter_rows >= counter_rows_at_start ? counter_rows - counter_rows_at_start : 0);
}

}  // namespace loom::design

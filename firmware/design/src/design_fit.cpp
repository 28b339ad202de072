// A picture fitted to a loom and mapped to its yarns (see design_fit.hpp).
#include "loom/design/design_fit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <unordered_map>

#include "loom/design/cielab.hpp"

namespace loom::design {
namespace {

std::string num(double v, int decimals) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string yarn_codes(const std::vector<Yarn>& yarns) {
  std::string s;
  for (const Yarn& y : yarns) s += (s.empty() ? "" : ", ") + y.code;
  return s;
}

// The rows a scaled picture becomes: its height in dm (its width's scale) at the loom's rows per dm.
long scaled_rows(const Picture& p, const LoomGrid& loom) {
  const double dm_per_pixel = loom.knots_per_row / loom.knots_per_dm / p.width();
  return std::max(1L, std::lround(p.height() * dm_per_pixel * loom.rows_per_dm));
}

std::string scale_figure(const Picture& p, const LoomGrid& loom) {
  return "x" + num(static_cast<double>(loom.knots_per_row) / p.width(), 2) + " to " +
         std::to_string(scaled_rows(p, loom)) + " rows";
}

}  // namespace

FitMode fit_mode(bool tile, bool scale, bool centre, const std::string& ground, int picture_width,
                 const LoomGrid& loom, const std::string& source) {
  std::string asked;
  if (tile) asked += "--tile";
  if (scale) asked += (asked.empty() ? "" : " and ") + std::string("--scale");
  if (centre) asked += (asked.empty() ? "" : " and ") + std::string("--centre");
  if (tile + scale + centre > 1) {
    throw DesignError(asked +
                      " together: give one of --tile, --scale and --centre (they fit the width differently)");
  }
  if (centre && ground.empty())
    throw DesignError("--centre needs --ground CODE: the yarn around the picture");
  if (!centre && !ground.empty()) {
    throw DesignError("--ground " + ground +
                      " without --centre: the ground is the yarn around a centred picture");
  }
  if (tile) return FitMode::kTile;
  if (scale) return FitMode::kScale;
  if (centre) return FitMode::kCentre;
  const int w = loom.knots_per_row;
  if (picture_width == w) return FitMode::kAsIs;
  const std::string what = source + ": " + std::to_string(picture_width) + " knots wide; the loom ties " +
                           std::to_string(w) + " per row: ";
  if (picture_width > w) throw DesignError(what + "give --scale (to the width, keeping its aspect)");
  throw DesignError(what + "give one of --tile (" + std::to_string(w / picture_width) +
                    (w % picture_width ? " whole" : "") +
                    " repeats), --scale (to the width, keeping its aspect) or --centre --ground CODE (" +
                    std::to_string(w - picture_width) + " knots of ground)");
}

FitGeometry fit_geometry(const Picture& p, const LoomGrid& loom, FitMode mode) {
  const int pw = p.width(), ph = p.height(), w = loom.knots_per_row;
  if (w < 1 || w > kMaxWidth)
    throw DesignError("the loom ties " + std::to_string(w) + " knots per row: want 1.." +
                      std::to_string(kMaxWidth));
  if (!(loom.knots_per_dm > 0.0) || !(loom.rows_per_dm > 0.0))
    throw DesignError("the loom's knot density must be positive");
  FitGeometry g;
  g.width = w;
  g.height = ph;
  const auto at = [pw](int x, int y) { return static_cast<std::int32_t>(y * pw + x); };
  if ((mode == FitMode::kTile || mode == FitMode::kCentre) && pw > w) {
    throw DesignError(p.source() + ": " + std::to_string(pw) + " knots wide, wider than the loom's " +
                      std::to_string(w) + " per row: " + (mode == FitMode::kTile ? "--tile" : "--centre") +
                      " cannot fit it; give --scale");
  }
  if (mode == FitMode::kAsIs && pw != w) {
    throw DesignError(p.source() + ": " + std::to_string(pw) + " knots wide; the loom ties " +
                      std::to_string(w) + " per row");
  }
  if (mode == FitMode::kScale) {
    const long rows = scaled_rows(p, loom);
    if (rows > kMaxHeight) {
      throw DesignError(p.source() + ": scaled " + scale_figure(p, loom) + ": more than " +
                        std::to_string(kMaxHeight) + " rows (crop the picture)");
    }
    g.height = static_cast<int>(rows);
  }
  g.pixel.resize(static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height));
  const int tile_offset = pw > 0 ? (w % pw) / 2 : 0;  // a part repeat split between the two sides
  const int left = (w - pw) / 2;                      // a centred picture's first knot
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < w; ++x) {
      std::int32_t px = -1;
      switch (mode) {
        case FitMode::kAsIs:
          px = at(x, y);
          break;
        case FitMode::kTile:
          px = at(((x - tile_offset) % pw + pw) % pw, y);
          break;
        case FitMode::kCentre:
          px = x >= left && x < left + pw ? at(x - left, y) : -1;
          break;
        case FitMode::kScale: {
          // The pixel under the knot's centre: (x + 1/2) · pw / w, in integers.
          const auto sx = static_cast<int>((2LL * x + 1) * pw / (2LL * w));
          const auto sy = static_cast<int>((2LL * y + 1) * ph / (2LL * g.height));
          px = at(sx, sy);
          break;
        }
      }
      g.pixel[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] = px;
    }
  }
  const std::string size = std::to_string(w) + " knots x " + std::to_string(g.height) + " rows";
  switch (mode) {
    case FitMode::kAsIs:
      g.how = "as drawn, one pixel per knot: " + size;
      break;
    case FitMode::kTile:
      g.how = "tiled: " + std::to_string(w / pw) + " whole repeats of " + std::to_string(pw) + " knots" +
              (w % pw ? " and " + std::to_string(w % pw) + " knots of a part repeat split between the sides"
                      : "") +
              ": " + size;
      break;
    case FitMode::kScale:
      g.how = "scaled " + scale_figure(p, loom) + " (nearest pixel): " + size;
      break;
    case FitMode::kCentre:
      g.how = "centred: " + std::to_string(left) + " knots of ground on the left, " +
              std::to_string(w - pw - left) + " on the right: " + size;
      break;
  }
  return g;
}

FitResult fit_design(const Picture& p, const LoomGrid& loom, const std::vector<Yarn>& yarns,
                     const FitOptions& options, const std::string& out_source) {
  if (yarns.empty()) throw DesignError("no yarns to map the picture's colours to");
  for (std::size_t i = 0; i < yarns.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (yarns[i].code == yarns[j].code) throw DesignError("yarn code '" + yarns[i].code + "' given twice");
    }
  }
  int ground = -1;
  if (options.mode == FitMode::kCentre) {
    for (std::size_t i = 0; i < yarns.size(); ++i) {
      if (yarns[i].code == options.ground) ground = static_cast<int>(i);
    }
    if (ground < 0) {
      throw DesignError("--ground " + options.ground + ": not one of the yarns (" + yarn_codes(yarns) + ")");
    }
  }
  FitResult r;
  r.geometry = fit_geometry(p, loom, options.mode);
  const FitGeometry& g = r.geometry;

  // Each distinct colour of the fitted map, in order of first appearance (top-left first).
  std::vector<ColourMatch> colours;
  std::unordered_map<std::uint32_t, std::size_t> index;
  std::vector<std::int32_t> colour_of(g.pixel.size(), -1);  // -1: ground
  for (std::size_t k = 0; k < g.pixel.size(); ++k) {
    const std::int32_t px = g.pixel[k];
    if (px < 0) {
      ++r.ground_knots;
      continue;
    }
    const int x = px % p.width(), y = px / p.width();
    const std::uint32_t rgb = p.at(x, y);
    auto [it, fresh] = index.emplace(rgb, colours.size());
    if (fresh) colours.push_back(ColourMatch{.rgb = rgb, .x = x, .y = y});
    ++colours[it->second].knots;
    colour_of[k] = static_cast<std::int32_t>(it->second);
  }
  std::vector<Lab> yarn_lab;
  for (const Yarn& y : yarns) yarn_lab.push_back(lab_from_srgb(y.rgb));
  for (ColourMatch& c : colours) {
    const Lab lab = lab_from_srgb(c.rgb);
    for (std::size_t i = 0; i < yarns.size(); ++i) {
      const double de = delta_e_2000(lab, yarn_lab[i]);
      if (c.yarn < 0 || de < c.delta_e) {
        c.yarn = static_cast<int>(i);
        c.delta_e = de;
      }
    }
    (c.delta_e <= options.max_delta_e ? r.mapped : r.unmapped).push_back(c);
  }
  const auto most_knots = [](const ColourMatch& a, const ColourMatch& b) { return a.knots > b.knots; };
  std::stable_sort(r.mapped.begin(), r.mapped.end(), most_knots);
  std::stable_sort(r.unmapped.begin(), r.unmapped.end(), most_knots);
  if (!r.unmapped.empty()) return r;

  // The design's palette: the yarns it uses, in the yarns' order.
  std::vector<bool> used(yarns.size(), false);
  if (ground >= 0 && r.ground_knots > 0) used[static_cast<std::size_t>(ground)] = true;
  for (const ColourMatch& c : colours) used[static_cast<std::size_t>(c.yarn)] = true;
  std::vector<Colour> palette;
  std::vector<std::uint16_t> palette_of_yarn(yarns.size(), 0);
  for (std::size_t i = 0; i < yarns.size(); ++i) {
    if (!used[i]) continue;
    palette_of_yarn[i] = static_cast<std::uint16_t>(palette.size());
    palette.push_back(Colour{yarns[i].code, yarns[i].rgb, yarns[i].name});
  }
  std::vector<std::uint16_t> knots(g.pixel.size());
  for (int row = 0; row < g.height; ++row) {
    const int y = g.height - 1 - row;  // design row 0, woven first, is the picture's bottom line
    for (int x = 0; x < g.width; ++x) {
      const std::size_t k =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(g.width) + static_cast<std::size_t>(x);
      const std::int32_t c = colour_of[k];
      const int yarn = c < 0 ? ground : colours[static_cast<std::size_t>(c)].yarn;
      knots[static_cast<std::size_t>(row) * static_cast<std::size_t>(g.width) + static_cast<std::size_t>(x)] =
          palette_of_yarn[static_cast<std::size_t>(yarn)];
    }
  }
  r.design = std::make_shared<const Design>(out_source, g.width, std::move(palette), std::move(knots));
  return r;
}

std::string design_csv_text(const Design& d, const std::vector<std::string>& comment) {
  std::string out;
  for (const std::string& line : comment) out += "# " + line + "\n";
  for (const Colour& c : d.palette()) {
    if (c.code.size() == 7 && c.code[0] == '#') continue;  // a literal colour names itself
    char rgb[8];
    std::snprintf(rgb, sizeof rgb, "#%06x", c.rgb & 0xFFFFFFu);
    out += "palette," + c.code + "," + rgb + (c.name.empty() ? "" : "," + c.name) + "\n";
  }
  out.reserve(out.size() + static_cast<std::size_t>(d.width()) * static_cast<std::size_t>(d.height()) * 2);
  for (int r = d.height() - 1; r >= 0; --r) {  // the picture's top line (the last row woven) first
    const auto row = d.row(r);
    for (std::size_t k = 0; k < row.size(); ++k) {
      if (k) out += ',';
      out += d.palette()[row[k]].code;
    }
    out += '\n';
  }
  return out;
}

PreviewSize preview_size(int knots_per_row, int rows, double knots_per_dm, double rows_per_dm) {
  const double finer = std::max(knots_per_dm, rows_per_dm);
  PreviewSize s;
  for (int k = 8; k >= 1; --k) {
    s.px_per_dm = finer * k;
    s.width_px = static_cast<int>(std::lround(knots_per_row * s.px_per_dm / knots_per_dm));
    s.height_px = static_cast<int>(std::lround(rows * s.px_per_dm / rows_per_dm));
    if (std::max(s.width_px, s.height_px) <= 1600) break;
  }
  return s;
}

}  // namespace loom::design

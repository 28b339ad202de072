// `loomctl design fit` (see design_cmd.hpp): the loom's figures and yarns from its config, the picture
// from its file, the fitting and mapping by loom::design, and the two files written together or not at all.
#include "design_cmd.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/design/design.hpp"
#include "loom/design/picture.hpp"
#include "loom/firmware/session.hpp"
#include "loom/state/durable_file.hpp"

namespace loom::firmware {
namespace {

constexpr std::size_t kMaxPictureBytes = 64u << 20;

// A refusal: the message is printed as "loomctl design fit: <message>" and nothing is written.
struct Refusal : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string hex(std::uint32_t rgb) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%06x", rgb & 0xFFFFFFu);
  return buf;
}

bool literal_colour(const std::string& code, std::uint32_t& rgb) {
  if (code.size() != 7 || code[0] != '#') return false;
  try {
    std::size_t used = 0;
    rgb = static_cast<std::uint32_t>(std::stoul(code.substr(1), &used, 16));
    return used == 6;
  } catch (const std::exception&) {
    return false;
  }
}

bool ends_with(const std::string& s, const std::string& tail) {
  if (s.size() < tail.size()) return false;
  for (std::size_t i = 0; i < tail.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(s[s.size() - tail.size() + i])) != tail[i]) return false;
  }
  return true;
}

// The yarns the picture's colours may become, each with the magazine slots holding it (for the report).
struct Yarns {
  std::vector<design::Yarn> yarns;
  std::vector<std::string> slots;  // per yarn: "slot 0" / "slots 0, 3" / "" (not in a magazine)
  std::string from;                // where they came from, for the weaver
};

// The colour of a magazine slot's code: a literal #rrggbb, or the loom design's palette line for it.
design::Yarn slot_yarn(const LoomConfig& c, std::size_t slot) {
  const std::string& code = c.knotting.slot_colours[slot];
  design::Yarn y{code, 0, ""};
  if (literal_colour(code, y.rgb)) return y;
  if (c.recipe.design) {
    for (const design::Colour& colour : c.recipe.design->palette()) {
      if (colour.code == code) return {code, colour.rgb, colour.name};
    }
  }
  throw Refusal(c.source + ": knotting.slot_colours[" + std::to_string(slot) + "] = \"" + code +
                "\": no colour known for this code (" +
                (c.recipe.design
                     ? "recipe.design = \"" + c.recipe.design_file + "\" has no palette line for it"
                     : std::string("recipe.design names no design whose palette gives it")) +
                "; or write the slot's colour as \"#rrggbb\")");
}

Yarns loom_yarns(const LoomConfig& c, bool from_magazines) {
  Yarns out;
  std::map<std::string, std::string> slots_of;
  for (std::size_t s = 0; s < c.knotting.slot_colours.size(); ++s) {
    std::string& text = slots_of[c.knotting.slot_colours[s]];
    text += (text.empty() ? "" : ", ") + std::to_string(s);
  }
  if (from_magazines) {
    if (c.knotting.slot_colours.empty()) {
      throw Refusal(
          c.source +
          ": knotting.slot_colours = []: the loom has no magazine yarns for --palette-from-magazines");
    }
    out.from = "the magazines (knotting.slot_colours)";
    for (std::size_t s = 0; s < c.knotting.slot_colours.size(); ++s) {
      const design::Yarn y = slot_yarn(c, s);
      bool seen = false;
      for (const design::Yarn& other : out.yarns) seen = seen || other.code == y.code;
      if (!seen) out.yarns.push_back(y);
    }
  } else {
    if (!c.recipe.design) {
      throw Refusal(c.source + ": recipe.design = \"\": no design whose palette names the loom's yarns; " +
                    (c.knotting.slot_colours.empty()
                         ? std::string("set recipe.design to a design whose palette lines are the yarns")
                         : std::string("set one, or give --palette-from-magazines")));
    }
    out.from = "the palette of recipe.design = \"" + c.recipe.design_file + "\"";
    for (const design::Colour& colour : c.recipe.design->palette())
      out.yarns.push_back({colour.code, colour.rgb, colour.name});
  }
  for (const design::Yarn& y : out.yarns) {
    const auto it = slots_of.find(y.code);
    out.slots.push_back(it == slots_of.end()
                            ? ""
                            : (it->second.find(',') == std::string::npos ? "slot " : "slots ") + it->second);
  }
  return out;
}

std::string read_picture_file(const std::string& path) {
  const state::StateFileRead r = state::read_state_file(path, kMaxPictureBytes);
  switch (r.outcome) {
    case state::StateFileRead::Outcome::kRead:
      return r.text;
    case state::StateFileRead::Outcome::kAbsent:
      throw Refusal(path + ": no such file");
    case state::StateFileRead::Outcome::kCannotOpen:
    case state::StateFileRead::Outcome::kCannotRead:
      throw Refusal(path + ": cannot read: " + r.error);
    case state::StateFileRead::Outcome::kNotRegular:
      break;
  }
  throw Refusal(path + ": not a regular file of at most " + std::to_string(kMaxPictureBytes >> 20) + " MiB");
}

std::string yarn_label(const Yarns& y, int i) {
  const design::Yarn& yarn = y.yarns[static_cast<std::size_t>(i)];
  std::string s = yarn.code + (yarn.name.empty() ? "" : " " + yarn.name) + " " + hex(yarn.rgb);
  return y.slots[static_cast<std::size_t>(i)].empty() ? s
                                                      : s + " (" + y.slots[static_cast<std::size_t>(i)] + ")";
}

// Both files complete beside their targets first, then renamed into place: never one without the other
// or a half-written one.
void write_both(const std::string& csv_path, const std::string& csv, const std::string& png_path,
                const std::string& png) {
  const std::string csv_new = csv_path + ".fit-new", png_new = png_path + ".fit-new";
  std::error_code ignored;
  try {
    state::write_file_durably(csv_new, csv);
    state::write_file_durably(png_new, png);
    std::filesystem::rename(csv_new, csv_path);
    std::filesystem::rename(png_new, png_path);
  } catch (const std::exception& e) {
    std::filesystem::remove(csv_new, ignored);
    std::filesystem::remove(png_new, ignored);
    throw Refusal(e.what());
  }
}

int fit(const DesignFitArgs& a) {
  if (!ends_with(a.out, ".csv")) throw Refusal("--out " + a.out + ": the knot map is a .csv design file");
  const std::string preview = a.preview.empty() ? a.out.substr(0, a.out.size() - 4) + ".png" : a.preview;
  if (!ends_with(preview, ".png")) throw Refusal("--preview " + preview + ": the preview is a .png picture");
  if (!std::isfinite(a.max_delta_e) || a.max_delta_e < 0.0) {
    throw Refusal("--max-delta-e " + std::to_string(a.max_delta_e) + ": want a CIEDE2000 difference >= 0");
  }
  std::error_code ec;
  if (std::filesystem::equivalent(a.picture, a.out, ec) ||
      std::filesystem::equivalent(a.picture, preview, ec)) {
    throw Refusal("--out/--preview would overwrite the picture " + a.picture);
  }

  const LoomConfig cfg = load_loom_config(a.loom);
  const design::LoomGrid grid{sequencer::knots_per_row(cfg.knotting, cfg.machine_spec.width_m),
                              cfg.knotting.knots_per_dm, cfg.knotting.rows_per_dm};
  const Yarns yarns = loom_yarns(cfg, a.palette_from_magazines);
  const design::Picture picture = design::Picture::read(read_picture_file(a.picture), a.picture);
  const design::FitMode mode =
      design::fit_mode(a.tile, a.scale, a.centre, a.ground, picture.width(), grid, a.picture);
  const design::FitResult r = design::fit_design(
      picture, grid, yarns.yarns, {.mode = mode, .ground = a.ground, .max_delta_e = a.max_delta_e}, a.out);
  const design::FitGeometry& g = r.geometry;

  std::printf("%s: %d x %d pixels; loom %s: %d knots per row at %g knots/dm, %g rows/dm\n", a.picture.c_str(),
              picture.width(), picture.height(), a.loom.c_str(), grid.knots_per_row, grid.knots_per_dm,
              grid.rows_per_dm);
  std::printf("fit: %s (%.2f m x %.2f m)\n", g.how.c_str(), g.width / grid.knots_per_dm / 10.0,
              g.height / grid.rows_per_dm / 10.0);
  std::printf("yarns from %s:", yarns.from.c_str());
  for (std::size_t i = 0; i < yarns.yarns.size(); ++i)
    std::printf("%s %s", i ? "," : "", yarn_label(yarns, static_cast<int>(i)).c_str());
  std::printf("\n");
  if (r.ground_knots > 0) std::printf("  ground %s: %ld knots\n", a.ground.c_str(), r.ground_knots);
  std::printf("%zu colour%s mapped (CIEDE2000 to the nearest yarn, at most %.1f):\n", r.mapped.size(),
              r.mapped.size() == 1 ? "" : "s", a.max_delta_e);
  int label_width = 0;  // the yarns' labels in one column
  for (std::size_t i = 0; i < yarns.yarns.size(); ++i) {
    label_width = std::max(label_width, static_cast<int>(yarn_label(yarns, static_cast<int>(i)).size()));
  }
  for (const design::ColourMatch& m : r.mapped) {
    std::printf("  %s %8ld knots -> %-*s  ΔE00 %5.2f\n", hex(m.rgb).c_str(), m.knots, label_width,
                yarn_label(yarns, m.yarn).c_str(), m.delta_e);
  }
  if (!r.unmapped.empty()) {
    long knots = 0;
    for (const design::ColourMatch& m : r.unmapped) knots += m.knots;
    std::fprintf(stderr,
                 "loomctl design fit: %s: %zu colour%s (%ld knots) further than ΔE00 %.1f from every yarn; "
                 "nothing written:\n",
                 a.picture.c_str(), r.unmapped.size(), r.unmapped.size() == 1 ? "" : "s", knots,
                 a.max_delta_e);
    for (const design::ColourMatch& m : r.unmapped) {
      std::fprintf(stderr, "  %s %8ld knots, e.g. at %s; nearest %s at ΔE00 %.2f\n", hex(m.rgb).c_str(),
                   m.knots, picture.where(m.x, m.y).c_str(), yarn_label(yarns, m.yarn).c_str(), m.delta_e);
    }
    std::fprintf(stderr,
                 "load a yarn near each (knotting.slot_colours and the design's palette), recolour the "
                 "picture, or allow "
                 "more with --max-delta-e (now %.1f)\n",
                 a.max_delta_e);
    return kExitBadInput;
  }

  const design::Design& d = *r.design;
  const std::vector<std::string> comment = {
      "fitted by loomctl design fit from " + std::filesystem::path(a.picture).filename().string() + " (" +
          std::to_string(picture.width()) + " x " + std::to_string(picture.height()) + " pixels) for " +
          std::filesystem::path(a.loom).filename().string(),
      g.how + "; yarns from " + yarns.from,
  };
  const std::string csv = design::design_csv_text(d, comment);
  const std::string png = design::preview_png(d, grid.knots_per_dm, grid.rows_per_dm);
  write_both(a.out, csv, preview, png);
  const design::PreviewSize ps =
      design::preview_size(d.width(), d.height(), grid.knots_per_dm, grid.rows_per_dm);
  std::printf(
      "wrote %s (%d knots x %d rows, %zu yarn%s) and %s (%d x %d px, %g px per dm: the carpet's aspect)\n",
      a.out.c_str(), d.width(), d.height(), d.palette().size(), d.palette().size() == 1 ? "" : "s",
      preview.c_str(), ps.width_px, ps.height_px, ps.px_per_dm);
  return 0;
}

}  // namespace

int run_design_fit(const DesignFitArgs& a) {
  try {
    return fit(a);
  } catch (const Refusal& e) {
    std::fprintf(stderr, "loomctl design fit: %s\n", e.what());
  } catch (const ConfigError& e) {
    std::fprintf(stderr, "loomctl design fit: %s\n", e.what());
  } catch (const design::DesignError& e) {
    std::fprintf(stderr, "loomctl design fit: %s\n", e.what());
  }
  return kExitBadInput;
}

DesignCommand::DesignCommand(CLI::App& app)
    : cmd_(app.add_subcommand("design",
                              "bring a picture to the loom: design fit IN.png|IN.csv --loom LOOM.toml "
                              "--out OUT.csv (a knot map and its preview); moves nothing")) {
  DesignFitArgs& a = args_;
  cmd_->add_option("action", a.action,
                   "fit: fit the picture to the loom's width and map its colours to the yarns")
      ->required()
      ->check(CLI::IsMember({"fit"}));
  cmd_->add_option("picture", a.picture, "the picture: a .png (any colours) or a .csv design grid")
      ->required();
  cmd_->add_option("--loom", a.loom, "the loom config (TOML): knots per row, knot density, yarns")
      ->required();
  cmd_->add_flag("--tile", a.tile, "repeat the picture across the width (rows as drawn)");
  cmd_->add_flag("--scale", a.scale, "resample to the width, nearest pixel; rows keep the picture's aspect");
  cmd_->add_flag("--centre", a.centre, "centre the picture on the --ground yarn (rows as drawn)");
  cmd_->add_option("--ground", a.ground, "with --centre: the ground yarn's code");
  cmd_->add_flag(
      "--palette-from-magazines", a.palette_from_magazines,
      "map to the yarns in the magazines (knotting.slot_colours) instead of recipe.design's palette");
  cmd_->add_option("--max-delta-e", a.max_delta_e,
                   "a colour further than this CIEDE2000 difference from every yarn is unmapped (default " +
                       std::to_string(static_cast<int>(design::kDefaultMaxDeltaE)) + ")")
      ->check(CLI::Range(0.0, 200.0));
  cmd_->add_option("--out", a.out, "the knot map to write (.csv)")->required();
  cmd_->add_option("--preview", a.preview,
                   "its preview at the carpet's true aspect (.png; default: beside --out)");
}

std::optional<int> DesignCommand::run() const {
  if (!cmd_->parsed()) return std::nullopt;
  return run_design_fit(args_);
}

}  // namespace loom::firmware

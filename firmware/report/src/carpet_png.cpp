// The knotted carpet as a PNG (see carpet_png.hpp), through libpng's simplified API.
#include "loom/report/carpet_png.hpp"

#include <png.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

namespace loom::report {

CarpetCheck write_carpet_png(const sim_hal::SimKnotter& carpet, const sequencer::KnotProgram& program,
                             const design::Design& design, std::uint32_t first_row, const std::string& path,
                             int rows_woven) {
  CarpetCheck c;
  c.rows = std::max(carpet.rows(), rows_woven);
  c.unrecorded = static_cast<int>(carpet.knots_beyond());
  const int w = carpet.knots_per_row();
  // The colour of each magazine slot, from the design's palette (slots hold palette codes).
  std::vector<std::uint32_t> slot_rgb(static_cast<std::size_t>(program.slots()), 0);
  for (int s = 0; s < program.slots(); ++s) {
    for (const design::Colour& colour : design.palette()) {
      if (colour.code == program.slot_colour(s)) slot_rgb[static_cast<std::size_t>(s)] = colour.rgb;
    }
  }
  const int h = std::max(1, c.rows);
  std::vector<png_byte> rgba(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4, 0);
  for (int r = 0; r < c.rows; ++r) {
    const int y = h - 1 - r;  // the first row woven at the bottom, as the design file draws it
    for (int k = 0; k < w; ++k) {
      const sim_hal::KnotCell cell = carpet.cell(r, k);
      png_byte* px =
          &rgba[(static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(k)) *
                4];
      const int want = program.slot(first_row + static_cast<std::uint32_t>(r), k);
      if (cell.ties == 0) {
        ++c.missing;
        continue;
      }
      ++c.knots;
      if (cell.by_hand) ++c.by_hand;
      if (cell.ties > 1) ++c.doubled;
      if (cell.slot != want) ++c.wrong;
      const std::uint32_t rgb =
          cell.slot >= 0 && cell.slot < program.slots() ? slot_rgb[static_cast<std::size_t>(cell.slot)] : 0;
      px[0] = static_cast<png_byte>(rgb >> 16);
      px[1] = static_cast<png_byte>(rgb >> 8);
      px[2] = static_cast<png_byte>(rgb);
      px[3] = cell.by_hand ? 128 : 255;
    }
  }
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  img.width = static_cast<png_uint_32>(w);
  img.height = static_cast<png_uint_32>(h);
  img.format = PNG_FORMAT_RGBA;
  if (png_image_write_to_file(&img, path.c_str(), 0, rgba.data(), 0, nullptr) == 0) {
    const std::string why = img.message;
    png_image_free(&img);
    throw std::runtime_error(path + ": cannot write the carpet's picture (libpng: " + why + ")");
  }
  return c;
}

}  // namespace loom::report

// The fitted design's preview PNG at the true knot aspect (see design_fit.hpp), through libpng's
// simplified API, written to memory so the command can write it durably beside the design.
#include <png.h>

#include <cmath>

#include "loom/design/design_fit.hpp"

namespace loom::design {

std::string preview_png(const Design& d, double knots_per_dm, double rows_per_dm) {
  const PreviewSize s = preview_size(d.width(), d.height(), knots_per_dm, rows_per_dm);
  // Knot k spans pixels [edge(k), edge(k + 1)): edges rounded, so every knot is within a pixel of its size.
  std::vector<int> column_knot(static_cast<std::size_t>(s.width_px)),
      line_row(static_cast<std::size_t>(s.height_px));
  for (int k = 0; k < d.width(); ++k) {
    const auto a = std::lround(k * s.px_per_dm / knots_per_dm),
               b = std::lround((k + 1) * s.px_per_dm / knots_per_dm);
    for (long x = a; x < b && x < s.width_px; ++x) column_knot[static_cast<std::size_t>(x)] = k;
  }
  for (int j = 0; j < d.height(); ++j) {  // j = 0: the picture's top line, the last design row
    const auto a = std::lround(j * s.px_per_dm / rows_per_dm),
               b = std::lround((j + 1) * s.px_per_dm / rows_per_dm);
    for (long y = a; y < b && y < s.height_px; ++y)
      line_row[static_cast<std::size_t>(y)] = d.height() - 1 - j;
  }
  std::vector<png_byte> rgb(static_cast<std::size_t>(s.width_px) * static_cast<std::size_t>(s.height_px) * 3);
  for (int y = 0; y < s.height_px; ++y) {
    const auto row = d.row(line_row[static_cast<std::size_t>(y)]);
    for (int x = 0; x < s.width_px; ++x) {
      const std::uint32_t c =
          d.palette()[row[static_cast<std::size_t>(column_knot[static_cast<std::size_t>(x)])]].rgb;
      png_byte* p = &rgb[(static_cast<std::size_t>(y) * static_cast<std::size_t>(s.width_px) +
                          static_cast<std::size_t>(x)) *
                         3];
      p[0] = static_cast<png_byte>(c >> 16);
      p[1] = static_cast<png_byte>(c >> 8);
      p[2] = static_cast<png_byte>(c);
    }
  }
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  img.width = static_cast<png_uint_32>(s.width_px);
  img.height = static_cast<png_uint_32>(s.height_px);
  img.format = PNG_FORMAT_RGB;
  png_alloc_size_t size = 0;
  std::string out;
  if (png_image_write_to_memory(&img, nullptr, &size, 0, rgb.data(), 0, nullptr) != 0) {
    out.resize(size);
    if (png_image_write_to_memory(&img, out.data(), &size, 0, rgb.data(), 0, nullptr) != 0) {
      out.resize(size);
      return out;
    }
  }
  const std::string why = img.message;
  png_image_free(&img);
  throw DesignError(d.name() + ": cannot encode the preview (libpng: " + why + ")");
}

}  // namespace loom::design

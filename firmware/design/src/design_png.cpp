// PNG designs through libpng's simplified API: decoded from memory to 8-bit RGB (alpha composited
// onto white, palette and grey images expanded), one pixel per knot, each distinct colour a code.
#include <png.h>

#include <cstdio>
#include <map>

#include "loom/design/design.hpp"

namespace loom::design {

Design parse_design_png(const std::string& bytes, const std::string& source) {
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  const auto fail = [&](const std::string& why) -> DesignError {
    const std::string lib = img.message[0] != '\0' ? std::string(" (libpng: ") + img.message + ")" : "";
    png_image_free(&img);
    return DesignError(source + ": " + why + lib);
  };
  if (png_image_begin_read_from_memory(&img, bytes.data(), bytes.size()) == 0) throw fail("not a readable PNG");
  const auto w = static_cast<long>(img.width), h = static_cast<long>(img.height);
  if (w < 1 || w > kMaxWidth || h < 1 || h > kMaxHeight) {
    throw fail(std::to_string(w) + " x " + std::to_string(h) + " pixels: a design is 1.." + std::to_string(kMaxWidth) +
               " knots wide and 1.." + std::to_string(kMaxHeight) + " rows (one pixel per knot)");
  }
  img.format = PNG_FORMAT_RGB;
  std::vector<png_byte> rgb(PNG_IMAGE_SIZE(img));
  const png_color white{255, 255, 255};
  if (png_image_finish_read(&img, &white, rgb.data(), 0, nullptr) == 0) throw fail("cannot decode");
  png_image_free(&img);

  std::vector<Colour> palette;
  std::map<std::uint32_t, std::uint16_t> index;
  std::vector<std::uint16_t> knots(static_cast<std::size_t>(w * h));
  for (long y = 0; y < h; ++y) {
    // Pixel row 0 is the top of the picture; design row 0 (woven first) is its bottom.
    const long r = h - 1 - y;
    for (long x = 0; x < w; ++x) {
      const png_byte* p = &rgb[static_cast<std::size_t>((y * w + x) * 3)];
      const std::uint32_t c = static_cast<std::uint32_t>(p[0]) << 16 | static_cast<std::uint32_t>(p[1]) << 8 | p[2];
      auto it = index.find(c);
      if (it == index.end()) {
        if (static_cast<int>(palette.size()) >= kMaxColours) {
          throw DesignError(source + ": more than " + std::to_string(kMaxColours) + " distinct colours (pixel " +
                            std::to_string(x) + "," + std::to_string(y) + "): a knot map uses one colour per yarn");
        }
        char code[8];
        std::snprintf(code, sizeof code, "#%06x", c);
        it = index.emplace(c, static_cast<std::uint16_t>(palette.size())).first;
        palette.push_back(Colour{code, c, ""});
      }
      knots[static_cast<std::size_t>(r * w + x)] = it->second;
    }
  }
  return Design(source, static_cast<int>(w), std::move(palette), std::move(knots));
}

}  // namespace loom::design

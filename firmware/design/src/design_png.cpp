// PNG designs: one pixel per knot (decode_png_rgb, picture.cpp), each distinct colour a code "#rrggbb".
#include <cstdio>
#include <map>

#include "loom/design/design.hpp"
#include "loom/design/picture.hpp"

namespace loom::design {

Design parse_design_png(const std::string& bytes, const std::string& source) {
  int w = 0, h = 0;
  const std::vector<std::uint32_t> rgb = decode_png_rgb(bytes, source, w, h);
  std::vector<Colour> palette;
  std::map<std::uint32_t, std::uint16_t> index;
  std::vector<std::uint16_t> knots(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  for (int y = 0; y < h; ++y) {
    // Pixel row 0 is the top of the picture; design row 0 (woven first) is its bottom.
    const int r = h - 1 - y;
    for (int x = 0; x < w; ++x) {
      const std::uint32_t c =
          rgb[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)];
      auto it = index.find(c);
      if (it == index.end()) {
        if (static_cast<int>(palette.size()) >= kMaxColours) {
          throw DesignError(source + ": more than " + std::to_string(kMaxColours) +
                            " distinct colours (pixel " + std::to_string(x) + "," + std::to_string(y) +
                            "): a knot map uses one colour per yarn");
        }
        char code[8];
        std::snprintf(code, sizeof code, "#%06x", c);
        it = index.emplace(c, static_cast<std::uint16_t>(palette.size())).first;
        palette.push_back(Colour{code, c, ""});
      }
      knots[static_cast<std::size_t>(r) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] =
          it->second;
    }
  }
  return Design(source, w, std::move(palette), std::move(knots));
}

}  // namespace loom::design

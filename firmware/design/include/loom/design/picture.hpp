// A picture a weaver brings, before it is fitted to a loom: its pixels as drawn (top row first), each an
// 8-bit sRGB colour, read from a PNG (any number of colours; alpha composited onto white) or from a
// design CSV (each cell its palette colour). It remembers where each pixel is in its file, so a refusal
// can point at it: "pixel (x, y)" of a PNG, "file:line:col" of a CSV. Configure-time only.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace loom::design {

class Picture {
 public:
  // Throws DesignError naming the file (and line:col of a CSV) when it is not a readable picture, or is
  // wider than kMaxWidth or taller than kMaxHeight pixels. By extension: .png or .csv, any case.
  static Picture read(const std::string& bytes, const std::string& source);
  // From pixels directly (tests): `rgb` is width × height, top row first.
  Picture(std::string source, int width, int height, std::vector<std::uint32_t> rgb);

  const std::string& source() const { return source_; }
  int width() const { return width_; }
  int height() const { return height_; }
  // 0xRRGGBB of pixel (x, y), x from the left, y from the top.
  std::uint32_t at(int x, int y) const {
    return rgb_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)];
  }
  // Where pixel (x, y) is, for a message: "pixel (x, y) of file.png" or "file.csv:line:col".
  std::string where(int x, int y) const;

 private:
  std::string source_;
  int width_ = 0, height_ = 0;
  std::vector<std::uint32_t> rgb_;
  // A CSV picture: its text and the file line of each grid line (top first), to name a cell's line:col.
  std::string csv_text_;
  std::vector<std::size_t> csv_lines_;
};

// libpng's simplified API: the PNG's pixels as 0xRRGGBB, top row first (alpha composited onto white,
// palette and grey images expanded). Throws DesignError naming `source` when it cannot be read or is
// outside 1..kMaxWidth × 1..kMaxHeight.
std::vector<std::uint32_t> decode_png_rgb(const std::string& bytes, const std::string& source, int& width,
                                          int& height);

}  // namespace loom::design

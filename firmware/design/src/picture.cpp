// Reading a picture to fit (see picture.hpp): PNG through libpng, CSV through the design reader.
#include "loom/design/picture.hpp"

#include <png.h>

#include <cctype>
#include <utility>

#include "loom/design/design.hpp"

namespace loom::design {

std::vector<std::uint32_t> decode_png_rgb(const std::string& bytes, const std::string& source, int& width,
                                          int& height) {
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  const auto fail = [&](const std::string& why) -> DesignError {
    const std::string lib = img.message[0] != '\0' ? std::string(" (libpng: ") + img.message + ")" : "";
    png_image_free(&img);
    return DesignError(source + ": " + why + lib);
  };
  if (png_image_begin_read_from_memory(&img, bytes.data(), bytes.size()) == 0)
    throw fail("not a readable PNG");
  const auto w = static_cast<long>(img.width), h = static_cast<long>(img.height);
  if (w < 1 || w > kMaxWidth || h < 1 || h > kMaxHeight) {
    throw fail(std::to_string(w) + " x " + std::to_string(h) + " pixels: a design is 1.." +
               std::to_string(kMaxWidth) + " knots wide and 1.." + std::to_string(kMaxHeight) +
               " rows (one pixel per knot)");
  }
  img.format = PNG_FORMAT_RGB;
  std::vector<png_byte> rgb(PNG_IMAGE_SIZE(img));
  const png_color white{255, 255, 255};
  if (png_image_finish_read(&img, &white, rgb.data(), 0, nullptr) == 0) throw fail("cannot decode");
  png_image_free(&img);
  std::vector<std::uint32_t> out(static_cast<std::size_t>(w * h));
  for (std::size_t i = 0; i < out.size(); ++i) {
    const png_byte* p = &rgb[i * 3];
    out[i] = static_cast<std::uint32_t>(p[0]) << 16 | static_cast<std::uint32_t>(p[1]) << 8 | p[2];
  }
  width = static_cast<int>(w);
  height = static_cast<int>(h);
  return out;
}

Picture::Picture(std::string source, int width, int height, std::vector<std::uint32_t> rgb)
    : source_(std::move(source)), width_(width), height_(height), rgb_(std::move(rgb)) {
  if (width_ < 1 || height_ < 1 ||
      rgb_.size() != static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_)) {
    throw DesignError(source_ + ": a picture needs width x height pixels");
  }
}

Picture Picture::read(const std::string& bytes, const std::string& source) {
  std::string ext = source.size() >= 4 ? source.substr(source.size() - 4) : source;
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".png") {
    int w = 0, h = 0;
    std::vector<std::uint32_t> rgb = decode_png_rgb(bytes, source, w, h);
    return Picture(source, w, h, std::move(rgb));
  }
  if (ext != ".csv") {
    throw DesignError(source + ": not a picture: want a .png or a .csv grid of colour codes");
  }
  std::vector<std::size_t> lines;
  const Design d = parse_design_csv(bytes, source, lines);
  std::vector<std::uint32_t> rgb(static_cast<std::size_t>(d.width()) * static_cast<std::size_t>(d.height()));
  for (int y = 0; y < d.height(); ++y) {
    const auto row = d.row(d.height() - 1 - y);  // design row 0 is the picture's bottom line
    for (int x = 0; x < d.width(); ++x) {
      rgb[static_cast<std::size_t>(y) * static_cast<std::size_t>(d.width()) + static_cast<std::size_t>(x)] =
          d.palette()[row[static_cast<std::size_t>(x)]].rgb;
    }
  }
  Picture p(source, d.width(), d.height(), std::move(rgb));
  p.csv_text_ = bytes;
  p.csv_lines_ = std::move(lines);
  return p;
}

std::string Picture::where(int x, int y) const {
  if (!csv_lines_.empty())
    return design_csv_cell_at(csv_text_, source_, csv_lines_[static_cast<std::size_t>(y)], x);
  return "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") of " + source_;
}

}  // namespace loom::design

// The design model, the CSV reader and the dispatch by file type (see design.hpp).
#include "loom/design/design.hpp"

#include <algorithm>
#include <cctype>
#include <map>

namespace loom::design {
namespace {

std::string base_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool hex_colour(const std::string& s, std::uint32_t& rgb) {
  if (s.size() != 7 || s[0] != '#') return false;
  rgb = 0;
  for (std::size_t i = 1; i < 7; ++i) {
    const char c = static_cast<char>(std::tolower(static_cast<unsigned char>(s[i])));
    const int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
    if (d < 0) return false;
    rgb = rgb << 4 | static_cast<std::uint32_t>(d);
  }
  return true;
}

bool code_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
}

// One CSV line split at commas, each cell trimmed, with the 1-based column where it starts.
struct Cell {
  std::string text;
  std::size_t col;
};
std::vector<Cell> split_cells(const std::string& line) {
  std::vector<Cell> cells;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    const std::size_t end = comma == std::string::npos ? line.size() : comma;
    std::size_t a = start, b = end;
    while (a < b && (line[a] == ' ' || line[a] == '\t')) ++a;
    while (b > a && (line[b - 1] == ' ' || line[b - 1] == '\t')) --b;
    cells.push_back({line.substr(a, b - a), a + 1});
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return cells;
}

class CsvReader {
 public:
  CsvReader(const std::string& text, const std::string& source,
            std::vector<std::size_t>* grid_lines = nullptr)
      : text_(text), source_(source), grid_lines_(grid_lines) {}

  Design read() {
    std::size_t pos = 0;
    if (text_.compare(0, 3, "\xEF\xBB\xBF") == 0) pos = 3;  // a spreadsheet's UTF-8 byte-order mark
    while (pos <= text_.size()) {
      const std::size_t nl = text_.find('\n', pos);
      std::string line = text_.substr(pos, nl == std::string::npos ? std::string::npos : nl - pos);
      ++line_no_;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      take(line);
      if (nl == std::string::npos) break;
      pos = nl + 1;
    }
    if (rows_.empty()) fail(line_no_, 1, "no rows of knots (a design needs at least one grid line)");
    // The file is the picture top line first; the carpet is woven from its bottom line up.
    std::vector<std::uint16_t> knots;
    knots.reserve(rows_.size() * static_cast<std::size_t>(width_));
    for (auto it = rows_.rbegin(); it != rows_.rend(); ++it)
      knots.insert(knots.end(), it->begin(), it->end());
    return Design(source_, width_, std::move(palette_), std::move(knots));
  }

 private:
  [[noreturn]] void fail(std::size_t line, std::size_t col, const std::string& why) const {
    throw DesignError(source_ + ":" + std::to_string(line) + ":" + std::to_string(col) + ": " + why);
  }

  void take(const std::string& line) {
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos) return;  // blank
    auto cells = split_cells(line);
    std::uint32_t rgb = 0;
    // '#' starts a comment, unless the line's first cell is a literal colour (a row of #RRGGBB cells).
    if (line[first] == '#' && !hex_colour(cells.front().text, rgb)) return;
    for (std::size_t i = 0; i < line.size(); ++i) {
      const auto c = static_cast<unsigned char>(line[i]);
      if (c < 0x20 && c != '\t')
        fail(line_no_, i + 1, "control character 0x" + hex2(c) + " in a design line");
    }
    if (cells.front().text == "palette") {
      palette_line(cells);
    } else {
      grid_line(cells);
    }
  }

  static std::string hex2(unsigned c) {
    const char* d = "0123456789abcdef";
    return {d[c >> 4 & 0xF], d[c & 0xF]};
  }

  void palette_line(const std::vector<Cell>& cells) {
    if (!rows_.empty())
      fail(line_no_, 1, "palette line after the grid began (define every code before the first row)");
    if (cells.size() < 3 || cells.size() > 4) {
      fail(line_no_, 1,
           "palette line has " + std::to_string(cells.size() - 1) +
               " fields: want palette,CODE,#RRGGBB[,name]");
    }
    const Cell& code = cells[1];
    check_code(code);
    if (code.text[0] == '#')
      fail(line_no_, code.col,
           "palette code '" + code.text + "' starts with '#' (reserved for literal colours)");
    if (codes_.count(code.text)) fail(line_no_, code.col, "palette code '" + code.text + "' defined twice");
    std::uint32_t rgb = 0;
    if (!hex_colour(cells[2].text, rgb)) {
      fail(line_no_, cells[2].col, "colour of '" + code.text + "' = '" + cells[2].text + "': want #RRGGBB");
    }
    add_colour(Colour{code.text, rgb, cells.size() == 4 ? cells[3].text : ""}, code.col);
  }

  void grid_line(const std::vector<Cell>& cells) {
    if (rows_.empty()) {
      width_ = static_cast<int>(cells.size());
      if (width_ > kMaxWidth)
        fail(line_no_, 1, std::to_string(width_) + " knots per row: more than " + std::to_string(kMaxWidth));
    } else if (static_cast<int>(cells.size()) != width_) {
      fail(line_no_, 1,
           "row of " + std::to_string(cells.size()) + " knots; the design's rows have " +
               std::to_string(width_) + " (every row the same width)");
    }
    if (static_cast<int>(rows_.size()) >= kMaxHeight)
      fail(line_no_, 1, "more than " + std::to_string(kMaxHeight) + " rows");
    std::vector<std::uint16_t> row;
    row.reserve(cells.size());
    for (const Cell& c : cells) {
      if (c.text.empty()) fail(line_no_, c.col, "empty cell: every knot needs a colour code");
      auto it = codes_.find(c.text);
      std::uint32_t rgb = 0;
      if (it == codes_.end() && hex_colour(c.text, rgb)) {
        add_colour(Colour{lower(c.text), rgb, ""}, c.col);
        codes_[c.text] = static_cast<std::uint16_t>(palette_.size() - 1);
        it = codes_.find(c.text);
      }
      if (it == codes_.end()) {
        check_code(c);
        fail(line_no_, c.col,
             "colour code '" + c.text + "' is not in the palette (" + known_codes() +
                 "); define it with palette," + c.text + ",#RRGGBB");
      }
      row.push_back(it->second);
    }
    rows_.push_back(std::move(row));
    if (grid_lines_ != nullptr) grid_lines_->push_back(line_no_);
  }

  void check_code(const Cell& c) const {
    const bool literal = c.text.size() == 7 && c.text[0] == '#';
    if (c.text.empty() || c.text.size() > kMaxCodeLength ||
        (!literal && !std::all_of(c.text.begin(), c.text.end(), code_char))) {
      fail(line_no_, c.col,
           "colour code '" + c.text.substr(0, 40) + "': want 1.." + std::to_string(kMaxCodeLength) +
               " letters, digits, '_', '-' or '.'");
    }
  }

  void add_colour(Colour c, std::size_t col) {
    if (static_cast<int>(palette_.size()) >= kMaxColours) {
      fail(line_no_, col, "more than " + std::to_string(kMaxColours) + " colours in one design");
    }
    codes_[c.code] = static_cast<std::uint16_t>(palette_.size());
    palette_.push_back(std::move(c));
  }

  std::string known_codes() const {
    if (palette_.empty()) return "no palette lines";
    std::string s = "the palette has ";
    for (std::size_t i = 0; i < palette_.size() && i < 12; ++i) s += (i ? ", " : "") + palette_[i].code;
    return palette_.size() > 12 ? s + ", ..." : s;
  }

  const std::string& text_;
  const std::string& source_;
  std::vector<std::size_t>* grid_lines_;  // where each grid line is, when the caller asks
  std::size_t line_no_ = 0;
  int width_ = 0;
  std::vector<Colour> palette_;
  std::map<std::string, std::uint16_t> codes_;
  std::vector<std::vector<std::uint16_t>> rows_;  // file order (top of the picture first)
};

}  // namespace

Design::Design(const std::string& source, int width, std::vector<Colour> palette,
               std::vector<std::uint16_t> knots_bottom_up)
    : name_(base_name(source)),
      width_(width),
      palette_(std::move(palette)),
      knots_(std::move(knots_bottom_up)) {
  if (width_ < 1 || width_ > kMaxWidth || knots_.empty() ||
      knots_.size() % static_cast<std::size_t>(width_) != 0) {
    throw DesignError(name_ + ": a design needs whole rows of 1.." + std::to_string(kMaxWidth) + " knots");
  }
  height_ = static_cast<int>(knots_.size() / static_cast<std::size_t>(width_));
  if (height_ > kMaxHeight) throw DesignError(name_ + ": more than " + std::to_string(kMaxHeight) + " rows");
  for (std::uint16_t k : knots_) {
    if (k >= palette_.size())
      throw DesignError(name_ + ": a knot refers to colour " + std::to_string(k) + " beyond the palette");
  }
}

std::span<const std::uint16_t> Design::row(int r) const {
  return std::span<const std::uint16_t>(knots_).subspan(
      static_cast<std::size_t>(r) * static_cast<std::size_t>(width_), static_cast<std::size_t>(width_));
}

Design parse_design_csv(const std::string& text, const std::string& source) {
  return CsvReader(text, source).read();
}

Design parse_design_csv(const std::string& text, const std::string& source,
                        std::vector<std::size_t>& grid_lines) {
  grid_lines.clear();
  return CsvReader(text, source, &grid_lines).read();
}

std::string design_csv_cell_at(const std::string& text, const std::string& source, std::size_t line,
                               int knot) {
  std::size_t pos = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  for (std::size_t n = 1; n < line && pos != std::string::npos; ++n) {
    pos = text.find('\n', pos);
    if (pos != std::string::npos) ++pos;
  }
  std::size_t col = 1;
  if (pos != std::string::npos) {
    const std::size_t nl = text.find('\n', pos);
    const auto cells = split_cells(text.substr(pos, nl == std::string::npos ? std::string::npos : nl - pos));
    if (knot >= 0 && static_cast<std::size_t>(knot) < cells.size())
      col = cells[static_cast<std::size_t>(knot)].col;
  }
  return source + ":" + std::to_string(line) + ":" + std::to_string(col);
}

Design parse_design(const std::string& bytes, const std::string& source) {
  const std::string ext = lower(source.size() >= 4 ? source.substr(source.size() - 4) : source);
  if (ext == ".csv") return parse_design_csv(bytes, source);
  if (ext == ".png") return parse_design_png(bytes, source);
  throw DesignError(
      source + ": not a design file: want a .csv grid of colour codes or a .png with one pixel per knot");
}

DesignPosition position_after(const Design& d, std::uint64_t rows_done) {
  const auto h = static_cast<std::uint64_t>(d.height());
  // Clamped before the +1: with one row and 2^64-1 rows done, rows_done / h + 1 wraps to repeat 0
  // (found by tests/fuzz/fuzz_design).
  return {static_cast<int>(rows_done % h),
          static_cast<int>(std::min<std::uint64_t>(rows_done / h, INT32_MAX - 1) + 1)};
}

}  // namespace loom::design

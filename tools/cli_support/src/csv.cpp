// CsvWriter (see csv.hpp): bounded buffering, one cell count per row, no NaN/inf ever printed.
#include "loom/cli/csv.hpp"

#include <cmath>

namespace loom::cli {

CsvWriter::CsvWriter(std::string_view header, bool full_precision, std::FILE* out, std::size_t hold_bytes)
    : full_(full_precision), out_(out), hold_(hold_bytes) {
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = header.find(',', start);
    columns_.emplace_back(
        header.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  buf_.reserve(hold_ + 256);
  buf_.append(header);
  buf_ += '\n';
}

void CsvWriter::cell_separator() {
  if (cells_ >= columns_.size()) {
    throw std::logic_error("CSV row " + std::to_string(rows_ + 1) + " has more cells than the " +
                           std::to_string(columns_.size()) + " columns");
  }
  if (cells_ > 0) buf_ += ',';
}

CsvWriter& CsvWriter::num(double v) {
  if (!std::isfinite(v)) {
    const std::string col = cells_ < columns_.size() ? columns_[cells_] : "?";
    throw NonFiniteOutput("row " + std::to_string(rows_ + 1) + ", column " + col + ": the result is " +
                          (std::isnan(v) ? "NaN" : "infinite") +
                          " (inputs beyond what double precision can represent here)");
  }
  cell_separator();
  char b[40];
  std::snprintf(b, sizeof b, full_ ? "%.17g" : "%.12g", v == 0.0 ? 0.0 : v);
  buf_ += b;
  ++cells_;
  return *this;
}

CsvWriter& CsvWriter::text(std::string_view cell) {
  cell_separator();
  buf_.append(cell);
  ++cells_;
  return *this;
}

void CsvWriter::end_row() {
  if (cells_ != columns_.size()) {
    throw std::logic_error("CSV row " + std::to_string(rows_ + 1) + " has " + std::to_string(cells_) +
                           " cells for " + std::to_string(columns_.size()) + " columns");
  }
  buf_ += '\n';
  cells_ = 0;
  ++rows_;
  if (buf_.size() >= hold_) spill();
}

void CsvWriter::spill() {
  if (!buf_.empty() && std::fwrite(buf_.data(), 1, buf_.size(), out_) != buf_.size()) {
    throw std::runtime_error("cannot write the CSV output");
  }
  buf_.clear();
}

void CsvWriter::finish() {
  if (cells_ != 0) throw std::logic_error("CSV: finish() inside a row");
  spill();
  if (std::fflush(out_) != 0) throw std::runtime_error("cannot write the CSV output");
}

std::string format_number(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

}  // namespace loom::cli

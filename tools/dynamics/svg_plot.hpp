// A hand-written SVG line chart: one x axis, any number of named series, linear axes with round
// ticks. Enough to see force/torque against crank angle without a plotting dependency.
#pragma once

#include <string>
#include <vector>

namespace loom::dyncli {

struct Series {
  std::string name;
  std::vector<double> y;
};

struct Chart {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<double> x;
  std::vector<Series> series;
};

// The chart as an SVG document (800×480 px).
std::string render_svg(const Chart& c);

// Writes the SVG to `path`; false (and errno set) when the file cannot be written.
bool write_svg(const Chart& c, const std::string& path);

}  // namespace loom::dyncli

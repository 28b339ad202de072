// A small SVG chart writer for run reports (no plotting library on the controller): line/point series
// and horizontal timeline bars on linear axes with ticks and labels. Output is a self-contained SVG.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace loom::report {

struct Series {
  std::string label;
  std::string colour = "#1f77b4";
  std::vector<std::pair<double, double>> points;  // (x, y)
  bool markers = true;
  bool line = true;
};

struct Band {  // a shaded horizontal band, e.g. the 80–100 N target
  double y0 = 0.0, y1 = 0.0;
  std::string label;
};

struct Chart {
  std::string title, x_label, y_label;
  std::vector<Series> series;
  std::vector<Band> bands;
  double width_px = 760, height_px = 420;
};

std::string render_svg(const Chart& chart);

struct TimelineBar {
  std::string lane;  // row label, e.g. "shed"
  double t0 = 0.0, t1 = 0.0;
  std::string colour = "#1f77b4";
};

struct Timeline {
  std::string title, x_label = "time (s)";
  std::vector<std::string> lanes;  // top to bottom
  std::vector<TimelineBar> bars;
  double width_px = 760, height_px = 260;
};

std::string render_svg(const Timeline& timeline);

}  // namespace loom::report

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
  // true: the y axis spans the data (at least `min_y_span`), bands are clipped to it, so a 0.4 N
  // spread is visible; false: the axis starts at 0 and includes every band.
  bool zoom_to_data = false;
  double min_y_span = 1.0;
};

std::string render_svg(const Chart& chart);

struct TimelineBar {
  std::string lane;  // lane label, e.g. "shed"; "" spans every lane (e.g. an incomplete row)
  double t0 = 0.0, t1 = 0.0;
  std::string colour = "#1f77b4";
  bool outline = false;  // drawn as a dashed outline (something that did not finish)
  std::string label;     // written above the bar when there is room
};

struct TimelineMarker {  // a vertical line across every lane, e.g. a fault
  double t = 0.0;
  std::string label;
  std::string colour = "#d62728";
};

struct Timeline {
  std::string title, x_label = "time (s)";
  std::vector<std::string> lanes;  // top to bottom
  std::vector<TimelineBar> bars;
  std::vector<TimelineMarker> markers;
  double width_px = 760, height_px = 260;
};

std::string render_svg(const Timeline& timeline);

}  // namespace loom::report

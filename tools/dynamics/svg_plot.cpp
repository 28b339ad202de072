// SVG line chart by hand: tick steps of 1, 2 or 5 × 10ⁿ so the grid reads in round numbers, one
// polyline per series, a legend in the corner. Non-finite values break the line instead of
// producing an invalid path.
#include "svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

namespace loom::dyncli {

namespace {

constexpr double kW = 800, kH = 480, kLeft = 80, kRight = 20, kTop = 40, kBottom = 60;
constexpr const char* kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                    "#8c564b", "#e377c2", "#7f7f7f", "#17becf", "#bcbd22"};

double nice_step(double span, int target) {
  const double raw = span / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * mag;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", std::abs(v) < 1e-12 ? 0.0 : v);
  return b;
}

std::string escape(const std::string& s) {
  std::string o;
  for (const char c : s) {
    if (c == '<')
      o += "&lt;";
    else if (c == '>')
      o += "&gt;";
    else if (c == '&')
      o += "&amp;";
    else
      o += c;
  }
  return o;
}

}  // namespace

std::string render_svg(const Chart& c) {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const double x : c.x) {
    if (std::isfinite(x)) {
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
    }
  }
  for (const Series& s : c.series) {
    for (const double y : s.y) {
      if (std::isfinite(y)) {
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
    }
  }
  if (!(x1 > x0)) {
    x0 = 0;
    x1 = 1;
  }
  if (!(y1 > y0)) {
    const double m = std::isfinite(y0) ? y0 : 0.0;
    y0 = m - 1;
    y1 = m + 1;
  }
  const double xs = nice_step(x1 - x0, 8), ys = nice_step(y1 - y0, 6);
  x0 = std::floor(x0 / xs) * xs;
  x1 = std::ceil(x1 / xs) * xs;
  y0 = std::floor(y0 / ys) * ys;
  y1 = std::ceil(y1 / ys) * ys;
  const double pw = kW - kLeft - kRight, ph = kH - kTop - kBottom;
  const auto px = [&](double x) { return kLeft + (x - x0) / (x1 - x0) * pw; };
  const auto py = [&](double y) { return kTop + (y1 - y) / (y1 - y0) * ph; };

  std::string o;
  o += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(kW) + "\" height=\"" + num(kH) +
       "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  o += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  o += "<text x=\"" + num(kW / 2) + "\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">" + escape(c.title) +
       "</text>\n";
  for (double x = x0; x <= x1 + 0.5 * xs; x += xs) {
    o += "<line x1=\"" + num(px(x)) + "\" y1=\"" + num(kTop) + "\" x2=\"" + num(px(x)) + "\" y2=\"" +
         num(kTop + ph) + "\" stroke=\"#ddd\"/>\n";
    o += "<text x=\"" + num(px(x)) + "\" y=\"" + num(kTop + ph + 16) + "\" text-anchor=\"middle\">" + num(x) +
         "</text>\n";
  }
  for (double y = y0; y <= y1 + 0.5 * ys; y += ys) {
    o += "<line x1=\"" + num(kLeft) + "\" y1=\"" + num(py(y)) + "\" x2=\"" + num(kLeft + pw) + "\" y2=\"" +
         num(py(y)) + "\" stroke=\"#ddd\"/>\n";
    o += "<text x=\"" + num(kLeft - 6) + "\" y=\"" + num(py(y) + 4) + "\" text-anchor=\"end\">" + num(y) +
         "</text>\n";
  }
  o += "<rect x=\"" + num(kLeft) + "\" y=\"" + num(kTop) + "\" width=\"" + num(pw) + "\" height=\"" +
       num(ph) + "\" fill=\"none\" stroke=\"black\"/>\n";
  o += "<text x=\"" + num(kLeft + pw / 2) + "\" y=\"" + num(kH - 16) + "\" text-anchor=\"middle\">" +
       escape(c.x_label) + "</text>\n";
  o += "<text transform=\"translate(18," + num(kTop + ph / 2) + ") rotate(-90)\" text-anchor=\"middle\">" +
       escape(c.y_label) + "</text>\n";
  for (std::size_t k = 0; k < c.series.size(); ++k) {
    const Series& s = c.series[k];
    const std::string colour = kColours[k % (sizeof kColours / sizeof *kColours)];
    std::string pts;
    const auto flush = [&] {
      if (!pts.empty())
        o += "<polyline fill=\"none\" stroke=\"" + colour + "\" stroke-width=\"1.5\" points=\"" + pts +
             "\"/>\n";
      pts.clear();
    };
    for (std::size_t i = 0; i < c.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(c.x[i]) || !std::isfinite(s.y[i])) {
        flush();
        continue;
      }
      pts += num(px(c.x[i])) + "," + num(py(s.y[i])) + " ";
    }
    flush();
    const double ly = kTop + 16 + 16 * static_cast<double>(k);
    o += "<line x1=\"" + num(kLeft + pw - 150) + "\" y1=\"" + num(ly - 4) + "\" x2=\"" +
         num(kLeft + pw - 130) + "\" y2=\"" + num(ly - 4) + "\" stroke=\"" + colour +
         "\" stroke-width=\"2\"/>\n";
    o += "<text x=\"" + num(kLeft + pw - 125) + "\" y=\"" + num(ly) + "\">" + escape(s.name) + "</text>\n";
  }
  o += "</svg>\n";
  return o;
}

bool write_svg(const Chart& c, const std::string& path) {
  std::ofstream f(path, std::ios::binary);
  if (!f) return false;
  f << render_svg(c);
  return static_cast<bool>(f.flush());
}

}  // namespace loom::dyncli

// SVG rendering: "nice" tick steps (1, 2, 5 × 10^k) so axes read like a technician's plot.
#include "loom/report/svg_chart.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace loom::report {
namespace {

struct Range {
  double lo = 0.0, hi = 1.0;
};

double nice_step(double span, int target_ticks) {
  const double raw = span / std::max(1, target_ticks);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * mag >= raw) return m * mag;
  }
  return 10.0 * mag;
}

Range padded(double lo, double hi) {
  if (!(hi > lo)) {
    lo -= 1.0;
    hi += 1.0;
  }
  const double step = nice_step(hi - lo, 6);
  return {std::floor(lo / step) * step, std::ceil(hi / step) * step};
}

std::string esc(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '&':
        o += "&amp;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

std::string num(double v) {
  std::ostringstream os;
  os << std::setprecision(6) << v;
  return os.str();
}

struct Frame {
  double left = 70, right = 20, top = 40, bottom = 55;
  double w, h;
  Range x, y;
  double px(double v) const { return left + (v - x.lo) / (x.hi - x.lo) * (w - left - right); }
  double py(double v) const { return h - bottom - (v - y.lo) / (y.hi - y.lo) * (h - top - bottom); }
};

void axes(std::ostringstream& os, const Frame& f, const std::string& xl, const std::string& yl,
          bool y_ticks) {
  os << "<rect x='" << f.left << "' y='" << f.top << "' width='" << f.w - f.left - f.right << "' height='"
     << f.h - f.top - f.bottom << "' fill='none' stroke='#333'/>\n";
  const double xs = nice_step(f.x.hi - f.x.lo, 8);
  for (double v = f.x.lo; v <= f.x.hi + 1e-9 * xs; v += xs) {
    os << "<line x1='" << f.px(v) << "' x2='" << f.px(v) << "' y1='" << f.h - f.bottom << "' y2='"
       << f.h - f.bottom + 5 << "' stroke='#333'/><text x='" << f.px(v) << "' y='" << f.h - f.bottom + 18
       << "' font-size='11' text-anchor='middle'>" << num(v) << "</text>\n";
  }
  if (y_ticks) {
    const double ys = nice_step(f.y.hi - f.y.lo, 6);
    for (double v = f.y.lo; v <= f.y.hi + 1e-9 * ys; v += ys) {
      os << "<line x1='" << f.left - 5 << "' x2='" << f.w - f.right << "' y1='" << f.py(v) << "' y2='"
         << f.py(v) << "' stroke='#ddd'/><text x='" << f.left - 8 << "' y='" << f.py(v) + 4
         << "' font-size='11' text-anchor='end'>" << num(v) << "</text>\n";
    }
  }
  os << "<text x='" << (f.left + f.w - f.right) / 2 << "' y='" << f.h - 12
     << "' font-size='12' text-anchor='middle'>" << esc(xl) << "</text>\n";
  os << "<text transform='translate(16," << (f.top + f.h - f.bottom) / 2
     << ") rotate(-90)' font-size='12' text-anchor='middle'>" << esc(yl) << "</text>\n";
}

}  // namespace

std::string render_svg(const Chart& c) {
  double xlo = 1e300, xhi = -1e300, ylo = 1e300, yhi = -1e300;
  for (const auto& s : c.series) {
    for (const auto& [x, y] : s.points) {
      xlo = std::min(xlo, x), xhi = std::max(xhi, x), ylo = std::min(ylo, y), yhi = std::max(yhi, y);
    }
  }
  const bool have_points = xlo <= xhi;
  if (!c.zoom_to_data || !have_points) {
    for (const auto& b : c.bands) ylo = std::min(ylo, b.y0), yhi = std::max(yhi, b.y1);
  }
  if (xlo > xhi) xlo = 0, xhi = 1;
  if (ylo > yhi) ylo = 0, yhi = 1;
  Frame f;
  f.w = c.width_px;
  f.h = c.height_px;
  f.x = padded(xlo, xhi);
  if (c.zoom_to_data && have_points) {
    const double mid = 0.5 * (ylo + yhi);
    const double half = 0.5 * std::max(c.min_y_span, (yhi - ylo) * 1.2);
    f.y = padded(mid - half, mid + half);
  } else {
    f.y = padded(std::min(0.0, ylo), yhi);
  }
  std::ostringstream os;
  os << "<svg xmlns='http://www.w3.org/2000/svg' width='" << f.w << "' height='" << f.h
     << "' font-family='sans-serif'>\n<rect width='100%' height='100%' fill='white'/>\n";
  os << "<text x='" << f.w / 2 << "' y='22' font-size='14' text-anchor='middle'>" << esc(c.title)
     << "</text>\n";
  for (const auto& b : c.bands) {
    // Clipped to the frame: with the axis zoomed to the data the band may cover all of it.
    const double y0 = std::max(b.y0, f.y.lo), y1 = std::min(b.y1, f.y.hi);
    if (y1 <= y0) continue;
    os << "<rect x='" << f.left << "' y='" << f.py(y1) << "' width='" << f.w - f.left - f.right
       << "' height='" << f.py(y0) - f.py(y1) << "' fill='#2ca02c' fill-opacity='0.12'/><text x='"
       << f.w - f.right - 4 << "' y='" << f.py(y1) + 13
       << "' font-size='11' text-anchor='end' fill='#2ca02c'>" << esc(b.label) << "</text>\n";
  }
  axes(os, f, c.x_label, c.y_label, true);
  int legend = 0;
  for (const auto& s : c.series) {
    if (s.line && s.points.size() > 1) {
      os << "<polyline fill='none' stroke='" << s.colour << "' stroke-width='1.5' points='";
      for (const auto& [x, y] : s.points) os << f.px(x) << ',' << f.py(y) << ' ';
      os << "'/>\n";
    }
    if (s.markers) {
      for (const auto& [x, y] : s.points) {
        os << "<circle cx='" << f.px(x) << "' cy='" << f.py(y) << "' r='3' fill='" << s.colour << "'/>\n";
      }
    }
    os << "<text x='" << f.left + 8 << "' y='" << f.top + 16 + 15 * legend++ << "' font-size='11' fill='"
       << s.colour << "'>" << esc(s.label) << "</text>\n";
  }
  os << "</svg>\n";
  return os.str();
}

std::string render_svg(const Timeline& t) {
  double thi = 0.0, tlo = 1e300;
  for (const auto& b : t.bars) thi = std::max(thi, b.t1), tlo = std::min(tlo, b.t0);
  for (const auto& m : t.markers) thi = std::max(thi, m.t), tlo = std::min(tlo, m.t);
  if (tlo > thi) tlo = 0, thi = 1;
  Frame f;
  f.left = 90;
  f.w = t.width_px;
  f.h = t.height_px;
  f.x = padded(tlo, thi);
  f.y = {0.0, static_cast<double>(std::max<std::size_t>(1, t.lanes.size()))};
  std::ostringstream os;
  os << "<svg xmlns='http://www.w3.org/2000/svg' width='" << f.w << "' height='" << f.h
     << "' font-family='sans-serif'>\n<rect width='100%' height='100%' fill='white'/>\n";
  os << "<text x='" << f.w / 2 << "' y='22' font-size='14' text-anchor='middle'>" << esc(t.title)
     << "</text>\n";
  axes(os, f, t.x_label, "", false);
  for (std::size_t i = 0; i < t.lanes.size(); ++i) {
    const double yc = f.y.hi - static_cast<double>(i) - 0.5;
    os << "<text x='" << f.left - 8 << "' y='" << f.py(yc) + 4 << "' font-size='12' text-anchor='end'>"
       << esc(t.lanes[i]) << "</text>\n";
  }
  for (const auto& b : t.bars) {
    double top = f.y.hi - 0.1, bottom = f.y.lo + 0.1;  // "" lane: across every lane
    if (!b.lane.empty()) {
      const auto it = std::find(t.lanes.begin(), t.lanes.end(), b.lane);
      if (it == t.lanes.end()) continue;
      const double yc = f.y.hi - static_cast<double>(it - t.lanes.begin()) - 0.5;
      top = yc + 0.35, bottom = yc - 0.35;
    }
    const double w = std::max(1.0, f.px(b.t1) - f.px(b.t0));
    os << "<rect x='" << f.px(b.t0) << "' y='" << f.py(top) << "' width='" << w << "' height='"
       << f.py(bottom) - f.py(top)
       << (b.outline ? "' fill='none' stroke-dasharray='5,3' stroke-width='1.5' stroke='" : "' fill='")
       << b.colour << "'/>\n";
    // An outlined bar (a row that did not finish) is always labelled: that is the point of drawing it.
    if (!b.label.empty() && (b.outline || w >= 7.0 * static_cast<double>(b.label.size()) * 0.8)) {
      os << "<text x='" << f.px(b.t0) + w / 2 << "' y='" << f.py(top) - 3
         << "' font-size='10' text-anchor='middle' fill='" << b.colour << "'>" << esc(b.label) << "</text>\n";
    }
  }
  for (const auto& m : t.markers) {
    os << "<line x1='" << f.px(m.t) << "' x2='" << f.px(m.t) << "' y1='" << f.top << "' y2='"
       << f.h - f.bottom << "' stroke='" << m.colour << "' stroke-width='2'/><text x='" << f.px(m.t) - 4
       << "' y='" << f.top + 12 << "' font-size='11' text-anchor='end' fill='" << m.colour << "'>"
       << esc(m.label) << "</text>\n";
  }
  os << "</svg>\n";
  return os.str();
}

}  // namespace loom::report

// SVG layout: a 2-column grid of panels, decade ticks on both log axes. Zero errors (the closed
// form, or a table that is exact to the last bit) sit on the panel's floor so they stay visible.
#include "chart.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "summary.hpp"

namespace loom::profile {

namespace {

constexpr double kPanelW = 560, kPanelH = 400, kLeft = 78, kRight = 18, kTop = 46, kBottom = 52;
constexpr int kColumns = 2;

const char* colour(const std::string& interp) {
  if (interp == "linear") return "#1f77b4";
  if (interp == "cubic") return "#ff7f0e";
  if (interp == "quintic") return "#2ca02c";
  return "#000000";  // exact
}

std::string fmt(const char* f, double a) {
  char b[64];
  std::snprintf(b, sizeof b, f, a);
  return b;
}

// Filled when the row meets the profile's velocity and acceleration bounds, hollow when it does not
// (linear tables: fast and accurate in position, but their slope is a staircase).
std::string marker(double x, double y, const AccuracyRow& r, bool front, bool derivatives_ok) {
  const char* c = colour(r.interp);
  std::string style = front ? std::string("fill='") + c + "' stroke='#000' stroke-width='0.8'"
                            : std::string("fill='") + c + "' fill-opacity='0.35' stroke='none'";
  if (!derivatives_ok)
    style = std::string("fill='white' fill-opacity='0' stroke='") + c + "' stroke-width='1.2'";
  const double s = front ? 5.0 : 3.5;
  std::string title = "<title>" + r.interp + " " + std::to_string(r.table_size) + " " + r.precision + ": " +
                      fmt("%.3g", r.max_pos_err) + ", " + fmt("%.3g ns", r.lookup_ns) + "</title>";
  if (r.precision == "float32") {
    return "<path d='M" + fmt("%.1f", x) + "," + fmt("%.1f", y - s) + " l" + fmt("%.1f", s) + "," +
           fmt("%.1f", 1.8 * s) + " h" + fmt("%.1f", -2 * s) + " z' " + style + ">" + title + "</path>\n";
  }
  return "<circle cx='" + fmt("%.1f", x) + "' cy='" + fmt("%.1f", y) + "' r='" + fmt("%.1f", s) + "' " +
         style + ">" + title + "</circle>\n";
}

}  // namespace

std::vector<const AccuracyRow*> pareto_front(const std::vector<const AccuracyRow*>& rows) {
  std::vector<const AccuracyRow*> front;
  for (const AccuracyRow* a : rows) {
    if (!std::isfinite(a->lookup_ns)) continue;
    bool beaten = false;
    for (const AccuracyRow* b : rows) {
      if (b == a || !std::isfinite(b->lookup_ns)) continue;
      if (b->lookup_ns <= a->lookup_ns && b->max_pos_err <= a->max_pos_err &&
          (b->lookup_ns < a->lookup_ns || b->max_pos_err < a->max_pos_err)) {
        beaten = true;
        break;
      }
    }
    if (!beaten) front.push_back(a);
  }
  std::sort(front.begin(), front.end(), [](auto* a, auto* b) { return a->lookup_ns < b->lookup_ns; });
  return front;
}

std::string pareto_svg(const Catalogue& cat, const std::vector<AccuracyRow>& rows) {
  const int n = static_cast<int>(cat.profiles.size());
  const int grid_rows = (n + kColumns - 1) / kColumns;
  const double width = kColumns * kPanelW, height = grid_rows * kPanelH + 52;
  std::string svg = "<svg xmlns='http://www.w3.org/2000/svg' width='" + fmt("%.0f", width) + "' height='" +
                    fmt("%.0f", height) + "' font-family='sans-serif' font-size='12'>\n";
  svg += "<rect width='100%' height='100%' fill='white'/>\n";
  // Legend.
  double lx = 20;
  for (const char* i : {"linear", "cubic", "quintic", "exact"}) {
    svg += "<circle cx='" + fmt("%.0f", lx) + "' cy='20' r='5' fill='" + colour(i) + "'/><text x='" +
           fmt("%.0f", lx + 9) + "' y='24'>" + i + "</text>\n";
    lx += 90;
  }
  svg += "<circle cx='" + fmt("%.0f", lx) + "' cy='20' r='5' fill='#888'/><text x='" + fmt("%.0f", lx + 9) +
         "' y='24'>double</text>\n";
  svg += "<path d='M" + fmt("%.0f", lx + 80) + ",15 l5,9 h-10 z' fill='#888'/><text x='" +
         fmt("%.0f", lx + 89) + "' y='24'>float32</text>\n";
  svg +=
      "<text x='20' y='42'>joined: Pareto front; hollow: misses the velocity/acceleration bounds; dashed: "
      "requirement; "
      "red ring: default; floor: zero error</text>\n";

  for (int k = 0; k < n; ++k) {
    const ReportProfile& prof = cat.profiles[static_cast<std::size_t>(k)];
    const double ox = (k % kColumns) * kPanelW, oy = 52 + (k / kColumns) * kPanelH;
    std::vector<const AccuracyRow*> mine;
    for (const AccuracyRow& r : rows) {
      if (r.profile == prof.name && std::isfinite(r.lookup_ns) && r.lookup_ns > 0) mine.push_back(&r);
    }
    if (mine.empty()) continue;
    double tmin = INFINITY, tmax = 0, emin = INFINITY, emax = 0;
    for (const AccuracyRow* r : mine) {
      tmin = std::min(tmin, r->lookup_ns);
      tmax = std::max(tmax, r->lookup_ns);
      if (r->max_pos_err > 0) emin = std::min(emin, r->max_pos_err);
      emax = std::max(emax, r->max_pos_err);
    }
    emin = std::min(emin, prof.requirement);
    emax = std::max(emax, prof.requirement);
    const double x0 = std::floor(std::log10(tmin)), x1 = std::max(x0 + 1, std::ceil(std::log10(tmax)));
    const double y0 = std::floor(std::log10(emin)) - 1, y1 = std::max(y0 + 1, std::ceil(std::log10(emax)));
    const double pw = kPanelW - kLeft - kRight, ph = kPanelH - kTop - kBottom;
    const auto X = [&](double ns) { return ox + kLeft + (std::log10(ns) - x0) / (x1 - x0) * pw; };
    const auto Y = [&](double e) {
      return oy + kTop + (y1 - std::log10(std::max(e, std::pow(10.0, y0)))) / (y1 - y0) * ph;
    };
    svg += "<text x='" + fmt("%.0f", ox + kLeft) + "' y='" + fmt("%.0f", oy + 28) + "' font-weight='bold'>" +
           prof.name + "</text><text x='" + fmt("%.0f", ox + kLeft + 130) + "' y='" + fmt("%.0f", oy + 28) +
           "'>" + prof.what + "</text>\n";
    svg += "<rect x='" + fmt("%.1f", ox + kLeft) + "' y='" + fmt("%.1f", oy + kTop) + "' width='" +
           fmt("%.1f", pw) + "' height='" + fmt("%.1f", ph) + "' fill='none' stroke='#444'/>\n";
    for (double d = x0; d <= x1 + 1e-9; d += 1) {
      for (int m = 1; m <= 9; ++m) {
        const double v = m * std::pow(10.0, d);
        if (std::log10(v) > x1 + 1e-9) break;
        const double x = X(v);
        svg += "<line x1='" + fmt("%.1f", x) + "' x2='" + fmt("%.1f", x) + "' y1='" + fmt("%.1f", oy + kTop) +
               "' y2='" + fmt("%.1f", oy + kTop + ph) + "' stroke='#" + (m == 1 ? "ccc" : "eee") + "'/>\n";
        if (m == 1 || m == 2 || m == 5) {
          svg += "<text x='" + fmt("%.1f", x) + "' y='" + fmt("%.1f", oy + kTop + ph + 16) +
                 "' text-anchor='middle'>" + fmt("%g", v) + "</text>\n";
        }
      }
    }
    for (double d = y0; d <= y1 + 1e-9; d += 1) {
      const double y = Y(std::pow(10.0, d));
      svg += "<line x1='" + fmt("%.1f", ox + kLeft) + "' x2='" + fmt("%.1f", ox + kLeft + pw) + "' y1='" +
             fmt("%.1f", y) + "' y2='" + fmt("%.1f", y) + "' stroke='#ddd'/>\n";
      if (static_cast<long>(d - y0) % 2 == 0) {
        svg += "<text x='" + fmt("%.1f", ox + kLeft - 6) + "' y='" + fmt("%.1f", y + 4) +
               "' text-anchor='end'>1e" + fmt("%.0f", d) + "</text>\n";
      }
    }
    svg += "<text x='" + fmt("%.1f", ox + kLeft + pw / 2) + "' y='" + fmt("%.1f", oy + kPanelH - 12) +
           "' text-anchor='middle'>lookup time (ns, Google Benchmark)</text>\n";
    svg += "<text transform='translate(" + fmt("%.1f", ox + 16) + "," + fmt("%.1f", oy + kTop + ph / 2) +
           ") rotate(-90)' text-anchor='middle'>max position error (" + prof.unit + ")</text>\n";
    const double ry = Y(prof.requirement);
    svg += "<line x1='" + fmt("%.1f", ox + kLeft) + "' x2='" + fmt("%.1f", ox + kLeft + pw) + "' y1='" +
           fmt("%.1f", ry) + "' y2='" + fmt("%.1f", ry) + "' stroke='#d62728' stroke-dasharray='6,4'/>\n";
    const std::vector<const AccuracyRow*> front = pareto_front(mine);
    std::string path;
    for (const AccuracyRow* r : front)
      path +=
          (path.empty() ? "M" : " L") + fmt("%.1f", X(r->lookup_ns)) + "," + fmt("%.1f", Y(r->max_pos_err));
    const auto ok = [&](const AccuracyRow* r) {
      return r->max_vel_err <= prof.vel_requirement() && r->max_acc_err <= prof.acc_requirement();
    };
    for (const AccuracyRow* r : mine) {
      if (std::find(front.begin(), front.end(), r) == front.end()) {
        svg += marker(X(r->lookup_ns), Y(r->max_pos_err), *r, false, ok(r));
      }
    }
    svg += "<path d='" + path + "' fill='none' stroke='#000' stroke-width='1'/>\n";
    for (const AccuracyRow* r : front) svg += marker(X(r->lookup_ns), Y(r->max_pos_err), *r, true, ok(r));
    if (const AccuracyRow* d = choose_default(prof, rows).row) {
      svg += "<circle cx='" + fmt("%.1f", X(d->lookup_ns)) + "' cy='" + fmt("%.1f", Y(d->max_pos_err)) +
             "' r='10' fill='none' stroke='#d62728' stroke-width='2'><title>default: " + choice_label(*d) +
             "</title></circle>\n<text x='" + fmt("%.1f", X(d->lookup_ns) + 13) + "' y='" +
             fmt("%.1f", Y(d->max_pos_err) - 8) + "' fill='#d62728'>default: " + choice_label(*d) +
             "</text>\n";
    }
  }
  svg += "</svg>\n";
  return svg;
}

}  // namespace loom::profile

// `loom-synth three-point`: seed 001's three-precision-point synthesis of the knotting linkage's chain
// A0 → O1 → O2 → P (first link fixed at θ0, last link at θ2_i at point i). Lengths in mm, angles in
// degrees; one CSV row per real solution with its loop-closure residual. No real solution, points that
// do not determine the chain (repeated or collinear), and a chain whose links run off to infinity are
// refused with the reason and exit 2.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/three_point.hpp"

namespace loom::synth {

namespace {

// Links longer than this many times the points' extent are the λ → 0 branch running off to infinity:
// dropped with a note (their digits are the roots' rounding, not a mechanism).
constexpr double kInfiniteLinkRatio = 1e6;
// Longer than this many times the extent: printed, flagged as a near-infinite link (ill-conditioned).
constexpr double kLongLinkRatio = 1e3;

}  // namespace

motion::PrecisionPoint parse_precision_point(const std::string& text, int index) {
  const std::string arg = "--point " + text;
  std::array<double, 3> v{};
  std::stringstream ss(text);
  std::string part;
  int n = 0;
  while (std::getline(ss, part, ',')) {
    if (n == 3) throw ArgError(arg + ": expected RX,RY,THETA2 (mm, mm, degrees): more than three numbers");
    std::size_t used = 0;
    double x = 0.0;
    try {
      x = std::stod(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != part.size() || !std::isfinite(x)) {
      throw ArgError(arg + ": '" + part +
                     "' is not a finite number (expected RX,RY,THETA2 in mm, mm, degrees)");
    }
    v[static_cast<std::size_t>(n++)] = x;
  }
  if (n != 3)
    throw ArgError(arg + ": expected RX,RY,THETA2 (mm, mm, degrees), point " + std::to_string(index + 1));
  return motion::PrecisionPoint{v[0], v[1], motion::rad(v[2])};
}

void run_three_point(const ThreePointArgs& args, std::ostream& out, std::ostream& err) {
  if (args.points.size() != 3) {
    throw ArgError("--point: give exactly three precision points (got " + std::to_string(args.points.size()) +
                   ")");
  }
  if (!std::isfinite(args.theta0_deg)) throw ArgError("--theta0-deg: must be a finite angle in degrees");
  std::array<motion::PrecisionPoint, 3> pts{};
  for (int i = 0; i < 3; ++i)
    pts[static_cast<std::size_t>(i)] = parse_precision_point(args.points[static_cast<std::size_t>(i)], i);
  double extent = 0.0;
  for (int i = 0; i < 3; ++i) {
    const auto& p = pts[static_cast<std::size_t>(i)];
    extent = std::max({extent, std::fabs(p.x), std::fabs(p.y)});
    for (int j = 0; j < i; ++j) {
      const auto& q = pts[static_cast<std::size_t>(j)];
      if (p.x == q.x && p.y == q.y) {
        throw ArgError("--point: points " + std::to_string(j + 1) + " and " + std::to_string(i + 1) +
                       " are at the same place (" + args.points[static_cast<std::size_t>(i)] +
                       "): three distinct positions are needed");
      }
    }
  }
  const double theta0 = motion::rad(args.theta0_deg);
  motion::ThreePointResult r;
  try {
    r = motion::three_point_synthesis(pts, theta0);
  } catch (const motion::MotionError& e) {
    if (e.code() == motion::ErrorCode::kSingular) {
      throw ArgError(
          std::string("--point: the three points do not determine the chain (collinear or repeated "
                      "positions with these angles): ") +
          e.what());
    }
    throw ArgError(std::string("--point/--theta0-deg: ") + e.what());
  }
  if (r.rejected_roots > 0) {
    err << "loom-synth: note: " << r.rejected_roots << " real root" << (r.rejected_roots > 1 ? "s" : "")
        << " of the lambda quadratic left out: lambda = 1/(a0 a2) = 0 (or a1^2 <= 0) is a chain with an "
           "infinite link, not a mechanism\n";
  }
  std::vector<motion::ThreePointSolution> finite;
  const double reach = std::max(extent, 1e-300);
  for (const motion::ThreePointSolution& s : r.solutions) {
    const double longest = std::max({std::fabs(s.a0), std::fabs(s.a1), std::fabs(s.a2)});
    if (!(longest <= kInfiniteLinkRatio * reach)) {
      err << "loom-synth: note: solution lambda = " << s.lambda << " dropped: a link of " << longest
          << " mm is " << longest / reach << " times the points' extent (infinite link)\n";
      continue;
    }
    if (longest > kLongLinkRatio * reach) {
      err << "loom-synth: warning: solution lambda = " << s.lambda << ": a link of " << longest << " mm is "
          << longest / reach << " times the points' extent: near the infinite-link root, ill-conditioned\n";
    }
    for (const auto& [name, len] : {std::pair{"a0", s.a0}, std::pair{"a2", s.a2}}) {
      if (len < 0.0) {
        err << "loom-synth: note: solution lambda = " << s.lambda << ": " << name << " = " << len
            << " < 0: that link points the other way (along its angle + 180 deg), length " << -len << " mm\n";
      }
    }
    finite.push_back(s);
  }
  if (finite.empty()) {
    std::ostringstream msg;
    msg << "--point: no real solution: ";
    if (r.complex_roots > 0) msg << "the lambda quadratic has complex roots";
    if (r.complex_roots > 0 && r.rejected_roots + static_cast<int>(r.solutions.size()) > 0) msg << "; ";
    if (r.rejected_roots > 0 || !r.solutions.empty())
      msg << "its real roots give no finite chain (infinite link)";
    throw ArgError(msg.str());
  }
  const CsvFormat f(args.full_precision);
  out << "lambda,a0,a1,a2,theta1_1_deg,theta1_2_deg,theta1_3_deg,closure_residual\n";
  for (const motion::ThreePointSolution& s : finite) {
    char lambda[64];
    std::snprintf(lambda, sizeof lambda, args.full_precision ? "%.17g" : "%.10g", s.lambda);
    write_row(out, {lambda, f.length(s.a0), f.length(s.a1), f.length(s.a2),
                    f.angle_deg(motion::deg(s.theta1_rad[0])), f.angle_deg(motion::deg(s.theta1_rad[1])),
                    f.angle_deg(motion::deg(s.theta1_rad[2])), [&] {
                      char b[64];
                      std::snprintf(b, sizeof b, "%.3g", s.closure_residual);
                      return std::string(b);
                    }()});
  }
}

}  // namespace loom::synth

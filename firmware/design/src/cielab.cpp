// sRGB → L*a*b* and CIEDE2000 (see cielab.hpp).
#include "loom/design/cielab.hpp"

#include <cmath>
#include <numbers>

namespace loom::design {
namespace {

// IEC 61966-2-1: the sRGB transfer function undone (an 8-bit channel to linear light, 0..1).
double linear(std::uint32_t channel) {
  const double v = static_cast<double>(channel & 0xFFu) / 255.0;
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

// CIE 15: the cube-root compression, linear near black (ε = 216/24389, κ = 24389/27 as exact fractions,
// so the two branches meet).
double f(double t) {
  constexpr double kEpsilon = 216.0 / 24389.0, kKappa = 24389.0 / 27.0;
  return t > kEpsilon ? std::cbrt(t) : (kKappa * t + 16.0) / 116.0;
}

double deg(double rad) {
  return rad * 180.0 / std::numbers::pi;
}
double rad(double deg) {
  return deg * std::numbers::pi / 180.0;
}

}  // namespace

Lab lab_from_srgb(std::uint32_t rgb) {
  const double r = linear(rgb >> 16), g = linear(rgb >> 8), b = linear(rgb);
  // Linear sRGB to XYZ (the sRGB primaries and the D65 white), then relative to that white.
  const double x = (0.4124564 * r + 0.3575761 * g + 0.1804375 * b) / 0.95047;
  const double y = (0.2126729 * r + 0.7151522 * g + 0.0721750 * b) / 1.0;
  const double z = (0.0193339 * r + 0.1191920 * g + 0.9503041 * b) / 1.08883;
  const double fx = f(x), fy = f(y), fz = f(z);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

// Sharma, Wu & Dalal (2005), equations (1)–(19); the hue conventions for neutral colours (C' = 0) as there.
double delta_e_2000(const Lab& p, const Lab& q) {
  constexpr double k25_7 = 6103515625.0;  // 25^7
  const double c_ab = (std::hypot(p.a, p.b) + std::hypot(q.a, q.b)) / 2.0;
  const double c7 = std::pow(c_ab, 7.0);
  const double g = 0.5 * (1.0 - std::sqrt(c7 / (c7 + k25_7)));
  const double a1 = (1.0 + g) * p.a, a2 = (1.0 + g) * q.a;
  const double c1 = std::hypot(a1, p.b), c2 = std::hypot(a2, q.b);
  const auto hue = [](double b, double a) {
    if (a == 0.0 && b == 0.0) return 0.0;
    const double h = deg(std::atan2(b, a));
    return h < 0.0 ? h + 360.0 : h;
  };
  const double h1 = hue(p.b, a1), h2 = hue(q.b, a2);

  const double dl = q.L - p.L, dc = c2 - c1;
  double dh = 0.0;
  if (c1 * c2 != 0.0) {
    dh = h2 - h1;
    if (dh > 180.0) dh -= 360.0;
    if (dh < -180.0) dh += 360.0;
  }
  const double d_big_h = 2.0 * std::sqrt(c1 * c2) * std::sin(rad(dh / 2.0));

  const double l_mean = (p.L + q.L) / 2.0, c_mean = (c1 + c2) / 2.0;
  double h_mean = h1 + h2;
  if (c1 * c2 != 0.0) {
    if (std::abs(h1 - h2) <= 180.0) {
      h_mean /= 2.0;
    } else {
      h_mean = h_mean < 360.0 ? (h_mean + 360.0) / 2.0 : (h_mean - 360.0) / 2.0;
    }
  }
  const double t = 1.0 - 0.17 * std::cos(rad(h_mean - 30.0)) + 0.24 * std::cos(rad(2.0 * h_mean)) +
                   0.32 * std::cos(rad(3.0 * h_mean + 6.0)) - 0.20 * std::cos(rad(4.0 * h_mean - 63.0));
  const double d_theta = 30.0 * std::exp(-std::pow((h_mean - 275.0) / 25.0, 2.0));
  const double c_mean7 = std::pow(c_mean, 7.0);
  const double r_c = 2.0 * std::sqrt(c_mean7 / (c_mean7 + k25_7));
  const double l50 = (l_mean - 50.0) * (l_mean - 50.0);
  const double s_l = 1.0 + 0.015 * l50 / std::sqrt(20.0 + l50);
  const double s_c = 1.0 + 0.045 * c_mean;
  const double s_h = 1.0 + 0.015 * c_mean * t;
  const double r_t = -std::sin(rad(2.0 * d_theta)) * r_c;
  const double tl = dl / s_l, tc = dc / s_c, th = d_big_h / s_h;
  return std::sqrt(tl * tl + tc * tc + th * th + r_t * tc * th);
}

}  // namespace loom::design

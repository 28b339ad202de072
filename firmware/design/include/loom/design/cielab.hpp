// Colour difference as a weaver sees it: 8-bit sRGB → linear → CIE XYZ (D65) → CIE L*a*b*, and the
// CIEDE2000 colour difference between two L*a*b* colours. Used to map a picture's colours to the yarns
// loaded on the loom (design_fit); configure-time only.
//
// The conversion is IEC 61966-2-1 (sRGB) with the D65 white XYZ = (0.95047, 1, 1.08883) and CIE 15's
// L*a*b*; CIEDE2000 is CIE 142-2001 as written out by Sharma, Wu and Dalal (2005), kL = kC = kH = 1.
#pragma once

#include <cstdint>

namespace loom::design {

struct Lab {
  double L = 0.0, a = 0.0, b = 0.0;
};

// The L*a*b* (D65, 2° observer) of an 8-bit sRGB colour 0xRRGGBB.
Lab lab_from_srgb(std::uint32_t rgb);

// CIEDE2000 ΔE00 between two colours (symmetric; 0 for equal colours; about 1 is a just noticeable
// difference).
double delta_e_2000(const Lab& x, const Lab& y);

}  // namespace loom::design

// The knot plan (see knot_plan.hpp): stripes, counts and selector moves, from the [knotting] facts.
#include "loom/sequencer/knot_plan.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <stdexcept>

namespace loom::sequencer {
namespace {
// The value among `values` whose name is `text` (false, `out` untouched, when none is).
template <class E>
bool parse_named(const char* text, std::initializer_list<E> values, const char* (*name)(E), E& out) {
  for (E v : values) {
    if (std::strcmp(text, name(v)) == 0) {
      out = v;
      return true;
    }
  }
  return false;
}
}  // namespace

const char* knotting_mode_name(KnottingMode m) {
  switch (m) {
    case KnottingMode::kNone:
      return "none";
    case KnottingMode::kWeaver:
      return "weaver";
    case KnottingMode::kHeads:
      return "heads";
  }
  return "?";
}

bool parse_knotting_mode(const char* text, KnottingMode& m) {
  return parse_named(text, {KnottingMode::kNone, KnottingMode::kWeaver, KnottingMode::kHeads},
                     knotting_mode_name, m);
}

const char* knot_type_name(KnotType k) {
  switch (k) {
    case KnotType::kTurkish:
      return "turkish";
    case KnotType::kPersianLeft:
      return "persian_left";
    case KnotType::kPersianRight:
      return "persian_right";
  }
  return "?";
}

bool parse_knot_type(const char* text, KnotType& k) {
  return parse_named(text, {KnotType::kTurkish, KnotType::kPersianLeft, KnotType::kPersianRight},
                     knot_type_name, k);
}

CarpetClass carpet_class(double n) {
  if (!(n >= 215.0) || n > 10000.0) return CarpetClass::kOutside;
  if (n <= 700.0) return CarpetClass::kCoarse;
  if (n <= 1400.0) return CarpetClass::kMedium;
  if (n <= 1850.0) return CarpetClass::kFine;
  if (n <= 2400.0) return CarpetClass::kExtraFine;
  return CarpetClass::kExtraExtraFine;
}

const char* carpet_class_name(CarpetClass c) {
  switch (c) {
    case CarpetClass::kOutside:
      return "outside the thesis' classes (215..10000 knots/dm^2)";
    case CarpetClass::kCoarse:
      return "coarse";
    case CarpetClass::kMedium:
      return "medium";
    case CarpetClass::kFine:
      return "fine";
    case CarpetClass::kExtraFine:
      return "extra fine";
    case CarpetClass::kExtraExtraFine:
      return "extra extra fine";
  }
  return "?";
}

double knot_pitch_m(const KnottingSpec& s) {
  return 0.1 / s.knots_per_dm;
}

// A hair of tolerance, so that 1.2 m at 30 knots/dm is 360 knots, not 359.999… → 359.
int knots_per_row(const KnottingSpec& s, double width_m) {
  return static_cast<int>(std::floor(width_m / knot_pitch_m(s) + 1e-9));
}

int knots_per_stripe(const KnottingSpec& s) {
  return static_cast<int>(std::floor(s.head_spacing_m / knot_pitch_m(s) + 1e-9));
}

double placement_tolerance_m(const KnottingSpec& s) {
  return s.placement_tolerance_m > 0.0 ? s.placement_tolerance_m
                                       : default_placement_tolerance_m(knot_pitch_m(s));
}

std::optional<KnottingFault> find_fault(const KnottingSpec& s, double width_m) {
  using F = KnottingField;
  const auto fin = [](double v) { return std::isfinite(v); };
  if (!fin(s.knots_per_dm) || s.knots_per_dm < 5.0 || s.knots_per_dm > 200.0) {
    return KnottingFault{F::kKnotsPerDm, "knotting.knots_per_dm must be in [5, 200]"};
  }
  if (!fin(s.rows_per_dm) || s.rows_per_dm < 5.0 || s.rows_per_dm > 200.0) {
    return KnottingFault{F::kRowsPerDm, "knotting.rows_per_dm must be in [5, 200]"};
  }
  if (s.mode != KnottingMode::kHeads) return std::nullopt;
  if (s.heads < 1 || s.heads > kMaxKnottingHeads) {
    return KnottingFault{F::kHeads, "knotting.heads must be 1.." + std::to_string(kMaxKnottingHeads)};
  }
  if (!fin(s.head_spacing_m) || knots_per_stripe(s) < 1) {
    return KnottingFault{F::kHeadSpacing, "knotting.head_spacing_m must hold at least one knot pitch"};
  }
  // Every head sits over a knot when head 1 does: the spacing is a whole number of knot pitches.
  if (const double p = knot_pitch_m(s), whole = knots_per_stripe(s) * p;
      std::abs(s.head_spacing_m - whole) > 0.01 * p) {
    return KnottingFault{F::kHeadSpacing,
                         "knotting.head_spacing_m = " + std::to_string(s.head_spacing_m) +
                             " is not a whole number of knot pitches (" + std::to_string(p) +
                             " m at knotting.knots_per_dm): the heads would miss their knots; " +
                             std::to_string(whole) + " m puts each over its knot"};
  }
  // The heads' stripes together must reach the right selvedge: head h ties [h·n, (h+1)·n).
  const int n = knots_per_stripe(s), k = knots_per_row(s, width_m);
  if (s.heads * n < k) {
    return KnottingFault{F::kHeadSpacing,
                         "knotting.head_spacing_m: " + std::to_string(s.heads) + " heads x " +
                             std::to_string(n) + " knots per stripe cover " + std::to_string(s.heads * n) +
                             " of the row's " + std::to_string(k) +
                             " knots (loom.width_m / knotting.heads is the spacing that covers the width)"};
  }
  if ((s.heads - 1) * n >= k) {
    return KnottingFault{F::kHeads, "knotting.heads: the last head's stripe starts beyond the row's " +
                                        std::to_string(k) + " knots (fewer heads, or a narrower spacing)"};
  }
  if (s.slot_colours.empty() || s.slot_colours.size() > static_cast<std::size_t>(kMaxMagazineSlots)) {
    return KnottingFault{F::kSlotColours, "knotting.slot_colours must name 1.." +
                                              std::to_string(kMaxMagazineSlots) +
                                              " colours (one per magazine slot)"};
  }
  for (std::size_t i = 0; i < s.slot_colours.size(); ++i) {
    if (s.slot_colours[i].empty()) {
      return KnottingFault{F::kSlotColours, "knotting.slot_colours[" + std::to_string(i) + "] is empty"};
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (s.slot_colours[i] == s.slot_colours[j]) {
        return KnottingFault{F::kSlotColours, "knotting.slot_colours: \"" + s.slot_colours[i] +
                                                  "\" is in slots " + std::to_string(j) + " and " +
                                                  std::to_string(i)};
      }
    }
  }
  if (s.knots_per_slot < 1)
    return KnottingFault{F::kKnotsPerSlot, "knotting.knots_per_slot must be at least 1"};
  // 0 is "not given" (the default); a given tolerance is positive and below half a pitch.
  if (const double p = knot_pitch_m(s), t = s.placement_tolerance_m; !fin(t) || t < 0.0 || t >= 0.5 * p) {
    return KnottingFault{F::kPlacementTolerance,
                         "knotting.placement_tolerance_m must be positive and below half the knot pitch (" +
                             std::to_string(0.5 * p) +
                             " m at knotting.knots_per_dm): half a pitch off, the gripper is over the "
                             "neighbouring knot; leave it out for the default, a quarter of the pitch (" +
                             std::to_string(default_placement_tolerance_m(p)) + " m)"};
  }
  return std::nullopt;
}

std::string validate(const KnottingSpec& s, double width_m) {
  const std::optional<KnottingFault> f = find_fault(s, width_m);
  return f ? f->message : std::string();
}

int slot_of(const KnottingSpec& s, const std::string& code) {
  for (std::size_t i = 0; i < s.slot_colours.size(); ++i) {
    if (s.slot_colours[i] == code) return static_cast<int>(i);
  }
  return -1;
}

RowKnotPlan plan_row(const KnottingSpec& s, double width_m, std::span<const std::uint16_t> row,
                     std::span<const std::string> palette, std::array<int, kMaxKnottingHeads>& slot_before) {
  RowKnotPlan p;
  p.knots = knots_per_row(s, width_m);
  if (static_cast<int>(row.size()) != p.knots) {
    throw std::invalid_argument("the design row is " + std::to_string(row.size()) +
                                " knots wide; the loom ties " + std::to_string(p.knots) +
                                " per row (loom.width_m at knotting.knots_per_dm)");
  }
  const int n = knots_per_stripe(s);
  for (int h = 0; h < s.heads; ++h) {
    const int first = h * n, last = std::min(p.knots, first + n);
    const auto hh = static_cast<std::size_t>(h);
    p.head_knots[hh] = std::max(0, last - first);
    for (int k = first; k < last; ++k) {
      const std::uint16_t colour = row[static_cast<std::size_t>(k)];
      const std::string& code = colour < palette.size() ? palette[colour] : std::string();
      const int slot = slot_of(s, code);
      if (slot < 0) {
        throw std::invalid_argument("colour \"" + code + "\" (knot " + std::to_string(k + 1) + ", head " +
                                    std::to_string(h + 1) +
                                    ") is in no magazine slot (knotting.slot_colours)");
      }
      if (slot != slot_before[hh]) ++p.selector_moves[hh];
      slot_before[hh] = slot;
    }
    p.knot_cycles = std::max(p.knot_cycles, p.head_knots[hh]);
  }
  p.carriage_steps = std::max(0, p.knot_cycles - 1);
  return p;
}

}  // namespace loom::sequencer

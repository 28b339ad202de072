// The knot plan: how the knotting heads on the carriage tie a row of the design. Pure and
// configure-time: the machine description's [knotting] facts in, per row the knots each head ties, the
// carriage steps between knots and the colour selector's moves out. Nothing here runs in the tick.
//
// Geometry: knot k of a row (0 = the left selvedge's, as the weaver faces the loom) sits k pitches from
// the left, pitch = 1 dm / knots_per_dm. Head h rides the carriage h · head_spacing from head 0 and ties
// the stripe of knots under it: knots [h·n, (h+1)·n), n = the knots in one spacing. All heads tie at once;
// between two knots the carriage steps one pitch, so a row takes n knot cycles whatever the head count.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "loom/hal/types.hpp"

namespace loom::sequencer {

inline constexpr int kMaxKnottingHeads = static_cast<int>(hal::kMaxKnottingHeads);
inline constexpr int kMaxMagazineSlots = 16;

// What the loom does about the pile: nothing (a flat weave), the weaver knots each row by hand while the
// loom waits, or the heads tie it.
enum class KnottingMode : std::uint8_t { kNone, kWeaver, kHeads };
const char* knotting_mode_name(KnottingMode m);
bool parse_knotting_mode(const char* text, KnottingMode& m);

// The knot (thesis ch. 2): the Turkish (Gördes) knot wraps a warp pair symmetrically; the Persian
// (Senneh) knot wraps one warp fully and the other half, open to the left or to the right.
enum class KnotType : std::uint8_t { kTurkish, kPersianLeft, kPersianRight };
const char* knot_type_name(KnotType k);
bool parse_knot_type(const char* text, KnotType& k);

// Carpet classes by knots per dm² (thesis Table 2.1): coarse 215–700, medium 701–1400, fine 1401–1850,
// extra fine 1851–2400, extra extra fine 2401–10000. kOutside below 215 or above 10000.
enum class CarpetClass : std::uint8_t { kOutside, kCoarse, kMedium, kFine, kExtraFine, kExtraExtraFine };
CarpetClass carpet_class(double knots_per_dm2);
const char* carpet_class_name(CarpetClass c);

struct KnottingSpec {
  KnottingMode mode = KnottingMode::kNone;
  KnotType knot = KnotType::kTurkish;
  double knots_per_dm = 30.0;  // across the width
  double rows_per_dm = 30.0;   // along the carpet
  int heads = 6;
  double head_spacing_m = 0.2;
  // Every head's colour selector holds the same magazine: slot s carries palette code slot_colours[s].
  std::vector<std::string> slot_colours;
  int knots_per_slot = 2000;  // yarn in a full slot, counted in knots
  // Commissioning and the selector's motion (the knotting servo's limits are in the knot cycle's spec; each
  // axis' top speed is its [axes.<name>] max_speed).
  double take_position_rad = 0.0;  // knotting servo reading with the gripper at TAKE
  double selector_zero_rad = 0.0;  // selector reading with slot 0 at the TAKE point
  double selector_accel_rad_s2 = 400.0;
  double selector_jerk_rad_s3 = 20000.0;
  // Knot placement: a knot cycle starts only with the carriage's measured position within this of the
  // knot's (m). 0: not given — the default, a fraction of the pitch (knot_tolerance_m()). Given, it must be
  // positive and below half the pitch (half a pitch off, the gripper is over the neighbouring knot's warp).
  double placement_tolerance_m = 0.0;
};

// The KnottingSpec fact a refusal is about: a caller maps it to its own input (the loom file's
// [knotting] key), never by reading the message.
enum class KnottingField : std::uint8_t {
  kKnotsPerDm,
  kRowsPerDm,
  kHeads,
  kHeadSpacing,
  kSlotColours,
  kKnotsPerSlot,
  kPlacementTolerance,
};
struct KnottingFault {
  KnottingField field;
  std::string message;  // why, naming the [knotting] key to change
};

// Configure-time. Nothing when the spec is usable on a loom `width_m` wide, else the first refusal.
std::optional<KnottingFault> find_fault(const KnottingSpec& spec, double width_m);
// Configure-time. "" when the spec is usable on a loom `width_m` wide, else find_fault()'s message.
std::string validate(const KnottingSpec& spec, double width_m);

// Knots across the loom: floor(width · knots per m), the pitch between them, and the knots in one
// head's stripe (the last head may have fewer).
int knots_per_row(const KnottingSpec& spec, double width_m);
double knot_pitch_m(const KnottingSpec& spec);
int knots_per_stripe(const KnottingSpec& spec);

// The default knot-placement tolerance, as a fraction of the knot pitch: a quarter of a pitch off, the
// gripper still enters the warp between the knot's own warp pair and a quarter-pitch from its neighbour's
// (half a pitch off it would be over the neighbour's).
inline constexpr double kPlacementToleranceOfPitch = 0.25;
inline double default_placement_tolerance_m(double pitch_m) noexcept {
  return kPlacementToleranceOfPitch * pitch_m;
}
// The tolerance the heads use: the spec's when given (> 0), else the default for its pitch.
double placement_tolerance_m(const KnottingSpec& spec);

// One row as the heads tie it.
struct RowKnotPlan {
  int knots = 0;                                        // in the row
  std::array<int, kMaxKnottingHeads> head_knots{};      // tied by each head
  std::array<int, kMaxKnottingHeads> selector_moves{};  // slot changes of each head's selector
  int carriage_steps = 0;                               // pitches the carriage steps between knots
  int knot_cycles = 0;                                  // sequential knot cycles (the longest stripe)
};

// The selector slot holding palette code `code`, or -1.
int slot_of(const KnottingSpec& spec, const std::string& code);

// Configure-time. The plan of one design row (palette indices, left to right) given the design's palette
// codes; `slot_before` (per head, -1 = unknown) is where each selector stands before the row, and is
// left where it stands after. Throws std::invalid_argument when the row's width is not the loom's or a
// colour has no slot (the message names the colour and where it is first needed).
RowKnotPlan plan_row(const KnottingSpec& spec, double width_m, std::span<const std::uint16_t> row,
                     std::span<const std::string> palette_codes,
                     std::array<int, kMaxKnottingHeads>& slot_before);

}  // namespace loom::sequencer

// The knot plan against numbers worked out by hand: the thesis' carpet classes (Table 2.1), knots per
// row and stripe, carriage steps and selector moves, and the refusals that name what is wrong.
#include "loom/sequencer/knot_plan.hpp"

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

using namespace loom::sequencer;

namespace {
KnottingSpec heads_spec() {
  KnottingSpec s;
  s.mode = KnottingMode::kHeads;
  s.knots_per_dm = 30.0;
  s.rows_per_dm = 30.0;
  s.heads = 2;
  s.head_spacing_m = 0.6;
  s.slot_colours = {"R", "B", "W"};
  return s;
}
std::array<int, kMaxKnottingHeads> unknown_slots() {
  std::array<int, kMaxKnottingHeads> a{};
  a.fill(-1);
  return a;
}
const std::vector<std::string> kPalette{"R", "B", "W", "G"};  // G is in no slot
}  // namespace

TEST(KnotPlan, CarpetClassesFollowTheThesisTable) {
  EXPECT_EQ(carpet_class(214.0), CarpetClass::kOutside);
  EXPECT_EQ(carpet_class(215.0), CarpetClass::kCoarse);
  EXPECT_EQ(carpet_class(700.0), CarpetClass::kCoarse);
  EXPECT_EQ(carpet_class(701.0), CarpetClass::kMedium);
  EXPECT_EQ(carpet_class(900.0),
            CarpetClass::kMedium);  // 30 x 30: the issue's "medium class, about 30 knots/dm"
  EXPECT_EQ(carpet_class(1400.0), CarpetClass::kMedium);
  EXPECT_EQ(carpet_class(1401.0), CarpetClass::kFine);
  EXPECT_EQ(carpet_class(1850.0), CarpetClass::kFine);
  EXPECT_EQ(carpet_class(1851.0), CarpetClass::kExtraFine);
  EXPECT_EQ(carpet_class(2400.0), CarpetClass::kExtraFine);
  EXPECT_EQ(carpet_class(2401.0), CarpetClass::kExtraExtraFine);
  EXPECT_EQ(carpet_class(10000.0), CarpetClass::kExtraExtraFine);
  EXPECT_EQ(carpet_class(10001.0), CarpetClass::kOutside);
  EXPECT_EQ(carpet_class(0.0 / 0.0), CarpetClass::kOutside);
}

TEST(KnotPlan, TheDefaultLoomsRowAtThirtyKnotsPerDecimetre) {
  const KnottingSpec s = heads_spec();
  // 1.2 m / (0.1 m / 30) = 360 knots at 3.333 mm; 0.6 m holds 180 of them per head.
  EXPECT_EQ(knots_per_row(s, 1.2), 360);
  EXPECT_NEAR(knot_pitch_m(s), 0.1 / 30.0, 1e-15);
  EXPECT_EQ(knots_per_stripe(s), 180);
  EXPECT_EQ(validate(s, 1.2), "");
  std::vector<std::uint16_t> row(360, 0);  // all red
  auto slots = unknown_slots();
  const RowKnotPlan p = plan_row(s, 1.2, row, kPalette, slots);
  EXPECT_EQ(p.knots, 360);
  EXPECT_EQ(p.head_knots[0], 180);
  EXPECT_EQ(p.head_knots[1], 180);
  EXPECT_EQ(p.knot_cycles, 180);      // both heads at once
  EXPECT_EQ(p.carriage_steps, 179);   // one pitch between consecutive knots
  EXPECT_EQ(p.selector_moves[0], 1);  // from "unknown" to red once
  EXPECT_EQ(p.selector_moves[1], 1);
  EXPECT_EQ(slots[0], 0);
  // The next row in the same colour needs no selector move at all.
  EXPECT_EQ(plan_row(s, 1.2, row, kPalette, slots).selector_moves[0], 0);
}

TEST(KnotPlan, SelectorMovesCountColourChangesInEachStripe) {
  KnottingSpec s = heads_spec();
  s.knots_per_dm = 10.0;  // 1.2 m: 120 knots, 60 per head
  std::vector<std::uint16_t> row(120, 0);
  // Head 0: R R ... then B for knots 10..19, then R again: 3 moves from unknown (R, B, R).
  for (int k = 10; k < 20; ++k) row[static_cast<std::size_t>(k)] = 1;
  // Head 1 (knots 60..119): alternating W/B every knot: 60 moves.
  for (int k = 60; k < 120; ++k) row[static_cast<std::size_t>(k)] = k % 2 ? 1 : 2;
  auto slots = unknown_slots();
  const RowKnotPlan p = plan_row(s, 1.2, row, kPalette, slots);
  EXPECT_EQ(p.selector_moves[0], 3);
  EXPECT_EQ(p.selector_moves[1], 60);
  EXPECT_EQ(slots[0], 0);  // left at red
  EXPECT_EQ(slots[1], 1);  // knot 119 is odd: blue
}

TEST(KnotPlan, AnUnevenLastStripe) {
  KnottingSpec s = heads_spec();
  s.heads = 3;
  s.head_spacing_m = 0.45;  // 135 knots per stripe: 135 + 135 + 90 = 360
  EXPECT_EQ(validate(s, 1.2), "");
  std::vector<std::uint16_t> row(360, 2);
  auto slots = unknown_slots();
  const RowKnotPlan p = plan_row(s, 1.2, row, kPalette, slots);
  EXPECT_EQ(p.head_knots[0], 135);
  EXPECT_EQ(p.head_knots[1], 135);
  EXPECT_EQ(p.head_knots[2], 90);
  EXPECT_EQ(p.knot_cycles, 135);
}

TEST(KnotPlan, RefusalsNameWhatIsWrong) {
  KnottingSpec s = heads_spec();
  std::vector<std::uint16_t> row(360, 0);
  row[250] = 3;  // G: knot 251, head 2
  auto slots = unknown_slots();
  try {
    (void)plan_row(s, 1.2, row, kPalette, slots);
    FAIL() << "a colour without a slot was planned";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "colour \"G\" (knot 251, head 2) is in no magazine slot (knotting.slot_colours)");
  }
  EXPECT_THROW((void)plan_row(s, 1.2, std::vector<std::uint16_t>(359, 0), kPalette, slots),
               std::invalid_argument);
  s.head_spacing_m = 0.5;  // 2 x 150 knots cover 300 of 360
  EXPECT_NE(validate(s, 1.2).find("cover 300 of the row's 360 knots"), std::string::npos) << validate(s, 1.2);
  s = heads_spec();
  s.slot_colours = {"R", "R"};
  EXPECT_NE(validate(s, 1.2).find("\"R\" is in slots 0 and 1"), std::string::npos);
  s.slot_colours = {};
  EXPECT_NE(validate(s, 1.2).find("knotting.slot_colours must name"), std::string::npos);
  s.mode = KnottingMode::kWeaver;  // the weaver needs no magazine
  EXPECT_EQ(validate(s, 1.2), "");
}

// ---------------------------------------------------------------------------------------------------
// The knot program: the design as magazine slots, read by the tick.
// ---------------------------------------------------------------------------------------------------
#include "loom/sequencer/knot_program.hpp"

TEST(KnotProgram, ProductionRowsMapToDesignRowsInTheDesignsOrderAndRepeat) {
  KnottingSpec s = heads_spec();
  s.knots_per_dm = 10.0;  // 120 knots, 60 per head
  // Three design rows (bottom first): all red, all blue, all white; palette index = slot here.
  std::vector<std::uint16_t> knots;
  for (const int colour : {0, 1, 2}) knots.insert(knots.end(), 120, static_cast<std::uint16_t>(colour));
  // Four design rows were woven by production row 10: production row 10 ties design row 4 % 3 = 1 (blue).
  const KnotProgram p = KnotProgram::build(s, 1.2, 120, 3, knots, kPalette, 4, 10);
  EXPECT_EQ(p.knots_per_row(), 120);
  EXPECT_EQ(p.stripe(), 60);
  EXPECT_EQ(p.design_row(10), 1);
  EXPECT_EQ(p.design_row(11), 2);
  EXPECT_EQ(p.design_row(12), 0);  // the design repeats
  EXPECT_EQ(p.design_row(9), 0);   // and rows before the start map back: row 9 tied design row 3 % 3
  EXPECT_EQ(p.design_row(8), 2);
  EXPECT_EQ(p.slot(10, 0), 1);
  EXPECT_EQ(p.slot(11, 119), 2);
  EXPECT_EQ(p.slot(12, 60), 0);
  EXPECT_EQ(p.slot(10, 120), -1);  // beyond the row
  // Head h ties knot h * 60 + j in cycle j, with head 0 over the middle of knot j's pitch.
  EXPECT_EQ(p.knot_of(0, 0), 0);
  EXPECT_EQ(p.knot_of(1, 59), 119);
  EXPECT_EQ(p.knot_of(1, 60), -1);
  EXPECT_NEAR(p.carriage_at(0), 0.005, 1e-15);
  EXPECT_NEAR(p.carriage_at(59), 0.595, 1e-12);
  EXPECT_EQ(p.slot_colour(2), "W");
}

TEST(KnotProgram, ADesignTheMagazinesCannotHoldIsRefusedNamingTheRowAndColour) {
  KnottingSpec s = heads_spec();
  s.knots_per_dm = 10.0;
  std::vector<std::uint16_t> knots(240, 0);
  knots[120 + 70] = 3;  // design row 2, knot 71: G is in no slot
  try {
    (void)KnotProgram::build(s, 1.2, 120, 2, knots, kPalette, 0, 0);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(
        std::string(e.what()).find("design row 2: colour \"G\" (knot 71, head 2) is in no magazine slot"),
        std::string::npos)
        << e.what();
  }
}

// Each refusal carries the spec's field (the config maps it to its key), the one its message names first.
TEST(KnotPlan, RefusalsCarryTheirField) {
  using loom::sequencer::KnottingField;
  const auto field_of = [](const KnottingSpec& s) {
    const std::optional<loom::sequencer::KnottingFault> f = find_fault(s, 1.2);
    EXPECT_TRUE(f.has_value());
    EXPECT_EQ(f ? f->message : "", validate(s, 1.2));
    return f ? f->field : KnottingField::kKnotsPerSlot;
  };
  KnottingSpec s = heads_spec();
  EXPECT_FALSE(find_fault(s, 1.2).has_value());
  s.knots_per_dm = 4.0;
  EXPECT_EQ(field_of(s), KnottingField::kKnotsPerDm);
  s = heads_spec();
  s.rows_per_dm = 300.0;
  EXPECT_EQ(field_of(s), KnottingField::kRowsPerDm);
  s = heads_spec();
  s.heads = 0;
  EXPECT_EQ(field_of(s), KnottingField::kHeads);
  s = heads_spec();
  s.head_spacing_m = 0.5;  // 2 x 150 knots cover 300 of 360
  EXPECT_EQ(field_of(s), KnottingField::kHeadSpacing);
  s.head_spacing_m = 0.6015;  // not a whole number of pitches
  EXPECT_EQ(field_of(s), KnottingField::kHeadSpacing);
  s = heads_spec();
  s.slot_colours = {"R", ""};
  EXPECT_EQ(field_of(s), KnottingField::kSlotColours);
  s = heads_spec();
  s.knots_per_slot = 0;
  EXPECT_EQ(field_of(s), KnottingField::kKnotsPerSlot);
  s = heads_spec();  // 30 knots/dm: a 3.333 mm pitch, half of it 1.667 mm
  s.placement_tolerance_m = 0.0017;
  EXPECT_EQ(field_of(s), KnottingField::kPlacementTolerance);
  s.placement_tolerance_m = -1e-4;
  EXPECT_EQ(field_of(s), KnottingField::kPlacementTolerance);
}

// The knot-placement tolerance: a quarter of the pitch unless given; a given one is used as it is, up to
// just below half the pitch.
TEST(KnotPlan, PlacementToleranceIsAQuarterPitchUnlessGiven) {
  KnottingSpec s = heads_spec();
  EXPECT_DOUBLE_EQ(placement_tolerance_m(s), 0.1 / 30.0 / 4.0);
  s.knots_per_dm = 40.0;  // 2.5 mm pitch
  s.head_spacing_m = 0.6;
  EXPECT_DOUBLE_EQ(placement_tolerance_m(s), 0.000625);
  s.placement_tolerance_m = 0.0012;  // below half of 2.5 mm
  EXPECT_FALSE(find_fault(s, 1.2).has_value());
  EXPECT_DOUBLE_EQ(placement_tolerance_m(s), 0.0012);
  s.placement_tolerance_m = 0.00125;  // half the pitch: refused
  EXPECT_TRUE(find_fault(s, 1.2).has_value());
}

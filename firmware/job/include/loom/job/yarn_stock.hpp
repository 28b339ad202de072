// The magazines' yarn, counted, not assumed: the knots of yarn left in every slot of every head's
// magazine, kept in the state directory (magazines.txt) with the counters' durability rules (written
// atomically, refused whole when not exactly what loomctl writes), so a restart starts from the levels
// before it, not from full magazines. Non-RT: read when a session is armed, written at row ends and
// when the weaver reloads a slot.
//
// The forecast: from the levels now and the knot program (which slot every knot of every row takes),
// which slot of which head runs out in which of the rows still to weave — so the loop asks for the
// reload before that row starts, not in its middle.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loom/sequencer/knot_plan.hpp"
#include "loom/sequencer/knot_program.hpp"

namespace loom::job {

class YarnStock {
 public:
  static constexpr const char* kFileName = "magazines.txt";
  static std::string path_in(const std::string& state_dir) { return state_dir + "/" + kFileName; }

  YarnStock() = default;
  // Every slot of `heads` magazines of `slots` slots full (`knots_per_slot` knots). JobError when out of
  // range (heads 1..kMaxKnottingHeads, slots 1..kMaxMagazineSlots, knots_per_slot >= 1).
  YarnStock(int heads, int slots, std::int32_t knots_per_slot);

  int heads() const { return heads_; }
  int slots() const { return slots_; }
  std::int32_t knots_per_slot() const { return capacity_; }  // a full slot
  // Knots left in `slot` of head `head` (both 0-based). JobError out of range.
  std::int32_t knots(int head, int slot) const;
  // Set a slot's level as the heads counted it (e.g. from RowKnotter::stock at a row end).
  void set(int head, int slot, std::int32_t knots);
  // The weaver reloaded the slot: full, or `knots` when given. JobError naming head, slot and the value
  // when it is not 0..knots_per_slot.
  void reload(int head, int slot, std::optional<std::int32_t> knots = std::nullopt);
  // "" when these levels are for a loom of `heads` heads, `slots` slots of `knots_per_slot`; else why not
  // (the machine description changed: the caller decides, e.g. refuses or starts from full magazines).
  std::string mismatch(int heads, int slots, std::int32_t knots_per_slot) const;

  // Missing file → nullopt (the first start: the caller fills the magazines and says so). Anything else
  // that is not a magazines file → JobError naming file:line, field and value.
  static std::optional<YarnStock> load(const std::string& path);
  // Durably (write_file_durably); std::runtime_error naming path and errno on failure (the old file stays).
  void save(const std::string& path) const;
  static std::string format(const YarnStock& s);
  static YarnStock parse(const std::string& text, const std::string& source);

 private:
  void check(int head, int slot) const;
  int heads_ = 0, slots_ = 0;
  std::int32_t capacity_ = 0;
  std::array<std::array<std::int32_t, sequencer::kMaxMagazineSlots>, sequencer::kMaxKnottingHeads> knots_{};
};

// A slot that runs out within the rows forecast.
struct SlotEmpty {
  int head = 0;                     // 0-based
  int slot = 0;                     // 0-based
  std::string colour;               // its palette code
  std::int32_t knots_left = 0;      // now
  std::uint64_t rows_from_now = 0;  // 0: the next row needs more than is left
  std::uint32_t counter_row = 0;    // that row as KnotProgram counts it (0-based production row)
  int cycle = 0;                    // the knot cycle of that row that finds it empty (0-based)
};

// Which slots empty in the `rows` rows from production row `next_counter_row` (0-based, = counters.rows),
// given the levels `stock` and the knot program (the heads' stripes and every knot's slot; it repeats the
// design as the carpet does). Each head's slot is listed once, at the first row it cannot finish, ordered
// by that row, then head, then slot. A lower bound on the yarn needed: a retried knot takes yarn again, so
// the loop forecasts again at every row end. Refused (JobError) when the stock is not for this program's
// heads and slots.
std::vector<SlotEmpty> forecast_empty_slots(const YarnStock& stock, const sequencer::KnotProgram& program,
                                            std::uint32_t next_counter_row, std::uint64_t rows);

}  // namespace loom::job

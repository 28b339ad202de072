// See yarn_stock.hpp. The file:
//   format = loomctl-magazines 1
//   knots_per_slot = 2000
//   head.1 = 2000 1873 0        (knots left in slot 0, 1, 2 of head 1)
#include "loom/job/yarn_stock.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <sstream>

#include "loom/job/job_queue.hpp"
#include "loom/state/durable_file.hpp"

namespace loom::job {
namespace {

constexpr const char* kFormat = "loomctl-magazines 1";

bool whole(const std::string& v, std::int64_t lo, std::int64_t hi, std::int64_t& out) {
  if (v.empty() || v.size() > 10 || (v.size() > 1 && v[0] == '0')) return false;
  if (!std::all_of(v.begin(), v.end(), [](char c) { return c >= '0' && c <= '9'; })) return false;
  out = std::stoll(v);
  return out >= lo && out <= hi;
}

}  // namespace

YarnStock::YarnStock(int heads, int slots, std::int32_t knots_per_slot)
    : heads_(heads), slots_(slots), capacity_(knots_per_slot) {
  if (heads < 1 || heads > sequencer::kMaxKnottingHeads || slots < 1 ||
      slots > sequencer::kMaxMagazineSlots || knots_per_slot < 1) {
    throw JobError("magazines of " + std::to_string(heads) + " heads, " + std::to_string(slots) +
                   " slots of " + std::to_string(knots_per_slot) + " knots: want 1.." +
                   std::to_string(sequencer::kMaxKnottingHeads) + " heads, 1.." +
                   std::to_string(sequencer::kMaxMagazineSlots) + " slots, at least 1 knot");
  }
  for (auto& head : knots_) head.fill(knots_per_slot);
}

void YarnStock::check(int head, int slot) const {
  if (head < 0 || head >= heads_ || slot < 0 || slot >= slots_) {
    throw JobError("head " + std::to_string(head + 1) + " slot " + std::to_string(slot) +
                   ": the magazines have heads 1.." + std::to_string(heads_) + " and slots 0.." +
                   std::to_string(slots_ - 1));
  }
}

std::int32_t YarnStock::knots(int head, int slot) const {
  check(head, slot);
  return knots_[static_cast<std::size_t>(head)][static_cast<std::size_t>(slot)];
}

void YarnStock::set(int head, int slot, std::int32_t knots) {
  check(head, slot);
  if (knots < 0 || knots > capacity_) {
    throw JobError("head " + std::to_string(head + 1) + " slot " + std::to_string(slot) + ": " +
                   std::to_string(knots) + " knots: a slot holds 0.." + std::to_string(capacity_));
  }
  knots_[static_cast<std::size_t>(head)][static_cast<std::size_t>(slot)] = knots;
}

void YarnStock::reload(int head, int slot, std::optional<std::int32_t> knots) {
  set(head, slot, knots.value_or(capacity_));
}

std::string YarnStock::mismatch(int heads, int slots, std::int32_t knots_per_slot) const {
  if (heads == heads_ && slots == slots_ && knots_per_slot == capacity_) return "";
  return "the magazines file is for " + std::to_string(heads_) + " heads of " + std::to_string(slots_) +
         " slots of " + std::to_string(capacity_) + " knots; the loom has " + std::to_string(heads) +
         " heads of " + std::to_string(slots) + " slots of " + std::to_string(knots_per_slot);
}

std::string YarnStock::format(const YarnStock& s) {
  std::ostringstream os;
  os << "# loomctl's magazines: knots of yarn left per head (head.1 = head 1) and slot (0, 1, ...)\n"
     << "format = " << kFormat << "\nknots_per_slot = " << s.capacity_ << "\n";
  for (int h = 0; h < s.heads_; ++h) {
    os << "head." << h + 1 << " =";
    for (int k = 0; k < s.slots_; ++k)
      os << " " << s.knots_[static_cast<std::size_t>(h)][static_cast<std::size_t>(k)];
    os << "\n";
  }
  return os.str();
}

YarnStock YarnStock::parse(const std::string& text, const std::string& source) {
  const auto fail = [&](std::size_t line, const std::string& why) -> void {
    throw JobError(source + ":" + std::to_string(line) + ": " + why +
                   " (refusing the magazines' levels; nothing changed)");
  };
  const auto bad = [&](std::size_t line, const std::string& field, const std::string& value,
                       const std::string& want) {
    fail(line, "field \"" + field + "\" = \"" + value.substr(0, 80) + "\": " + want);
  };
  YarnStock s;
  std::map<std::string, std::size_t> seen;
  std::vector<std::vector<std::int64_t>> heads;
  std::vector<std::size_t> head_line;
  std::int64_t capacity = 0;
  std::istringstream in(text);
  std::string line;
  std::size_t n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty() || line[0] == '#') continue;
    const auto eq = line.find(" = ");
    if (eq == std::string::npos || eq == 0) fail(n, "\"" + line.substr(0, 80) + "\": want field = value");
    const std::string field = line.substr(0, eq), value = line.substr(eq + 3);
    if (seen.count(field))
      fail(n, "field \"" + field + "\" given twice (first on line " + std::to_string(seen[field]) + ")");
    seen[field] = n;
    if (field == "format") {
      if (value != kFormat) bad(n, field, value, std::string("want \"") + kFormat + "\"");
    } else if (field == "knots_per_slot") {
      if (!whole(value, 1, std::numeric_limits<std::int32_t>::max(), capacity)) {
        bad(n, field, value, "want a whole number of knots in 1..2147483647");
      }
    } else if (field.rfind("head.", 0) == 0) {
      std::int64_t h = 0;
      if (!whole(field.substr(5), 1, sequencer::kMaxKnottingHeads, h) ||
          h != static_cast<std::int64_t>(heads.size()) + 1) {
        fail(n, "field \"" + field + "\": want head.1, head.2, ... in order, at most " +
                    std::to_string(sequencer::kMaxKnottingHeads) + " heads (next: head." +
                    std::to_string(heads.size() + 1) + ")");
      }
      std::istringstream items(value);
      std::string item;
      std::vector<std::int64_t> levels;
      while (items >> item) {
        std::int64_t v = 0;
        if (!whole(item, 0, std::numeric_limits<std::int32_t>::max(), v)) {
          bad(n, field, value,
              "slot " + std::to_string(levels.size()) + " = \"" + item + "\": not a whole number of knots");
        }
        levels.push_back(v);
      }
      if (levels.empty() || levels.size() > static_cast<std::size_t>(sequencer::kMaxMagazineSlots)) {
        bad(n, field, value, "want 1.." + std::to_string(sequencer::kMaxMagazineSlots) + " slots");
      }
      if (!heads.empty() && levels.size() != heads.front().size()) {
        bad(n, field, value,
            std::to_string(levels.size()) + " slots; head.1 has " + std::to_string(heads.front().size()));
      }
      heads.push_back(levels);
      head_line.push_back(n);
    } else {
      fail(n, "unknown field \"" + field + "\"");
    }
  }
  if (!seen.count("format"))
    fail(1, std::string("lacks \"format = ") + kFormat + "\" (not a loomctl magazines file)");
  if (!seen.count("knots_per_slot")) fail(1, "lacks \"knots_per_slot\"");
  if (heads.empty()) fail(1, "lacks \"head.1\"");
  s = YarnStock(static_cast<int>(heads.size()), static_cast<int>(heads.front().size()),
                static_cast<std::int32_t>(capacity));
  for (std::size_t h = 0; h < heads.size(); ++h) {
    for (std::size_t k = 0; k < heads[h].size(); ++k) {
      if (heads[h][k] > capacity) {
        bad(head_line[h], "head." + std::to_string(h + 1), std::to_string(heads[h][k]),
            "slot " + std::to_string(k) + " holds more than knots_per_slot = " + std::to_string(capacity));
      }
      s.knots_[h][k] = static_cast<std::int32_t>(heads[h][k]);
    }
  }
  return s;
}

std::optional<YarnStock> YarnStock::load(const std::string& path) {
  const state::StateFileRead r = state::read_state_file(path, 64 * 1024);
  using O = state::StateFileRead::Outcome;
  switch (r.outcome) {
    case O::kAbsent:
      return std::nullopt;
    case O::kCannotOpen:
      throw JobError(path + ": magazines file exists but cannot be read: " + r.error);
    case O::kNotRegular:
      throw JobError(path + ": not a magazines file (not a regular file of at most 64 KiB)");
    case O::kCannotRead:
      throw JobError(path + ": magazines file cannot be read: " + r.error);
    case O::kRead:
      break;
  }
  return parse(r.text, path);
}

void YarnStock::save(const std::string& path) const {
  state::write_file_durably(path, format(*this));
}

std::vector<SlotEmpty> forecast_empty_slots(const YarnStock& stock, const sequencer::KnotProgram& program,
                                            std::uint32_t next_counter_row, std::uint64_t rows) {
  if (program.empty()) return {};
  const std::string why = stock.mismatch(program.heads(), program.slots(), program.knots_per_slot());
  if (!why.empty()) throw JobError("cannot forecast the yarn: " + why);
  const int heads = program.heads(), slots = program.slots(), stripe = program.stripe();
  const auto hs = [&](int h, int s) { return static_cast<std::size_t>(h * slots + s); };
  // Production rows are 32-bit: never forecast past the last one.
  rows = std::min<std::uint64_t>(rows, std::uint64_t{UINT32_MAX} - next_counter_row);
  // Knots each head takes from each slot in the rows of one pass through the design, from the next row on
  // (the program repeats the design, so row next + i uses what row next + (i mod period) uses).
  const std::uint64_t period = static_cast<std::uint64_t>(program.design_rows());
  const std::uint64_t used_rows = std::min(period, rows);
  std::vector<std::int64_t> per_row(used_rows * static_cast<std::size_t>(heads * slots), 0);
  std::vector<std::int64_t> per_period(static_cast<std::size_t>(heads * slots), 0);
  for (std::uint64_t i = 0; i < used_rows; ++i) {
    for (int h = 0; h < heads; ++h) {
      for (int j = 0; j < stripe; ++j) {
        const int k = program.knot_of(h, j);
        if (k < 0) continue;
        const int s = program.slot(next_counter_row + static_cast<std::uint32_t>(i), k);
        ++per_row[i * static_cast<std::size_t>(heads * slots) + hs(h, s)];
        ++per_period[hs(h, s)];
      }
    }
  }
  std::vector<std::int64_t> left(static_cast<std::size_t>(heads * slots));
  std::vector<bool> out(left.size(), false);
  for (int h = 0; h < heads; ++h) {
    for (int s = 0; s < slots; ++s) left[hs(h, s)] = stock.knots(h, s);
  }
  std::vector<SlotEmpty> found;
  std::uint64_t offset = 0;
  while (offset < rows) {
    // Whole passes through the design that empty no slot are taken in one step (a long carpet's forecast
    // costs a pass per slot that runs out, not a step per row).
    if (offset % period == 0 && period <= rows - offset) {
      std::uint64_t passes = (rows - offset) / period;
      for (std::size_t i = 0; i < left.size(); ++i) {
        if (!out[i] && per_period[i] > 0)
          passes = std::min<std::uint64_t>(passes, static_cast<std::uint64_t>(left[i] / per_period[i]));
      }
      if (passes > 0) {
        for (std::size_t i = 0; i < left.size(); ++i) {
          if (!out[i]) left[i] -= static_cast<std::int64_t>(passes) * per_period[i];
        }
        offset += passes * period;
        continue;
      }
    }
    const std::int64_t* use = &per_row[(offset % period) * static_cast<std::size_t>(heads * slots)];
    const std::uint32_t counter_row = next_counter_row + static_cast<std::uint32_t>(offset);
    for (int h = 0; h < heads; ++h) {
      for (int s = 0; s < slots; ++s) {
        const std::size_t i = hs(h, s);
        if (out[i]) continue;
        if (use[i] <= left[i]) {
          left[i] -= use[i];
          continue;
        }
        // It runs out in this row: at the cycle that needs one knot more than is left.
        std::int64_t need = 0;
        int cycle = 0;
        for (int j = 0; j < stripe; ++j) {
          const int k = program.knot_of(h, j);
          if (k >= 0 && program.slot(counter_row, k) == s && ++need > left[i]) {
            cycle = j;
            break;
          }
        }
        found.push_back({h, s, program.slot_colour(s), stock.knots(h, s), offset, counter_row, cycle});
        out[i] = true;
      }
    }
    ++offset;
  }
  return found;
}

}  // namespace loom::job

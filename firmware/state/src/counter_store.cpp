// Atomic counter persistence as a tiny JSON object {"rows":R,"picks":P,"beats":B,"picks_in_row":K}, plus the
// knotting heads' counts ("knots", "knots_retried", "knots_by_hand", "knot_cycles_started",
// "knot_cycles_done"); a file written before the heads existed lacks them, and they were zero then.
// The parser accepts exactly that shape (whitespace aside): four distinct keys, each a whole number
// in the 32-bit range; 1.5, -1, 1e3, 4294967296 and duplicates are refused, never rounded or wrapped.
#include "loom/state/counter_store.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "loom/config/config.hpp"
#include "loom/state/durable_file.hpp"

namespace loom::state {

using firmware::ConfigError;
namespace {

// A cursor over the text that reports the column of what it could not accept.
struct Cursor {
  const std::string& text;
  const std::string& source;
  std::size_t i = 0;

  [[noreturn]] void fail(const std::string& why) const {
    throw ConfigError(source + ": offset " + std::to_string(i) + ": " + why +
                      " (counters file: " + text.substr(0, 80) + (text.size() > 80 ? "..." : "") + ")");
  }
  void skip_ws() {
    while (i < text.size() && (text[i] == ' ' || text[i] == '\t' || text[i] == '\n' || text[i] == '\r')) ++i;
  }
  void expect(char c) {
    skip_ws();
    if (i >= text.size() || text[i] != c) fail(std::string("expected '") + c + "'");
    ++i;
  }
  bool peek(char c) {
    skip_ws();
    return i < text.size() && text[i] == c;
  }
  std::string key() {
    expect('"');
    const std::size_t start = i;
    while (i < text.size() && text[i] != '"') {
      if (!(std::islower(static_cast<unsigned char>(text[i])) || text[i] == '_'))
        fail("unexpected character in a key");
      ++i;
    }
    if (i >= text.size()) fail("unterminated key");
    return text.substr(start, i++ - start);
  }
  std::uint32_t count(const std::string& field) {
    skip_ws();
    const std::size_t start = i;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
    const std::string digits = text.substr(start, i - start);
    // Anything glued to the digits (".5", "e3", "-") makes the value something other than a count.
    const bool trailing = i < text.size() && (std::isalnum(static_cast<unsigned char>(text[i])) ||
                                              text[i] == '.' || text[i] == '+' || text[i] == '-');
    if (digits.empty() || trailing || (digits.size() > 1 && digits[0] == '0')) {
      std::size_t end = i;
      while (end < text.size() && text[end] != ',' && text[end] != '}') ++end;
      fail("\"" + field + "\" = " + text.substr(start, end - start) +
           ": must be a whole number in 0..4294967295");
    }
    if (digits.size() > 10 || std::stoull(digits) > UINT32_MAX) {
      fail("\"" + field + "\" = " + digits + ": beyond 4294967295 (a counter is never wrapped)");
    }
    return static_cast<std::uint32_t>(std::stoull(digits));
  }
};

}  // namespace

std::string CounterStore::format(const sequencer::Counters& c) {
  std::ostringstream os;
  os << "{\"rows\":" << c.rows << ",\"picks\":" << c.picks << ",\"beats\":" << c.beats
     << ",\"picks_in_row\":" << c.picks_in_row;
  const sequencer::KnotCounters& k = c.knot;
  if (k.tied != 0 || k.retried != 0 || k.by_hand != 0 || k.cycles_started != 0 || k.cycles_done != 0) {
    os << ",\"knots\":" << k.tied << ",\"knots_retried\":" << k.retried << ",\"knots_by_hand\":" << k.by_hand
       << ",\"knot_cycles_started\":" << k.cycles_started << ",\"knot_cycles_done\":" << k.cycles_done;
  }
  // Only while a cycle's knots are partly counted (a file from before it existed has none: zero).
  if (k.cycle_heads_done != 0) os << ",\"knot_cycle_heads_done\":" << k.cycle_heads_done;
  // Only while a row is partly knotted (a file from before they existed has none: its row counts from the
  // restart).
  if (k.row_tied != 0 || k.row_retried != 0 || k.row_by_hand != 0) {
    os << ",\"row_knots\":" << k.row_tied << ",\"row_knots_retried\":" << k.row_retried
       << ",\"row_knots_by_hand\":" << k.row_by_hand;
  }
  os << "}\n";
  return os.str();
}

sequencer::Counters CounterStore::parse(const std::string& text, const std::string& source) {
  Cursor cur{text, source};
  std::map<std::string, std::uint32_t> fields;
  cur.expect('{');
  if (!cur.peek('}')) {
    for (;;) {
      const std::string k = cur.key();
      static const std::set<std::string> known{"rows",
                                               "picks",
                                               "beats",
                                               "picks_in_row",
                                               "knots",
                                               "knots_retried",
                                               "knots_by_hand",
                                               "knot_cycles_started",
                                               "knot_cycles_done",
                                               "knot_cycle_heads_done",
                                               "row_knots",
                                               "row_knots_retried",
                                               "row_knots_by_hand"};
      if (!known.count(k)) cur.fail("unknown field \"" + k + "\"");
      if (fields.count(k)) cur.fail("field \"" + k + "\" given twice");
      cur.expect(':');
      fields[k] = cur.count(k);
      if (cur.peek(',')) {
        cur.expect(',');
        continue;
      }
      break;
    }
  }
  cur.expect('}');
  cur.skip_ws();
  if (cur.i != text.size()) cur.fail("trailing text after the counters object");
  for (const char* k : {"rows", "picks", "beats", "picks_in_row"}) {
    if (!fields.count(k)) cur.fail(std::string("lacks \"") + k + "\"");
  }
  sequencer::Counters c{fields["rows"], fields["picks"], fields["beats"], fields["picks_in_row"], {}};
  std::string contradict_early;  // found among the knot counts, said with the other contradictions
  // The knot counts come together or not at all (a file from before the heads has none).
  const char* knot_fields[] = {"knots", "knots_retried", "knots_by_hand", "knot_cycles_started",
                               "knot_cycles_done"};
  const auto knot_given = std::count_if(std::begin(knot_fields), std::end(knot_fields),
                                        [&](const char* k) { return fields.count(k) > 0; });
  if (knot_given != 0 && knot_given != 5)
    cur.fail(
        "the knot counts come together: some of knots, knots_retried, knots_by_hand, knot_cycles_started, "
        "knot_cycles_done are missing");
  c.knot = {fields["knots"],
            fields["knots_retried"],
            fields["knots_by_hand"],
            fields["knot_cycles_started"],
            fields["knot_cycles_done"],
            fields["knot_cycle_heads_done"],
            fields["row_knots"],
            fields["row_knots_retried"],
            fields["row_knots_by_hand"]};
  if (c.knot.cycle_heads_done >> hal::kMaxKnottingHeads != 0) {
    cur.fail("knot_cycle_heads_done = " + std::to_string(c.knot.cycle_heads_done) +
             " names a head beyond the " + std::to_string(hal::kMaxKnottingHeads) + " a loom may have");
  }
  if (c.knot.cycle_heads_done != 0 && c.knot.cycles_started <= c.knot.cycles_done) {
    contradict_early =
        "knot_cycle_heads_done = " + std::to_string(c.knot.cycle_heads_done) +
        " names heads of a cycle that was not started (knot_cycles_started = knot_cycles_done = " +
        std::to_string(c.knot.cycles_done) + ")";
  }
  // Every completed row had at least one pick and one beat; the picks of the row in progress are
  // picks too. Counts that say otherwise were not written by loomctl.
  const auto contradict = [&](const std::string& why) {
    throw ConfigError(source + ": counters contradict each other: " + why);
  };
  if (static_cast<std::uint64_t>(c.rows) + c.picks_in_row > c.picks) {
    contradict("picks = " + std::to_string(c.picks) + " is less than rows + picks_in_row = " +
               std::to_string(static_cast<std::uint64_t>(c.rows) + c.picks_in_row));
  }
  if (!contradict_early.empty()) contradict(contradict_early);
  if (c.knot.row_tied > c.knot.tied || c.knot.row_retried > c.knot.retried ||
      c.knot.row_by_hand > c.knot.by_hand) {
    contradict("the row in progress's knots (row_knots " + std::to_string(c.knot.row_tied) + ", retried " +
               std::to_string(c.knot.row_retried) + ", by hand " + std::to_string(c.knot.row_by_hand) +
               ") exceed the totals (knots " + std::to_string(c.knot.tied) + ", retried " +
               std::to_string(c.knot.retried) + ", by hand " + std::to_string(c.knot.by_hand) + ")");
  }
  if (c.knot.cycles_done > c.knot.cycles_started) {
    contradict("knot_cycles_done = " + std::to_string(c.knot.cycles_done) +
               " exceeds knot_cycles_started = " + std::to_string(c.knot.cycles_started));
  }
  if (c.beats < c.rows) {
    contradict("beats = " + std::to_string(c.beats) + " is less than rows = " + std::to_string(c.rows));
  }
  return c;
}

std::optional<sequencer::Counters> CounterStore::load() const {
  const StateFileRead r = read_state_file(path_, 4096);
  switch (r.outcome) {
    case StateFileRead::Outcome::kAbsent:
      return std::nullopt;  // the only case that starts from zero
    case StateFileRead::Outcome::kCannotOpen:
      throw ConfigError(path_ + ": counters file exists but cannot be read: " + r.error +
                        " (refusing to restart the production counts)");
    case StateFileRead::Outcome::kNotRegular:
      throw ConfigError(path_ + ": not a counters file (not a regular file of at most 4 KiB)");
    case StateFileRead::Outcome::kCannotRead:
      throw ConfigError(path_ + ": counters file cannot be read: " + r.error);
    case StateFileRead::Outcome::kRead:
      break;
  }
  return parse(r.text, path_);
}

void CounterStore::save(const sequencer::Counters& c) const {
  write_file_durably(path_, format(c));
}

}  // namespace loom::state

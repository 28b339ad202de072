// See job_queue.hpp. The file is line-oriented text so a weaver (or a support call) can read it; the
// parser accepts exactly what format() writes, field by field, and names file:line, field and value.
#include "loom/job/job_queue.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>
#include <utility>

#include "loom/design/design.hpp"
#include "loom/job/design_hash.hpp"
#include "loom/sequencer/knot_plan.hpp"
#include "loom/state/durable_file.hpp"

namespace loom::job {
namespace {

constexpr const char* kFormat = "loomctl-jobs 2";
// Version 1 had no `weaving` (every job was in its first): read, and written back as version 2.
constexpr const char* kFormatV1 = "loomctl-jobs 1";
constexpr std::size_t kMaxQueueBytes = 16u << 20;
constexpr std::size_t kMaxDesignBytes = 256u << 20;  // a 4000 × 20000 CSV of short codes fits

const char* const kStateNames[] = {"queued", "current", "carpet_done", "removed"};

// The fields of a [job N] stanza, in the order format() writes them.
const char* const kJobFields[] = {"state",         "design_path",    "design_name", "sha256",
                                  "knots_per_row", "design_rows",    "length_rows", "weaving",
                                  "rows_done",     "cycles_started", "cycles_done", "at_counter_rows"};

std::string yarn_text(const HeadYarn& y) {
  std::string s;
  for (const auto& [code, slot] : y) s += (s.empty() ? "" : " ") + code + ":" + std::to_string(slot);
  return s;
}

// Whole number in [lo, hi], decimal digits only (no sign, no leading zero, no exponent).
bool whole(const std::string& v, std::uint64_t lo, std::uint64_t hi, std::uint64_t& out) {
  if (v.empty() || v.size() > 20 || (v.size() > 1 && v[0] == '0')) return false;
  if (!std::all_of(v.begin(), v.end(), [](char c) { return c >= '0' && c <= '9'; })) return false;
  try {
    out = std::stoull(v);
  } catch (const std::exception&) {
    return false;
  }
  return out >= lo && out <= hi;
}

bool valid_code(const std::string& code) {
  return !code.empty() && code.size() <= design::kMaxCodeLength &&
         std::none_of(code.begin(), code.end(),
                      [](char c) { return c == ' ' || c == ':' || c < 0x21 || c == 0x7F; });
}

struct Reader {
  const std::string& source;
  [[noreturn]] void fail(std::size_t line, const std::string& why) const {
    throw JobError(source + ":" + std::to_string(line) + ": " + why +
                   " (refusing the job queue; nothing changed)");
  }
  [[noreturn]] void bad(std::size_t line, const std::string& field, const std::string& value,
                        const std::string& want) const {
    fail(line, "field \"" + field + "\" = \"" + value.substr(0, 80) + "\": " + want);
  }
};

HeadYarn parse_yarn(const Reader& r, std::size_t line, const std::string& field, const std::string& value) {
  HeadYarn y;
  std::istringstream in(value);
  std::string item;
  while (in >> item) {
    const auto colon = item.rfind(':');
    std::uint64_t slot = 0;
    if (colon == std::string::npos || !valid_code(item.substr(0, colon)) ||
        !whole(item.substr(colon + 1), 0, sequencer::kMaxMagazineSlots - 1, slot)) {
      r.bad(line, field, value,
            "want CODE:SLOT items, a palette code of 1.." + std::to_string(design::kMaxCodeLength) +
                " characters and a slot in 0.." + std::to_string(sequencer::kMaxMagazineSlots - 1) + " (\"" +
                item + "\")");
    }
    if (!y.emplace(item.substr(0, colon), static_cast<int>(slot)).second) {
      r.bad(line, field, value, "colour " + item.substr(0, colon) + " given twice");
    }
  }
  if (y.empty()) r.bad(line, field, value, "no CODE:SLOT items");
  return y;
}

}  // namespace

const char* job_state_name(JobState s) {
  return kStateNames[static_cast<int>(s)];
}

std::uint64_t length_in_rows(const JobLength& length, int design_rows, double rows_per_dm) {
  const int given = (length.rows != 0) + (length.metres != 0.0) + (length.repeats != 0);
  if (given > 1) throw JobError("a job's length is rows, metres or repeats: give one of them");
  double rows = static_cast<double>(design_rows);
  std::string what = "the design once (" + std::to_string(design_rows) + " rows)";
  if (length.rows != 0) {
    rows = static_cast<double>(length.rows);
    what = "rows = " + std::to_string(length.rows);
  } else if (length.repeats != 0) {
    rows = static_cast<double>(length.repeats) * design_rows;
    what = "repeats = " + std::to_string(length.repeats);
  } else if (length.metres != 0.0) {
    if (!std::isfinite(length.metres) || length.metres < 0.0) {
      throw JobError("metres = " + std::to_string(length.metres) + ": not a length");
    }
    rows = std::round(length.metres * 10.0 * rows_per_dm);  // 10 dm per metre
    std::ostringstream os;
    os << "metres = " << length.metres << " at rows_per_dm = " << rows_per_dm;
    what = os.str();
  }
  if (!(rows >= 1.0 && rows <= 4294967295.0)) {
    std::ostringstream os;
    os << what << " is " << rows << " rows: a carpet has 1..4294967295 rows (the production counters' range)";
    throw JobError(os.str());
  }
  return static_cast<std::uint64_t>(rows);
}

std::string JobQueue::format(const std::vector<Job>& jobs, std::uint32_t next_id) {
  std::ostringstream os;
  os << "# loomctl's carpet job queue (loomctl job list|show|add|remove|start-over); written by loomctl\n"
     << "format = " << kFormat << "\nnext_id = " << next_id << "\n";
  for (const Job& j : jobs) {
    os << "\n[job " << j.id << "]\n"
       << "state = " << job_state_name(j.state) << "\ndesign_path = " << j.design_path
       << "\ndesign_name = " << j.design_name << "\nsha256 = " << j.sha256
       << "\nknots_per_row = " << j.knots_per_row << "\ndesign_rows = " << j.design_rows
       << "\nlength_rows = " << j.length_rows << "\nweaving = " << j.weaving << "\n";
    for (std::size_t h = 0; h < j.yarn.size(); ++h)
      os << "yarn." << h + 1 << " = " << yarn_text(j.yarn[h]) << "\n";
    os << "rows_done = " << j.progress.rows_done << "\ncycles_started = " << j.progress.cycles_started
       << "\ncycles_done = " << j.progress.cycles_done << "\nat_counter_rows = " << j.progress.at_counter_rows
       << "\n";
  }
  return os.str();
}

JobQueue JobQueue::parse(const std::string& text, const std::string& source) {
  const Reader r{source};
  JobQueue q(source);
  std::map<std::string, std::size_t> header;             // field → line
  bool format_v1 = false;                                // an older loomctl's queue: no weaving field
  std::vector<std::map<std::string, std::size_t>> seen;  // per job: field → line
  std::vector<std::size_t> job_line;
  std::uint64_t next_id = 0;
  std::size_t next_id_line = 0;
  std::istringstream in(text);
  std::string line;
  std::size_t n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r')
      r.fail(n, "a carriage return (the file was not written by loomctl)");
    if (line.empty() || line[0] == '#') continue;
    if (line[0] == '[') {
      std::uint64_t id = 0;
      if (line.size() < 7 || line.rfind("[job ", 0) != 0 || line.back() != ']' ||
          !whole(line.substr(5, line.size() - 6), 1, UINT32_MAX, id)) {
        r.fail(n, "\"" + line.substr(0, 80) + "\": want a stanza header [job N], N in 1..4294967295");
      }
      if (!q.jobs_.empty() && id <= q.jobs_.back().id) {
        r.fail(n, "[job " + std::to_string(id) + "] after [job " + std::to_string(q.jobs_.back().id) +
                      "]: jobs are listed once each, in ascending order");
      }
      q.jobs_.push_back(Job{});
      q.jobs_.back().id = static_cast<std::uint32_t>(id);
      seen.emplace_back();
      job_line.push_back(n);
      continue;
    }
    const auto eq = line.find(" = ");
    if (eq == std::string::npos || eq == 0) r.fail(n, "\"" + line.substr(0, 80) + "\": want field = value");
    const std::string field = line.substr(0, eq), value = line.substr(eq + 3);
    if (q.jobs_.empty()) {  // the header
      if (header.count(field))
        r.fail(n,
               "field \"" + field + "\" given twice (first on line " + std::to_string(header[field]) + ")");
      header[field] = n;
      if (field == "format") {
        if (value != kFormat && value != kFormatV1)
          r.bad(n, field, value, std::string("want \"") + kFormat + "\" (another loomctl's queue?)");
        format_v1 = value == kFormatV1;
      } else if (field == "next_id") {
        if (!whole(value, 1, UINT32_MAX, next_id))
          r.bad(n, field, value, "want a job number in 1..4294967295");
        next_id_line = n;
      } else {
        r.fail(n, "unknown field \"" + field + "\" in the header");
      }
      continue;
    }
    Job& j = q.jobs_.back();
    auto& fields = seen.back();
    const bool is_yarn = field.rfind("yarn.", 0) == 0;
    if (!is_yarn && std::find(std::begin(kJobFields), std::end(kJobFields), field) == std::end(kJobFields)) {
      r.fail(n, "unknown field \"" + field + "\" in [job " + std::to_string(j.id) + "]");
    }
    if (fields.count(field)) {
      r.fail(n, "field \"" + field + "\" given twice in [job " + std::to_string(j.id) + "] (first on line " +
                    std::to_string(fields[field]) + ")");
    }
    fields[field] = n;
    std::uint64_t v = 0;
    if (is_yarn) {
      std::uint64_t head = 0;
      if (!whole(field.substr(5), 1, sequencer::kMaxKnottingHeads, head) || head != j.yarn.size() + 1) {
        r.fail(n, "field \"" + field + "\": want yarn.1, yarn.2, ... in order, at most " +
                      std::to_string(sequencer::kMaxKnottingHeads) + " heads (next: yarn." +
                      std::to_string(j.yarn.size() + 1) + ")");
      }
      j.yarn.push_back(parse_yarn(r, n, field, value));
      if (j.yarn.size() > 1 && j.yarn.back().size() != j.yarn.front().size()) {
        r.bad(n, field, value,
              "every head carries the same colours (yarn.1 has " + yarn_text(j.yarn.front()) + ")");
      }
    } else if (field == "state") {
      const auto it = std::find(std::begin(kStateNames), std::end(kStateNames), value);
      if (it == std::end(kStateNames)) r.bad(n, field, value, "want queued, current, carpet_done or removed");
      j.state = static_cast<JobState>(it - std::begin(kStateNames));
    } else if (field == "design_path") {
      if (value.empty() || value[0] != '/') r.bad(n, field, value, "want the design file's absolute path");
      j.design_path = value;
    } else if (field == "design_name") {
      if (value.empty() || value.size() > 255 || value.find('/') != std::string::npos) {
        r.bad(n, field, value, "want a file name of 1..255 characters");
      }
      j.design_name = value;
    } else if (field == "sha256") {
      if (!is_sha256_hex(value))
        r.bad(n, field, value, "want 64 lowercase hex digits (the design file's SHA-256)");
      j.sha256 = value;
    } else if (field == "knots_per_row") {
      if (!whole(value, 1, design::kMaxWidth, v))
        r.bad(n, field, value, "want 1.." + std::to_string(design::kMaxWidth));
      j.knots_per_row = static_cast<int>(v);
    } else if (field == "design_rows") {
      if (!whole(value, 1, design::kMaxHeight, v))
        r.bad(n, field, value, "want 1.." + std::to_string(design::kMaxHeight));
      j.design_rows = static_cast<int>(v);
    } else if (field == "length_rows") {
      if (!whole(value, 1, UINT32_MAX, v)) r.bad(n, field, value, "want 1..4294967295 rows");
      j.length_rows = v;
    } else if (field == "weaving") {
      if (format_v1) r.fail(n, "unknown field \"weaving\" in a \"" + std::string(kFormatV1) + "\" queue");
      if (!whole(value, 1, UINT32_MAX, v)) r.bad(n, field, value, "want 1..4294967295");
      j.weaving = static_cast<std::uint32_t>(v);
    } else if (field == "rows_done") {
      if (!whole(value, 0, UINT32_MAX, v)) r.bad(n, field, value, "want 0..4294967295 rows");
      j.progress.rows_done = v;
    } else if (field == "cycles_started" || field == "cycles_done" || field == "at_counter_rows") {
      if (!whole(value, 0, UINT32_MAX, v)) r.bad(n, field, value, "want a whole number in 0..4294967295");
      (field == "cycles_started" ? j.progress.cycles_started
       : field == "cycles_done"  ? j.progress.cycles_done
                                 : j.progress.at_counter_rows) = static_cast<std::uint32_t>(v);
    }
  }
  if (!header.count("format"))
    r.fail(1, "lacks \"format = " + std::string(kFormat) + "\" (not a loomctl job queue)");
  if (!header.count("next_id")) r.fail(1, "lacks \"next_id\"");
  // Whole-stanza checks: every field once, and the fields agree with each other.
  std::size_t current = 0;
  for (std::size_t i = 0; i < q.jobs_.size(); ++i) {
    const Job& j = q.jobs_[i];
    const std::size_t at = job_line[i];
    const std::string name = "[job " + std::to_string(j.id) + "]";
    for (const char* f : kJobFields) {
      if (format_v1 && std::string(f) == "weaving") continue;  // version 1: the first weaving
      if (!seen[i].count(f)) r.fail(at, name + " lacks field \"" + f + "\"");
    }
    const auto line_of = [&](const char* f) { return seen[i].at(f); };
    if (j.progress.rows_done > j.length_rows) {
      r.bad(line_of("rows_done"), "rows_done", std::to_string(j.progress.rows_done),
            "beyond length_rows = " + std::to_string(j.length_rows));
    }
    if (j.progress.cycles_done > j.progress.cycles_started) {
      r.bad(line_of("cycles_done"), "cycles_done", std::to_string(j.progress.cycles_done),
            "exceeds cycles_started = " + std::to_string(j.progress.cycles_started));
    }
    if (j.progress.cycles_started > static_cast<std::uint32_t>(j.knots_per_row)) {
      r.bad(line_of("cycles_started"), "cycles_started", std::to_string(j.progress.cycles_started),
            "a row has at most knots_per_row = " + std::to_string(j.knots_per_row) + " knot cycles");
    }
    if (j.state == JobState::kCarpetDone && !j.all_rows_woven()) {
      r.bad(line_of("state"), "state", "carpet_done",
            "rows_done = " + std::to_string(j.progress.rows_done) +
                " of length_rows = " + std::to_string(j.length_rows));
    }
    if (j.state == JobState::kCurrent) {
      if (current != 0)
        r.bad(line_of("state"), "state", "current", "job " + std::to_string(current) + " is current too");
      current = j.id;
    }
    if (j.id >= next_id) {
      r.bad(next_id_line, "next_id", std::to_string(next_id),
            "not beyond job " + std::to_string(j.id) + " (ids are never reused)");
    }
  }
  q.next_id_ = static_cast<std::uint32_t>(next_id);
  return q;
}

JobQueue JobQueue::load(const std::string& path) {
  const state::StateFileRead r = state::read_state_file(path, kMaxQueueBytes);
  using O = state::StateFileRead::Outcome;
  switch (r.outcome) {
    case O::kAbsent:
      return JobQueue(path);
    case O::kCannotOpen:
      throw JobError(path + ": job queue exists but cannot be read: " + r.error);
    case O::kNotRegular:
      throw JobError(path + ": not a job queue (not a regular file of at most 16 MiB)");
    case O::kCannotRead:
      throw JobError(path + ": job queue cannot be read: " + r.error);
    case O::kRead:
      break;
  }
  JobQueue q = parse(r.text, path);
  q.path_ = path;
  return q;
}

const Job& JobQueue::job(std::uint32_t id) const {
  for (const Job& j : jobs_) {
    if (j.id == id) return j;
  }
  throw JobError("no job " + std::to_string(id) + " in " + path_);
}

Job& JobQueue::mutable_job(std::uint32_t id) {
  return const_cast<Job&>(job(id));
}

const Job* JobQueue::current() const {
  for (const Job& j : jobs_) {
    if (j.state == JobState::kCurrent) return &j;
  }
  return nullptr;
}

Job& JobQueue::mutable_current(const char* what) {
  const Job* j = current();
  if (j == nullptr) throw JobError(std::string("no current job in ") + path_ + " to " + what);
  return const_cast<Job&>(*j);
}

void JobQueue::save() const {
  state::write_file_durably(path_, format(jobs_, next_id_));
}

namespace {

struct DesignRead {
  std::string bytes;
  std::string error;  // "" when read
};
DesignRead read_design(const std::string& path) {
  const state::StateFileRead r = state::read_state_file(path, kMaxDesignBytes);
  using O = state::StateFileRead::Outcome;
  switch (r.outcome) {
    case O::kAbsent:
      return {{}, "no such file"};
    case O::kCannotOpen:
    case O::kCannotRead:
      return {{}, r.error};
    case O::kNotRegular:
      return {{}, "not a regular file of at most 256 MiB"};
    case O::kRead:
      break;
  }
  return {r.text, ""};
}

bool has_heads(const firmware::LoomConfig& loom) {
  return loom.knotting.mode == sequencer::KnottingMode::kHeads;
}

std::string magazine_list(const firmware::LoomConfig& loom) {
  std::string s;
  for (std::size_t i = 0; i < loom.knotting.slot_colours.size(); ++i) {
    s += (i ? ", " : "") + loom.knotting.slot_colours[i] + " in slot " + std::to_string(i);
  }
  return s.empty() ? "none" : s;
}

}  // namespace

const Job& JobQueue::add(const std::string& design_path, const firmware::LoomConfig& loom,
                         const JobLength& length) {
  const std::string abs = std::filesystem::absolute(design_path).lexically_normal().string();
  if (abs.find('\n') != std::string::npos) throw JobError("design path has a line break: " + design_path);
  const DesignRead file = read_design(abs);
  if (!file.error.empty()) throw JobError(abs + ": cannot read the design: " + file.error);
  design::Design d = [&] {
    try {
      return design::parse_design(file.bytes, abs);
    } catch (const design::DesignError& e) {
      throw JobError(e.what());
    }
  }();
  const int loom_knots = sequencer::knots_per_row(loom.knotting, loom.machine_spec.width_m);
  if (d.width() != loom_knots) {
    throw JobError(abs + ": the design is " + std::to_string(d.width()) + " knots wide; the loom (" +
                   loom.source + ") ties " + std::to_string(loom_knots) +
                   " knots per row: fit the design to the loom first");
  }
  Job j;
  j.design_path = abs;
  j.design_name = std::filesystem::path(abs).filename().string();
  j.sha256 = sha256_hex(file.bytes);
  j.knots_per_row = d.width();
  j.design_rows = d.height();
  j.length_rows = length_in_rows(length, d.height(), loom.knotting.rows_per_dm);
  if (has_heads(loom)) {
    // The colours the design uses (a palette line nobody knots needs no yarn), with their knot counts.
    std::vector<std::uint64_t> used(d.palette().size(), 0);
    for (int r = 0; r < d.height(); ++r) {
      for (const std::uint16_t p : d.row(r)) ++used[p];
    }
    HeadYarn y;
    std::string missing;
    for (std::size_t p = 0; p < used.size(); ++p) {
      if (used[p] == 0) continue;
      const std::string& code = d.palette()[p].code;
      const int slot = sequencer::slot_of(loom.knotting, code);
      if (slot < 0) {
        missing += (missing.empty() ? "" : ", ") + code + " (" + std::to_string(used[p]) + " knots)";
      } else {
        y[code] = slot;
      }
    }
    if (!missing.empty()) {
      throw JobError(abs + ": colours in no magazine slot: " + missing + "; the magazines hold " +
                     magazine_list(loom) + " (knotting.slot_colours in " + loom.source + ")");
    }
    j.yarn.assign(static_cast<std::size_t>(loom.knotting.heads), y);  // every head holds the same magazine
  }
  JobQueue next = *this;
  j.id = next.next_id_;
  if (next.next_id_ == UINT32_MAX) throw JobError(path_ + ": no job numbers left");
  ++next.next_id_;
  next.jobs_.push_back(j);
  next.save();
  *this = std::move(next);
  return jobs_.back();
}

void JobQueue::remove(std::uint32_t id) {
  JobQueue next = *this;
  Job& j = next.mutable_job(id);
  if (j.state == JobState::kCurrent) {
    throw JobError("job " + std::to_string(id) + " is the current job (row " + std::to_string(j.next_row()) +
                   " of " + std::to_string(j.length_rows) +
                   "): finish it or start it over, it cannot be removed");
  }
  if (j.state == JobState::kRemoved) throw JobError("job " + std::to_string(id) + " is already removed");
  j.state = JobState::kRemoved;
  next.save();
  *this = std::move(next);
}

void JobQueue::start_over(std::uint32_t id) {
  JobQueue next = *this;
  Job& j = next.mutable_job(id);
  if (j.state == JobState::kRemoved)
    throw JobError("job " + std::to_string(id) + " is removed: add the design again");
  // A job the loom began is woven again as its next weaving (the record keeps each); one never begun is
  // only reset.
  const bool begun =
      j.state != JobState::kQueued || j.progress.rows_done != 0 || j.progress.cycles_started != 0;
  if (begun && j.weaving == UINT32_MAX) {
    throw JobError("job " + std::to_string(id) + " was woven 4294967295 times: add the design as a new job");
  }
  if (begun) ++j.weaving;
  const std::uint32_t base = j.progress.at_counter_rows;
  j.progress = JobProgress{};
  j.progress.at_counter_rows = base;
  if (j.state == JobState::kCarpetDone) j.state = JobState::kQueued;
  next.save();
  *this = std::move(next);
}

const Job& JobQueue::start(std::uint32_t id, std::uint32_t counter_rows) {
  JobQueue next = *this;
  if (const Job* c = next.current(); c != nullptr && c->id != id) {
    throw JobError("job " + std::to_string(c->id) + " is current: it ends in carpet_done before job " +
                   std::to_string(id) + " starts");
  }
  Job& j = next.mutable_job(id);
  if (j.state != JobState::kQueued) {
    throw JobError("job " + std::to_string(id) + " is " + job_state_name(j.state) +
                   ", not queued: it cannot start");
  }
  j.state = JobState::kCurrent;
  j.progress.at_counter_rows = counter_rows;
  next.save();
  *this = std::move(next);
  return job(id);
}

bool JobQueue::advance(std::uint32_t counter_rows) {
  JobQueue next = *this;
  Job& j = next.mutable_current("advance");
  const std::string name = "job " + std::to_string(j.id);
  if (counter_rows < j.progress.at_counter_rows) {
    throw JobError(path_ + ": " + name + " was written at production row " +
                   std::to_string(j.progress.at_counter_rows) + " but the counters say " +
                   std::to_string(counter_rows) + " (production counts never go back; refusing to guess)");
  }
  const std::uint64_t rows = j.progress.rows_done + (counter_rows - j.progress.at_counter_rows);
  if (rows > j.length_rows) {
    throw JobError(name + ": " + std::to_string(rows) + " rows woven would pass its length of " +
                   std::to_string(j.length_rows) + " rows (a carpet is not woven beyond its last row)");
  }
  j.progress = JobProgress{rows, 0, 0, counter_rows};
  next.save();
  *this = std::move(next);
  return current()->all_rows_woven();
}

void JobQueue::knot_progress(std::uint32_t cycles_started, std::uint32_t cycles_done) {
  JobQueue next = *this;
  Job& j = next.mutable_current("record knot cycles for");
  if (cycles_done > cycles_started || cycles_started > static_cast<std::uint32_t>(j.knots_per_row)) {
    throw JobError("job " + std::to_string(j.id) + ": knot cycles started " + std::to_string(cycles_started) +
                   ", done " + std::to_string(cycles_done) +
                   " (want done <= started <= " + std::to_string(j.knots_per_row) + ")");
  }
  j.progress.cycles_started = cycles_started;
  j.progress.cycles_done = cycles_done;
  next.save();
  *this = std::move(next);
}

void JobQueue::mark_carpet_done() {
  JobQueue next = *this;
  Job& j = next.mutable_current("mark carpet_done");
  if (!j.all_rows_woven()) {
    throw JobError("job " + std::to_string(j.id) + " has " +
                   std::to_string(j.length_rows - j.progress.rows_done) + " rows left: not carpet_done");
  }
  j.state = JobState::kCarpetDone;
  next.save();
  *this = std::move(next);
}

void JobQueue::check_design(const Job& job) {
  (void)read_checked_design(job);
}

std::string JobQueue::read_checked_design(const Job& job) {
  DesignRead file = read_design(job.design_path);
  if (!file.error.empty()) {
    throw JobError("the design file of job " + std::to_string(job.id) +
                   " cannot be read: " + job.design_path + ": " + file.error);
  }
  const std::string now = sha256_hex(file.bytes);
  if (now != job.sha256) {
    throw JobError("the design file changed under job " + std::to_string(job.id) + ": hash " + now +
                   ", was " + job.sha256 + " (" + job.design_path +
                   "; add it as a new job to weave the new design)");
  }
  return std::move(file.bytes);
}

void JobQueue::check_yarn(const Job& job, const firmware::LoomConfig& loom) {
  if (job.yarn.empty()) return;  // added for a loom without heads: the weaver ties every knot
  if (!has_heads(loom)) return;
  if (static_cast<int>(job.yarn.size()) != loom.knotting.heads) {
    throw JobError("job " + std::to_string(job.id) + " was added for " + std::to_string(job.yarn.size()) +
                   " knotting heads; the loom (" + loom.source + ") has " +
                   std::to_string(loom.knotting.heads));
  }
  // A colour moved to another slot is still loaded (the knot program takes the slots from the loom's
  // magazines); a colour in no slot cannot be tied.
  std::string wrong;
  for (const auto& entry : job.yarn.front()) {
    if (sequencer::slot_of(loom.knotting, entry.first) < 0)
      wrong += (wrong.empty() ? "" : ", ") + entry.first;
  }
  if (!wrong.empty()) {
    throw JobError("job " + std::to_string(job.id) + ": colours in no magazine slot: " + wrong +
                   "; the magazines hold " + magazine_list(loom) + " (knotting.slot_colours in " +
                   loom.source + ")");
  }
}

}  // namespace loom::job

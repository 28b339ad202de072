// Default choice and the markdown summary. The policy is stated in the output next to the numbers,
// so a reader can disagree with it from the same table.
#include "summary.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace loom::profile {

namespace {

std::string g(double v, const char* f = "%.2g") {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

std::string kib(std::size_t bytes) {
  return bytes == 0     ? std::string("0")
         : bytes < 1024 ? std::to_string(bytes) + " B"
                        : g(static_cast<double>(bytes) / 1024.0, "%.3g") + " KiB";
}

const AccuracyRow* find(const std::vector<AccuracyRow>& rows, const std::string& prof,
                        const std::string& interp, std::size_t n, const std::string& prec) {
  for (const AccuracyRow& r : rows) {
    if (r.profile == prof && r.interp == interp && r.table_size == n && r.precision == prec) return &r;
  }
  return nullptr;
}

double best_of(int reps, const motion::ProfileSpec& spec) {
  double best = INFINITY;
  for (int i = 0; i < reps; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const motion::ProfileSet set(spec);
    best = std::min(best,
                    std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

}  // namespace

Choice choose_default(const ReportProfile& prof, const std::vector<AccuracyRow>& rows,
                      const std::string& precision) {
  std::vector<const AccuracyRow*> ok;
  for (const AccuracyRow& r : rows) {
    if (r.profile != prof.name || !std::isfinite(r.lookup_ns)) continue;
    if (r.max_pos_err > prof.requirement || r.max_vel_err > prof.vel_requirement() ||
        r.max_acc_err > prof.acc_requirement()) {
      continue;
    }
    if (!precision.empty() && (r.interp == "exact" || r.precision != precision)) continue;
    ok.push_back(&r);
  }
  Choice c;
  if (ok.empty()) {
    c.why = "nothing meets " + g(prof.requirement) + " " + prof.unit +
            " with its velocity and acceleration bounds";
    return c;
  }
  // An exact closed form that fits the lookup budget needs no table at all.
  for (const AccuracyRow* r : ok) {
    if (r->interp == "exact" && r->lookup_ns <= kLookupBudgetNs) {
      c.row = r;
      c.why = "the closed form is exact and fits the " + g(kLookupBudgetNs, "%.0f") + " ns lookup budget";
      return c;
    }
  }
  std::erase_if(ok, [](const AccuracyRow* r) { return r->interp == "exact"; });
  if (ok.empty()) {
    c.why = "no table meets the bounds, and the closed form misses the lookup budget";
    return c;
  }
  double fastest = INFINITY;
  for (const AccuracyRow* r : ok) fastest = std::min(fastest, r->lookup_ns);
  const double as_fast = fastest * 1.1 + 0.3;
  bool margin_exists = false;
  for (const AccuracyRow* r : ok)
    margin_exists |= r->lookup_ns <= as_fast && r->max_pos_err <= 0.1 * prof.requirement;
  for (const AccuracyRow* r : ok) {
    if (r->lookup_ns > as_fast || (margin_exists && r->max_pos_err > 0.1 * prof.requirement)) continue;
    if (!c.row || r->bytes < c.row->bytes ||
        (r->bytes == c.row->bytes && r->max_acc_err < c.row->max_acc_err))
      c.row = r;
  }
  c.why = "smallest table " + std::string(margin_exists ? "with 10x margin on " : "meeting ") +
          g(prof.requirement) + " " + prof.unit + " among lookups within 10 % of the fastest qualifying (" +
          g(fastest, "%.3g") + " ns)";
  return c;
}

std::string choice_label(const AccuracyRow& r) {
  return r.interp == "exact" ? std::string("closed form")
                             : r.interp + " " + std::to_string(r.table_size) + " " + r.precision;
}

BuildTimes measure_build_times() {
  BuildTimes b;
  const motion::ProfileSpec c = default_spec(), e = elliptic_spec();
  b.constant_us = best_of(20, c);
  b.elliptic_us = best_of(20, e);
  const motion::ProfileSet set(e);
  b.table_bytes = set.table_bytes();
  b.tables = std::to_string(c.table_size) + "-knot " + motion::interp_name(c.table_interp) + " " +
             motion::precision_name(c.table_precision);
  return b;
}

std::string summary_markdown(const Catalogue& cat, const std::vector<AccuracyRow>& rows,
                             const BuildTimes& build) {
  std::string md;
  md += "Requirement: max position error as stated; velocity and acceleration errors below " +
        g(ReportProfile::kVelocityShare) + " and " + g(ReportProfile::kAccelerationShare) +
        " of the profile's peaks. Errors are measured at 262,144 phases against the exact kinematics at the "
        "default crank speed; lookup time is the fastest of three Google Benchmark repetitions, random phase "
        "order.\n\n";
  md +=
      "| profile | default (report's choice) | max pos err | requirement | max vel err | max acc err | "
      "lookup | memory | why |\n";
  md += "|---|---|---|---|---|---|---|---|---|\n";
  for (const ReportProfile& p : cat.profiles) {
    const Choice c = choose_default(p, rows);
    if (!c.row) {
      md += "| " + p.name + " | none | | " + g(p.requirement) + " " + p.unit + " | | | | | " + c.why + " |\n";
      continue;
    }
    const AccuracyRow& r = *c.row;
    md += "| " + p.name + " | " + choice_label(r) + " | " + g(r.max_pos_err) + " " + p.unit + " | " +
          g(p.requirement) + " " + p.unit + " (vel " + g(p.vel_requirement()) + ", acc " +
          g(p.acc_requirement()) + ") | " + g(r.max_vel_err) + " " + p.unit + "/s | " + g(r.max_acc_err) +
          " " + p.unit + "/s² | " + g(r.lookup_ns, "%.3g") + " ns | " + kib(r.bytes) + " | " + c.why + " |\n";
  }
  md += "\nfloat32 against double knots (each the report's choice within that precision):\n\n";
  md += "| profile | double | float32 |\n|---|---|---|\n";
  for (const ReportProfile& p : cat.profiles) {
    std::string cells[2];
    int k = 0;
    for (const char* prec : {"double", "float32"}) {
      const Choice c = choose_default(p, rows, prec);
      cells[k++] = c.row ? choice_label(*c.row) + ": " + g(c.row->max_pos_err) + " " + p.unit + ", " +
                               g(c.row->lookup_ns, "%.3g") + " ns, " + kib(c.row->bytes)
                         : c.why;
    }
    // The finest float32 table: how close float32 knots can get at all.
    double floor_err = INFINITY;
    for (const AccuracyRow& r : rows) {
      if (r.profile == p.name && r.precision == "float32") floor_err = std::min(floor_err, r.max_pos_err);
    }
    md += "| " + p.name + " | " + cells[0] + " | " + cells[1] +
          " (best float32 error at any size: " + g(floor_err) + " " + p.unit + ") |\n";
  }
  if (!cat.profiles.empty()) {
    const ReportProfile& p = cat.profiles.front();
    md += "\nWhat accuracy costs, " + p.name + " (" + p.unit +
          "), double knots — max position error / lookup ns:\n\n";
    md += "| interp | 256 | 1024 | 4096 | 16384 | 65536 |\n|---|---|---|---|---|---|\n";
    for (const char* interp : {"linear", "cubic", "quintic"}) {
      md += std::string("| ") + interp + " |";
      for (std::size_t n : {256u, 1024u, 4096u, 16384u, 65536u}) {
        const AccuracyRow* r = find(rows, p.name, interp, n, "double");
        md += r ? " " + g(r->max_pos_err) + " / " + g(r->lookup_ns, "%.3g") + " |" : " — |";
      }
      md += "\n";
    }
    for (const AccuracyRow& r : rows) {
      if (r.profile == p.name && r.interp == "exact") {
        md += "| closed form (linkage solve) | " + g(r.lookup_ns, "%.3g") + " ns | | | | |\n";
      }
    }
  }
  md += "\nWhole ProfileSet build (" + build.tables + " tables, " + kib(build.table_bytes) +
        " with the elliptic law): " + g(build.constant_us, "%.0f") + " µs constant law, " +
        g(build.elliptic_us, "%.0f") + " µs elliptic law (target ≤ 5000 µs).\n";
  return md;
}

}  // namespace loom::profile

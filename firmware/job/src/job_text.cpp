// See job_text.hpp.
#include "loom/job/job_text.hpp"

#include <cstdarg>
#include <cstdio>

namespace loom::job {
namespace {

// printf into a std::string (the lines are short: names and numbers).
std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
  char buf[1024];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  return buf;
}

}  // namespace

std::string progress_text(const Job& j) {
  if (j.state == JobState::kCarpetDone) return "all " + std::to_string(j.length_rows) + " rows woven";
  return "row " + std::to_string(j.next_row()) + " of " + std::to_string(j.length_rows) + " next";
}

std::string list_text(const std::vector<Job>& jobs, const std::string& where) {
  if (jobs.empty()) return "no jobs in " + where + "\n";
  std::string out = format("%-5s %-12s %-28s %-14s %s\n", "job", "state", "design", "sha256", "progress");
  for (const Job& j : jobs) {
    out += format("%-5u %-12s %-28s %-14s %s\n", j.id, job_state_name(j.state), j.design_name.c_str(),
                  (j.sha256.substr(0, 12) + "..").c_str(), progress_text(j).c_str());
  }
  return out;
}

std::string show_text(const Job& j) {
  std::string out = format("job %u: %s\n", j.id, job_state_name(j.state));
  out += "  design      " + j.design_name + "\n  file        " + j.design_path + "\n  sha256      " +
         j.sha256 + "\n";
  try {
    JobQueue::check_design(j);
    out += "  file check  unchanged since the job was added\n";
  } catch (const JobError& e) {
    out += std::string("  file check  ") + e.what() + "\n";
  }
  out += format("  size        %d knots per row x %d design rows\n", j.knots_per_row, j.design_rows);
  const std::uint64_t repeats = j.length_rows / static_cast<std::uint64_t>(j.design_rows);
  const std::uint64_t extra = j.length_rows % static_cast<std::uint64_t>(j.design_rows);
  out += format("  length      %llu rows (the design %llu time%s%s)\n",
                static_cast<unsigned long long>(j.length_rows), static_cast<unsigned long long>(repeats),
                repeats == 1 ? "" : "s", extra ? (" and " + std::to_string(extra) + " rows").c_str() : "");
  if (j.weaving > 1) {
    out += format(
        "  weaving     %u (started over %u time%s; the record keeps each: loomctl report job %u --weaving "
        "K)\n",
        j.weaving, j.weaving - 1, j.weaving == 2 ? "" : "s", j.id);
  }
  out += format("  progress    %s (design row %d); knot cycles of that row started %u, done %u\n",
                progress_text(j).c_str(), j.next_design_row() + 1, j.progress.cycles_started,
                j.progress.cycles_done);
  if (j.yarn.empty()) out += "  yarn        no knotting heads: the weaver ties every knot\n";
  for (std::size_t h = 0; h < j.yarn.size(); ++h) {
    std::string s;
    for (const auto& [code, slot] : j.yarn[h])
      s += (s.empty() ? "" : ", ") + code + " in slot " + std::to_string(slot);
    out += format("  yarn head %zu %s\n", h + 1, s.c_str());
  }
  return out;
}

}  // namespace loom::job

// Markdown reporter for Google Benchmark (see markdown_reporter.hpp). Collects the iteration runs,
// then writes the table once at the end so its columns can be aligned to the widest cell.
#include "markdown_reporter.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ostream>
#include <string>
#include <vector>

namespace loom::kinreport {

namespace {

std::string format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

class MarkdownReporter : public benchmark::BenchmarkReporter {
 public:
  explicit MarkdownReporter(const char* title) : title_(title) {}

  bool ReportContext(const Context& context) override {
    machine_ = std::to_string(context.cpu_info.num_cpus) + " CPUs at " +
               format("%.0f", context.cpu_info.cycles_per_second * 1e-6) + " MHz";
    return true;
  }

  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.error_occurred || r.run_type != Run::RT_Iteration) continue;
      const double ns = r.GetAdjustedRealTime() * 1e9 / benchmark::GetTimeUnitMultiplier(r.time_unit);
      const auto counter = [&r](const char* name, const char* fmt) -> std::string {
        const auto it = r.counters.find(name);
        return it == r.counters.end() ? "—" : format(fmt, it->second.value);
      };
      rows_.push_back({r.benchmark_name(), format(ns < 100 ? "%.1f" : "%.0f", ns), counter("tol", "%.0e"),
                       counter("mean_iters", "%.2f"), counter("max_err_rad", "%.1e")});
    }
  }

  void Finalize() override {
    const std::vector<std::string> head{"case", "ns per evaluation", "tolerance", "mean Newton steps",
                                        "max angle error (rad)"};
    std::vector<std::size_t> width(head.size());
    for (std::size_t c = 0; c < head.size(); ++c) {
      width[c] = cells_width(head[c]);
      for (const auto& row : rows_) width[c] = std::max(width[c], cells_width(row[c]));
    }
    std::ostream& out = GetOutputStream();
    out << "### " << title_ << "\n\n"
        << "Measured on " << machine_ << ".\n\n";
    write_row(out, head, width);
    std::vector<std::string> rule;
    for (std::size_t w : width) rule.push_back(std::string(w, '-'));
    write_row(out, rule, width);
    for (const auto& row : rows_) write_row(out, row, width);
    out << "\n";
  }

 private:
  // Display width: the dash "—" is one column but three bytes.
  static std::size_t cells_width(const std::string& s) {
    std::size_t n = 0;
    for (unsigned char ch : s) n += (ch & 0xC0) != 0x80;
    return n;
  }

  static void write_row(std::ostream& out, const std::vector<std::string>& cells,
                        const std::vector<std::size_t>& width) {
    out << '|';
    for (std::size_t c = 0; c < cells.size(); ++c) {
      out << ' ' << cells[c] << std::string(width[c] - cells_width(cells[c]), ' ') << " |";
    }
    out << '\n';
  }

  std::string title_;
  std::string machine_;
  std::vector<std::vector<std::string>> rows_;
};

}  // namespace

int run_benchmarks(int argc, char** argv, const char* title) {
  bool markdown = false;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    if (i > 0 && std::strcmp(argv[i], "--markdown") == 0) {
      markdown = true;
    } else {
      args.push_back(argv[i]);
    }
  }
  int n = static_cast<int>(args.size());
  benchmark::Initialize(&n, args.data());
  if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 2;
  if (markdown) {
    MarkdownReporter reporter(title);
    benchmark::RunSpecifiedBenchmarks(&reporter);
  } else {
    benchmark::RunSpecifiedBenchmarks();
  }
  benchmark::Shutdown();
  return 0;
}

}  // namespace loom::kinreport

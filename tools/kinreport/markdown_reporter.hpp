// Google Benchmark results as a markdown table, for the README's accuracy-vs-time section: one row
// per benchmark with ns per evaluation and, where the benchmark sets them, the counters "tol",
// "mean_iters" and "max_err_rad" (what the accuracy cost and what it bought).
#pragma once

namespace loom::kinreport {

// Configure-time only (offline tool). A benchmark executable's main(): with --markdown the runs are
// printed as one markdown table titled `title` instead of the console report; every other argument
// goes to Google Benchmark (--benchmark_filter, --benchmark_min_time, ...). Returns the exit status.
int run_benchmarks(int argc, char** argv, const char* title);

}  // namespace loom::kinreport

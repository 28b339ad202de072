// Lookup timing for the report through Google Benchmark: each case is registered as a benchmark,
// run a few times, and the fastest repetition's CPU time per iteration is kept (the least disturbed
// by other work on a shared machine). Timing lives here and in the benchmarks, never in unit tests.
#pragma once

#include <benchmark/benchmark.h>

#include <functional>
#include <string>
#include <vector>

namespace loom::profile {

struct TimedCase {
  std::string name;                             // unique
  std::function<void(benchmark::State&)> body;  // one lookup per iteration
};

struct TimingOptions {
  double min_time_s = 0.05;  // per repetition
  int repetitions = 3;
};

// Configure-time only (allocates, runs for a while). ns per iteration for each case, in order; NaN
// for a case that reported an error.
std::vector<double> time_cases(const std::vector<TimedCase>& cases, const TimingOptions& opt);

}  // namespace loom::profile

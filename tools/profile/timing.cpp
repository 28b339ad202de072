// Runs the registered cases with a reporter that only collects numbers: the report tool prints its
// own progress and tables, and the CSV is the durable output.
#include "timing.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace loom::profile {

namespace {

class Collect : public benchmark::BenchmarkReporter {
 public:
  bool ReportContext(const Context&) override { return true; }
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.run_type != Run::RT_Iteration || r.error_occurred) continue;
      double& best =
          best_.try_emplace(r.run_name.function_name, std::numeric_limits<double>::infinity()).first->second;
      best = std::min(best, r.GetAdjustedCPUTime());
    }
  }
  double best(const std::string& name) const {
    const auto it = best_.find(name);
    return it == best_.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
  }

 private:
  std::map<std::string, double> best_;
};

}  // namespace

std::vector<double> time_cases(const std::vector<TimedCase>& cases, const TimingOptions& opt) {
  static bool initialised = false;
  if (!initialised) {
    int argc = 1;
    char name[] = "loom-profile";
    char* argv[] = {name, nullptr};
    benchmark::Initialize(&argc, argv);
    initialised = true;
  }
  benchmark::ClearRegisteredBenchmarks();
  for (const TimedCase& c : cases) {
    benchmark::RegisterBenchmark(c.name.c_str(), c.body)
        ->Unit(benchmark::kNanosecond)
        ->MinTime(opt.min_time_s)
        ->Repetitions(opt.repetitions);
  }
  Collect collect;
  benchmark::RunSpecifiedBenchmarks(&collect);
  benchmark::ClearRegisteredBenchmarks();
  std::vector<double> ns;
  ns.reserve(cases.size());
  for (const TimedCase& c : cases) ns.push_back(collect.best(c.name));
  return ns;
}

}  // namespace loom::profile

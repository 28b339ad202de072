// The run's summary as the operator reads it at the end of a run: the wording only, apart from the runner
// that measures (runner.cpp paces; this says what it measured).
#pragma once

#include <string>

#include "loom/firmware/runner.hpp"

namespace loom::firmware {

// One line for the end of a run: ticks, wall time, achieved ratio, tick cost p50/p99.9/max in µs, the
// telemetry wait apart (virtual time), wake-up latency p50/p99/max, overruns, dropped events; and a
// WARNING line when it fell behind.
std::string describe_run(const RunResult& r, const RunOptions& opt);

}  // namespace loom::firmware

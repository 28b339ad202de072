// The run's summary line and its warnings (see run_summary.hpp).
#include "loom/firmware/run_summary.hpp"

#include <sched.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>

namespace loom::firmware {

std::string describe_run(const RunResult& r, const RunOptions& opt) {
  char buf[768];
  const double machine_s = static_cast<double>(r.ticks) * opt.period_s;
  const char* ratio_fmt = r.achieved_ratio < 10.0 ? "%.2f" : "%.0f";
  char ratio[32];
  std::snprintf(ratio, sizeof ratio, ratio_fmt, r.achieved_ratio);
  const auto us = [](std::int64_t ns) { return static_cast<double>(ns) * 1e-3; };
  int n = std::snprintf(
      buf, sizeof buf,
      "loop: %lld ticks (%.2f s machine time) in %.3f s wall (%sx real time); tick cost (the tick's "
      "own work) median %.1f \u00b5s, p99.9 %.1f \u00b5s, max %.1f \u00b5s; overruns %u",
      static_cast<long long>(r.ticks), machine_s, r.wall_s, ratio, us(r.median_tick_cost_ns),
      us(r.p999_tick_cost_ns), us(r.max_tick_cost_ns), r.overruns);
  std::string s(buf, static_cast<std::size_t>(std::max(n, 0)));
  if (r.telemetry_wait_ticks > 0) {
    n = std::snprintf(
        buf, sizeof buf,
        "; telemetry wait (virtual time: the loop waited between ticks for the LCM publisher to free "
        "ring space, not part of the tick) %llu ticks, total %.1f \u00b5s, max %.1f \u00b5s, %llu yields",
        static_cast<unsigned long long>(r.telemetry_wait_ticks), us(r.telemetry_wait_total_ns),
        us(r.telemetry_wait_max_ns), static_cast<unsigned long long>(r.telemetry_wait_yields));
    s.append(buf, static_cast<std::size_t>(std::max(n, 0)));
  }
  if (opt.realtime) {
    n = std::snprintf(
        buf, sizeof buf, "; wake-up latency p50 %lld ns, p99 %lld ns, max %lld ns; loop thread %s",
        static_cast<long long>(r.wake_latency_p50_ns), static_cast<long long>(r.wake_latency_p99_ns),
        static_cast<long long>(r.wake_latency_max_ns),
        r.loop_policy == SCHED_FIFO ? ("SCHED_FIFO " + std::to_string(r.loop_priority)).c_str()
                                    : "SCHED_OTHER");
    s.append(buf, static_cast<std::size_t>(std::max(n, 0)));
  }
  if (r.events_dropped > 0) s += "; run events dropped " + std::to_string(r.events_dropped);
  if (r.acks_refused > 0) {
    s += "; acknowledgements refused while the link could not be re-armed " + std::to_string(r.acks_refused);
  }
  if (r.acks_refused_unsaved > 0) {
    s += "; acknowledgements refused while the counters could not be saved " +
         std::to_string(r.acks_refused_unsaved);
  }
  if (r.fifo_refused) s += "\nloomctl: WARNING: SCHED_FIFO was refused; the loop ran at SCHED_OTHER";
  if (r.fell_behind) {
    n = std::snprintf(
        buf, sizeof buf,
        "\nloomctl: WARNING: could not keep up: asked for %gx real time, achieved %.2fx (%u overruns; "
        "a tick period of %.0f ns is shorter than the loop can hold)",
        opt.pace, r.achieved_ratio, r.overruns, opt.period_s * 1e9 / opt.pace);
    s.append(buf, static_cast<std::size_t>(std::max(n, 0)));
  }
  if (r.overrun_stop) {
    s += "\nloomctl: the loop overran " + std::to_string(opt.overrun_stop_after) +
         " deadlines in a row: safe stop (loop_overrun)";
  }
  return s;
}

}  // namespace loom::firmware

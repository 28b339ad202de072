// Per-channel decimation with change-triggered STATUS (see schedule.hpp for the rules).
#include "loom/telemetry/schedule.hpp"

#include <algorithm>

namespace loom::telemetry {

std::string decimation_error(const Decimation& d) {
  const struct {
    const char* field;
    std::int64_t value;
  } fields[] = {{"status_every_n_ticks", d.status_every_n_ticks},
                {"axes_every_n_ticks", d.axes_every_n_ticks},
                {"rt_every_n_ticks", d.rt_every_n_ticks}};
  for (const auto& f : fields) {
    if (f.value < 1) {
      return std::string("telemetry ") + f.field + " = " + std::to_string(f.value) + " must be >= 1";
    }
  }
  return {};
}

ChannelSchedule::StatusKey ChannelSchedule::key_of(const Snapshot& s) noexcept {
  StatusKey k;
  k.state = s.state;
  k.first_fault = s.first_fault;
  k.first_fault_code = s.first_fault_code;
  k.row = s.row;
  k.pick = s.pick;
  k.beat = s.beat;
  k.knot_cycle = s.knots.cycle;
  k.knot_cycles_done = s.knots.cycles_done;
  k.knot_ask = s.knots.ask;
  k.knot_requests = s.knots.requests;
  return k;
}

bool ChannelSchedule::due(hal::Tick now, hal::Tick& last, std::int64_t every) noexcept {
  if (last == hal::kNeverTick || now - last >= every) {
    last = now;
    return true;
  }
  return false;
}

void ChannelSchedule::restart() noexcept {
  last_status_ = last_axes_ = last_rt_ = hal::kNeverTick;
}

ChannelSet ChannelSchedule::decide(const Snapshot& s) noexcept {
  if (prev_tick_ != hal::kNeverTick && s.tick <= prev_tick_) restart();
  prev_tick_ = s.tick;
  ChannelSet out;
  const StatusKey key = key_of(s);
  const bool changed = last_status_ == hal::kNeverTick || !(key == last_key_);
  out.status = due(s.tick, last_status_, d_.status_every_n_ticks);
  if (changed && !out.status) {
    // A change restarts the heartbeat interval: the subscriber has just heard from us.
    out.status = true;
    last_status_ = s.tick;
  }
  last_key_ = key;
  out.axes = due(s.tick, last_axes_, d_.axes_every_n_ticks);
  out.rt = due(s.tick, last_rt_, d_.rt_every_n_ticks);
  return out;
}

}  // namespace loom::telemetry

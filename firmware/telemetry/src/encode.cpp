// Field-by-field mapping from the RT snapshot to the three LCM messages (STATUS, AXES, RT).
#include "loom/telemetry/encode.hpp"

#include <algorithm>
#include <limits>

#include "loom/hal/types.hpp"

namespace loom::telemetry {

namespace {

// Snapshot strings are NUL-terminated when they fit, but a name that fills the array exactly has no
// terminator: never read past the array.
template <std::size_t N>
std::string from_cstr(const std::array<char, N>& a) {
  return std::string(a.begin(), std::find(a.begin(), a.end(), '\0'));
}

std::int64_t to_i64(std::uint64_t v) noexcept {
  return static_cast<std::int64_t>(
      std::min<std::uint64_t>(v, static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())));
}

}  // namespace

double loop_time_s(const Snapshot& s) noexcept {
  return static_cast<double>(s.tick) * static_cast<double>(s.period_ns) * 1e-9;
}

loomlcm::status_t to_status(const Snapshot& s, const std::string& loom_id, std::int64_t utime) {
  loomlcm::status_t m;
  m.utime = utime;
  m.loom_id = loom_id;
  m.tick = s.tick;
  m.time_s = loop_time_s(s);
  m.period_ns = s.period_ns;
  m.state = from_cstr(s.state);
  m.row = s.row;
  m.pick = s.pick;
  m.beat = s.beat;
  m.first_fault = from_cstr(s.first_fault);
  m.first_fault_code = s.first_fault_code;
  m.outputs = s.outputs;
  m.inputs = s.inputs;
  return m;
}

loomlcm::axes_t to_axes(const Snapshot& s, const std::string& loom_id, std::int64_t utime) {
  loomlcm::axes_t m;
  m.utime = utime;
  m.loom_id = loom_id;
  m.tick = s.tick;
  m.time_s = loop_time_s(s);
  m.crank_phase_rad = s.crank_phase_rad;
  m.beater_angle_rad = s.beater_angle_rad;
  m.beat_force_n = s.beat_force_n;
  m.num_axes = static_cast<std::int8_t>(s.axes.size());
  m.axes.resize(s.axes.size());
  for (std::size_t i = 0; i < s.axes.size(); ++i) {
    const AxisSample& a = s.axes[i];
    loomlcm::axis_t& o = m.axes[i];
    o.name = hal::axis_name(static_cast<hal::Axis>(i));
    o.position = a.position;
    o.velocity = a.velocity;
    o.target = a.target;
    o.following_error = a.following_error;
    o.effort = a.effort;
    o.drive_state = hal::drive_state_name(static_cast<hal::DriveState>(a.drive_state));
    o.drive_state_code = static_cast<std::int8_t>(a.drive_state);
    o.request = static_cast<std::int8_t>(a.request);
  }
  return m;
}

loomlcm::rt_stats_t to_rt_stats(const Snapshot& s, const std::string& loom_id, std::int64_t utime,
                                std::uint64_t dropped, std::uint64_t backlog) {
  loomlcm::rt_stats_t m;
  m.utime = utime;
  m.loom_id = loom_id;
  m.tick = s.tick;
  m.time_s = loop_time_s(s);
  m.period_ns = s.period_ns;
  m.overruns = s.overruns;
  m.tick_cost_ns = s.tick_cost_ns;
  m.max_tick_cost_ns = s.max_tick_cost_ns;
  m.dropped_snapshots = to_i64(dropped);
  m.backlog = to_i64(backlog);
  return m;
}

}  // namespace loom::telemetry

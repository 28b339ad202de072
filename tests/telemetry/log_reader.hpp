// Test helper: read an LCM log file back as (channel, decoded message) lists, so tests can check what
// the publisher really put on the wire through LCM's own file provider.
#pragma once

#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "loomlcm/axes_t.hpp"
#include "loomlcm/beat_t.hpp"
#include "loomlcm/fault_t.hpp"
#include "loomlcm/identity_t.hpp"
#include "loomlcm/row_t.hpp"
#include "loomlcm/rt_stats_t.hpp"
#include "loomlcm/status_t.hpp"

namespace loom::telemetry::test_support {

struct LoggedMessages {
  std::vector<loomlcm::status_t> status;
  std::vector<loomlcm::axes_t> axes;
  std::vector<loomlcm::rt_stats_t> rt;
  std::vector<loomlcm::beat_t> beat;
  std::vector<loomlcm::fault_t> fault;
  std::vector<loomlcm::row_t> row;
  std::vector<loomlcm::identity_t> identity;  // who publishes: once a second with STATUS
  std::vector<std::string> other_channels;
  int decode_errors = 0;
};

template <typename M>
bool decode_into(const lcm::LogEvent& ev, std::vector<M>& out) {
  M m;
  if (m.decode(ev.data, 0, static_cast<int>(ev.datalen)) < 0) return false;
  out.push_back(std::move(m));
  return true;
}

inline LoggedMessages read_log(const std::string& path, const std::string& prefix_and_id) {
  LoggedMessages out;
  lcm::LogFile log(path, "r");
  if (!log.good()) {
    out.decode_errors = -1;
    return out;
  }
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    bool ok = true;
    if (ev->channel == prefix_and_id + ".STATUS")
      ok = decode_into(*ev, out.status);
    else if (ev->channel == prefix_and_id + ".AXES")
      ok = decode_into(*ev, out.axes);
    else if (ev->channel == prefix_and_id + ".RT")
      ok = decode_into(*ev, out.rt);
    else if (ev->channel == prefix_and_id + ".BEAT")
      ok = decode_into(*ev, out.beat);
    else if (ev->channel == prefix_and_id + ".FAULT")
      ok = decode_into(*ev, out.fault);
    else if (ev->channel == prefix_and_id + ".ROW")
      ok = decode_into(*ev, out.row);
    else if (ev->channel == prefix_and_id + ".IDENTITY")
      ok = decode_into(*ev, out.identity);
    else
      out.other_channels.push_back(ev->channel);
    if (!ok) ++out.decode_errors;
  }
  return out;
}

}  // namespace loom::telemetry::test_support

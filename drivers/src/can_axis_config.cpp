// The servo axes' configuration checks and bus-load plan (can_axis_config.hpp): pure arithmetic on the
// config, shared by the CAN port's configure() and the loom config's parse-time checks.
#include "loom/drivers/can_axis_config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "loom/drivers/cia402.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/hal/types.hpp"

namespace loom::drivers {

namespace {

std::string fmt(const char* format, double a, double b = 0.0, double c = 0.0) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), format, a, b, c);
  return buf;
}

bool is_whole_ms(double s) {
  const double ms = s * 1e3;
  return std::abs(ms - std::round(ms)) < 1e-6;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Configuration
// ---------------------------------------------------------------------------------------------------
std::optional<CanAxisConfigFault> find_fault(const CanAxisPortConfig& c) {
  const auto fault = [](CanAxisField field, std::size_t axis, std::string message) {
    return std::optional<CanAxisConfigFault>{CanAxisConfigFault{field, axis, std::move(message)}};
  };
  std::array<std::array<bool, 128>, kMaxBuses> used{};
  if (c.axes.empty() || c.axes.size() > hal::kMaxAxes) {
    return fault(CanAxisField::kAxisCount, 0,
                 "axes: " + std::to_string(c.axes.size()) + " axes on the bus (1.." +
                     std::to_string(hal::kMaxAxes) + ")");
  }
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    const CanAxisConfig& a = c.axes[i];
    const std::string field = "axes." + a.name;
    if (a.node_id < kMinNodeId || a.node_id > kMaxNodeId) {
      return fault(CanAxisField::kNodeId, i,
                   field + ".node_id = " + std::to_string(a.node_id) + " is outside 1..127");
    }
    if (a.bus >= kMaxBuses) {
      return fault(
          CanAxisField::kBus, i,
          field + ".bus = " + std::to_string(a.bus) + " is outside 0.." + std::to_string(kMaxBuses - 1));
    }
    if (used[a.bus][a.node_id]) {
      return fault(CanAxisField::kNodeIdTaken, i,
                   field + ".node_id = " + std::to_string(a.node_id) +
                       " is already used by another axis on bus " + std::to_string(a.bus));
    }
    used[a.bus][a.node_id] = true;
    if (!(a.counts_per_unit > 0.0) || !std::isfinite(a.counts_per_unit)) {
      return fault(CanAxisField::kCountsPerUnit, i,
                   field + fmt(".counts_per_unit = %g must be a positive number", a.counts_per_unit));
    }
    if (!(a.rated_effort >= 0.0) || !std::isfinite(a.rated_effort)) {
      return fault(CanAxisField::kRatedEffort, i,
                   field + fmt(".rated_effort = %g must be ≥ 0", a.rated_effort));
    }
    if (!(a.ferror_min >= 0.0) || !std::isfinite(a.ferror_min)) {
      return fault(CanAxisField::kFerrorMin, i,
                   field + fmt(".ferror_min = %g must be ≥ 0 (0 = off)", a.ferror_min));
    }
    if (!(a.ferror_k_s >= 0.0) || !std::isfinite(a.ferror_k_s)) {
      return fault(CanAxisField::kFerrorK, i, field + fmt(".ferror_k_s = %g s must be ≥ 0", a.ferror_k_s));
    }
    if (!(a.boot_timeout_s >= 0.0) || !(a.operational_timeout_s >= 0.0)) {
      return fault(CanAxisField::kBringUpTimeouts, i,
                   field + fmt(".boot_timeout_s = %g s / .operational_timeout_s = %g s must be ≥ 0",
                               a.boot_timeout_s, a.operational_timeout_s));
    }
    if (a.homing_method != 0) {
      if (a.homing_method < 1 || a.homing_method > 37) {
        return fault(CanAxisField::kHomingMethod, i,
                     field + ".homing_method = " + std::to_string(a.homing_method) +
                         " is not a CiA 402 homing method (1..37)");
      }
      if (a.homing_method != 37 && (!(a.homing_speed > 0.0) || !(a.homing_accel > 0.0) ||
                                    !std::isfinite(a.homing_speed) || !std::isfinite(a.homing_accel))) {
        return fault(CanAxisField::kHomingSpeed, i,
                     field + fmt(".homing_speed = %g / .homing_accel = %g must be > 0 for a homing run",
                                 a.homing_speed, a.homing_accel));
      }
      if (!std::isfinite(a.home_offset) || std::abs(a.home_offset * a.counts_per_unit) > 2147483647.0) {
        return fault(CanAxisField::kHomeOffset, i,
                     field + fmt(".home_offset = %g does not fit 0x607C (32-bit counts)", a.home_offset));
      }
    }
    if (c.master_node_id == a.node_id) {
      return fault(CanAxisField::kNodeIdIsMaster, i,
                   field + ".node_id = " + std::to_string(a.node_id) + " is the master's own node id");
    }
  }
  if (!(c.cycle_period_s > 0.0) || !encode_interpolation_period(c.cycle_period_s)) {
    return fault(CanAxisField::kCyclePeriod, 0,
                 fmt("cycle_period_s = %g s cannot be written to 0x60C2 (needs value·10^index "
                     "with value 1..255, index −3..−6, e.g. 0.002)",
                     c.cycle_period_s));
  }
  if (!(c.heartbeat_producer_s >= 0.001 && c.heartbeat_producer_s <= 65.535) ||
      !is_whole_ms(c.heartbeat_producer_s)) {
    return fault(CanAxisField::kHeartbeatProducer, 0,
                 fmt("heartbeat_producer_s = %g s must be a whole number of ms in 0.001..65.535",
                     c.heartbeat_producer_s));
  }
  if (!(c.heartbeat_consumer_s > c.heartbeat_producer_s)) {
    return fault(CanAxisField::kHeartbeatConsumer, 0,
                 fmt("heartbeat_consumer_s = %g s must exceed heartbeat_producer_s = %g s",
                     c.heartbeat_consumer_s, c.heartbeat_producer_s));
  }
  if (c.heartbeat_consumer_s + c.cycle_period_s > 3.0 * c.heartbeat_producer_s + 1e-12) {
    return fault(CanAxisField::kHeartbeatConsumer, 0,
                 fmt("heartbeat_consumer_s = %g s is too long: a lost drive must be detected "
                     "within 3 heartbeat periods (needs ≤ 3 × %g − %g s)",
                     c.heartbeat_consumer_s, c.heartbeat_producer_s, c.cycle_period_s));
  }
  if (!(c.sdo_timeout_s > 0.0))
    return fault(CanAxisField::kSdoTimeout, 0, fmt("sdo_timeout_s = %g s must be > 0", c.sdo_timeout_s));
  if (!(c.boot_timeout_s > 0.0))
    return fault(CanAxisField::kBootTimeout, 0, fmt("boot_timeout_s = %g s must be > 0", c.boot_timeout_s));
  if (!(c.state_timeout_s >= 4.0 * c.cycle_period_s)) {
    return fault(CanAxisField::kStateTimeout, 0,
                 fmt("state_timeout_s = %g s must be at least 4 cycles (%g s): a transition "
                     "takes two cycles to be confirmed",
                     c.state_timeout_s, 4.0 * c.cycle_period_s));
  }
  if (c.tpdo2_every_n_sync < 1 || c.tpdo2_every_n_sync > 240) {
    return fault(CanAxisField::kTpdo2EveryN, 0,
                 "tpdo2_every_n_sync = " + std::to_string(c.tpdo2_every_n_sync) +
                     " must be 1..240 (synchronous transmission type)");
  }
  if (c.bitrate_bps == 0) return fault(CanAxisField::kBitrate, 0, "bitrate_bps = 0 must be > 0");
  if (!(c.operational_timeout_s > 0.0)) {
    return fault(CanAxisField::kOperationalTimeout, 0,
                 fmt("operational_timeout_s = %g s must be > 0", c.operational_timeout_s));
  }
  if (c.master_node_id > kMaxNodeId) {
    return fault(CanAxisField::kMasterNode, 0,
                 "master_node_id = " + std::to_string(c.master_node_id) + " is outside 0..127");
  }
  if (c.master_node_id != 0) {
    if (!(c.master_heartbeat_s >= c.cycle_period_s) || !(c.master_consumer_s > c.master_heartbeat_s) ||
        !is_whole_ms(c.master_consumer_s) || c.master_consumer_s > 65.535) {
      return fault(CanAxisField::kMasterHeartbeat, 0,
                   fmt("master_heartbeat_s = %g s / master_consumer_s = %g s: the heartbeat must be at "
                       "least one cycle, the consumer time longer and a whole number of ms",
                       c.master_heartbeat_s, c.master_consumer_s));
    }
  }
  if (!(c.bus_load_budget > 0.0 && c.bus_load_budget <= 1.0)) {
    return fault(CanAxisField::kBusLoadBudget, 0,
                 fmt("bus_load_budget = %g must be in (0, 1]", c.bus_load_budget));
  }
  for (const std::vector<FrameGroup>& bus : c.other_frames_per_cycle) {
    for (const FrameGroup& g : bus) {
      if (g.data_bytes > 8) {
        return fault(CanAxisField::kOtherFrames, 0,
                     "other_frames_per_cycle: data_bytes = " + std::to_string(g.data_bytes) +
                         " exceeds 8 (classic CAN)");
      }
    }
  }
  return std::nullopt;
}

Status validate(const CanAxisPortConfig& c) {
  const std::optional<CanAxisConfigFault> f = find_fault(c);
  return f ? Status::error(f->message) : Status::ok();
}

std::size_t bus_count(const CanAxisPortConfig& c) {
  std::size_t n = 1;
  for (const CanAxisConfig& a : c.axes) n = std::max<std::size_t>(n, a.bus + 1U);
  for (std::size_t b = 0; b < kMaxBuses; ++b) {
    if (!c.other_frames_per_cycle[b].empty() || c.other_nodes_per_bus[b] != 0) n = std::max(n, b + 1);
  }
  return n;
}

BusLoad planned_bus_load(const CanAxisPortConfig& c, std::size_t bus) {
  // Per mode, the axes on this bus; homed axes carry the mode in RPDO1/TPDO1 (7 bytes instead of 6).
  std::uint32_t cyclic = 0, cyclic_homed = 0, profile = 0, profile_homed = 0;
  for (const CanAxisConfig& a : c.axes) {
    if (a.bus != bus) continue;
    const bool homed = a.homing_method != 0;
    if (a.mode == DriveMode::kProfilePosition) {
      (homed ? profile_homed : profile) += 1;
    } else {
      (homed ? cyclic_homed : cyclic) += 1;
    }
  }
  const std::uint32_t axes = cyclic + cyclic_homed + profile + profile_homed;
  // Synchronous: SYNC; each cyclic-position drive's RPDO1 and TPDO1, every SYNC; TPDO2 of every drive when
  // configured (synchronous, every n-th SYNC: all of them may fall on one, the worst cycle); the other
  // nodes' PDOs (the I/O modules'); the master heartbeat, in full (bus_load.cpp says why).
  std::vector<FrameGroup> synchronous{{0, 1}, {kRpdo1Bytes, cyclic}, {kTpdo1Bytes, cyclic}};
  if (cyclic_homed != 0) {
    synchronous.push_back({kRpdo1HomingBytes, cyclic_homed});
    synchronous.push_back({kTpdo1HomingBytes, cyclic_homed});
  }
  if (c.tpdo2) synchronous.push_back({kTpdo2Bytes, axes});
  if (bus < kMaxBuses) {
    const std::vector<FrameGroup>& other = c.other_frames_per_cycle[bus];
    synchronous.insert(synchronous.end(), other.begin(), other.end());
  }
  if (c.master_node_id != 0) synchronous.push_back({kHeartbeatBytes, 1});
  // Every node's own heartbeat: each drive's and each other node's (the loom writes the same producer time
  // to all of them), at its rate (bus_load.cpp: one in progress is the blocking frame).
  const RateGroup heartbeats[] = {
      {kHeartbeatBytes, axes + (bus < kMaxBuses ? c.other_nodes_per_bus[bus] : 0U), c.heartbeat_producer_s}};
  // Profile-position axes. Their TPDO1 is event-driven: sent on a change of statusword or position, at most
  // once per inhibit time, and once per event timer when nothing changes; the fastest it can go is once per
  // inhibit time (or per event timer, were that shorter), the rate counted. Their RPDO1 goes only when
  // the controlword or target changes: a move's set-point, and its release once the drive has acknowledged
  // the set-point (statusword bit 12, which arrives in that TPDO1). So the handshake spaces the master's
  // RPDO1s by at least one drive response, and the drive's responses are inhibited: RPDO1 is bounded by the
  // same rate. (A stop's controlword is one more frame, on a cycle whose motion stops anyway.)
  double interval = c.profile_tpdo_inhibit_s;
  if (c.profile_tpdo_event_timer_s > 0.0 && (interval <= 0.0 || c.profile_tpdo_event_timer_s < interval)) {
    interval = c.profile_tpdo_event_timer_s;
  }
  if (!(interval > 0.0)) interval = c.cycle_period_s;  // no bound: one per cycle
  const RateGroup events[] = {{kRpdo1Bytes, profile, interval},
                              {kTpdo1Bytes, profile, interval},
                              {kRpdo1HomingBytes, profile_homed, interval},
                              {kTpdo1HomingBytes, profile_homed, interval}};
  CycleTraffic traffic;
  traffic.synchronous = synchronous;
  traffic.heartbeats = heartbeats;
  traffic.events = events;
  traffic.blocking = true;    // the largest asynchronous frame (an SDO) may be on the wire at SYNC
  traffic.emcy_headroom = 1;  // one EMCY per cycle (bus_load.cpp justifies the figure)
  return compute_cycle_load(traffic, c.bitrate_bps, c.cycle_period_s);
}

}  // namespace loom::drivers

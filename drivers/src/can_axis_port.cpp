// CiA 402 servo axes over CANopen: configure-time bring-up (NMT + SDO) and the per-tick RT exchange.
// The RT half touches only fixed arrays; every fault it detects is latched in the per-axis record and
// reported through hal::AxisFeedback / hal::LinkStatus, never thrown or logged.
#include "loom/drivers/can_axis_port.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "loom/drivers/can_error_frame.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/drivers/sdo.hpp"
#include "loom/drivers/sdo_client.hpp"

namespace loom::drivers {

using hal::AxisRequest;
using hal::DriveState;

namespace {

std::string fmt(const char* format, double a, double b = 0.0, double c = 0.0) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), format, a, b, c);
  return buf;
}

std::uint32_t ceil_ticks(double seconds, double period_s) {
  return static_cast<std::uint32_t>(std::ceil(seconds / period_s - 1e-9));
}

// How bad a recovery state is, for reporting the worst over several buses.
int rank(hal::LinkRecovery r) {
  switch (r) {
    case hal::LinkRecovery::kHealthy: return 0;
    case hal::LinkRecovery::kReady: return 1;
    case hal::LinkRecovery::kNodeSilent: return 2;
    case hal::LinkRecovery::kBusOff: return 3;
  }
  return 0;
}

bool is_whole_ms(double s) {
  const double ms = s * 1e3;
  return std::abs(ms - std::round(ms)) < 1e-6;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Configuration
// ---------------------------------------------------------------------------------------------------
Status validate(const CanAxisPortConfig& c) {
  std::array<std::array<bool, 128>, kMaxBuses> used{};
  if (c.axes.empty() || c.axes.size() > hal::kMaxAxes) {
    return Status::error("axes: " + std::to_string(c.axes.size()) + " axes on the bus (1.." +
                         std::to_string(hal::kMaxAxes) + ")");
  }
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    const CanAxisConfig& a = c.axes[i];
    const std::string field = "axes." + a.name;
    if (a.node_id < kMinNodeId || a.node_id > kMaxNodeId) {
      return Status::error(field + ".node_id = " + std::to_string(a.node_id) + " is outside 1..127");
    }
    if (a.bus >= kMaxBuses) {
      return Status::error(field + ".bus = " + std::to_string(a.bus) + " is outside 0.." +
                           std::to_string(kMaxBuses - 1));
    }
    if (used[a.bus][a.node_id]) {
      return Status::error(field + ".node_id = " + std::to_string(a.node_id) +
                           " is already used by another axis on bus " + std::to_string(a.bus));
    }
    used[a.bus][a.node_id] = true;
    if (!(a.counts_per_unit > 0.0) || !std::isfinite(a.counts_per_unit)) {
      return Status::error(field + fmt(".counts_per_unit = %g must be a positive number", a.counts_per_unit));
    }
    if (!(a.rated_effort >= 0.0) || !std::isfinite(a.rated_effort)) {
      return Status::error(field + fmt(".rated_effort = %g must be ≥ 0", a.rated_effort));
    }
    if (!(a.ferror_min >= 0.0) || !std::isfinite(a.ferror_min)) {
      return Status::error(field + fmt(".ferror_min = %g must be ≥ 0 (0 = off)", a.ferror_min));
    }
    if (!(a.ferror_k_s >= 0.0) || !std::isfinite(a.ferror_k_s)) {
      return Status::error(field + fmt(".ferror_k_s = %g s must be ≥ 0", a.ferror_k_s));
    }
    if (!(a.boot_timeout_s >= 0.0) || !(a.operational_timeout_s >= 0.0)) {
      return Status::error(field + fmt(".boot_timeout_s = %g s / .operational_timeout_s = %g s must be ≥ 0",
                                       a.boot_timeout_s, a.operational_timeout_s));
    }
    if (a.homing_method != 0) {
      if (a.homing_method < 1 || a.homing_method > 37) {
        return Status::error(field + ".homing_method = " + std::to_string(a.homing_method) +
                             " is not a CiA 402 homing method (1..37)");
      }
      if (a.homing_method != 37 && (!(a.homing_speed > 0.0) || !(a.homing_accel > 0.0) ||
                                    !std::isfinite(a.homing_speed) || !std::isfinite(a.homing_accel))) {
        return Status::error(field + fmt(".homing_speed = %g / .homing_accel = %g must be > 0 for a homing run",
                                         a.homing_speed, a.homing_accel));
      }
      if (!std::isfinite(a.home_offset) || std::abs(a.home_offset * a.counts_per_unit) > 2147483647.0) {
        return Status::error(field + fmt(".home_offset = %g does not fit 0x607C (32-bit counts)", a.home_offset));
      }
    }
    if (c.master_node_id == a.node_id) {
      return Status::error(field + ".node_id = " + std::to_string(a.node_id) + " is the master's own node id");
    }
  }
  if (!(c.cycle_period_s > 0.0) || !encode_interpolation_period(c.cycle_period_s)) {
    return Status::error(
        fmt("cycle_period_s = %g s cannot be written to 0x60C2 (needs value·10^index "
            "with value 1..255, index −3..−6, e.g. 0.002)",
            c.cycle_period_s));
  }
  if (!(c.heartbeat_producer_s >= 0.001 && c.heartbeat_producer_s <= 65.535) ||
      !is_whole_ms(c.heartbeat_producer_s)) {
    return Status::error(fmt("heartbeat_producer_s = %g s must be a whole number of ms in 0.001..65.535",
                             c.heartbeat_producer_s));
  }
  if (!(c.heartbeat_consumer_s > c.heartbeat_producer_s)) {
    return Status::error(fmt("heartbeat_consumer_s = %g s must exceed heartbeat_producer_s = %g s",
                             c.heartbeat_consumer_s, c.heartbeat_producer_s));
  }
  if (c.heartbeat_consumer_s + c.cycle_period_s > 3.0 * c.heartbeat_producer_s + 1e-12) {
    return Status::error(
        fmt("heartbeat_consumer_s = %g s is too long: a lost drive must be detected "
            "within 3 heartbeat periods (needs ≤ 3 × %g − %g s)",
            c.heartbeat_consumer_s, c.heartbeat_producer_s, c.cycle_period_s));
  }
  if (!(c.sdo_timeout_s > 0.0))
    return Status::error(fmt("sdo_timeout_s = %g s must be > 0", c.sdo_timeout_s));
  if (!(c.boot_timeout_s > 0.0))
    return Status::error(fmt("boot_timeout_s = %g s must be > 0", c.boot_timeout_s));
  if (!(c.state_timeout_s >= 4.0 * c.cycle_period_s)) {
    return Status::error(
        fmt("state_timeout_s = %g s must be at least 4 cycles (%g s): a transition "
            "takes two cycles to be confirmed",
            c.state_timeout_s, 4.0 * c.cycle_period_s));
  }
  if (c.tpdo2_every_n_sync < 1 || c.tpdo2_every_n_sync > 240) {
    return Status::error("tpdo2_every_n_sync = " + std::to_string(c.tpdo2_every_n_sync) +
                         " must be 1..240 (synchronous transmission type)");
  }
  if (c.bitrate_bps == 0) return Status::error("bitrate_bps = 0 must be > 0");
  if (!(c.operational_timeout_s > 0.0)) {
    return Status::error(fmt("operational_timeout_s = %g s must be > 0", c.operational_timeout_s));
  }
  if (c.master_node_id > kMaxNodeId) {
    return Status::error("master_node_id = " + std::to_string(c.master_node_id) + " is outside 0..127");
  }
  if (c.master_node_id != 0) {
    if (!(c.master_heartbeat_s >= c.cycle_period_s) || !(c.master_consumer_s > c.master_heartbeat_s) ||
        !is_whole_ms(c.master_consumer_s) || c.master_consumer_s > 65.535) {
      return Status::error(fmt("master_heartbeat_s = %g s / master_consumer_s = %g s: the heartbeat must be at "
                               "least one cycle, the consumer time longer and a whole number of ms",
                               c.master_heartbeat_s, c.master_consumer_s));
    }
  }
  if (!(c.bus_load_budget > 0.0 && c.bus_load_budget <= 1.0)) {
    return Status::error(fmt("bus_load_budget = %g must be in (0, 1]", c.bus_load_budget));
  }
  for (const std::vector<FrameGroup>& bus : c.other_frames_per_cycle) {
    for (const FrameGroup& g : bus) {
      if (g.data_bytes > 8) {
        return Status::error("other_frames_per_cycle: data_bytes = " + std::to_string(g.data_bytes) +
                             " exceeds 8 (classic CAN)");
      }
    }
  }
  return Status::ok();
}

std::size_t bus_count(const CanAxisPortConfig& c) {
  std::size_t n = 1;
  for (const CanAxisConfig& a : c.axes) n = std::max<std::size_t>(n, a.bus + 1U);
  for (std::size_t b = 0; b < c.other_frames_per_cycle.size(); ++b) {
    if (!c.other_frames_per_cycle[b].empty()) n = std::max(n, b + 1);
  }
  return n;
}

BusLoad planned_bus_load(const CanAxisPortConfig& c, std::size_t bus) {
  std::uint32_t n = 0, homed = 0;  // homed axes carry the mode in RPDO1/TPDO1 (7 bytes instead of 6)
  for (const CanAxisConfig& a : c.axes) {
    n += a.bus == bus && a.homing_method == 0 ? 1U : 0U;
    homed += a.bus == bus && a.homing_method != 0 ? 1U : 0U;
  }
  std::vector<FrameGroup> frames{{0, 1}, {kRpdo1Bytes, n}, {kTpdo1Bytes, n}};
  if (homed != 0) {
    frames.push_back({kRpdo1HomingBytes, homed});
    frames.push_back({kTpdo1HomingBytes, homed});
  }
  n += homed;
  if (c.tpdo2) frames.push_back({kTpdo2Bytes, n});
  if (bus < kMaxBuses) {
    const std::vector<FrameGroup>& other = c.other_frames_per_cycle[bus];
    frames.insert(frames.end(), other.begin(), other.end());
  }
  // The master heartbeat (1 byte) counted as if it were sent every cycle: the worst cycle holds it.
  if (c.master_node_id != 0) frames.push_back({1, 1});
  return compute_bus_load(frames, c.bitrate_bps, c.cycle_period_s);
}

// ---------------------------------------------------------------------------------------------------
// The port: one master per bus, one CiA 402 profile per axis
// ---------------------------------------------------------------------------------------------------
CanAxisPort::CanAxisPort(CanAxisPortConfig config) {
  d_.config = std::move(config);
  d_.n_axes = std::min(d_.config.axes.size(), hal::kMaxAxes);
  d_.n_buses = std::min(drivers::bus_count(d_.config), kMaxBuses);
  const CanMasterConfig mc{d_.config.cycle_period_s, d_.config.sdo_timeout_s, d_.config.boot_timeout_s,
                           d_.config.operational_timeout_s, d_.config.master_node_id,
                           d_.config.master_heartbeat_s};
  for (CanMaster& m : d_.masters) m = CanMaster(mc);
  for (std::size_t i = 0; i < d_.n_axes; ++i) d_.axes[i].setup(d_.config.axes[i], d_.config);
  relink();
}

CanAxisPort::CanAxisPort(const CanAxisPort& other) : hal::AxisPort(other), d_(other.d_) { relink(); }

CanAxisPort& CanAxisPort::operator=(const CanAxisPort& other) {
  d_ = other.d_;
  relink();
  return *this;
}

void CanAxisPort::relink() {
  for (CanMaster& m : d_.masters) m.clear_nodes();
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    if (d_.axes[i].bus() < kMaxBuses) d_.masters[d_.axes[i].bus()].add(d_.axes[i]);
  }
  for (std::size_t k = 0; k < d_.n_attached; ++k) {
    if (d_.attached[k].bus < kMaxBuses) d_.masters[d_.attached[k].bus].add(*d_.attached[k].node);
  }
}

void CanAxisPort::attach(CanNode& node, std::size_t bus) {
  if (d_.n_attached < d_.attached.size()) d_.attached[d_.n_attached++] = {&node, bus};
  relink();
}

Status CanAxisPort::configure(CanBus& bus) {
  MonotonicConfigureClock clock;
  return configure(bus, clock);
}

Status CanAxisPort::configure(CanBus& bus, ConfigureClock& clock) {
  CanBus* const one[] = {&bus};
  return configure(std::span<CanBus* const>(one), clock);
}

Status CanAxisPort::configure(std::span<CanBus* const> buses, ConfigureClock& clock) {
  d_.configured = false;
  d_.notes.clear();
  if (Status s = validate(d_.config); !s) return Status::error("CAN axis configuration: " + s.message());
  if (buses.size() != d_.n_buses) {
    return Status::error("the axes use " + std::to_string(d_.n_buses) + " CAN bus(es) (highest axes.<name>.bus = " +
                         std::to_string(d_.n_buses - 1) + ") but " + std::to_string(buses.size()) +
                         " interface(s) were given");
  }
  for (std::size_t b = 0; b < d_.n_buses; ++b) {
    d_.bus_loads[b] = planned_bus_load(d_.config, b);
    if (Status s = check_bus_load(d_.bus_loads[b], d_.config.bus_load_budget); !s) {
      return d_.n_buses == 1 ? s : Status::error("bus " + std::to_string(b) + ": " + s.message());
    }
  }
  for (std::size_t k = 0; k < d_.n_attached; ++k) {
    if (d_.attached[k].bus >= d_.n_buses) {
      return Status::error(d_.attached[k].node->label() + " is attached to bus " + std::to_string(d_.attached[k].bus) +
                           " but the port has " + std::to_string(d_.n_buses) +
                           " bus(es): its frames are not in other_frames_per_cycle");
    }
  }
  relink();
  std::size_t expected = d_.n_axes + d_.n_attached;
  for (std::size_t b = 0; b < d_.n_buses; ++b) expected -= d_.masters[b].node_count();
  if (expected != 0) return Status::error("an attached node shares its node id with another node on its bus");
  d_.consumer_ticks = ceil_ticks(d_.config.heartbeat_consumer_s, d_.config.cycle_period_s);
  d_.state_timeout_ticks = ceil_ticks(d_.config.state_timeout_s, d_.config.cycle_period_s);

  for (std::size_t b = 0; b < d_.n_buses; ++b) {
    if (buses[b] == nullptr) return Status::error("bus " + std::to_string(b) + ": no interface");
    if (Status s = d_.masters[b].bring_up(*buses[b], clock); !s) return s;
  }
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    d_.notes.insert(d_.notes.end(), d_.axes[i].notes().begin(), d_.axes[i].notes().end());
  }
  d_.configured = true;
  return Status::ok();
}

// ---------------------------------------------------------------------------------------------------
// Per tick (RT-safe)
// ---------------------------------------------------------------------------------------------------
void CanAxisPort::read_axes(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) {
  if (d_.configured) {
    for (std::size_t b = 0; b < d_.n_buses; ++b) d_.masters[b].poll(now);
  }
  link = hal::LinkStatus{};
  if (!d_.configured) {
    link.link_fault = true;
    link.link_fault_code = fault_code::kCommunication;
    link.link_fault_kind = hal::FaultKind::kCommunication;
  }
  for (std::size_t b = 0; b < d_.n_buses; ++b) d_.masters[b].report_link(link);
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    const CanMaster& m = d_.masters[d_.axes[i].bus()];
    d_.axes[i].fill_feedback(axes[i], m.bus_off(), d_.configured && m.configured());
    link.rx_errors += d_.axes[i].rx_errors();
  }
  // The worst recovery state over the buses: a bus-off first, then a silent node, then ready.
  link.recovery = d_.configured ? hal::LinkRecovery::kHealthy : hal::LinkRecovery::kReady;
  for (std::size_t b = 0; b < d_.n_buses; ++b) {
    std::uint8_t silent = 0;
    const hal::LinkRecovery r = d_.masters[b].recovery(now, silent);
    if (static_cast<int>(rank(r)) > static_cast<int>(rank(link.recovery))) {
      link.recovery = r;
      link.silent_node = r == hal::LinkRecovery::kNodeSilent ? silent : 0;
    }
  }
}

bool CanAxisPort::any_fault() const {
  for (std::size_t b = 0; b < d_.n_buses; ++b) {
    if (d_.masters[b].any_fault()) return true;
  }
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    if (d_.axes[i].faulted()) return true;
  }
  return false;
}

void CanAxisPort::write_axes(hal::Tick now, const hal::AxisCommands& commands) {
  if (!d_.configured) return;
  bool reset = false;
  for (std::size_t i = 0; i < d_.n_axes; ++i) reset = reset || commands[i].request == AxisRequest::kFaultReset;
  if (reset) {
    for (std::size_t b = 0; b < d_.n_buses; ++b) d_.masters[b].acknowledge();
  }
  // Any fault anywhere (EMCY from any node, a lost node, following error, a bus-off on any bus) stops
  // every axis in this very tick, whatever the sequencer asked and whatever the drives' statuswords say.
  const bool stop_all = any_fault();
  for (std::size_t b = 0; b < d_.n_buses; ++b) d_.masters[b].start_cycle(now);
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    CanMaster& m = d_.masters[d_.axes[i].bus()];
    m.send(d_.axes[i].command(commands[i], stop_all, m.bus_off(), d_.state_timeout_ticks));
  }
}

}  // namespace loom::drivers

// CiA 402 servo axes over CANopen: configure-time bring-up (NMT + SDO) and the per-tick RT exchange.
// The RT half touches only fixed arrays; every fault it detects is latched in the per-axis record and
// reported through hal::AxisFeedback / hal::LinkStatus, never thrown or logged.
#include "loom/drivers/can_axis_port.hpp"

#include <cmath>
#include <cstdio>

#include "loom/drivers/can_error_frame.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/drivers/pdo.hpp"
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

bool is_whole_ms(double s) {
  const double ms = s * 1e3;
  return std::abs(ms - std::round(ms)) < 1e-6;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Configuration
// ---------------------------------------------------------------------------------------------------
Status validate(const CanAxisPortConfig& c) {
  std::array<bool, 128> used{};
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    const CanAxisConfig& a = c.axes[i];
    const std::string field = std::string("axes.") + hal::axis_name(static_cast<hal::Axis>(i));
    if (a.node_id < kMinNodeId || a.node_id > kMaxNodeId) {
      return Status::error(field + ".node_id = " + std::to_string(a.node_id) + " is outside 1..127");
    }
    if (used[a.node_id]) {
      return Status::error(field + ".node_id = " + std::to_string(a.node_id) +
                           " is already used by another axis");
    }
    used[a.node_id] = true;
    if (!(a.counts_per_unit > 0.0) || !std::isfinite(a.counts_per_unit)) {
      return Status::error(field + fmt(".counts_per_unit = %g must be a positive number", a.counts_per_unit));
    }
    if (!(a.rated_effort >= 0.0) || !std::isfinite(a.rated_effort)) {
      return Status::error(field + fmt(".rated_effort = %g must be ≥ 0", a.rated_effort));
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
  if (!(c.bus_load_budget > 0.0 && c.bus_load_budget <= 1.0)) {
    return Status::error(fmt("bus_load_budget = %g must be in (0, 1]", c.bus_load_budget));
  }
  for (const FrameGroup& g : c.other_frames_per_cycle) {
    if (g.data_bytes > 8) {
      return Status::error("other_frames_per_cycle: data_bytes = " + std::to_string(g.data_bytes) +
                           " exceeds 8 (classic CAN)");
    }
  }
  return Status::ok();
}

CanAxisPort::CanAxisPort(CanAxisPortConfig config) : config_(std::move(config)) {
  reset_runtime();
}

void CanAxisPort::reset_runtime() {
  configured_ = false;
  bus_off_ = false;
  axis_of_node_.fill(-1);
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    axes_[i] = AxisRuntime{};
    axes_[i].node = config_.axes[i].node_id;
    axes_[i].counts_per_unit = config_.axes[i].counts_per_unit;
    axes_[i].rated_effort = config_.axes[i].rated_effort;
    if (axes_[i].node <= kMaxNodeId) axis_of_node_[axes_[i].node] = static_cast<std::int8_t>(i);
  }
}

std::string CanAxisPort::node_label(std::size_t axis) const {
  return "node " + std::to_string(config_.axes[axis].node_id) + " (" +
         hal::axis_name(static_cast<hal::Axis>(axis)) + ")";
}

// ---------------------------------------------------------------------------------------------------
// Bring-up (configure-time only)
// ---------------------------------------------------------------------------------------------------
Status CanAxisPort::configure(CanBus& bus) {
  MonotonicConfigureClock clock;
  return configure(bus, clock);
}

Status CanAxisPort::configure_node(std::size_t axis, SdoClient& sdo) {
  const std::uint8_t node = axes_[axis].node;
  const std::string who = node_label(axis) + ": ";
  const auto fail = [&](const Status& s) { return Status::error(who + s.message()); };

  // The drive must offer CSP before we select it.
  Result<std::uint32_t> modes = sdo.read(node, od::kSupportedDriveModes, 0);
  if (!modes) return fail(modes.status());
  if ((modes.value() & od::kSupportsCspBit) == 0) {
    char buf[128];
    std::snprintf(buf, sizeof(buf),
                  "the drive does not support cyclic synchronous position (0x6502 = 0x%08X, bit 7 clear)",
                  modes.value());
    return Status::error(who + buf);
  }
  if (Status s = sdo.write(node, od::kModesOfOperation, 0, static_cast<std::uint8_t>(od::kModeCsp), 1); !s) {
    return fail(s);
  }
  Result<std::uint32_t> display = sdo.read(node, od::kModesOfOperationDisplay, 0);
  if (!display) return fail(display.status());
  const auto shown = static_cast<std::int8_t>(display.value() & 0xFF);
  if (shown != od::kModeCsp) {
    return Status::error(who + "0x6061 (modes of operation display) reads " + std::to_string(shown) +
                         " after writing 8 (cyclic synchronous position) to 0x6060");
  }

  const auto producer_ms = static_cast<std::uint32_t>(std::lround(config_.heartbeat_producer_s * 1e3));
  if (Status s = sdo.write(node, od::kHeartbeatProducer, 0, producer_ms, 2); !s) return fail(s);

  const InterpolationPeriod ip = *encode_interpolation_period(config_.cycle_period_s);
  if (Status s = sdo.write(node, od::kInterpolationPeriod, 1, ip.value, 1); !s) return fail(s);
  if (Status s = sdo.write(node, od::kInterpolationPeriod, 2, static_cast<std::uint8_t>(ip.index), 1); !s) {
    return fail(s);
  }

  // PDO mapping (CiA 301 re-map procedure): invalidate, clear count, write entries, set count, set
  // transmission type, validate. A disabled PDO only gets its invalid bit.
  struct PdoPlan {
    std::uint16_t comm;
    std::uint16_t map;
    std::uint32_t cob_id;
    const PdoMapEntry* entries;
    std::uint8_t n_entries;
    std::uint8_t transmission_type;
  };
  const PdoPlan plans[] = {
      {od::kRpdoComm, od::kRpdoMap, cob::rpdo(1, node), kRpdo1Mapping.data(), 2, 1},
      {od::kTpdoComm, od::kTpdoMap, cob::tpdo(1, node), kTpdo1Mapping.data(), 2, 1},
      {static_cast<std::uint16_t>(od::kTpdoComm + 1), static_cast<std::uint16_t>(od::kTpdoMap + 1),
       cob::tpdo(2, node), config_.tpdo2 ? kTpdo2Mapping.data() : nullptr,
       static_cast<std::uint8_t>(config_.tpdo2 ? 2 : 0), config_.tpdo2_every_n_sync},
      {static_cast<std::uint16_t>(od::kTpdoComm + 2), 0, cob::tpdo(3, node), nullptr, 0, 0},
      {static_cast<std::uint16_t>(od::kTpdoComm + 3), 0, cob::tpdo(4, node), nullptr, 0, 0},
  };
  for (const PdoPlan& p : plans) {
    if (Status s = sdo.write(node, p.comm, 1, p.cob_id | od::kPdoInvalidBit, 4); !s) return fail(s);
    if (p.entries == nullptr) continue;
    if (Status s = sdo.write(node, p.map, 0, 0, 1); !s) return fail(s);
    for (std::uint8_t k = 0; k < p.n_entries; ++k) {
      if (Status s =
              sdo.write(node, p.map, static_cast<std::uint8_t>(k + 1), encode_map_entry(p.entries[k]), 4);
          !s) {
        return fail(s);
      }
    }
    if (Status s = sdo.write(node, p.map, 0, p.n_entries, 1); !s) return fail(s);
    if (Status s = sdo.write(node, p.comm, 2, p.transmission_type, 1); !s) return fail(s);
    if (Status s = sdo.write(node, p.comm, 1, p.cob_id, 4); !s) return fail(s);
  }

  // Seed the state machine and the first target from the drive, so enabling never jumps.
  Result<std::uint32_t> sw = sdo.read(node, od::kStatusword, 0);
  if (!sw) return fail(sw.status());
  Result<std::uint32_t> pos = sdo.read(node, od::kPositionActual, 0);
  if (!pos) return fail(pos.status());
  AxisRuntime& a = axes_[axis];
  a.statusword = static_cast<std::uint16_t>(sw.value());
  a.state = decode_statusword(a.statusword);
  a.position.reset(static_cast<std::int32_t>(pos.value()));
  a.last_target_counts = a.position.value();
  a.last_position_si = counts_to_si(a.position.value(), a.counts_per_unit);
  return Status::ok();
}

Status CanAxisPort::configure(CanBus& bus, ConfigureClock& clock) {
  reset_runtime();
  bus_ = nullptr;
  if (Status s = validate(config_); !s) return Status::error("CAN axis configuration: " + s.message());

  std::vector<FrameGroup> frames{{0, 1}, {kRpdo1Bytes, hal::kAxisCount}, {kTpdo1Bytes, hal::kAxisCount}};
  if (config_.tpdo2) frames.push_back({kTpdo2Bytes, hal::kAxisCount});
  frames.insert(frames.end(), config_.other_frames_per_cycle.begin(), config_.other_frames_per_cycle.end());
  bus_load_ = compute_bus_load(frames, config_.bitrate_bps, config_.cycle_period_s);
  if (Status s = check_bus_load(bus_load_, config_.bus_load_budget); !s) return s;

  consumer_ticks_ = ceil_ticks(config_.heartbeat_consumer_s, config_.cycle_period_s);
  state_timeout_ticks_ = ceil_ticks(config_.state_timeout_s, config_.cycle_period_s);

  // What the nodes said while we were busy with something else.
  std::array<bool, hal::kAxisCount> booted{};
  std::array<bool, hal::kAxisCount> operational{};
  const auto note = [&](const CanFrame& f) {
    if (f.is_error()) {
      if (decode_error_frame(f).bus_off) bus_off_ = true;
      return;
    }
    if (auto hb = parse_heartbeat(f)) {
      const std::int8_t ax = axis_of_node_[hb->node];
      if (ax < 0) return;
      if (hb->state == NmtState::kBootUp) booted[static_cast<std::size_t>(ax)] = true;
      operational[static_cast<std::size_t>(ax)] = hb->state == NmtState::kOperational;
    }
  };
  const auto drain = [&] {
    CanFrame f;
    for (int i = 0; i < 4096 && bus.receive(f); ++i) note(f);
  };
  const auto send = [&](const CanFrame& f, const std::string& what) -> Status {
    const std::int64_t deadline = clock.now_us() + static_cast<std::int64_t>(config_.sdo_timeout_s * 1e6);
    for (;;) {
      const SendResult r = bus.send(f);
      if (r == SendResult::kOk) return Status::ok();
      if (r == SendResult::kError || clock.now_us() >= deadline) {
        return Status::error(what + ": the CAN bus refused the frame" +
                             (r == SendResult::kError ? "" : " (transmit queue full)"));
      }
      clock.idle();
    }
  };
  // Wait until `done` holds for every axis, or name the first axis that did not make it.
  const auto wait_all = [&](std::array<bool, hal::kAxisCount>& done, double timeout_s, const char* what,
                            const char* hint) -> Status {
    const std::int64_t deadline = clock.now_us() + static_cast<std::int64_t>(timeout_s * 1e6);
    for (;;) {
      drain();
      if (bus_off_) return Status::error("CAN bus-off while waiting for " + std::string(what));
      bool all = true;
      for (bool d : done) all = all && d;
      if (all) return Status::ok();
      if (clock.now_us() >= deadline) {
        for (std::size_t i = 0; i < done.size(); ++i) {
          if (!done[i]) {
            return Status::error(node_label(i) + ": no " + what + fmt(" within %.3g s", timeout_s) + hint);
          }
        }
      }
      clock.idle();
    }
  };

  drain();  // stale frames from before the reset mean nothing
  booted.fill(false);
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    if (Status s = send(make_nmt(NmtCommand::kResetNode, axes_[i].node), node_label(i) + ": NMT reset-node");
        !s) {
      return s;
    }
  }
  if (Status s = wait_all(booted, config_.boot_timeout_s, "boot-up after NMT reset-node",
                          " (is the drive powered, on this bus, with this node id?)");
      !s) {
    return s;
  }

  SdoClient sdo(bus, clock, static_cast<std::int64_t>(config_.sdo_timeout_s * 1e6), note);
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    if (Status s = configure_node(i, sdo); !s) return s;
    if (bus_off_) return Status::error(node_label(i) + ": CAN bus-off during configuration");
  }

  operational.fill(false);
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    if (Status s = send(make_nmt(NmtCommand::kStart, axes_[i].node), node_label(i) + ": NMT start"); !s) {
      return s;
    }
  }
  if (Status s = wait_all(operational, config_.heartbeat_consumer_s, "operational heartbeat after NMT start",
                          " (heartbeat producer time written to 0x1017 not honoured?)");
      !s) {
    return s;
  }

  bus_ = &bus;
  configured_ = true;
  return Status::ok();
}

// ---------------------------------------------------------------------------------------------------
// Per tick (RT-safe)
// ---------------------------------------------------------------------------------------------------
void CanAxisPort::count_send(SendResult r) {
  if (r != SendResult::kOk) ++tx_dropped_;
}

void CanAxisPort::handle_frame(hal::Tick now, const CanFrame& f) {
  if (f.is_error()) {
    ++rx_errors_;
    if (decode_error_frame(f).bus_off) bus_off_ = true;
    return;
  }
  const CobDecoded cob_fn = decode_cob_id(f.id);
  const std::int8_t ax = cob_fn.node <= kMaxNodeId ? axis_of_node_[cob_fn.node] : std::int8_t{-1};
  if (ax < 0) return;  // other nodes' traffic, SYNC/NMT echoes of other masters
  AxisRuntime& a = axes_[static_cast<std::size_t>(ax)];

  switch (cob_fn.function) {
    case CobFunction::kTpdo1: {
      const auto p = unpack_tpdo1(f, a.node);
      if (!p) {
        ++rx_errors_;
        return;
      }
      a.statusword = p->statusword;
      a.state = decode_statusword(p->statusword);
      const double pos = counts_to_si(a.position.update(p->position_actual), a.counts_per_unit);
      if (!config_.tpdo2 && a.refreshed != hal::kNeverTick && now > a.refreshed) {
        a.velocity =
            (pos - a.last_position_si) / (static_cast<double>(now - a.refreshed) * config_.cycle_period_s);
      }
      a.last_position_si = pos;
      a.refreshed = now;
      return;
    }
    case CobFunction::kTpdo2: {
      const auto p = unpack_tpdo2(f, a.node);
      if (!p || !config_.tpdo2) {
        ++rx_errors_;
        return;
      }
      a.velocity = static_cast<double>(p->velocity_actual) / a.counts_per_unit;
      a.effort = static_cast<double>(p->torque_actual) * a.rated_effort / 1000.0;
      return;
    }
    case CobFunction::kHeartbeat: {
      const auto hb = parse_heartbeat(f);
      if (!hb) {
        ++rx_errors_;
        return;
      }
      a.last_heartbeat = now;
      if (a.link_fault == 0 && hb->state == NmtState::kBootUp) a.link_fault = fault_code::kNodeRebooted;
      if (a.link_fault == 0 && hb->state != NmtState::kOperational && hb->state != NmtState::kBootUp) {
        a.link_fault = fault_code::kNodeNotOperational;
      }
      return;
    }
    case CobFunction::kEmcy: {
      const auto e = parse_emcy(f);
      if (!e) {
        ++rx_errors_;
        return;
      }
      a.emcy_code = e->code;
      return;
    }
    default:
      return;  // SDO replies to someone else's tool, our own RPDO echo, ...
  }
}

void CanAxisPort::read_axes(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) {
  if (configured_) {
    CanFrame f;
    for (int i = 0; i < kMaxFramesPerRead && bus_->receive(f); ++i) handle_frame(now, f);
    for (AxisRuntime& a : axes_) {
      // The consumer starts counting at the first tick; heartbeats during bring-up carry no tick.
      if (a.last_heartbeat == hal::kNeverTick) a.last_heartbeat = now;
      if (a.link_fault == 0 && now - a.last_heartbeat > static_cast<hal::Tick>(consumer_ticks_)) {
        a.link_fault = fault_code::kHeartbeatLost;
      }
    }
  }
  fill_feedback(axes, link);
}

void CanAxisPort::fill_feedback(hal::AxisFeedbacks& axes, hal::LinkStatus& link) const {
  link.link_fault = !configured_ || bus_off_;
  link.link_fault_code = link.link_fault ? fault_code::kCommunication : fault_code::kNone;
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    const AxisRuntime& a = axes_[i];
    hal::AxisFeedback& fb = axes[i];
    fb.state = a.state;
    fb.position = counts_to_si(a.position.value(), a.counts_per_unit);
    fb.velocity = a.velocity;
    fb.effort = a.effort;
    fb.refreshed = a.refreshed;
    fb.following_error =
        a.state == DriveState::kOperationEnabled && (a.statusword & statusword::kCspFollowingError) != 0;
    const bool drive_fault = a.state == DriveState::kFault || a.state == DriveState::kFaultReactionActive;
    fb.fault = !configured_ || a.link_fault != 0 || drive_fault || a.tracker.timed_out || bus_off_;
    if (a.link_fault != 0) {
      fb.fault_code = a.link_fault;
    } else if (bus_off_ || !configured_) {
      fb.fault_code = fault_code::kCommunication;
    } else if (a.emcy_code != 0) {
      fb.fault_code = a.emcy_code;
    } else if (a.tracker.timed_out) {
      fb.fault_code = fault_code::kStateTimeout;
    } else {
      fb.fault_code = fault_code::kNone;
    }
    if (a.link_fault != 0 && !link.link_fault) {
      link.link_fault = true;
      link.link_fault_code = a.link_fault;
    }
  }
  link.tx_dropped = tx_dropped_;
  link.rx_errors = rx_errors_;
}

void CanAxisPort::write_axes(hal::Tick /*now*/, const hal::AxisCommands& commands) {
  if (!configured_) return;
  count_send(bus_->send(make_sync()));
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    AxisRuntime& a = axes_[i];
    // A drive we cannot supervise (lost, rebooted, bus-off) gets quick stop, never an enable command.
    const bool lost = a.link_fault != 0 || bus_off_;
    const AxisRequest request = lost ? AxisRequest::kQuickStop : commands[i].request;
    const Cia402Step step = cia402_step(a.state, request, a.tracker, state_timeout_ticks_);
    a.tracker = step.next;

    // Outside Operation Enabled the target follows the actual position, so enabling never jumps.
    std::int64_t target = a.position.value();
    const double wanted = commands[i].target_position;
    if (a.state == DriveState::kOperationEnabled && step.controlword == controlword::kEnableOperation &&
        std::isfinite(wanted)) {
      target = si_to_counts(wanted, a.counts_per_unit);
    }
    a.last_target_counts = target;
    count_send(bus_->send(pack_rpdo1(a.node, Rpdo1{step.controlword, wire_counts(target)})));
  }
}

}  // namespace loom::drivers

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

constexpr std::uint16_t kConsumerHeartbeat = 0x1016;

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

void CanAxisPort::attach(CanNodeListener& node) {
  if (n_listeners_ < listeners_.size()) listeners_[n_listeners_++] = &node;
}

void CanAxisPort::reset_runtime() {
  configured_ = false;
  bus_off_ = false;
  restarted_ = false;
  foreign_emcy_code_ = 0;
  next_master_hb_ = 0;
  notes_.clear();
  axis_of_node_.fill(-1);
  n_axes_ = std::min(config_.axes.size(), hal::kMaxAxes);
  for (std::size_t i = 0; i < n_axes_; ++i) {
    axes_[i] = AxisRuntime{};
    axes_[i].node = config_.axes[i].node_id;
    axes_[i].counts_per_unit = config_.axes[i].counts_per_unit;
    axes_[i].rated_effort = config_.axes[i].rated_effort;
    axes_[i].ferror_min = config_.axes[i].ferror_min;
    axes_[i].ferror_k_s = config_.axes[i].ferror_k_s;
    if (axes_[i].node <= kMaxNodeId) axis_of_node_[axes_[i].node] = static_cast<std::int8_t>(i);
  }
}

std::string CanAxisPort::node_label(std::size_t axis) const {
  return "node " + std::to_string(config_.axes[axis].node_id) + " (" + config_.axes[axis].name + ")";
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

  // The master's heartbeat watched by the drive (optional object: used when present, noted when absent).
  if (config_.master_node_id != 0) {
    const std::uint32_t v = (static_cast<std::uint32_t>(config_.master_node_id) << 16) |
                            static_cast<std::uint32_t>(std::lround(config_.master_consumer_s * 1e3));
    if (Status s = sdo.write(node, kConsumerHeartbeat, 1, v, 4); !s) {
      if (sdo.last_abort() != sdo_abort::kNoObject && sdo.last_abort() != sdo_abort::kNoSubIndex) return fail(s);
      notes_.push_back(who + "0x1016 (consumer heartbeat time) absent: the drive will not stop by itself if the "
                             "master dies");
    } else {
      axes_[axis].has_consumer = true;
    }
  }

  if (Status s = configure_pdos(axis, sdo); !s) return s;

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

Status CanAxisPort::configure_pdos(std::size_t axis, SdoClient& sdo) {
  const std::uint8_t node = axes_[axis].node;
  const std::string who = node_label(axis) + ": ";
  const auto fail = [&](const Status& s) { return Status::error(who + s.message()); };
  // A module with a fixed mapping refuses writes with read-only (0x06010002) or unsupported access.
  const auto fixed_code = [&] {
    return sdo.last_abort() == sdo_abort::kReadOnly || sdo.last_abort() == sdo_abort::kUnsupportedAccess;
  };
  const auto read_map = [&](std::uint16_t map, std::array<std::uint32_t, 8>& e) -> Result<std::uint32_t> {
    Result<std::uint32_t> n = sdo.read(node, map, 0);
    if (!n) return n;
    if (n.value() > 8) return Status::error(describe_object(map, 0) + " = " + std::to_string(n.value()) + " (> 8)");
    for (std::uint32_t k = 0; k < n.value(); ++k) {
      Result<std::uint32_t> v = sdo.read(node, map, static_cast<std::uint8_t>(k + 1));
      if (!v) return v.status();
      e[k] = v.value();
    }
    return n;
  };
  // PDO mapping (CiA 301 re-map procedure): invalidate, clear count, write entries, set count, set
  // transmission type, validate. When the drive's mapping is fixed, read it back and accept it only if it
  // is exactly the layout the RT codec packs (pdo.hpp); otherwise refuse, naming what is missing.
  struct PdoPlan {
    std::uint16_t comm;
    std::uint16_t map;
    std::uint32_t cob_id;
    const PdoMapEntry* entries;
    std::uint8_t n_entries;
    std::uint8_t transmission_type;
    bool optional;  // used when the drive has it, noted when absent (TPDO2: velocity and torque)
  };
  const PdoPlan plans[] = {
      {od::kRpdoComm, od::kRpdoMap, cob::rpdo(1, node), kRpdo1Mapping.data(), 2, 1, false},
      {od::kTpdoComm, od::kTpdoMap, cob::tpdo(1, node), kTpdo1Mapping.data(), 2, 1, false},
      {static_cast<std::uint16_t>(od::kTpdoComm + 1), static_cast<std::uint16_t>(od::kTpdoMap + 1),
       cob::tpdo(2, node), config_.tpdo2 ? kTpdo2Mapping.data() : nullptr,
       static_cast<std::uint8_t>(config_.tpdo2 ? 2 : 0), config_.tpdo2_every_n_sync, true},
      {static_cast<std::uint16_t>(od::kTpdoComm + 2), 0, cob::tpdo(3, node), nullptr, 0, 0, true},
      {static_cast<std::uint16_t>(od::kTpdoComm + 3), 0, cob::tpdo(4, node), nullptr, 0, 0, true},
  };
  for (const PdoPlan& p : plans) {
    if (Status s = sdo.write(node, p.comm, 1, p.cob_id | od::kPdoInvalidBit, 4); !s) {
      if (sdo.last_abort() == sdo_abort::kNoObject && p.optional) {
        // Nothing to disable; a wanted optional PDO the drive lacks is reported.
        if (p.entries != nullptr) {
          notes_.push_back(who + describe_object(p.comm, 1) +
                           " absent: no velocity/torque PDO, velocity is derived from positions");
        }
        continue;
      }
      if (!fixed_code()) return fail(s);
      if (p.entries == nullptr) continue;  // cannot disable a fixed PDO: the master ignores its frames
    }
    if (p.entries == nullptr) continue;
    bool fixed = false;
    if (Status s = sdo.write(node, p.map, 0, 0, 1); !s) {
      if (!fixed_code()) return fail(s);
      fixed = true;
    }
    if (!fixed) {
      for (std::uint8_t k = 0; k < p.n_entries; ++k) {
        if (Status s = sdo.write(node, p.map, static_cast<std::uint8_t>(k + 1), encode_map_entry(p.entries[k]), 4);
            !s) {
          return fail(s);
        }
      }
      if (Status s = sdo.write(node, p.map, 0, p.n_entries, 1); !s) return fail(s);
    } else {
      std::array<std::uint32_t, 8> e{};
      Result<std::uint32_t> n = read_map(p.map, e);
      if (!n) return fail(n.status());
      bool same = n.value() == p.n_entries;
      for (std::uint8_t k = 0; same && k < p.n_entries; ++k) same = e[k] == encode_map_entry(p.entries[k]);
      if (!same) {
        std::string missing;
        for (std::uint8_t k = 0; k < p.n_entries; ++k) {
          char buf[48];
          std::snprintf(buf, sizeof(buf), "%s0x%04X (%s, %u bits) at entry %u", missing.empty() ? "" : ", ",
                        p.entries[k].index, object_name(p.entries[k].index), p.entries[k].bits, k + 1U);
          if (k >= n.value() || e[k] != encode_map_entry(p.entries[k])) missing += buf;
        }
        if (p.optional) {
          notes_.push_back(who + describe_object(p.map, 0) + " is fixed and lacks " + missing +
                           ": velocity is derived from positions");
          continue;
        }
        return Status::error(who + describe_object(p.map, 0) + " is read-only and does not carry what the "
                                   "master needs: missing " + missing);
      }
      notes_.push_back(who + describe_object(p.map, 0) + " is fixed (read-only); read back and accepted");
    }
    if (Status s = sdo.write(node, p.comm, 2, p.transmission_type, 1); !s) {
      if (!fixed_code()) return fail(s);
      Result<std::uint32_t> t = sdo.read(node, p.comm, 2);
      if (!t) return fail(t.status());
      if (t.value() < 1 || t.value() > 240) {
        return Status::error(who + describe_object(p.comm, 2) + " = " + std::to_string(t.value()) +
                             " cannot be changed and is not synchronous (1..240)");
      }
    }
    if (Status s = sdo.write(node, p.comm, 1, p.cob_id, 4); !s) {
      if (!fixed_code()) return fail(s);
      Result<std::uint32_t> c = sdo.read(node, p.comm, 1);
      if (!c) return fail(c.status());
      if ((c.value() & od::kPdoInvalidBit) != 0 || (c.value() & 0x7FF) != p.cob_id) {
        return Status::error(who + describe_object(p.comm, 1) + " cannot be set to the pre-defined COB-ID");
      }
    }
    if (p.comm == od::kTpdoComm + 1) axes_[axis].has_tpdo2 = true;
  }
  return Status::ok();
}

BusLoad planned_bus_load(const CanAxisPortConfig& c) {
  const auto n = static_cast<std::uint32_t>(c.axes.size());
  std::vector<FrameGroup> frames{{0, 1}, {kRpdo1Bytes, n}, {kTpdo1Bytes, n}};
  if (c.tpdo2) frames.push_back({kTpdo2Bytes, n});
  frames.insert(frames.end(), c.other_frames_per_cycle.begin(), c.other_frames_per_cycle.end());
  // The master heartbeat (1 byte) counted as if it were sent every cycle: the worst cycle holds it.
  if (c.master_node_id != 0) frames.push_back({1, 1});
  return compute_bus_load(frames, c.bitrate_bps, c.cycle_period_s);
}

Status CanAxisPort::configure(CanBus& bus, ConfigureClock& clock) {
  reset_runtime();
  bus_ = nullptr;
  if (Status s = validate(config_); !s) return Status::error("CAN axis configuration: " + s.message());

  bus_load_ = planned_bus_load(config_);
  if (Status s = check_bus_load(bus_load_, config_.bus_load_budget); !s) return s;

  consumer_ticks_ = ceil_ticks(config_.heartbeat_consumer_s, config_.cycle_period_s);
  state_timeout_ticks_ = ceil_ticks(config_.state_timeout_s, config_.cycle_period_s);

  // What the nodes said while we were busy with something else.
  std::array<bool, hal::kMaxAxes> booted{};
  std::array<bool, hal::kMaxAxes> operational{};
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
  // Wait until `done` holds for every axis, each within its own window (per-node setting, else the
  // port-wide one), or name the first axis that did not make it.
  const auto wait_all = [&](std::array<bool, hal::kMaxAxes>& done, std::array<double, hal::kMaxAxes> timeout_s,
                            const char* what, const char* hint) -> Status {
    const std::int64_t start = clock.now_us();
    for (;;) {
      drain();
      if (bus_off_) return Status::error("CAN bus-off while waiting for " + std::string(what));
      bool all = true;
      for (std::size_t i = 0; i < n_axes_; ++i) {
        all = all && done[i];
        if (!done[i] && clock.now_us() - start >= static_cast<std::int64_t>(timeout_s[i] * 1e6)) {
          return Status::error(node_label(i) + ": no " + what + fmt(" within %.3g s", timeout_s[i]) + hint);
        }
      }
      if (all) return Status::ok();
      clock.idle();
    }
  };
  std::array<double, hal::kMaxAxes> boot_window{}, op_window{};
  for (std::size_t i = 0; i < n_axes_; ++i) {
    const CanAxisConfig& a = config_.axes[i];
    boot_window[i] = a.boot_timeout_s > 0.0 ? a.boot_timeout_s : config_.boot_timeout_s;
    const double op = config_.operational_timeout_s;
    op_window[i] = a.operational_timeout_s > 0.0 ? a.operational_timeout_s : op;
  }

  drain();  // stale frames from before the reset mean nothing
  booted.fill(false);
  for (std::size_t i = 0; i < n_axes_; ++i) {
    if (Status s = send(make_nmt(NmtCommand::kResetNode, axes_[i].node), node_label(i) + ": NMT reset-node");
        !s) {
      return s;
    }
  }
  if (Status s = wait_all(booted, boot_window, "boot-up after NMT reset-node",
                          " (is the drive powered, on this bus, with this node id?)");
      !s) {
    return s;
  }

  SdoClient sdo(bus, clock, static_cast<std::int64_t>(config_.sdo_timeout_s * 1e6), note);
  for (std::size_t i = 0; i < n_axes_; ++i) {
    if (Status s = configure_node(i, sdo); !s) return s;
    if (bus_off_) return Status::error(node_label(i) + ": CAN bus-off during configuration");
  }

  operational.fill(false);
  for (std::size_t i = 0; i < n_axes_; ++i) {
    if (Status s = send(make_nmt(NmtCommand::kStart, axes_[i].node), node_label(i) + ": NMT start"); !s) {
      return s;
    }
  }
  if (Status s = wait_all(operational, op_window, "operational heartbeat after NMT start",
                          " (heartbeat producer time written to 0x1017 not honoured?)");
      !s) {
    return s;
  }

  master_hb_ticks_ = config_.master_node_id == 0
                        ? 0
                        : std::max<std::uint32_t>(1, static_cast<std::uint32_t>(std::floor(
                                                         config_.master_heartbeat_s / config_.cycle_period_s + 1e-9)));
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
    const CanErrorInfo e = decode_error_frame(f);
    if (e.bus_off) {
      bus_off_ = true;
      restarted_ = false;
    }
    if (e.restarted && bus_off_) restarted_ = true;
    return;
  }
  const CobDecoded cob_fn = decode_cob_id(f.id);
  const std::int8_t ax = cob_fn.node <= kMaxNodeId ? axis_of_node_[cob_fn.node] : std::int8_t{-1};
  if (ax < 0) {
    // Any node's EMCY with a non-zero code stops every axis (error reset 0x0000 clears nothing here:
    // recovery is the operator's acknowledgement).
    if (cob_fn.function == CobFunction::kEmcy && cob_fn.node != 0) {
      if (const auto e = parse_emcy(f); e && e->code != 0 && foreign_emcy_code_ == 0) foreign_emcy_code_ = e->code;
    }
    for (std::size_t k = 0; k < n_listeners_; ++k) {
      if (listeners_[k]->node_id() == cob_fn.node) listeners_[k]->on_frame(now, f);
    }
    return;  // other nodes' traffic, SYNC/NMT echoes of other masters
  }
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
      // Following error against the target commanded before this feedback (LinuxCNC's velocity-scaled rule).
      if (a.ferror_min > 0.0 && a.cmd_valid && a.state == DriveState::kOperationEnabled) {
        const double err = std::abs(a.last_cmd_si - pos);
        if (err > a.ferror_high_water) a.ferror_high_water = err;
        if (err > std::max(a.ferror_min, a.ferror_k_s * std::abs(a.cmd_velocity))) a.ferror_fault = true;
      }
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
      if (hb->state == NmtState::kBootUp) a.booted = true;
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
      // A non-zero code latches (even while the statusword still says Operation Enabled) until the
      // operator acknowledges; the drive's 0x0000 (error reset) after that acknowledgement clears it.
      if (e->code != 0) {
        a.emcy_code = e->code;
        a.acknowledged = false;
      } else if (a.acknowledged) {
        a.emcy_code = 0;
      }
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
    for (AxisRuntime& a : live()) {
      // The consumer starts counting at the first tick; heartbeats during bring-up carry no tick.
      if (a.last_heartbeat == hal::kNeverTick) a.last_heartbeat = now;
      if (a.link_fault == 0 && now - a.last_heartbeat > static_cast<hal::Tick>(consumer_ticks_)) {
        a.link_fault = fault_code::kHeartbeatLost;
      }
    }
    for (std::size_t k = 0; k < n_listeners_; ++k) listeners_[k]->supervise(now);
  }
  fill_feedback(now, axes, link);
}

hal::LinkRecovery CanAxisPort::recovery(hal::Tick now, std::uint8_t& silent) const {
  using R = hal::LinkRecovery;
  if (bus_off_ && !restarted_) return R::kBusOff;
  const auto heard = [&](const AxisRuntime& a) {
    return a.booted || (a.last_heartbeat != hal::kNeverTick && now - a.last_heartbeat <= static_cast<hal::Tick>(consumer_ticks_));
  };
  bool faulted = bus_off_ || !configured_ || foreign_emcy_code_ != 0;
  for (const AxisRuntime& a : live()) {
    if (a.link_fault == 0) continue;
    faulted = true;
    if (!heard(a)) {
      silent = a.node;
      return R::kNodeSilent;
    }
  }
  for (std::size_t k = 0; k < n_listeners_; ++k) {
    if (listeners_[k]->link_fault_code() == 0) continue;
    faulted = true;
    if (!listeners_[k]->heard_again(now)) {
      silent = listeners_[k]->node_id();
      return R::kNodeSilent;
    }
  }
  return faulted ? R::kReady : R::kHealthy;
}

void CanAxisPort::fill_feedback(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) const {
  link.link_fault = !configured_ || bus_off_;
  link.link_fault_code = link.link_fault ? fault_code::kCommunication : fault_code::kNone;
  link.link_fault_kind = bus_off_ ? hal::FaultKind::kBusOff
                                  : link.link_fault ? hal::FaultKind::kCommunication : hal::FaultKind::kNone;
  for (std::size_t i = 0; i < n_axes_; ++i) {
    const AxisRuntime& a = axes_[i];
    hal::AxisFeedback& fb = axes[i];
    fb.state = a.state;
    fb.position = counts_to_si(a.position.value(), a.counts_per_unit);
    fb.velocity = a.velocity;
    fb.effort = a.effort;
    fb.refreshed = a.refreshed;
    fb.following_error =
        a.state == DriveState::kOperationEnabled && (a.statusword & statusword::kCspFollowingError) != 0;
    const bool drive_fault = a.state == DriveState::kFault || a.state == DriveState::kFaultReactionActive ||
                             a.emcy_code != 0 || a.ferror_fault;
    fb.fault = !configured_ || a.link_fault != 0 || drive_fault || a.tracker.timed_out || bus_off_;
    const bool in_fault_state = a.state == DriveState::kFault || a.state == DriveState::kFaultReactionActive;
    if (a.link_fault != 0) {
      fb.fault_code = a.link_fault;
      fb.fault_kind = hal::FaultKind::kNodeLost;
    } else if (bus_off_ || !configured_) {
      fb.fault_code = fault_code::kCommunication;
      fb.fault_kind = bus_off_ ? hal::FaultKind::kBusOff : hal::FaultKind::kCommunication;
    } else if (a.emcy_code != 0) {
      fb.fault_code = a.emcy_code;
      fb.fault_kind = in_fault_state ? hal::FaultKind::kDrive : hal::FaultKind::kEmcy;
    } else if (a.ferror_fault) {
      fb.fault_code = fault_code::kFollowingError;
      fb.fault_kind = hal::FaultKind::kDrive;
    } else if (a.tracker.timed_out) {
      fb.fault_code = fault_code::kStateTimeout;
      fb.fault_kind = hal::FaultKind::kDrive;
    } else {
      fb.fault_code = fault_code::kNone;
      fb.fault_kind = in_fault_state ? hal::FaultKind::kDrive : hal::FaultKind::kNone;
    }
    if (a.link_fault != 0 && !link.link_fault) {
      link.link_fault = true;
      link.link_fault_code = a.link_fault;
      link.link_fault_kind = hal::FaultKind::kNodeLost;
    }
  }
  // Other nodes: the I/O node's own faults, then an EMCY from any node that is not an axis.
  for (std::size_t k = 0; k < n_listeners_ && !link.link_fault; ++k) {
    if (const std::uint16_t c = listeners_[k]->link_fault_code(); c != 0) {
      link.link_fault = true;
      link.link_fault_code = c;
      link.link_fault_kind = link_fault_kind(c);
    }
  }
  if (!link.link_fault && foreign_emcy_code_ != 0) {
    link.link_fault = true;
    link.link_fault_code = foreign_emcy_code_;
    link.link_fault_kind = hal::FaultKind::kEmcy;
  }
  link.tx_dropped = tx_dropped_;
  link.rx_errors = rx_errors_;
  link.silent_node = 0;
  link.recovery = recovery(now, link.silent_node);
}

bool CanAxisPort::any_fault() const {
  if (bus_off_ || foreign_emcy_code_ != 0) return true;
  for (const AxisRuntime& a : live()) {
    if (a.link_fault != 0 || a.emcy_code != 0 || a.ferror_fault || a.state == DriveState::kFault ||
        a.state == DriveState::kFaultReactionActive) {
      return true;
    }
  }
  for (std::size_t k = 0; k < n_listeners_; ++k) {
    if (listeners_[k]->link_fault_code() != 0) return true;
  }
  return false;
}

// The operator acknowledged (the sequencer requests a fault reset): latches whose cause the master
// itself decided are cleared; a drive still in Fault gets its reset edge through the CiA 402 table.
void CanAxisPort::acknowledge() {
  foreign_emcy_code_ = 0;
  for (AxisRuntime& a : live()) {
    a.ferror_fault = false;
    a.acknowledged = true;
    if (a.state != DriveState::kFault && a.state != DriveState::kFaultReactionActive) a.emcy_code = 0;
  }
  for (std::size_t k = 0; k < n_listeners_; ++k) listeners_[k]->acknowledge();
}

void CanAxisPort::write_axes(hal::Tick now, const hal::AxisCommands& commands) {
  if (!configured_) return;
  bool reset = false;
  for (std::size_t i = 0; i < n_axes_; ++i) reset = reset || commands[i].request == AxisRequest::kFaultReset;
  if (reset) acknowledge();
  // Any fault anywhere on the bus (EMCY from any node, a lost node, following error) stops every axis in
  // this very tick, whatever the sequencer asked and whatever the drives' statuswords say.
  const bool stop_all = any_fault();
  count_send(bus_->send(make_sync()));
  if (master_hb_ticks_ != 0 && now >= next_master_hb_) {
    count_send(bus_->send(make_heartbeat(config_.master_node_id, NmtState::kOperational)));
    next_master_hb_ = now + static_cast<hal::Tick>(master_hb_ticks_);
  }
  for (std::size_t i = 0; i < n_axes_; ++i) {
    AxisRuntime& a = axes_[i];
    // A drive we cannot supervise (lost, rebooted, bus-off) gets quick stop, never an enable command.
    const bool lost = a.link_fault != 0 || bus_off_;
    const AxisRequest wanted_request = commands[i].request;
    const AxisRequest request =
        lost || (stop_all && wanted_request != AxisRequest::kFaultReset && wanted_request != AxisRequest::kDisable)
            ? AxisRequest::kQuickStop
            : wanted_request;
    const Cia402Step step = cia402_step(a.state, request, a.tracker, state_timeout_ticks_);
    a.tracker = step.next;

    // Outside Operation Enabled the target follows the actual position, so enabling never jumps.
    std::int64_t target = a.position.value();
    const double wanted = commands[i].target_position;
    if (a.state == DriveState::kOperationEnabled && step.controlword == controlword::kEnableOperation &&
        std::isfinite(wanted)) {
      target = si_to_counts(wanted, a.counts_per_unit);
    }
    const double cmd_si = counts_to_si(target, a.counts_per_unit);
    a.cmd_velocity = a.cmd_valid ? (cmd_si - a.last_cmd_si) / config_.cycle_period_s : 0.0;
    a.last_cmd_si = cmd_si;
    a.cmd_valid = true;
    a.last_target_counts = target;
    count_send(bus_->send(pack_rpdo1(a.node, Rpdo1{step.controlword, wire_counts(target)})));
  }
}

}  // namespace loom::drivers

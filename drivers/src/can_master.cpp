// The bus owner (see can_master.hpp): one NMT bring-up for every node of a bus, and the per-tick drain,
// dispatch, SYNC and master heartbeat. Every fault found in the RT half is latched, never thrown.
#include "loom/drivers/can_master.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "loom/drivers/can_error_frame.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/eds_boot.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/drivers/node_description.hpp"
#include "loom/drivers/sdo_client.hpp"

namespace loom::drivers {

// ---------------------------------------------------------------------------------------------------
// CanNode
// ---------------------------------------------------------------------------------------------------
void CanNode::on_frame(hal::Tick now, const CanFrame& f) noexcept {
  if (!supervisor_.armed() || f.is_error()) return;
  const CobDecoded d = decode_cob_id(f.id);
  if (d.node != node_id()) return;
  switch (d.function) {
    case CobFunction::kHeartbeat:
      if (!supervisor_.on_heartbeat(now, f)) ++rx_errors_;
      return;
    case CobFunction::kEmcy:
      if (!supervisor_.on_emcy(f)) ++rx_errors_;
      return;
    default:
      on_profile_frame(now, f);
      return;
  }
}

// ---------------------------------------------------------------------------------------------------
// Node table (configure-time)
// ---------------------------------------------------------------------------------------------------
void CanMaster::clear_nodes() {
  nodes_.fill(nullptr);
  n_nodes_ = 0;
  index_of_node_ = make_empty_index();
}

bool CanMaster::add(CanNode& node) {
  const std::uint8_t id = node.node_id();
  if (n_nodes_ == nodes_.size() || id > kMaxNodeId || index_of_node_[id] >= 0) return false;
  index_of_node_[id] = static_cast<std::int8_t>(n_nodes_);
  nodes_[n_nodes_++] = &node;
  return true;
}

std::uint32_t CanMaster::consumer_ticks(const CanNode& node) const {
  return static_cast<std::uint32_t>(
      std::ceil(node.timing().heartbeat_consumer_s / config_.cycle_period_s - 1e-9));
}

// ---------------------------------------------------------------------------------------------------
// Bring-up (configure-time only)
// ---------------------------------------------------------------------------------------------------
Status CanMaster::bring_up(CanBus& bus, ConfigureClock& clock) {
  configured_ = false;
  bus_ = nullptr;
  bus_off_ = false;
  restarted_ = false;
  foreign_emcy_code_ = 0;
  next_master_hb_ = 0;
  for (std::size_t i = 0; i < n_nodes_; ++i) {
    nodes_[i]->supervisor_.disarm();
    nodes_[i]->bring_up_started();
  }

  // What the nodes said while we were busy with something else (SDO replies are the SDO client's).
  std::array<bool, kMaxNodes> booted{};
  std::array<bool, kMaxNodes> operational{};
  bool bus_off = false;
  const auto note = [&](const CanFrame& f) {
    if (f.is_error()) {
      bus_off = bus_off || decode_error_frame(f).bus_off;
      return;
    }
    if (auto hb = parse_heartbeat(f)) {
      const std::int8_t k = index_of_node_[hb->node];
      if (k < 0) return;
      if (hb->state == NmtState::kBootUp) booted[static_cast<std::size_t>(k)] = true;
      operational[static_cast<std::size_t>(k)] = hb->state == NmtState::kOperational;
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
  // Every node within its own window (or the master's default), else the first one that did not make it.
  const auto wait_all = [&](const std::array<bool, kMaxNodes>& done, bool boot, const char* what,
                            const char* hint) -> Status {
    const std::int64_t start = clock.now_us();
    for (;;) {
      drain();
      if (bus_off) return Status::error("CAN bus-off while waiting for " + std::string(what));
      bool all = true;
      for (std::size_t i = 0; i < n_nodes_; ++i) {
        all = all && done[i];
        const NodeTiming t = nodes_[i]->timing();
        const double window =
            boot ? (t.boot_timeout_s > 0.0 ? t.boot_timeout_s : config_.boot_timeout_s)
                 : (t.operational_timeout_s > 0.0 ? t.operational_timeout_s : config_.operational_timeout_s);
        if (!done[i] && clock.now_us() - start >= static_cast<std::int64_t>(window * 1e6)) {
          char buf[48];
          std::snprintf(buf, sizeof(buf), " within %.3g s", window);
          return Status::error(nodes_[i]->label() + ": no " + what + buf + hint);
        }
      }
      if (all) return Status::ok();
      clock.idle();
    }
  };

  drain();  // stale frames from before the reset mean nothing
  booted.fill(false);
  for (std::size_t i = 0; i < n_nodes_; ++i) {
    if (Status s = send(make_nmt(NmtCommand::kResetNode, nodes_[i]->node_id()),
                        nodes_[i]->label() + ": NMT reset-node");
        !s) {
      return s;
    }
  }
  if (Status s = wait_all(booted, true, "boot-up after NMT reset-node",
                          " (is it powered, on this bus, with this node id?)");
      !s) {
    return s;
  }

  SdoClient sdo(bus, clock, static_cast<std::int64_t>(config_.sdo_timeout_s * 1e6), note);
  for (std::size_t i = 0; i < n_nodes_; ++i) {
    // A node with an EDS: the right node (0x1018), then the description's configuration, only what differs.
    const NodeDescription* d = nodes_[i]->description();
    const int downloads_before = sdo.downloads();
    if (d != nullptr) {
      Result<eds::Identity> id = read_identity(sdo, nodes_[i]->node_id());
      if (!id) return Status::error(nodes_[i]->label() + ": 0x1018 identity: " + id.error());
      if (Status s = eds::check_identity(d->eds, nodes_[i]->label(), id.value()); !s) return s;
      Result<ApplyReport> applied = apply_configuration(sdo, nodes_[i]->node_id(), d->writes, false);
      if (!applied) return Status::error(nodes_[i]->label() + ": " + applied.error());
    }
    sdo.set_skip_unchanged(d != nullptr);
    const Status profile = nodes_[i]->configure_profile(sdo);
    sdo.set_skip_unchanged(false);
    if (Status s = profile; !s) return s;
    if (bus_off) return Status::error(nodes_[i]->label() + ": CAN bus-off during configuration");
    // Stored (0x1010) on the builder's request, after all of the node's configuration writes — the
    // description's and the profile's — and only when one of them changed something.
    if (d != nullptr && d->store && can_store(d->eds) && sdo.downloads() > downloads_before) {
      if (Status s = store_parameters(sdo, nodes_[i]->node_id(), nodes_[i]->label()); !s) return s;
    }
  }

  operational.fill(false);
  for (std::size_t i = 0; i < n_nodes_; ++i) {
    if (Status s =
            send(make_nmt(NmtCommand::kStart, nodes_[i]->node_id()), nodes_[i]->label() + ": NMT start");
        !s) {
      return s;
    }
  }
  if (Status s = wait_all(operational, false, "operational heartbeat after NMT start",
                          " (heartbeat producer time written to 0x1017 not honoured?)");
      !s) {
    return s;
  }

  master_hb_ticks_ =
      config_.master_node_id == 0
          ? 0
          : std::max<std::uint32_t>(1, static_cast<std::uint32_t>(std::floor(
                                           config_.master_heartbeat_s / config_.cycle_period_s + 1e-9)));
  bus_ = &bus;
  for (std::size_t i = 0; i < n_nodes_; ++i) {
    nodes_[i]->supervisor_.arm(consumer_ticks(*nodes_[i]));
    nodes_[i]->brought_up(bus);
  }
  configured_ = true;
  return Status::ok();
}

// ---------------------------------------------------------------------------------------------------
// Per tick (RT-safe)
// ---------------------------------------------------------------------------------------------------
void CanMaster::handle_error_frame(const CanFrame& f) noexcept {
  ++rx_errors_;
  const CanErrorInfo e = decode_error_frame(f);
  if (e.bus_off) {
    bus_off_ = true;
    restarted_ = false;
  }
  if (e.restarted && bus_off_) restarted_ = true;
}

void CanMaster::poll(hal::Tick now) noexcept {
  if (!configured_) return;
  CanFrame f;
  for (int i = 0; i < kMaxFramesPerPoll && bus_->receive(f); ++i) {
    if (f.is_error()) {
      handle_error_frame(f);
      continue;
    }
    const CobDecoded d = decode_cob_id(f.id);
    const std::int8_t k = d.node <= kMaxNodeId ? index_of_node_[d.node] : std::int8_t{-1};
    if (k >= 0) {
      nodes_[static_cast<std::size_t>(k)]->on_frame(now, f);
    } else if (d.function == CobFunction::kEmcy && d.node != 0) {
      // An EMCY from a node nobody owns stops every axis too (recovery is the operator's acknowledgement).
      if (const auto e = parse_emcy(f); e && e->code != 0 && foreign_emcy_code_ == 0)
        foreign_emcy_code_ = e->code;
    }
    // Anything else: other nodes' traffic, SYNC/NMT echoes of other masters.
  }
  for (std::size_t i = 0; i < n_nodes_; ++i) nodes_[i]->supervise(now);
}

void CanMaster::send(const CanFrame& frame) noexcept {
  if (bus_ == nullptr || bus_->send(frame) != SendResult::kOk) ++tx_dropped_;
}

void CanMaster::start_cycle(hal::Tick now) noexcept {
  if (!configured_) return;
  send(make_sync());
  if (master_hb_ticks_ != 0 && now >= next_master_hb_) {
    send(make_heartbeat(config_.master_node_id, NmtState::kOperational));
    next_master_hb_ = now + static_cast<hal::Tick>(master_hb_ticks_);
  }
}

bool CanMaster::any_fault() const noexcept {
  if (bus_off_ || foreign_emcy_code_ != 0) return true;
  for (std::size_t i = 0; i < n_nodes_; ++i) {
    const CanNode& n = *nodes_[i];
    if (n.link_fault_code() != 0) return true;
    if (!n.reports_own_emcy() && n.supervisor().emcy_code() != 0) return true;
  }
  return false;
}

void CanMaster::report_link(hal::LinkStatus& link) const noexcept {
  link.tx_dropped += tx_dropped_;
  link.rx_errors += rx_errors_;
  if (link.link_fault) return;
  const auto set = [&](std::uint16_t code, hal::FaultKind kind) {
    link.link_fault = true;
    link.link_fault_code = code;
    link.link_fault_kind = kind;
  };
  if (!configured_ || bus_off_) {
    set(fault_code::kCommunication, bus_off_ ? hal::FaultKind::kBusOff : hal::FaultKind::kCommunication);
    return;
  }
  for (std::size_t i = 0; i < n_nodes_; ++i) {
    if (const std::uint16_t c = nodes_[i]->link_fault_code(); c != 0) {
      set(c, link_fault_kind(c));
      return;
    }
  }
  for (std::size_t i = 0; i < n_nodes_; ++i) {
    const CanNode& n = *nodes_[i];
    if (!n.reports_own_emcy() && n.supervisor().emcy_code() != 0) {
      set(n.supervisor().emcy_code(), hal::FaultKind::kEmcy);
      return;
    }
  }
  if (foreign_emcy_code_ != 0) set(foreign_emcy_code_, hal::FaultKind::kEmcy);
}

hal::LinkRecovery CanMaster::recovery(hal::Tick now, std::uint8_t& silent) const noexcept {
  using R = hal::LinkRecovery;
  if (bus_off_ && !restarted_) return R::kBusOff;
  bool faulted = bus_off_ || !configured_ || foreign_emcy_code_ != 0;
  for (std::size_t i = 0; i < n_nodes_; ++i) {
    const CanNode& n = *nodes_[i];
    if (n.link_fault_code() == 0) continue;
    faulted = true;
    if (!n.heard_again(now)) {
      silent = n.node_id();
      return R::kNodeSilent;
    }
  }
  return faulted ? R::kReady : R::kHealthy;
}

void CanMaster::acknowledge() noexcept {
  foreign_emcy_code_ = 0;
  for (std::size_t i = 0; i < n_nodes_; ++i) nodes_[i]->acknowledge();
}

}  // namespace loom::drivers

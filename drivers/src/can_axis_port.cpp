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

std::uint32_t ceil_ticks(double seconds, double period_s) {
  return static_cast<std::uint32_t>(std::ceil(seconds / period_s - 1e-9));
}

// How bad a recovery state is, for reporting the worst over several buses.
int rank(hal::LinkRecovery r) {
  switch (r) {
    case hal::LinkRecovery::kHealthy:
      return 0;
    case hal::LinkRecovery::kReady:
      return 1;
    case hal::LinkRecovery::kNodeSilent:
      return 2;
    case hal::LinkRecovery::kBusOff:
      return 3;
  }
  return 0;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// The port: one master per bus, one CiA 402 profile per axis
// ---------------------------------------------------------------------------------------------------
CanAxisPort::CanAxisPort(CanAxisPortConfig config) {
  d_.config = std::move(config);
  d_.n_axes = std::min(d_.config.axes.size(), hal::kMaxAxes);
  d_.n_buses = std::min(drivers::bus_count(d_.config), kMaxBuses);
  const CanMasterConfig mc{d_.config.cycle_period_s, d_.config.sdo_timeout_s,
                           d_.config.boot_timeout_s, d_.config.operational_timeout_s,
                           d_.config.master_node_id, d_.config.master_heartbeat_s};
  for (CanMaster& m : d_.masters) m = CanMaster(mc);
  for (std::size_t i = 0; i < d_.n_axes; ++i) d_.axes[i].setup(d_.config.axes[i], d_.config);
  relink();
}

CanAxisPort::CanAxisPort(const CanAxisPort& other) : hal::AxisPort(other), d_(other.d_) {
  relink();
}

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
    return Status::error("the axes use " + std::to_string(d_.n_buses) +
                         " CAN bus(es) (highest axes.<name>.bus = " + std::to_string(d_.n_buses - 1) +
                         ") but " + std::to_string(buses.size()) + " interface(s) were given");
  }
  for (std::size_t b = 0; b < d_.n_buses; ++b) {
    d_.bus_loads[b] = planned_bus_load(d_.config, b);
    if (Status s = check_bus_load(d_.bus_loads[b], d_.config.bus_load_budget); !s) {
      return d_.n_buses == 1 ? s : Status::error("bus " + std::to_string(b) + ": " + s.message());
    }
  }
  for (std::size_t k = 0; k < d_.n_attached; ++k) {
    if (d_.attached[k].bus >= d_.n_buses) {
      return Status::error(d_.attached[k].node->label() + " is attached to bus " +
                           std::to_string(d_.attached[k].bus) + " but the port has " +
                           std::to_string(d_.n_buses) +
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
void CanAxisPort::read_axes(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) noexcept {
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
    d_.axes[i].fill_feedback(now, axes[i], m.bus_off(), d_.configured && m.configured());
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
  d_.link_edge.raise(link);
}

bool CanAxisPort::any_fault() const noexcept {
  for (std::size_t b = 0; b < d_.n_buses; ++b) {
    if (d_.masters[b].any_fault()) return true;
  }
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    if (d_.axes[i].faulted()) return true;
  }
  return false;
}

void CanAxisPort::write_axes(hal::Tick now, const hal::AxisCommands& commands) noexcept {
  if (!d_.configured) return;
  bool reset = false;
  for (std::size_t i = 0; i < d_.n_axes; ++i)
    reset = reset || commands[i].request == AxisRequest::kFaultReset;
  if (reset) {
    for (std::size_t b = 0; b < d_.n_buses; ++b) d_.masters[b].acknowledge();
  }
  // Any fault anywhere (EMCY from any node, a lost node, following error, a bus-off on any bus) stops
  // every axis in this very tick, whatever the sequencer asked and whatever the drives' statuswords say.
  const bool stop_all = any_fault();
  for (std::size_t b = 0; b < d_.n_buses; ++b) d_.masters[b].start_cycle(now);
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    CanMaster& m = d_.masters[d_.axes[i].bus()];
    CanFrame rpdo1{};
    // (A profile-position axis' RPDO1 goes out only when it changed.)
    if (d_.axes[i].command(now, commands[i], stop_all, m.bus_off(), d_.state_timeout_ticks, rpdo1))
      m.send(rpdo1);
  }
}

}  // namespace loom::drivers

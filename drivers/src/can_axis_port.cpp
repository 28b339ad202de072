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

}  // namespace

// ---------------------------------------------------------------------------------------------------
// The port: one CiA 402 profile per axis on the port's network (one master per bus)
// ---------------------------------------------------------------------------------------------------
CanAxisPort::CanAxisPort(CanAxisPortConfig config) {
  d_.config = std::move(config);
  d_.n_axes = std::min(d_.config.axes.size(), hal::kMaxAxes);
  const CanMasterConfig mc{d_.config.cycle_period_s, d_.config.sdo_timeout_s,
                           d_.config.boot_timeout_s, d_.config.operational_timeout_s,
                           d_.config.master_node_id, d_.config.master_heartbeat_s};
  d_.network = CanNetwork(mc, drivers::bus_count(d_.config));
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
  d_.network.clear_nodes();
  for (std::size_t i = 0; i < d_.n_axes; ++i) d_.network.add(d_.axes[i], d_.axes[i].bus());
  for (std::size_t k = 0; k < d_.n_attached; ++k) d_.network.add(*d_.attached[k].node, d_.attached[k].bus);
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
  d_.network.unconfigure();
  d_.notes.clear();
  if (Status s = check(buses.size()); !s) return s;
  if (Status s = d_.network.configure(buses, clock); !s) return s;  // every bus, in order
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    d_.notes.insert(d_.notes.end(), d_.axes[i].notes().begin(), d_.axes[i].notes().end());
  }
  return Status::ok();
}

Status CanAxisPort::check(std::size_t interfaces) {
  const std::size_t n_buses = d_.network.bus_count();
  if (Status s = validate(d_.config); !s) return Status::error("CAN axis configuration: " + s.message());
  if (interfaces != n_buses) {
    return Status::error("the axes use " + std::to_string(n_buses) +
                         " CAN bus(es) (highest axes.<name>.bus = " + std::to_string(n_buses - 1) + ") but " +
                         std::to_string(interfaces) + " interface(s) were given");
  }
  for (std::size_t b = 0; b < n_buses; ++b) {
    d_.bus_loads[b] = planned_bus_load(d_.config, b);
    if (Status s = check_bus_load(d_.bus_loads[b], d_.config.bus_load_budget); !s) {
      return n_buses == 1 ? s : Status::error("bus " + std::to_string(b) + ": " + s.message());
    }
  }
  for (std::size_t k = 0; k < d_.n_attached; ++k) {
    if (d_.attached[k].bus >= n_buses) {
      return Status::error(d_.attached[k].node->label() + " is attached to bus " +
                           std::to_string(d_.attached[k].bus) + " but the port has " +
                           std::to_string(n_buses) +
                           " bus(es): its frames are not in other_frames_per_cycle");
    }
  }
  relink();
  std::size_t expected = d_.n_axes + d_.n_attached;
  expected -= d_.network.node_count();
  if (expected != 0) return Status::error("an attached node shares its node id with another node on its bus");
  d_.consumer_ticks = ceil_ticks(d_.config.heartbeat_consumer_s, d_.config.cycle_period_s);
  d_.state_timeout_ticks = ceil_ticks(d_.config.state_timeout_s, d_.config.cycle_period_s);
  return Status::ok();
}

// ---------------------------------------------------------------------------------------------------
// Per tick (RT-safe)
// ---------------------------------------------------------------------------------------------------
void CanAxisPort::read_axes(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) noexcept {
  d_.network.poll(now);
  d_.network.read_link(now, link);
  const bool configured = d_.network.configured();
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    const CanMaster& m = d_.network.master(d_.axes[i].bus());
    d_.axes[i].fill_feedback(now, axes[i], m.bus_off(), configured && m.configured());
    link.rx_errors += d_.axes[i].rx_errors();
  }
}

bool CanAxisPort::any_fault() const noexcept {
  if (d_.network.any_fault()) return true;
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    if (d_.axes[i].faulted()) return true;
  }
  return false;
}

void CanAxisPort::write_axes(hal::Tick now, const hal::AxisCommands& commands) noexcept {
  if (!d_.network.configured()) return;
  bool reset = false;
  for (std::size_t i = 0; i < d_.n_axes; ++i)
    reset = reset || commands[i].request == AxisRequest::kFaultReset;
  if (reset) d_.network.acknowledge();
  // Any fault anywhere (EMCY from any node, a lost node, following error, a bus-off on any bus) stops
  // every axis in this very tick, whatever the sequencer asked and whatever the drives' statuswords say.
  const bool stop_all = any_fault();
  d_.network.start_cycle(now);
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    CanMaster& m = d_.network.master(d_.axes[i].bus());
    CanFrame rpdo1{};
    // (A profile-position axis' RPDO1 goes out only when it changed.)
    if (d_.axes[i].command(now, commands[i], stop_all, m.bus_off(), d_.state_timeout_ticks, rpdo1))
      m.send(rpdo1);
  }
}

}  // namespace loom::drivers

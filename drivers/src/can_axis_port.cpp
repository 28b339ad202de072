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
// The port: one CiA 402 profile per axis, registered on the network (one master per bus)
// ---------------------------------------------------------------------------------------------------
CanMasterConfig can_master_config(const CanAxisPortConfig& config) {
  return CanMasterConfig{config.cycle_period_s,        config.sdo_timeout_s,  config.boot_timeout_s,
                         config.operational_timeout_s, config.master_node_id, config.master_heartbeat_s};
}

CanAxisPort::CanAxisPort(CanNetwork& network, CanAxisPortConfig config) : network_(&network) {
  d_.config = std::move(config);
  d_.n_axes = std::min(d_.config.axes.size(), hal::kMaxAxes);
  for (std::size_t i = 0; i < d_.n_axes; ++i) d_.axes[i].setup(d_.config.axes[i], d_.config);
  register_axes();
}

CanAxisPort::CanAxisPort(const CanAxisPort& configured, CanNetwork& network)
    : hal::AxisPort(configured), network_(&network), d_(configured.d_) {
  register_axes();
}

void CanAxisPort::register_axes() {
  d_.n_registered = 0;
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    if (network_->add(d_.axes[i], d_.axes[i].bus())) ++d_.n_registered;
  }
}

Status bring_up(CanNetwork& network, CanAxisPort& axes, std::span<CanBus* const> buses,
                ConfigureClock& clock) {
  network.unconfigure();  // a refused port leaves no network up (recovery: a fresh bring-up)
  if (Status s = axes.check(buses.size()); !s) return s;
  return network.configure(buses, clock);  // every bus, in order
}

Status bring_up(CanNetwork& network, CanAxisPort& axes, CanBus& bus, ConfigureClock& clock) {
  CanBus* const one[] = {&bus};
  return bring_up(network, axes, std::span<CanBus* const>(one), clock);
}

std::vector<std::string> CanAxisPort::notes() const {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < d_.n_axes; ++i)
    out.insert(out.end(), d_.axes[i].notes().begin(), d_.axes[i].notes().end());
  return out;
}

Status CanAxisPort::check(std::size_t interfaces) {
  const std::size_t n_buses = drivers::bus_count(d_.config);
  if (Status s = validate(d_.config); !s) return Status::error("CAN axis configuration: " + s.message());
  if (network_->bus_count() != n_buses) {
    return Status::error("the axes use " + std::to_string(n_buses) + " CAN bus(es) but their network has " +
                         std::to_string(network_->bus_count()));
  }
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
  if (d_.n_registered != d_.n_axes) {
    return Status::error(
        "an axis shares its node id with another node on its bus, or its bus is not one of "
        "the network's");
  }
  d_.consumer_ticks = ceil_ticks(d_.config.heartbeat_consumer_s, d_.config.cycle_period_s);
  d_.state_timeout_ticks = ceil_ticks(d_.config.state_timeout_s, d_.config.cycle_period_s);
  return Status::ok();
}

// ---------------------------------------------------------------------------------------------------
// Per tick (RT-safe)
// ---------------------------------------------------------------------------------------------------
void CanAxisPort::read_axes(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) noexcept {
  network_->read_link(now, link);
  const bool configured = network_->configured();
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    const CanMaster& m = network_->master(d_.axes[i].bus());
    d_.axes[i].fill_feedback(now, axes[i], m.bus_off(), configured && m.configured());
    link.rx_errors += d_.axes[i].rx_errors();
  }
}

bool CanAxisPort::any_fault() const noexcept {
  if (network_->any_fault()) return true;
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    if (d_.axes[i].faulted()) return true;
  }
  return false;
}

void CanAxisPort::write_axes(hal::Tick now, const hal::AxisCommands& commands) noexcept {
  if (!network_->configured()) return;
  bool reset = false;
  for (std::size_t i = 0; i < d_.n_axes; ++i)
    reset = reset || commands[i].request == AxisRequest::kFaultReset;
  if (reset) network_->acknowledge();
  // Any fault anywhere (EMCY from any node, a lost node, following error, a bus-off on any bus) stops
  // every axis in this very tick, whatever the sequencer asked and whatever the drives' statuswords say.
  const bool stop_all = any_fault();
  for (std::size_t i = 0; i < d_.n_axes; ++i) {
    CanMaster& m = network_->master(d_.axes[i].bus());
    CanFrame rpdo1{};
    // (A profile-position axis' RPDO1 goes out only when it changed.)
    if (d_.axes[i].command(now, commands[i], stop_all, m.bus_off(), d_.state_timeout_ticks, rpdo1))
      m.send(rpdo1);
  }
}

}  // namespace loom::drivers

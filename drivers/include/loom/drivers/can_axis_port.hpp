// The machine's servo axes (the core three and any added ones, on one or more CAN buses) as CiA 402
// drives in cyclic synchronous position mode behind hal::AxisPort. check() refuses what no bus could
// carry before the network brings the buses up by NMT and SDO (may block, with timeouts);
// read_axes()/write_axes() are the per-tick RT path: one RPDO per axis out, the TPDOs the network handed
// to the axes in, fixed arrays only.
#pragma once

#include <array>
#include <cstdint>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "loom/drivers/bus_load.hpp"
#include "loom/drivers/can_axis_config.hpp"
#include "loom/drivers/can_frame.hpp"
#include "loom/drivers/can_master.hpp"
#include "loom/drivers/can_network.hpp"
#include "loom/drivers/cia402_axis.hpp"
#include "loom/drivers/configure_clock.hpp"
#include "loom/drivers/position_scaling.hpp"
#include "loom/drivers/status.hpp"
#include "loom/hal/fault_events.hpp"
#include "loom/hal/hal.hpp"

namespace loom::drivers {

class SdoClient;

// The hal::AxisPort of the CAN servo axes: a view on a CanNetwork it does not own (can_network.hpp: one
// CanMaster per bus — drain, dispatch, SYNC, master heartbeat, bus-off, NMT bring-up of its nodes in one
// sequence — and the link status), with one Cia402Axis per axis registered on it. The network is polled
// and its cycle started once per tick by the HAL (can_hal.hpp) around the ports' reads and writes; the I/O
// modules are registered on the same network by whoever assembles the machine. A fault of any node on any
// bus stops every axis in the same tick.
class CanAxisPort final : public hal::AxisPort {
 public:
  // Configure-time only. Registers the axes of `config` on `network`, which must have bus_count(config)
  // buses (can_master_config(config) is its masters' settings) and outlive the port. An axis whose node id
  // is taken on its bus is not registered: check() refuses the port then.
  CanAxisPort(CanNetwork& network, CanAxisPortConfig config);
  // A copy of a configured port, registered on `network` (a copy of the original's network whose node
  // tables were cleared): the fuzz harness starts every input from one brought-up port.
  CanAxisPort(const CanAxisPort& configured, CanNetwork& network);
  CanAxisPort(const CanAxisPort&) = delete;
  CanAxisPort& operator=(const CanAxisPort&) = delete;

  // Configure-time only; before the network's bring-up (CanNetwork::configure), which it does not do. The
  // port's own checks, before any frame is sent: the configuration, `interfaces` == the buses the axes
  // use, each bus' load, every axis registered on the network; then the heartbeat-consumer and state
  // timeouts in ticks. The network then brings every bus up in one NMT sequence (can_master.hpp):
  // reset-node → every boot-up → per drive by SDO: 0x6502 has CSP, 0x6060 = 8 confirmed by 0x6061,
  // 0x1017, 0x60C2, PDO mapping (pdo.hpp), 0x6041 and 0x6064 to seed state and the first target; the other
  // nodes' own configuration → NMT start → an operational heartbeat from every node. Checking and bringing
  // up again (from the non-RT side, after the loop has stopped using the network, on fresh buses) is how a
  // lost node or a bus-off is recovered; read_axes() reports in LinkStatus::recovery whether that can work.
  Status check(std::size_t interfaces);

  // RT-safe. Every axis and the link (the network's, polled by the HAL this tick before the ports read),
  // with the fault events of this tick (each axis' fault_raised: Cia402Axis; the link's:
  // CanNetwork::read_link).
  void read_axes(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) noexcept override;
  // RT-safe. One RPDO1 per axis (after the network's SYNC, which the HAL sends before the ports write).
  void write_axes(hal::Tick now, const hal::AxisCommands& axes) noexcept override;

  // Diagnostics; RT-safe to read.
  bool configured() const noexcept { return network_->configured(); }
  // What the bring-up found optional and absent (0x1016, TPDO2) or accepted as read back; one line each.
  std::vector<std::string> notes() const;
  // Largest following error seen per axis since configure(), in SI units (telemetry high-water mark).
  double ferror_high_water(std::size_t slot) const noexcept { return d_.axes[slot].ferror_high_water(); }
  bool has_consumer(std::size_t slot) const noexcept { return d_.axes[slot].has_consumer(); }
  bool has_tpdo2(std::size_t slot) const noexcept { return d_.axes[slot].has_tpdo2(); }
  std::size_t axis_count() const noexcept { return d_.n_axes; }
  std::size_t bus_count() const noexcept { return network_->bus_count(); }
  const BusLoad& bus_load(std::size_t bus = 0) const noexcept { return d_.bus_loads[bus]; }
  const CanAxisPortConfig& config() const { return d_.config; }
  std::uint16_t last_controlword(std::size_t slot) const noexcept { return d_.axes[slot].last_controlword(); }
  std::int64_t last_target_counts(std::size_t slot) const noexcept {
    return d_.axes[slot].last_target_counts();
  }
  std::uint32_t heartbeat_consumer_ticks() const noexcept { return d_.consumer_ticks; }

 private:
  void register_axes();
  bool any_fault() const noexcept;

  struct Data {
    CanAxisPortConfig config;
    std::array<BusLoad, kMaxBuses> bus_loads{};
    std::uint32_t consumer_ticks = 0;
    std::uint32_t state_timeout_ticks = 0;
    std::array<Cia402Axis, hal::kMaxAxes> axes{};
    std::size_t n_axes = 0;
    std::size_t n_registered = 0;  // axes the network took (a taken node id leaves one out)
  };
  CanNetwork* network_;  // not owned
  Data d_;
};

// Configure-time; blocks with timeouts. The bring-up of a network with its axis port: the port's checks
// (CanAxisPort::check), then every bus brought up (CanNetwork::configure) with every node registered on it.
// `buses[i]` is bus i. Again, on fresh buses after the loop stopped using them, it is the recovery.
Status bring_up(CanNetwork& network, CanAxisPort& axes, std::span<CanBus* const> buses,
                ConfigureClock& clock);
Status bring_up(CanNetwork& network, CanAxisPort& axes, CanBus& bus, ConfigureClock& clock);  // one bus

// The settings of the masters of a network that carries the axes of `config` (its cycle, SDO and bring-up
// timeouts, the master's node id and heartbeat).
CanMasterConfig can_master_config(const CanAxisPortConfig& config);

}  // namespace loom::drivers

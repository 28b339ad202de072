// The machine's CAN network: one CanMaster per bus (can_master.hpp), the nodes registered on it (the
// drives by the CanAxisPort constructed on it, each CanIoPort by whoever assembles the machine), brought
// up once (configure(): every bus in one NMT sequence each) and, by the HAL (can_hal.hpp), polled once
// per tick before the ports read and its cycle started before they write. The link status is the
// network's: bus-off, a lost node, an EMCY of a node that does not report its own, with the recovery state
// and the link's fault event. The ports are views on the nodes they hold; an I/O module needs no axis port.
#pragma once

#include <array>
#include <cstddef>
#include <span>

#include "loom/drivers/can_axis_config.hpp"
#include "loom/drivers/can_frame.hpp"
#include "loom/drivers/can_master.hpp"
#include "loom/drivers/configure_clock.hpp"
#include "loom/drivers/status.hpp"
#include "loom/hal/fault_events.hpp"
#include "loom/hal/types.hpp"

namespace loom::drivers {

class CanNetwork {
 public:
  // Configure-time. `bus_count` buses (1..kMaxBuses), each with a master of `config`.
  CanNetwork() = default;
  CanNetwork(const CanMasterConfig& config, std::size_t bus_count);

  // Configure-time. The node tables (not the RT state): add() is false when `bus` is not one of the
  // network's, the bus' table is full or the node's id is taken on it. The nodes are not owned: a copy's
  // tables still name the original's nodes until they are cleared and its own are registered.
  bool add(CanNode& node, std::size_t bus = 0);
  void clear_nodes();
  std::size_t node_count() const;
  std::size_t bus_count() const noexcept { return n_buses_; }

  // Configure-time; blocks with timeouts. Brings every bus up, in bus order, each in its one NMT sequence
  // (CanMaster::bring_up). `buses[i]` is bus i; there must be bus_count() of them. Calling it again (from
  // the non-RT side, after the loop stopped using the network) is how a lost node or a bus-off recovers.
  Status configure(std::span<CanBus* const> buses, ConfigureClock& clock);
  Status configure(CanBus& bus, ConfigureClock& clock);  // one bus
  // Configure-time: not usable until the next configure() (a port's own checks failed before it).
  void unconfigure() { configured_ = false; }

  // RT-safe. Once per tick, before the ports read: every bus drains at most CanMaster::kMaxFramesPerPoll
  // frames to its nodes, then supervises them. Nothing before configure() succeeded.
  void poll(hal::Tick now) noexcept;
  // RT-safe. The link status (counters and faults, overwritten): not configured, or the first fault of
  // the first faulted bus; the worst recovery state over the buses; fault_raised when its report begins.
  void read_link(hal::Tick now, hal::LinkStatus& link) noexcept;
  // RT-safe. Once per tick, before the ports write: SYNC on every bus, and the master heartbeat when due.
  // Nothing before configure() succeeded.
  void start_cycle(hal::Tick now) noexcept;
  // RT-safe. The operator acknowledged: every master's and node's latches whose cause is gone.
  void acknowledge() noexcept;
  // RT-safe. Any fault on any bus that must stop every axis (bus-off, a node lost, an EMCY of a node that
  // does not report it itself, an EMCY of a node nobody owns).
  bool any_fault() const noexcept;
  bool configured() const noexcept { return configured_; }
  CanMaster& master(std::size_t bus) noexcept { return masters_[bus]; }
  const CanMaster& master(std::size_t bus) const noexcept { return masters_[bus]; }

 private:
  std::array<CanMaster, kMaxBuses> masters_{};
  std::size_t n_buses_ = 0;
  bool configured_ = false;
  hal::LinkFaultEdge link_edge_;  // the link report of the last read_link, for its event
};

}  // namespace loom::drivers

// The machine's servo axes (the core three and any added ones, on one or more CAN buses) as CiA 402
// drives in cyclic synchronous position mode behind hal::AxisPort. configure() brings every bus up by
// NMT and SDO (may block, with timeouts); read_axes()/write_axes() are the per-tick RT path: per bus
// SYNC + one RPDO per axis out, TPDOs, heartbeats, EMCYs and error frames in, fixed arrays only.
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
#include "loom/drivers/can_io_port.hpp"
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

// The hal::AxisPort of the CAN servo axes: one Cia402Axis per axis (the CiA 402 profile) registered on
// the port's CanNetwork (can_network.hpp: one CanMaster per bus — drain, dispatch, SYNC, master heartbeat,
// bus-off, NMT bring-up of its nodes in one sequence — and the link status), with the other nodes (the
// I/O modules) attached to it. A fault of any node on any bus stops every axis in the same tick.
class CanAxisPort final : public hal::AxisPort {
 public:
  // Bounds of the RT path (per bus).
  static constexpr int kMaxFramesPerRead = CanMaster::kMaxFramesPerPoll;

  // Configure-time only.
  explicit CanAxisPort(CanAxisPortConfig config);
  // Copies rebind the network to the copy's own axes (the fuzz harness copies a configured port).
  CanAxisPort(const CanAxisPort& other);
  CanAxisPort& operator=(const CanAxisPort& other);

  // Configure-time only. Another node on bus `bus` (an I/O module): brought up in the same NMT sequence as
  // that bus' drives, its frames handed to it, its faults stop every axis and are reported as link faults.
  // At most kMaxAttached; its frames must be in config.other_frames_per_cycle[bus].
  static constexpr std::size_t kMaxAttached = 8;
  void attach(CanNode& node, std::size_t bus = 0);

  // Configure-time only; blocks with timeouts. Validates the configuration and every bus' load, then
  // brings each bus up in one NMT sequence (can_master.hpp): reset-node → every boot-up → per drive by
  // SDO: 0x6502 has CSP, 0x6060 = 8 confirmed by 0x6061, 0x1017, 0x60C2, PDO mapping (pdo.hpp), 0x6041
  // and 0x6064 to seed state and the first target; the attached nodes' own configuration → NMT start →
  // an operational heartbeat from every node. Errors name node, axis and step. Calling it again (from
  // the non-RT side, after the loop has stopped using the port, on fresh buses) is how a lost node or a
  // bus-off is recovered; read_axes() reports in LinkStatus::recovery whether that can work yet.
  // `buses[i]` is bus i; there must be bus_count(config) of them.
  Status configure(std::span<CanBus* const> buses, ConfigureClock& clock);
  Status configure(CanBus& bus, ConfigureClock& clock);  // one bus
  Status configure(CanBus& bus);                         // with MonotonicConfigureClock

  // RT-safe. Per bus: drains at most kMaxFramesPerRead frames; then reports every axis and the link (the
  // network's), with the fault events of this tick (each axis' fault_raised: Cia402Axis; the link's:
  // CanNetwork::read_link).
  void read_axes(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) noexcept override;
  // RT-safe. Per bus: SYNC, then one RPDO1 per axis.
  void write_axes(hal::Tick now, const hal::AxisCommands& axes) noexcept override;

  // Diagnostics; RT-safe to read.
  bool configured() const noexcept { return d_.network.configured(); }
  // What configure() found optional and absent (0x1016, TPDO2) or accepted as read back; one line each.
  const std::vector<std::string>& notes() const { return d_.notes; }
  // Largest following error seen per axis since configure(), in SI units (telemetry high-water mark).
  double ferror_high_water(std::size_t slot) const noexcept { return d_.axes[slot].ferror_high_water(); }
  bool has_consumer(std::size_t slot) const noexcept { return d_.axes[slot].has_consumer(); }
  bool has_tpdo2(std::size_t slot) const noexcept { return d_.axes[slot].has_tpdo2(); }
  std::size_t axis_count() const noexcept { return d_.n_axes; }
  std::size_t bus_count() const noexcept { return d_.network.bus_count(); }
  const BusLoad& bus_load(std::size_t bus = 0) const noexcept { return d_.bus_loads[bus]; }
  const CanAxisPortConfig& config() const { return d_.config; }
  std::uint16_t last_controlword(std::size_t slot) const noexcept { return d_.axes[slot].last_controlword(); }
  std::int64_t last_target_counts(std::size_t slot) const noexcept {
    return d_.axes[slot].last_target_counts();
  }
  std::uint32_t heartbeat_consumer_ticks() const noexcept { return d_.consumer_ticks; }

 private:
  // Configure-time. The port's own checks, before any frame is sent: the configuration, `interfaces` ==
  // the buses the axes use, each bus' load, the attached nodes' buses and ids (the network's node tables
  // rebuilt); then the heartbeat-consumer and state timeouts in ticks. configure() makes them, then has
  // the network bring every bus up.
  Status check(std::size_t interfaces);
  void relink();  // the network's node tables from the axes and the attached nodes
  bool any_fault() const noexcept;

  struct Data {
    CanAxisPortConfig config;
    std::array<BusLoad, kMaxBuses> bus_loads{};
    std::uint32_t consumer_ticks = 0;
    std::uint32_t state_timeout_ticks = 0;
    std::array<Cia402Axis, hal::kMaxAxes> axes{};
    std::size_t n_axes = 0;
    CanNetwork network;  // the masters, one per bus; configured() once every bus is up
    struct Attached {
      CanNode* node = nullptr;  // not owned
      std::size_t bus = 0;
    };
    std::array<Attached, kMaxAttached> attached{};
    std::size_t n_attached = 0;
    std::vector<std::string> notes;
  };
  Data d_;
};

}  // namespace loom::drivers

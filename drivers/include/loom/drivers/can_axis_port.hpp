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
#include "loom/drivers/can_frame.hpp"
#include "loom/drivers/can_io_port.hpp"
#include "loom/drivers/can_master.hpp"
#include "loom/drivers/cia402_axis.hpp"
#include "loom/drivers/configure_clock.hpp"
#include "loom/drivers/position_scaling.hpp"
#include "loom/drivers/status.hpp"
#include "loom/hal/hal.hpp"

namespace loom::drivers {

class SdoClient;

// 20-bit single-turn encoders; the carriage's ball screw advances 10 mm per motor revolution.
inline constexpr double kCountsPerRev = 1048576.0;  // 2^20
inline constexpr double kDefaultCountsPerRad = kCountsPerRev / (2.0 * std::numbers::pi);
inline constexpr double kDefaultCarriageLeadM = 0.010;
inline constexpr double kDefaultCountsPerM = kCountsPerRev / kDefaultCarriageLeadM;

struct CanAxisConfig {
  std::string name = "axis";  // the machine description's name, for messages
  std::uint8_t bus = 0;       // which bus (0 = the first interface); node ids are unique per bus
  std::uint8_t node_id = 1;
  double counts_per_unit = kDefaultCountsPerRad;  // counts per rad (rotary) or per m (carriage)
  double rated_effort = 0.0;  // N·m or N at 1000 ‰ of 0x6077; 0 = effort not reported (needs TPDO2)
  // Following-error supervision (LinuxCNC rule): |commanded − actual| > max(ferror_min, ferror_k_s·|v_cmd|)
  // is a fault. SI units of the axis (rad or m) and seconds. ferror_min = 0 disables it.
  double ferror_min = 0.0;
  double ferror_k_s = 0.0;
  // Per-node bring-up windows (drives differ: some boot or go operational in hundreds of ms).
  // 0 = the port-wide boot_timeout_s / operational_timeout_s.
  double boot_timeout_s = 0.0;
  double operational_timeout_s = 0.0;
  // Referencing. 0 = an absolute encoder: always referenced. Else a CiA 402 homing method (19/21 home
  // switch, 33/34 index pulse, 37 current position, or any other 1..35 the drive offers): the axis is
  // unreferenced after every bring-up or boot-up until a homing run (hal::AxisRequest::kHome) attains.
  std::int8_t homing_method = 0;
  double home_offset = 0.0;   // SI: the reading at the home point (0x607C)
  double homing_speed = 0.0;  // SI/s: 0x6099:01; 0x6099:02 (search for zero) a quarter of it
  double homing_accel = 0.0;  // SI/s² (0x609A)
};

// Buses a port can drive (can0..can3): CanAxisConfig::bus is 0..kMaxBuses-1.
inline constexpr std::size_t kMaxBuses = 4;

struct CanAxisPortConfig {
  // One per axis of the machine, in slot order (hal::AxisLayout); at most hal::kMaxAxes.
  std::vector<CanAxisConfig> axes{
      {"beat_crank", 0, 1, kDefaultCountsPerRad, 0.0},
      {"carriage", 0, 2, kDefaultCountsPerM, 0.0},
      {"helix", 0, 3, kDefaultCountsPerRad, 0.0},
  };
  double cycle_period_s = 0.002;        // SYNC period = tick period; written to 0x60C2
  double heartbeat_producer_s = 0.100;  // written to each drive's 0x1017 (whole ms)
  // A drive is lost when no heartbeat arrived for longer than this. Must exceed the producer time and
  // leave a lost drive detected within 3 producer periods (consumer + one cycle ≤ 3 × producer).
  double heartbeat_consumer_s = 0.250;
  double sdo_timeout_s = 0.100;
  double boot_timeout_s = 2.0;          // wait for every boot-up after NMT reset-node
  double state_timeout_s = 0.5;         // CiA 402 transition not confirmed → fault
  // Operational heartbeat after NMT start (many commercial drives take hundreds of ms); per-node
  // CanAxisConfig::operational_timeout_s overrides it.
  double operational_timeout_s = 1.0;
  // The master's own heartbeat (0x700 + id, state operational) every master_heartbeat_s, and each drive's
  // consumer 0x1016:01 set to watch it for master_consumer_s where the drive has 0x1016, so a drive stops
  // when the host dies. master_node_id = 0: no master heartbeat, no consumer configured.
  std::uint8_t master_node_id = 0x7F;
  // A CSP drive that stops receiving targets holds its last one at once; the consumer adds the power
  // stage's own reaction (quick stop) and must not trip on a loaded host's scheduling stalls.
  double master_heartbeat_s = 0.100;
  double master_consumer_s = 0.500;
  bool tpdo2 = false;                   // velocity + torque PDO (adds 3 frames per cycle)
  std::uint8_t tpdo2_every_n_sync = 1;  // 1..240
  std::uint32_t bitrate_bps = 1'000'000;
  double bus_load_budget = 0.70;                   // worst-case utilisation allowed, per bus
  // The other nodes' frames per bus (the I/O modules), by bus index: a bus that carries only an I/O
  // module is still one of the port's buses, with its own master, SYNC and budget.
  std::array<std::vector<FrameGroup>, kMaxBuses> other_frames_per_cycle{};
};

// Configure-time only. Error naming the field and its value.
Status validate(const CanAxisPortConfig& config);
// Configure-time only. The buses the configuration uses: 1 + the highest bus an axis or another node's
// frames are on.
std::size_t bus_count(const CanAxisPortConfig& config);
// Configure-time only. The worst cycle this configuration puts on bus `bus`: SYNC, each of its drives'
// RPDO1 and TPDO1 (and TPDO2), the other nodes' frames on that bus (the I/O modules) and the master
// heartbeat. The same figure the port checks against its budget when it configures, and `loomctl check`
// prints per bus.
BusLoad planned_bus_load(const CanAxisPortConfig& config, std::size_t bus = 0);

// The hal::AxisPort of the CAN servo axes: one CanMaster per bus (bus owner: drain, dispatch, SYNC,
// master heartbeat, bus-off, NMT bring-up of its nodes in one sequence), one Cia402Axis per axis (the
// CiA 402 profile), and the other nodes (the I/O modules) attached to their bus' master. A fault of any
// node on any bus stops every axis in the same tick.
class CanAxisPort final : public hal::AxisPort {
 public:
  // Bounds of the RT path (per bus).
  static constexpr int kMaxFramesPerRead = CanMaster::kMaxFramesPerPoll;

  // Configure-time only.
  explicit CanAxisPort(CanAxisPortConfig config);
  // Copies rebind the masters to the copy's own axes (the fuzz harness copies a configured port).
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

  // RT-safe. Per bus: drains at most kMaxFramesPerRead frames; then reports every axis and the link.
  void read_axes(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) override;
  // RT-safe. Per bus: SYNC, then one RPDO1 per axis.
  void write_axes(hal::Tick now, const hal::AxisCommands& axes) override;

  // Diagnostics; RT-safe to read.
  bool configured() const { return d_.configured; }
  // What configure() found optional and absent (0x1016, TPDO2) or accepted as read back; one line each.
  const std::vector<std::string>& notes() const { return d_.notes; }
  // Largest following error seen per axis since configure(), in SI units (telemetry high-water mark).
  double ferror_high_water(std::size_t slot) const { return d_.axes[slot].ferror_high_water(); }
  bool has_consumer(std::size_t slot) const { return d_.axes[slot].has_consumer(); }
  bool has_tpdo2(std::size_t slot) const { return d_.axes[slot].has_tpdo2(); }
  std::size_t axis_count() const { return d_.n_axes; }
  std::size_t bus_count() const { return d_.n_buses; }
  const BusLoad& bus_load(std::size_t bus = 0) const { return d_.bus_loads[bus]; }
  const CanAxisPortConfig& config() const { return d_.config; }
  std::uint16_t last_controlword(std::size_t slot) const { return d_.axes[slot].last_controlword(); }
  std::int64_t last_target_counts(std::size_t slot) const { return d_.axes[slot].last_target_counts(); }
  std::uint32_t heartbeat_consumer_ticks() const { return d_.consumer_ticks; }

 private:
  void relink();  // the masters' node tables from the axes and the attached nodes
  bool any_fault() const;

  struct Data {
    CanAxisPortConfig config;
    bool configured = false;
    std::array<BusLoad, kMaxBuses> bus_loads{};
    std::uint32_t consumer_ticks = 0;
    std::uint32_t state_timeout_ticks = 0;
    std::array<Cia402Axis, hal::kMaxAxes> axes{};
    std::size_t n_axes = 0;
    std::array<CanMaster, kMaxBuses> masters{};
    std::size_t n_buses = 0;
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

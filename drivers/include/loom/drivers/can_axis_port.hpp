// The three servo axes (beat crank, carriage, helix shaft) as CiA 402 drives in cyclic synchronous
// position mode behind hal::AxisPort. configure() brings the drives up by NMT and SDO (may block, with
// timeouts); read_axes()/write_axes() are the per-tick RT path: SYNC + one RPDO per axis out, TPDOs,
// heartbeats, EMCYs and error frames in, fixed arrays only, bounded work.
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
#include "loom/drivers/cia402.hpp"
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
};

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
  double bus_load_budget = 0.70;                   // worst-case utilisation allowed
  std::vector<FrameGroup> other_frames_per_cycle;  // other nodes sharing the bus (e.g. the I/O node)
};

// Configure-time only. Error naming the field and its value.
Status validate(const CanAxisPortConfig& config);
// Configure-time only. The worst cycle this configuration puts on the bus: SYNC, each drive's RPDO1
// and TPDO1 (and TPDO2), the other nodes' frames and the master heartbeat. The same figure the port
// checks against its budget when it configures, and `loomctl check` prints.
BusLoad planned_bus_load(const CanAxisPortConfig& config);

class CanAxisPort final : public hal::AxisPort {
 public:
  // Bounds of the RT path.
  static constexpr int kMaxFramesPerRead = 64;

  // Configure-time only.
  explicit CanAxisPort(CanAxisPortConfig config);

  // Configure-time only. Another node on this bus (the I/O node): every frame it sends is handed to it
  // in read_axes(), its faults stop every axis, its fault code is reported as a link fault. At most 4.
  void attach(CanNodeListener& node);

  // Configure-time only; blocks with timeouts. Validates the configuration and the bus load, then:
  // NMT reset-node → every boot-up → per drive by SDO: 0x6502 has CSP, 0x6060 = 8 confirmed by 0x6061,
  // 0x1017, 0x60C2, PDO mapping (pdo.hpp), 0x6041 and 0x6064 to seed state and the first target →
  // NMT start → an operational heartbeat from every drive. Errors name node, axis and step. Calling it
  // again (from the non-RT side, after the loop has stopped using the port, on a fresh bus) is how a lost
  // drive or a bus-off is recovered; read_axes() reports in LinkStatus::recovery whether that can work
  // yet (the controller restarted, every lost node heard again), and the loop honours the operator's
  // acknowledgement only then.
  Status configure(CanBus& bus, ConfigureClock& clock);
  Status configure(CanBus& bus);  // with MonotonicConfigureClock

  // RT-safe. Drains at most kMaxFramesPerRead frames, then reports every axis and the link.
  void read_axes(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) override;
  // RT-safe. SYNC, then one RPDO1 per axis.
  void write_axes(hal::Tick now, const hal::AxisCommands& axes) override;

  // Diagnostics; RT-safe to read.
  bool configured() const { return configured_; }
  // What configure() found optional and absent (0x1016, TPDO2) or accepted as read back; one line each.
  const std::vector<std::string>& notes() const { return notes_; }
  // Largest following error seen per axis since configure(), in SI units (telemetry high-water mark).
  double ferror_high_water(std::size_t slot) const { return axes_[slot].ferror_high_water; }
  bool has_consumer(std::size_t slot) const { return axes_[slot].has_consumer; }
  bool has_tpdo2(std::size_t slot) const { return axes_[slot].has_tpdo2; }
  std::size_t axis_count() const { return n_axes_; }
  const BusLoad& bus_load() const { return bus_load_; }
  const CanAxisPortConfig& config() const { return config_; }
  std::uint16_t last_controlword(std::size_t slot) const { return axes_[slot].tracker.last_controlword; }
  std::int64_t last_target_counts(std::size_t slot) const { return axes_[slot].last_target_counts; }
  std::uint32_t heartbeat_consumer_ticks() const { return consumer_ticks_; }

 private:
  struct AxisRuntime {
    std::uint8_t node = 0;
    double counts_per_unit = 1.0;
    double rated_effort = 0.0;
    PositionUnwrapper position;
    std::int64_t last_target_counts = 0;
    std::uint16_t statusword = 0;
    hal::DriveState state = hal::DriveState::kUnknown;
    Cia402Tracker tracker;
    hal::Tick refreshed = hal::kNeverTick;
    double last_position_si = 0.0;
    double velocity = 0.0;
    double effort = 0.0;
    hal::Tick last_heartbeat = hal::kNeverTick;
    bool booted = false;           // a boot-up since configure(): back on the bus, needing configuration
    std::uint16_t emcy_code = 0;
    std::uint16_t link_fault = 0;  // latched: heartbeat lost / rebooted / not operational
    double ferror_min = 0.0;
    double ferror_k_s = 0.0;
    double last_cmd_si = 0.0;       // last commanded target (SI), for following-error supervision
    double cmd_velocity = 0.0;      // SI/s, from successive commanded targets
    bool cmd_valid = false;
    bool ferror_fault = false;      // latched until acknowledged
    bool acknowledged = false;      // operator acked while the drive was in Fault: its EMCY 0x0000 clears
    double ferror_high_water = 0.0;
    bool has_consumer = false;      // the drive watches our heartbeat (0x1016)
    bool has_tpdo2 = false;         // velocity/torque PDO configured
  };

  void reset_runtime();
  void handle_frame(hal::Tick now, const CanFrame& frame);
  void fill_feedback(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) const;
  // The recovery state of a link fault (see hal::LinkRecovery); `silent` names the node still missing.
  hal::LinkRecovery recovery(hal::Tick now, std::uint8_t& silent) const;
  void count_send(SendResult r);
  std::string node_label(std::size_t axis) const;
  Status configure_node(std::size_t axis, SdoClient& sdo);
  Status configure_pdos(std::size_t axis, SdoClient& sdo);
  bool any_fault() const;
  void acknowledge();

  CanAxisPortConfig config_;
  CanBus* bus_ = nullptr;
  bool configured_ = false;
  BusLoad bus_load_{};
  std::uint32_t consumer_ticks_ = 0;
  std::uint32_t state_timeout_ticks_ = 0;
  std::array<AxisRuntime, hal::kMaxAxes> axes_{};
  std::size_t n_axes_ = 0;  // config_.axes.size()
  std::span<AxisRuntime> live() { return {axes_.data(), n_axes_}; }
  std::span<const AxisRuntime> live() const { return {axes_.data(), n_axes_}; }
  std::array<std::int8_t, 128> axis_of_node_{};  // −1 = not ours
  bool bus_off_ = false;                         // latched until configure()
  bool restarted_ = false;                       // the controller restarted after the bus-off
  std::array<CanNodeListener*, 4> listeners_{};
  std::size_t n_listeners_ = 0;
  std::uint16_t foreign_emcy_code_ = 0;  // EMCY from a node that is not an axis (latched until ack)
  std::uint32_t master_hb_ticks_ = 0;
  hal::Tick next_master_hb_ = 0;
  std::vector<std::string> notes_;
  std::uint32_t tx_dropped_ = 0;
  std::uint32_t rx_errors_ = 0;
};

}  // namespace loom::drivers

// One CiA 402 servo drive as a node of a CanMaster, in cyclic synchronous position (a set-point every
// SYNC) or profile position (one set-point per move with the handshake, event-driven PDOs): its profile
// only (SDO configuration of the mode, interpolation period, heartbeat producer, master consumer and the
// PDO mapping; the power-state machine; the RPDO1/TPDO1/TPDO2 exchange; following-error supervision in
// CSP, set-point acknowledge and target-reached supervision in PP).
// Heartbeats, boot-ups and EMCYs are the master's NodeSupervisor's. CanAxisPort holds one per axis.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "loom/drivers/can_axis_config.hpp"
#include "loom/drivers/can_master.hpp"
#include "loom/drivers/cia402.hpp"
#include "loom/drivers/position_scaling.hpp"
#include "loom/hal/fault_events.hpp"
#include "loom/hal/types.hpp"

namespace loom::drivers {

struct CanAxisConfig;
struct CanAxisPortConfig;

class Cia402Axis final : public CanNode {
 public:
  // Configure-time. The axis' own settings and the port-wide ones its profile writes.
  void setup(const CanAxisConfig& axis, const CanAxisPortConfig& port);

  // CanNode.
  std::uint8_t node_id() const override { return node_; }
  std::string label() const override { return label_; }
  NodeTiming timing() const override { return timing_; }
  void bring_up_started() override;
  Status configure_profile(SdoClient& sdo) override;
  void brought_up(CanBus& bus) override;
  void on_profile_frame(hal::Tick now, const CanFrame& frame) noexcept override;
  void acknowledge() noexcept override;
  bool reports_own_emcy() const noexcept override { return true; }
  const NodeDescription* description() const override { return description_.get(); }

  // RT-safe. This tick's feedback, given the state of the axis' bus. A profile-position axis' TPDO1 is
  // sent on change only: while its last one said the axis stands still, its data is current until the
  // event timer (plus margin) has passed without one (`refreshed` = now); after that it ages as a CSP
  // axis' does, so a PP drive whose TPDO stops is stale feedback for the sequencer too. Raises
  // fb.fault_raised on the tick this axis' fault report begins or changes its code (once per tick).
  void fill_feedback(hal::Tick now, hal::AxisFeedback& fb, bool bus_off, bool bus_configured) noexcept;
  // RT-safe. Any fault of this drive that must stop every axis.
  bool faulted() const noexcept;
  // RT-safe. The next step toward `command` (quick stop when `stop_all` and the request is not a reset
  // or disable; always quick stop while the drive cannot be supervised) into `rpdo1`. True when it is to
  // be sent: every tick in CSP; in PP only when the controlword or the target changed.
  bool command(hal::Tick now, const hal::AxisCommand& command, bool stop_all, bool bus_down,
               std::uint32_t state_timeout_ticks, CanFrame& rpdo1) noexcept;

  // Diagnostics; RT-safe.
  std::uint8_t bus() const noexcept { return bus_; }
  double ferror_high_water() const noexcept { return ferror_high_water_; }
  bool has_consumer() const noexcept { return has_consumer_; }
  bool has_tpdo2() const noexcept { return has_tpdo2_; }
  std::uint16_t last_controlword() const noexcept { return tracker_.last_controlword; }
  std::int64_t last_target_counts() const noexcept { return last_target_counts_; }
  DriveMode mode() const noexcept { return mode_; }
  std::uint32_t setpoints_sent() const noexcept { return pp_setpoints_; }  // PP: set-points (bit 4 rising)
  const std::vector<std::string>& notes() const { return notes_; }

 private:
  Status configure_pdos(SdoClient& sdo);
  Status configure_homing(SdoClient& sdo, std::uint32_t supported_modes);
  Status configure_profile_position(SdoClient& sdo);
  // PP, RT-safe: the controlword bits and target of the set-point handshake for this tick.
  std::uint16_t profile_setpoint(hal::Tick now, const hal::AxisCommand& cmd, bool enabled,
                                 std::uint32_t state_timeout_ticks) noexcept;
  std::uint32_t profile_move_ticks(std::int64_t distance_counts) const;
  bool profile_fault() const noexcept { return pp_fault_ != 0; }

  // Configuration (configure-time).
  // What configure_profile() writes (from CanAxisPortConfig).
  struct SdoSettings {
    double cycle_period_s = 0.002;
    double heartbeat_producer_s = 0.100;
    std::uint8_t master_node_id = 0;
    double master_consumer_s = 0.500;
    bool tpdo2 = false;
    std::uint8_t tpdo2_every_n_sync = 1;
  };
  SdoSettings sdo_cfg_{};
  std::string label_;
  std::uint8_t node_ = 0;
  std::uint8_t bus_ = 0;
  NodeTiming timing_{};
  double cycle_period_s_ = 0.002;
  bool tpdo2_wanted_ = false;
  double counts_per_unit_ = 1.0;
  double rated_effort_ = 0.0;
  double ferror_min_ = 0.0;
  double ferror_k_s_ = 0.0;
  std::int8_t homing_method_ = 0;  // 0 = absolute encoder
  std::int32_t home_offset_counts_ = 0;
  double homing_speed_ = 0.0;
  double homing_accel_ = 0.0;
  DriveMode mode_ = DriveMode::kCyclicPosition;
  std::int8_t run_mode_ = 8;       // 0x6060 outside homing: od::kModeCsp or od::kModeProfilePosition
  double profile_velocity_ = 0.0;  // SI/s, SI/s² (PP)
  double profile_acceleration_ = 0.0;
  double profile_jerk_ = 0.0;
  double tpdo_inhibit_s_ = 0.010;      // PP TPDO1 0x1800:03
  double tpdo_event_timer_s_ = 0.100;  // PP TPDO1 0x1800:05
  hal::Tick fresh_ticks_ = 0;          // PP: a still axis' last TPDO is current this long
  double state_timeout_s_ = 0.5;
  std::vector<std::string> notes_;
  std::shared_ptr<const NodeDescription> description_;

  // RT state.
  bool up_ = false;
  PositionUnwrapper position_;
  std::int64_t last_target_counts_ = 0;
  std::uint16_t statusword_ = 0;
  hal::DriveState state_ = hal::DriveState::kUnknown;
  Cia402Tracker tracker_;
  hal::Tick refreshed_ = hal::kNeverTick;
  double last_position_si_ = 0.0;
  double velocity_ = 0.0;
  double effort_ = 0.0;
  double last_cmd_si_ = 0.0;   // last commanded target (SI), for following-error supervision
  double cmd_velocity_ = 0.0;  // SI/s, from successive commanded targets
  bool cmd_valid_ = false;
  bool ferror_fault_ = false;  // latched until acknowledged
  double ferror_high_water_ = 0.0;
  bool has_consumer_ = false;      // the drive watches our heartbeat (0x1016)
  bool has_tpdo2_ = false;         // velocity/torque PDO configured
  std::int8_t mode_display_ = 8;   // 0x6061 from TPDO1 (always CSP for an absolute axis)
  bool referenced_ = true;         // absolute, or homed since the last bring-up
  bool homing_error_ = false;      // the drive said homing error (latched until acknowledged)
  bool homing_commanded_ = false;  // bit 4 sent in this homing run: attained/error bits are ours
  // The RPDO1 last sent (PP sends one only when it differs).
  bool sent_any_ = false;
  CanFrame last_sent_{};
  // Profile position's set-point handshake.
  double last_cmd_target_ = 0.0;      // the sequencer's per-tick target last tick
  bool pp_have_ = false;              // pp_target_ is the drive's current set-point
  std::int64_t pp_target_ = 0;        // counts: the target RPDO1 carries
  bool pp_pending_ = false;           // bit 4 up, waiting for the acknowledge (bit 12)
  bool pp_moving_ = false;            // acknowledged, waiting for target reached (bit 10)
  std::uint32_t pp_wait_ticks_ = 0;   // ticks in the current wait
  std::uint32_t pp_limit_ticks_ = 0;  // the current move's planned duration and margin
  std::uint16_t pp_fault_ = 0;        // latched until acknowledged (fault_code)
  std::uint32_t pp_setpoints_ = 0;
  hal::Tick pp_since_ = 0;  // tick the current set-point was raised
  bool still_ = false;      // PP: the last TPDO1 said the axis stands still
  // The fault report fill_feedback last gave, for its event; kept across bring-ups (a report that goes on
  // after a reconfiguration is not a new one).
  hal::AxisFaultEdge fault_edge_;
};

}  // namespace loom::drivers

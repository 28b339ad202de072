// One CiA 402 servo drive in cyclic synchronous position mode as a node of a CanMaster: its profile
// only (SDO configuration of CSP, interpolation period, heartbeat producer, master consumer and the PDO
// mapping; the power-state machine; the RPDO1/TPDO1/TPDO2 exchange; following-error supervision).
// Heartbeats, boot-ups and EMCYs are the master's NodeSupervisor's. CanAxisPort owns one per axis.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "loom/drivers/can_master.hpp"
#include "loom/drivers/cia402.hpp"
#include "loom/drivers/position_scaling.hpp"
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
  void on_profile_frame(hal::Tick now, const CanFrame& frame) override;
  void acknowledge() override;
  bool reports_own_emcy() const override { return true; }
  const NodeDescription* description() const override { return description_.get(); }

  // RT-safe. This tick's feedback, given the state of the axis' bus.
  void fill_feedback(hal::AxisFeedback& fb, bool bus_off, bool bus_configured) const;
  // RT-safe. Any fault of this drive that must stop every axis.
  bool faulted() const;
  // RT-safe. The next step toward `command` (quick stop when `stop_all` and the request is not a reset
  // or disable; always quick stop while the drive cannot be supervised); returns its RPDO1.
  CanFrame command(const hal::AxisCommand& command, bool stop_all, bool bus_down,
                   std::uint32_t state_timeout_ticks);

  // Diagnostics; RT-safe.
  std::uint8_t bus() const { return bus_; }
  double ferror_high_water() const { return ferror_high_water_; }
  bool has_consumer() const { return has_consumer_; }
  bool has_tpdo2() const { return has_tpdo2_; }
  std::uint16_t last_controlword() const { return tracker_.last_controlword; }
  std::int64_t last_target_counts() const { return last_target_counts_; }
  const std::vector<std::string>& notes() const { return notes_; }

 private:
  Status configure_pdos(SdoClient& sdo);
  Status configure_homing(SdoClient& sdo, std::uint32_t supported_modes);

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
};

}  // namespace loom::drivers

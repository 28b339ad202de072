// A simulated CiA 402 servo drive as a CANopen node: NMT states and boot-up, an SDO server for the
// objects the master configures, PDO mapping that is really honoured, heartbeat producer, EMCY, and the
// drive state machine with ideal position tracking on SYNC. Driven through drivers::CanBus with injected
// time, so tests run master and drives in one process and the executable runs them on (v)CAN.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "loom/drivers/can_frame.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/hal/types.hpp"

namespace loom::sim_can {

struct SimDriveConfig {
  std::uint8_t node_id = 1;
  std::int32_t initial_position = 0;  // counts, what 0x6064 reads after power-on
  // Largest target step per SYNC the drive follows; a bigger jump trips following error (EMCY 0x8611).
  // 0 = unlimited.
  std::uint32_t max_step_counts = 0;
  bool supports_csp = true;                    // 0x6502 bit 7; false refuses 0x6060 = 8
  std::vector<std::uint16_t> missing_objects;  // indices this drive lacks (SDO abort 0x06020000)
  // "Commercial" personality: PDO mapping objects read-only, sub-index 0 included (abort 0x06010002);
  // the factory TPDO1 mapping may be replaced (empty = statusword + position actual).
  bool fixed_mapping = false;
  std::vector<std::uint32_t> tpdo1_factory_mapping;
  std::int64_t boot_delay_us = 0;         // power-on / NMT reset → boot-up frame
  std::int64_t operational_delay_us = 0;  // NMT start → operational
};

class SimDriveNode {
 public:
  // Configure-time only. The node is powered off until power_on().
  SimDriveNode(drivers::CanBus& bus, SimDriveConfig config);

  // RT-safe (no allocation; sends through the bus). Power cycle: every object to its default, 402
  // state Switch On Disabled, boot-up sent.
  void power_on(std::int64_t now_us);
  // RT-safe. Silent from now on (cable pulled / power lost): sends nothing, ignores every frame.
  void power_off();
  // RT-safe. Drive detects a fault: Fault Reaction Active, EMCY with `code`, Fault at the next SYNC.
  void inject_fault(std::uint16_t code);

  // RT-safe. One received frame (the node filters what is addressed to it).
  void handle(const drivers::CanFrame& frame, std::int64_t now_us);
  // RT-safe. Timers: heartbeat production.
  void step(std::int64_t now_us);
  // RT-safe. Earliest time step() has something to do (INT64_MAX when nothing is scheduled).
  std::int64_t next_deadline_us() const;

  // Observation for tests and the executable's log; all RT-safe.
  std::uint8_t node_id() const { return config_.node_id; }
  bool powered() const { return powered_; }
  drivers::NmtState nmt_state() const { return nmt_; }
  hal::DriveState drive_state() const { return state_; }
  std::int32_t position() const { return position_; }
  std::int32_t target() const { return target_; }
  std::int8_t mode() const { return mode_; }
  std::uint16_t heartbeat_ms() const { return heartbeat_ms_; }
  std::uint16_t controlword() const { return controlword_; }
  std::uint16_t statusword() const;
  std::uint32_t syncs_seen() const { return syncs_; }
  bool master_lost() const { return master_lost_; }  // 0x1016 consumer expired (the drive quick-stopped)

 private:
  struct PdoComm {
    std::uint32_t cob_id = 0;  // bit 31 = invalid
    std::uint8_t type = 1;
  };
  struct PdoMap {
    std::uint8_t count = 0;
    std::array<std::uint32_t, 8> entries{};
  };

  void reset_communication();
  void boot_up(std::int64_t now_us);
  void reset_application();
  void send(const drivers::CanFrame& f);
  void on_nmt(const drivers::CanFrame& f, std::int64_t now_us);
  void on_sdo(const drivers::CanFrame& f, std::int64_t now_us);
  void on_sync();
  void on_rpdo(std::size_t pdo, const drivers::CanFrame& f);
  void apply_rpdo(std::size_t pdo, const std::array<std::uint8_t, 8>& data);
  void send_tpdo(std::size_t pdo);
  void set_controlword(std::uint16_t cw);
  void enter_fault(std::uint16_t code);
  bool object_missing(std::uint16_t index) const;
  // SDO server: 0 on success, else the abort code.
  std::uint32_t read_object(std::uint16_t index, std::uint8_t sub, std::uint32_t& value,
                            std::uint8_t& size) const;
  std::uint32_t write_object(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::uint8_t size,
                             std::int64_t now_us);
  std::uint32_t write_pdo_comm(PdoComm& c, bool rx, std::uint8_t sub, std::uint32_t value);
  std::uint32_t write_pdo_map(PdoMap& m, const PdoComm& c, bool rx, std::uint8_t sub, std::uint32_t value);
  bool mappable(std::uint32_t entry, bool rx) const;
  std::uint32_t mapped_value(std::uint16_t index) const;
  double interpolation_period_s() const;

  drivers::CanBus& bus_;
  SimDriveConfig config_;
  bool powered_ = false;
  drivers::NmtState nmt_ = drivers::NmtState::kBootUp;

  // Communication objects.
  std::uint16_t heartbeat_ms_ = 0;
  std::int64_t next_heartbeat_us_ = 0;
  std::array<PdoComm, 4> rpdo_comm_{};
  std::array<PdoMap, 4> rpdo_map_{};
  std::array<PdoComm, 4> tpdo_comm_{};
  std::array<PdoMap, 4> tpdo_map_{};
  std::array<bool, 4> rpdo_pending_{};
  std::array<std::array<std::uint8_t, 8>, 4> rpdo_data_{};
  std::uint32_t syncs_ = 0;

  // Drive objects.
  hal::DriveState state_ = hal::DriveState::kNotReadyToSwitchOn;
  std::uint16_t controlword_ = 0;
  std::int8_t mode_ = 0;
  std::int32_t position_ = 0;
  std::int32_t previous_position_ = 0;
  std::int32_t target_ = 0;
  std::uint16_t error_code_ = 0;
  std::uint8_t error_register_ = 0;
  std::uint8_t ip_value_ = 1;
  std::int8_t ip_index_ = -3;
  bool following_error_ = false;
  // Timers of the slow personality and the 0x1016 heartbeat consumer.
  std::int64_t boot_at_us_ = -1;
  std::int64_t operational_at_us_ = -1;
  std::uint32_t consumer_ = 0;  // 0x1016:01
  std::int64_t master_seen_us_ = -1;
  bool master_lost_ = false;
};

}  // namespace loom::sim_can

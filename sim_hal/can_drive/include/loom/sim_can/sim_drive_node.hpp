// A simulated CiA 402 servo drive as a CANopen node: NMT states and boot-up, an SDO server for the
// objects the master configures, PDO mapping that is really honoured, heartbeat producer, EMCY, and the
// drive state machine with ideal position tracking on SYNC. Driven through drivers::CanBus with injected
// time, so tests run master and drives in one process and the executable runs them on (v)CAN.
//
// Its object dictionary is one table in sim_drive_node.cpp served by the slave-side CiA 301 code in
// slave_od.hpp (shared with SimIoNode, independent of the master's codecs in drivers/); the
// personalities below only filter or override that table.
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "loom/drivers/can_frame.hpp"
#include "loom/hal/types.hpp"
#include "loom/sim_can/slave_od.hpp"

// The master's NMT state type is nmt_state()'s return type only (its values are the heartbeat bytes);
// declared, not included, so no drivers/ codec reaches the simulated node.
namespace loom::drivers {
enum class NmtState : std::uint8_t;
}  // namespace loom::drivers

namespace loom::sim_can {

struct SimDriveConfig {
  std::uint8_t node_id = 1;
  std::int32_t initial_position = 0;  // counts, what 0x6064 reads after power-on
  // Largest target step per SYNC the drive follows; a bigger jump trips following error (EMCY 0x8611).
  // 0 = unlimited.
  std::uint32_t max_step_counts = 0;
  bool supports_csp = true;  // 0x6502 bit 7; false refuses 0x6060 = 8
  // Profile position (0x6502 bit 0, 0x6060 = 1): the set-point handshake and a trapezoidal profile from
  // 0x6081/0x6083/0x6084 (0x6086 takes 0, linear ramp, only); false refuses 0x6060 = 1.
  bool supports_pp = true;
  std::vector<std::uint16_t> missing_objects;  // indices this drive lacks (SDO abort 0x06020000)
  // "Commercial" personality: PDO mapping objects read-only, sub-index 0 included (abort 0x06010002);
  // the factory TPDO1 mapping may be replaced (empty = statusword + position actual).
  bool fixed_mapping = false;
  std::vector<std::uint32_t> tpdo1_factory_mapping;
  std::int64_t boot_delay_us = 0;         // power-on / NMT reset → boot-up frame
  std::int64_t operational_delay_us = 0;  // NMT start → operational
  // CiA 402 homing (mode 6, 0x6502 bit 5; methods 19/21 home switch, 33/34 index pulse, 37 current
  // position). The axis has a physical position the count is an image of: with power_up_seed != 0 every
  // power-on draws a random count in ±power_up_range for the same physical position (an incremental
  // encoder), so only a homing run gives the count a meaning again.
  bool supports_homing = false;  // 0x6502 bit 5 (off: the drive announces what it always did)
  std::uint64_t power_up_seed = 0;
  std::int32_t power_up_range = 1 << 20;
  std::int32_t home_switch_at = 0;   // physical position (counts) of the home switch's edge
  std::int32_t index_every = 4096;   // an index pulse at every multiple of this (physical counts)
  bool home_switch_missing = false;  // methods 19/21 never see the switch: homing error after a while
  // A drive described by an EDS (eds_dictionary.hpp): its own dictionary table (sorted, 1/2/4-byte
  // entries) instead of the built-in one, 0x6502 as the table says. Empty = the built-in drive.
  std::vector<slave::Entry> dictionary;
};

class SimDriveNode : private slave::ObjectHooks, private slave::FrameHandlers {
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
  drivers::NmtState nmt_state() const { return static_cast<drivers::NmtState>(nmt_); }
  hal::DriveState drive_state() const { return state_; }
  std::int32_t position() const { return position_; }
  std::int32_t target() const;
  std::int8_t mode() const;
  std::uint16_t heartbeat_ms() const;
  std::uint16_t controlword() const { return controlword_; }
  std::uint16_t statusword() const;
  std::uint32_t syncs_seen() const { return syncs_; }
  // The axis' physical position (counts): what the count would read without the power-up offset.
  std::int64_t physical_position() const { return static_cast<std::int64_t>(position_) - count_offset_; }
  bool homing_attained() const { return homing_attained_; }
  bool master_lost() const { return master_lost_; }
  // Profile position: set-points latched (bit 4 rising edges taken) since power-on.
  std::uint32_t setpoints_latched() const {
    return pp_latched_;
  }  // 0x1016 consumer expired (the drive quick-stopped)

 private:
  // The bus's writes reach the drive through the ObjectHooks (object rules beyond CiA 301, side effects).
  std::uint32_t check(std::uint16_t index, std::uint8_t sub, std::uint32_t value) const override;
  void written(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::int64_t now_us) override;

  void reset_communication();
  void reset_application();
  void restart(std::int64_t now_us);
  void boot_up(std::int64_t now_us);
  void send(const drivers::CanFrame& f);
  // Frames routed by slave::deliver.
  void on_nmt(std::uint8_t command, std::int64_t now_us) override;
  void on_watched_heartbeat(std::int64_t now_us) override;
  void on_sdo(const drivers::CanFrame& f, std::int64_t now_us) override;
  void on_sync(std::int64_t now_us) override;
  void on_rpdo(int pdo, const drivers::CanFrame& f, std::int64_t now_us) override;
  void track_target();
  void run_homing();
  void set_home();
  void send_tpdos();
  // Event-driven TPDOs (type 254/255): sent when their data changed, at most once per inhibit time
  // (0x18xx:03) and at least once per event timer (0x18xx:05).
  void send_event_tpdos(std::int64_t now_us);
  void latch_setpoint();
  void run_profile();
  double sync_period_s() const;
  void publish();
  void set_controlword(std::uint16_t cw);
  void enter_fault(std::uint16_t code);
  void watch_master(std::int64_t now_us);
  void produce_heartbeat(std::int64_t now_us);
  std::int32_t velocity() const;
  std::int64_t consumer_window_us() const;

  drivers::CanBus& bus_;
  SimDriveConfig config_;
  slave::ObjectDictionary od_;  // communication parameters, commands, and what the drive reports
  bool powered_ = false;
  std::uint8_t nmt_ = slave::nmt::kBootUp;  // as the heartbeat carries it

  // Communication state.
  std::int64_t next_heartbeat_us_ = 0;
  slave::RpdoInbox rpdos_;
  std::uint32_t syncs_ = 0;

  // Drive state (the physical side; published into the dictionary before the bus reads it).
  hal::DriveState state_ = hal::DriveState::kNotReadyToSwitchOn;
  std::uint16_t controlword_ = 0;  // last one the state machine saw (fault reset is an edge)
  std::int32_t position_ = 0;
  std::int32_t previous_position_ = 0;
  std::uint16_t error_code_ = 0;
  std::uint8_t error_register_ = 0;
  bool following_error_ = false;
  // Timers of the slow personality and the 0x1016 heartbeat consumer.
  std::int64_t boot_at_us_ = -1;
  std::int64_t operational_at_us_ = -1;
  std::int64_t master_seen_us_ = -1;
  bool master_lost_ = false;
  // Homing: count = physical + count_offset_ (random per power-on with power_up_seed).
  std::mt19937_64 rng_;
  std::int64_t count_offset_ = 0;
  bool homing_running_ = false;
  bool homing_attained_ = false;
  bool homing_error_ = false;
  std::uint32_t homing_syncs_ = 0;
  // Profile position.
  bool pp_latch_ = false;     // bit 4 rose: take the target once the RPDO's objects are all written
  bool pp_ack_ = false;       // statusword bit 12
  bool pp_active_ = false;    // a move runs toward pp_goal_
  std::int32_t pp_goal_ = 0;  // counts
  double pp_pos_ = 0.0;       // counts, the profile's exact position
  double pp_vel_ = 0.0;       // counts/s
  std::uint32_t pp_latched_ = 0;
  // Event-driven TPDOs.
  std::array<std::int64_t, 4> tpdo_sent_us_{};
  std::array<std::array<std::uint8_t, 8>, 4> tpdo_data_{};
  std::array<std::uint8_t, 4> tpdo_dlc_{};
  std::array<bool, 4> tpdo_held_{};  // changed while inhibited: due when the inhibit time is over
};

}  // namespace loom::sim_can

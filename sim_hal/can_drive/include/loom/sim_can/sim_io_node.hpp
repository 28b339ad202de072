// A simulated CiA 401 generic I/O module as a CANopen node, with the loom's plant behind it: two
// pneumatic pistons (valve coil → end sensors after a fill time), the shuttle-arrival sensors (the
// shuttle rides the helix shaft's carrier), each of these six safety sensors twice (two independent
// switches on their own terminals), the beater's load cell (from the crank angle), the e-stop chain and
// the operator buttons (set by the test or the executable's control file).
//
// Deliberately independent of the master's codec: its object dictionary is one table in
// sim_io_node.cpp (index, sub, size, access, PDO direction, default) from which SDO read/write, PDO
// mapping checks and PDO packing all come, through the slave-side CiA 301 code in slave_od.hpp (shared
// with SimDriveNode), not drivers/. A bug in the master's encoders therefore cannot hide behind the
// same bug in the peer. Only the transport (drivers::CanBus, CanFrame) is shared.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "loom/drivers/can_frame.hpp"
#include "loom/hal/types.hpp"
#include "loom/sim_can/slave_od.hpp"
#include "loom/sim_hal/knotter.hpp"
#include "loom/sim_hal/random.hpp"

namespace loom::sim_can {

// One switch of a safety sensor that reads `level` whatever the plant does (a welded reed contact, a
// light barrier blinded by fluff): the other channel of that sensor still follows the plant, which is
// what a two-channel master must notice.
struct StuckSwitch {
  bool active = false;
  hal::SafetySensor sensor = hal::SafetySensor::kPistonAExtended;
  bool second = false;  // false: the first switch (terminals 0..5), true: the second (terminals 16..21)
  bool level = false;   // what its terminal reads
};

// What the module's inputs physically see, set by the caller every step (RT-safe plain data).
struct IoPlant {
  double helix_rad = 0.0;   // helix shaft position (shuttle carrier), rad
  double crank_rad = 0.0;   // beat-up crank position, rad
  bool estop_open = false;  // e-stop chain opened
  bool button_start = false;
  bool button_pause = false;
  bool button_ack = false;
  bool row_knotted = false;
  bool silent = false;  // cable pulled: sends nothing, hears nothing
  StuckSwitch stuck{};  // test hook: one channel of one safety sensor stuck
  // The knotting heads' servos and the carriage (SI, by the loom's axis slot; read only when the module
  // has heads behind it: SimIoConfig::knotting).
  std::array<double, hal::kMaxAxes> axis_position{};
};

struct SimIoConfig {
  std::uint8_t node_id = 4;
  // Plant.
  double width_m = 1.2;              // loom width between the selvedge sensors' far edges
  double helix_lead_m = 0.1;         // shuttle travel per helix turn
  double selvedge_window_m = 0.005;  // shuttle sensor sees the shuttle this close to its selvedge
  double piston_travel_s = 0.25;     // valve switched → the piston reaches its other end
  // > 0: the plant (pistons) advances this much per SYNC received — machine time follows the
  // controller's cycle, as it does on a real loom whose controller keeps time. 0: wall-clock time.
  // (A controller under emulation runs slower than real time; a wall-clock plant then moves faster
  // than any frame can, and the sequencer rightly calls that a sensor fault.)
  double plant_cycle_s = 0.0;
  double beat_peak_n = 90.0;                 // load-cell force at the fell
  double fell_crank_rad = 3.14159265358979;  // crank angle (mod 2π) at which the beater meets the fell
  double load_cell_n_per_count = 0.01;
  // The knotting heads behind the module (heads = 0: none), as the in-process simulator models them
  // (sim_hal::SimKnotter, no misses): head h's gripper on output terminal 8 + h, its cutter on 20 + h, its
  // yarn-present switch on input terminal 24 + h. Their servos and the carriage come in
  // IoPlant::axis_position. A weaver asked for a hand tie is the person at the HIL bench (ctl next).
  sim_hal::SimKnotting knotting{};
  double weaver_s = 5.0;
  // Interoperability variants.
  bool fixed_mapping = false;  // 0x16xx/0x1Axx read-only, sub 0 included
  // A module's own factory TPDO1/TPDO2 (mapping entries index << 16 | sub << 8 | bits), e.g. a fixed
  // 16-input module's {0x60000108, 0x60000208}; empty = the defaults in sim_io_node.cpp.
  std::vector<std::uint32_t> tpdo1_factory_mapping;
  std::vector<std::uint32_t> tpdo2_factory_mapping;
  // 8-bit input groups the module has (1..8; 2 = a 16-input module without the second channels'
  // terminals 16..21): 0x6000:00 says so, its default TPDO1 carries them all (at most three), the missing
  // groups read 0 and cannot be mapped (abort 0x06040041).
  int digital_input_groups = 8;
  std::vector<std::uint16_t> absent_objects;  // e.g. 0x1016, 0x6206, 0x1802
  // A module described by an EDS (eds_dictionary.hpp: io_from_eds()): its own dictionary table (sorted,
  // 1/2/4-byte entries) instead of the built-in one — its objects, access, PDO mapping and identity, e.g.
  // digital inputs only as 16-bit groups (0x6100). Empty: the built-in module.
  std::vector<slave::Entry> dictionary;
  std::int64_t boot_delay_us = 0;  // power-on / reset → boot-up
};

class SimIoNode : private slave::ObjectHooks, private slave::FrameHandlers {
 public:
  // Configure-time only. Powered off until power_on().
  SimIoNode(drivers::CanBus& bus, SimIoConfig config);
  ~SimIoNode();

  void power_on(std::int64_t now_us);  // RT-safe
  void power_off();                    // RT-safe
  // RT-safe. One received frame; the node filters what concerns it.
  void handle(const drivers::CanFrame& frame, std::int64_t now_us);
  // RT-safe. Plant and timers (boot-up, heartbeat producer, master-heartbeat consumer).
  void step(std::int64_t now_us, const IoPlant& plant);
  std::int64_t next_deadline_us() const;

  // Observation (tests, logs).
  std::uint8_t node_id() const { return config_.node_id; }
  std::uint8_t nmt_state() const { return nmt_; }  // 0x00, 0x04, 0x05, 0x7F as on the wire
  std::uint8_t outputs(int byte) const;            // what drives the valve coils now (error state applied)
  std::uint8_t inputs(int byte) const { return in_[static_cast<std::size_t>(byte)]; }  // terminals 8·byte..
  std::int16_t analog_counts() const { return analog_; }
  bool comm_lost() const { return comm_lost_; }   // master heartbeat consumer expired
  double piston_a() const { return piston_[0]; }  // 0 = retracted … 1 = extended
  double piston_b() const { return piston_[1]; }
  // The heads' carpet as knotted (null without heads).
  const sim_hal::SimKnotter* knotter() const { return knotter_.get(); }

 private:
  // The bus's writes reach the module through the ObjectHooks (timers react to them).
  void written(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::int64_t now_us) override;
  std::uint32_t check(std::uint16_t index, std::uint8_t sub, std::uint32_t value) const override;

  // Frames routed by slave::deliver.
  void on_nmt(std::uint8_t command, std::int64_t now_us) override;
  void on_watched_heartbeat(std::int64_t now_us) override;
  void on_sdo(const drivers::CanFrame& f, std::int64_t now_us) override;
  void on_sync(std::int64_t now_us) override;
  void on_rpdo(int pdo, const drivers::CanFrame& f, std::int64_t now_us) override;
  void send_tpdo(int pdo);
  void send_changed_inputs();
  void reset_communication(std::int64_t now_us);
  void reset_application();
  void send(const drivers::CanFrame& f);
  void update_inputs();
  void set_factory_mapping(int tpdo, const std::vector<std::uint32_t>& entries);
  int input_groups() const;
  std::array<bool, hal::kSafetySensorCount> safety_sensors_truth() const;
  void move_pistons(double dt);
  void step_knotter();
  void watch_master(std::int64_t now_us);
  void produce_heartbeat(std::int64_t now_us);

  drivers::CanBus& bus_;
  SimIoConfig config_;
  slave::ObjectDictionary od_;
  bool powered_ = false;
  std::uint8_t nmt_ = slave::nmt::kPreOperational;  // as the heartbeat carries it
  std::int64_t boot_at_us_ = -1;                    // pending boot-up
  std::int64_t next_hb_us_ = 0;
  std::int64_t master_seen_us_ = -1;
  bool comm_lost_ = false;
  std::uint32_t syncs_ = 0;
  std::uint64_t syncs_total_ = 0, syncs_at_last_step_ = 0;  // plant_cycle_s: machine time in SYNCs
  slave::RpdoInbox rpdos_;
  // Plant.
  IoPlant plant_{};
  std::int64_t last_step_us_ = -1;
  std::array<double, 2> piston_{0.0, 0.0};
  static constexpr std::size_t kInputGroups = 8;
  static constexpr double kKnotterPeriodS = 0.01;  // the plant steps at least every 10 ms (weaver timing)
  std::array<std::uint8_t, kInputGroups> in_{};    // terminals 0..63
  std::unique_ptr<sim_hal::SimKnotter> knotter_;
  sim_hal::SimRandom rng_{1};
  int shuttle_side_ = 0;  // -1 left, +1 right, 0 not yet seen at a selvedge
  std::int16_t analog_ = 0;
};

}  // namespace loom::sim_can

// The CAN servo axes' configuration as plain data: each axis' drive (bus, node, scaling, supervision,
// referencing) and the port's timing, with the checks and the bus-load plan made on them before any
// frame is sent. Configure-time only and free of SocketCAN, so the loom config library and offline tools
// use it without the CANopen runtime (can_axis_port.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "loom/drivers/bus_load.hpp"
#include "loom/drivers/status.hpp"

namespace loom::drivers {

struct NodeDescription;  // node_description.hpp

// 20-bit single-turn encoders; the carriage's belt advances 20 mm per motor revolution (a 100 mm pulley
// behind a 5:1 gearbox).
inline constexpr double kCountsPerRev = 1048576.0;  // 2^20
inline constexpr double kDefaultCountsPerRad = kCountsPerRev / (2.0 * std::numbers::pi);
inline constexpr double kDefaultCarriageLeadM = 0.020;
inline constexpr double kDefaultCountsPerM = kCountsPerRev / kDefaultCarriageLeadM;

// How the master commands a drive (CiA 402 modes of operation, 0x6060).
enum class DriveMode : std::uint8_t {
  // Cyclic synchronous position (8): a set-point every SYNC; RPDO1 and TPDO1 synchronous, every cycle.
  kCyclicPosition,
  // Profile position (1): the move's end target once, with the set-point handshake (controlword bit 4,
  // statusword bit 12); the drive runs its own profile. For axes that move point to point between knots
  // (the colour selectors): their PDOs are event-driven, so an idle axis costs the bus almost nothing.
  kProfilePosition,
};

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
  // The drive's EDS (node_description.hpp), when the machine description names one: its identity is
  // checked and its configuration written (only what differs) at bring-up. Null: none.
  std::shared_ptr<const NodeDescription> description{};
  DriveMode mode = DriveMode::kCyclicPosition;
  // Profile position only: the drive's own profile (0x6081, 0x6083 = 0x6084, 0x6086), SI/s and SI/s²,
  // the limits the sequencer plans the axis' moves with (jerk: the drive's jerk-limited profile when it
  // offers one). 0 = not given (refused for a profile-position axis).
  double profile_velocity = 0.0;
  double profile_acceleration = 0.0;
  double profile_jerk = 0.0;
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
  double boot_timeout_s = 2.0;   // wait for every boot-up after NMT reset-node
  double state_timeout_s = 0.5;  // CiA 402 transition not confirmed → fault
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
  // Profile-position axes (DriveMode::kProfilePosition): their TPDO1 is event-driven (transmission type
  // 255), sent when the statusword or position changes but at most once per inhibit time (0x1800:03) and
  // at least once per event timer (0x1800:05) while nothing changes, so a still axis is still supervised.
  // Their RPDO1 is sent only when the controlword or target changes. These set the bus-load plan's rates.
  // 30 ms: with it four selectors share a 2 ms bus with four cyclic knotters within the 70 % budget (at
  // 10 ms they would take 75 %). It costs a knot cycle at most that much of a selector's arrival being seen
  // late (its set-point starts the move at once; only the ack and "target reached" wait for the inhibit),
  // and the wait for a selector's arrival is derived from it (derive.cpp: selector_settle_s).
  double profile_tpdo_inhibit_s = 0.030;
  double profile_tpdo_event_timer_s = 0.100;
  bool tpdo2 = false;                   // velocity + torque PDO (adds 3 frames per cycle)
  std::uint8_t tpdo2_every_n_sync = 1;  // 1..240
  std::uint32_t bitrate_bps = 1'000'000;
  double bus_load_budget = 0.70;  // worst-case utilisation allowed, per bus
  // The other nodes' frames per bus (the I/O modules), by bus index: a bus that carries only an I/O
  // module is still one of the port's buses, with its own master, SYNC and budget.
  std::array<std::vector<FrameGroup>, kMaxBuses> other_frames_per_cycle{};
  // The other nodes on each bus (the I/O modules), by bus index: each sends its heartbeat with the same
  // producer time as the drives (heartbeat_producer_s), which the bus-load plan counts.
  std::array<std::uint32_t, kMaxBuses> other_nodes_per_bus{};
};

// Which setting a refusal of the configuration is about. The loom config maps it (with the axis) to the
// TOML key that sets it, so its file:line:col message never has to read the refusal's text.
enum class CanAxisField {
  kAxisCount,
  // Per axis (CanAxisConfigFault::axis says which).
  kNodeId,          // outside 1..127
  kNodeIdTaken,     // another axis on the same bus has it
  kNodeIdIsMaster,  // the master's own node id
  kBus,
  kCountsPerUnit,
  kRatedEffort,
  kFerrorMin,
  kFerrorK,
  kBringUpTimeouts,  // boot_timeout_s / operational_timeout_s
  kHomingMethod,
  kHomingSpeed,  // homing_speed / homing_accel
  kHomeOffset,
  // The port's.
  kCyclePeriod,
  kHeartbeatProducer,
  kHeartbeatConsumer,
  kSdoTimeout,
  kBootTimeout,
  kStateTimeout,
  kTpdo2EveryN,
  kBitrate,
  kOperationalTimeout,
  kMasterNode,
  kMasterHeartbeat,  // master_heartbeat_s / master_consumer_s
  kBusLoadBudget,
  kOtherFrames,
};

// A refusal: the field, the axis it is on (per-axis fields), and the message naming field, value and reason.
struct CanAxisConfigFault {
  CanAxisField field = CanAxisField::kAxisCount;
  std::size_t axis = 0;  // index into CanAxisPortConfig::axes
  std::string message;   // "axes.carriage.counts_per_unit = 0 must be a positive number"
};

// Configure-time only. The first refusal of the configuration, or none.
std::optional<CanAxisConfigFault> find_fault(const CanAxisPortConfig& config);
// Configure-time only. Error naming the field and its value (find_fault()'s message).
Status validate(const CanAxisPortConfig& config);
// Configure-time only. The buses the configuration uses: 1 + the highest bus an axis or another node is on.
std::size_t bus_count(const CanAxisPortConfig& config);
// Configure-time only. The worst cycle this configuration puts on bus `bus` (compute_cycle_load()): SYNC,
// each cyclic-position drive's RPDO1 and TPDO1, every drive's TPDO2 when configured, the other nodes'
// frames on that bus (the I/O modules) and the master heartbeat; one blocking 8-byte frame and one EMCY;
// every node's heartbeat at its producer time; each profile-position drive's RPDO1 and TPDO1 at its
// inhibit-time rate. The same figure the port checks against its budget when it configures, and
// `loomctl check` prints per bus.
BusLoad planned_bus_load(const CanAxisPortConfig& config, std::size_t bus = 0);

}  // namespace loom::drivers

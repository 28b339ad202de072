// One CANopen master per CAN bus, and the interface of the remote nodes it owns.
//
// CanMaster is the bus owner: it alone drains the bus (at most kMaxFramesPerPoll frames per tick),
// decodes error frames (bus-off, controller restart), dispatches every frame by node id, sends SYNC and
// the master's own heartbeat, and brings every node of its bus up in ONE NMT sequence:
//   reset-node to all → every boot-up → each node's SDO configuration (its profile) → start all →
//   every operational heartbeat.
// Each remote node is a CanNode: a profile driver (CiA 402 axis, CiA 401 I/O module) that only does its
// profile, plus the master's NodeSupervisor for it (heartbeat consumer, boot-up, EMCY latch). bring_up()
// blocks with timeouts (configure-time); poll() and start_cycle() are the RT path: fixed arrays only.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "loom/drivers/can_frame.hpp"
#include "loom/drivers/configure_clock.hpp"
#include "loom/drivers/node_supervisor.hpp"
#include "loom/drivers/status.hpp"
#include "loom/hal/types.hpp"

namespace loom::drivers {

class SdoClient;
struct NodeDescription;

// A node's bring-up windows and heartbeat consumer time (seconds; 0 window = the master's default).
struct NodeTiming {
  double boot_timeout_s = 0.0;
  double operational_timeout_s = 0.0;
  double heartbeat_consumer_s = 0.250;
};

// One remote node on a master's bus: its profile driver, with the master's supervision of it.
class CanNode {
 public:
  virtual ~CanNode() = default;
  virtual std::uint8_t node_id() const = 0;
  // Configure-time. "node 3 (helix)", the prefix of every message about this node.
  virtual std::string label() const = 0;
  virtual NodeTiming timing() const = 0;
  // Configure-time. A bring-up of this node's bus begins: forget the RT state of the last one.
  virtual void bring_up_started() = 0;
  // Configure-time. The profile's SDO configuration, between boot-up and NMT start. Errors name the node.
  virtual Status configure_profile(SdoClient& sdo) = 0;
  // Configure-time. The whole bus is operational: the node's RT frames go to `bus` from now on.
  virtual void brought_up(CanBus& bus) = 0;
  // RT-safe. One of this node's frames that is neither its heartbeat nor its EMCY (PDOs).
  virtual void on_profile_frame(hal::Tick now, const CanFrame& frame) noexcept = 0;
  // RT-safe. The operator acknowledged: clear the latches whose cause is gone.
  virtual void acknowledge() noexcept { supervisor_.acknowledge(false); }
  // True when the profile reports the node's EMCY itself (a drive's in its axis feedback); otherwise the
  // master reports it as a link fault that stops every axis.
  virtual bool reports_own_emcy() const noexcept { return false; }
  // Configure-time. The node's EDS when the machine description names one (null: none): bring_up()
  // checks its 0x1018 identity against it and makes its writes (only those that differ) before
  // configure_profile(), which then writes only what still differs as well.
  virtual const NodeDescription* description() const { return nullptr; }

  // RT-safe. A frame from the bus: heartbeat and EMCY to the supervisor, the rest to the profile. Frames
  // of other nodes and error frames are ignored; nothing is taken before the node was brought up.
  void on_frame(hal::Tick now, const CanFrame& frame) noexcept;
  // RT-safe. After the tick's frames: the heartbeat consumer.
  void supervise(hal::Tick now) noexcept { supervisor_.supervise(now); }
  // RT-safe. 0 = healthy, else the master's link verdict on the node (node lost, rebooted, not operational).
  std::uint16_t link_fault_code() const noexcept { return supervisor_.link_fault(); }
  bool heard_again(hal::Tick now) const noexcept { return supervisor_.heard_again(now); }
  const NodeSupervisor& supervisor() const noexcept { return supervisor_; }
  // Malformed frames of this node (PDO of the wrong length, bad heartbeat or EMCY), cumulative.
  std::uint32_t rx_errors() const noexcept { return rx_errors_; }

 protected:
  friend class CanMaster;  // arms the supervisor when the bus is up
  NodeSupervisor supervisor_;
  std::uint32_t rx_errors_ = 0;
};

struct CanMasterConfig {
  double cycle_period_s = 0.002;  // SYNC period = tick period
  double sdo_timeout_s = 0.100;
  double boot_timeout_s = 2.0;  // default window for nodes that give none
  double operational_timeout_s = 1.0;
  // The master's own heartbeat (0x700 + id, operational) every master_heartbeat_s; 0 = none.
  std::uint8_t master_node_id = 0x7F;
  double master_heartbeat_s = 0.100;
};

class CanMaster {
 public:
  static constexpr std::size_t kMaxNodes = hal::kMaxAxes + 4;
  static constexpr int kMaxFramesPerPoll = 64;

  CanMaster() = default;
  explicit CanMaster(const CanMasterConfig& config) : config_(config) {}

  // Configure-time. The node table (not the RT state): add() is false when full or the id is taken.
  void clear_nodes();
  bool add(CanNode& node);
  std::size_t node_count() const { return n_nodes_; }

  // Configure-time; blocks with timeouts. The one NMT sequence for every node of this bus. Errors name
  // the node and the step; a bus-off during it is an error.
  Status bring_up(CanBus& bus, ConfigureClock& clock);

  // RT-safe. Drains at most kMaxFramesPerPoll frames (error frames latch bus-off; the rest go to their
  // node by id; EMCYs of unknown nodes latch a foreign EMCY), then supervises every node.
  void poll(hal::Tick now) noexcept;
  // RT-safe. SYNC, and the master heartbeat when it is due.
  void start_cycle(hal::Tick now) noexcept;
  // RT-safe. Sends and counts a dropped frame.
  void send(const CanFrame& frame) noexcept;

  // RT-safe state.
  bool configured() const noexcept { return configured_; }
  bool bus_off() const noexcept { return bus_off_; }
  // Any fault on this bus that must stop every axis: bus-off, a node lost, an EMCY of a node that does
  // not report it itself, an EMCY of a node nobody owns.
  bool any_fault() const noexcept;
  // RT-safe. Fills link_fault/link_fault_kind/link_fault_code when this bus has a link fault and `link`
  // has none yet (the first fault found is reported), and adds this bus' counters.
  void report_link(hal::LinkStatus& link) const noexcept;
  // RT-safe. How far a link fault on this bus has recovered; `silent` names the node still missing.
  hal::LinkRecovery recovery(hal::Tick now, std::uint8_t& silent) const noexcept;
  // RT-safe. The operator acknowledged: the foreign EMCY latch and every node's latches.
  void acknowledge() noexcept;
  std::uint32_t tx_dropped() const noexcept { return tx_dropped_; }
  std::uint32_t rx_errors() const noexcept { return rx_errors_; }
  std::uint32_t consumer_ticks(const CanNode& node) const;
  const CanMasterConfig& config() const { return config_; }

 private:
  void handle_error_frame(const CanFrame& frame) noexcept;

  CanMasterConfig config_{};
  std::array<CanNode*, kMaxNodes> nodes_{};
  std::size_t n_nodes_ = 0;
  std::array<std::int8_t, 128> index_of_node_ = make_empty_index();
  CanBus* bus_ = nullptr;
  bool configured_ = false;
  bool bus_off_ = false;    // latched until bring_up()
  bool restarted_ = false;  // the controller restarted after the bus-off
  std::uint16_t foreign_emcy_code_ = 0;
  std::uint32_t master_hb_ticks_ = 0;
  hal::Tick next_master_hb_ = 0;
  std::uint32_t tx_dropped_ = 0;
  std::uint32_t rx_errors_ = 0;

  static std::array<std::int8_t, 128> make_empty_index() {
    std::array<std::int8_t, 128> a{};
    a.fill(-1);
    return a;
  }
};

}  // namespace loom::drivers

// Test rig: drivers::CanAxisPort on its drivers::CanNetwork on one endpoint of the fake CAN network,
// simulated CiA 402 drives on another, all in virtual time. Other nodes (I/O modules) join the rig's
// network before configure(). configure() runs on a virtual ConfigureClock whose idle() advances time and
// steps the drives; tick() is one RT cycle as drivers::CanHal runs it (poll → read → decide → cycle →
// write) followed by one cycle period.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "fake_can_network.hpp"
#include "loom/drivers/can_axis_port.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/sim_can/sim_drive_rack.hpp"

namespace loom::test {

inline std::vector<sim_can::SimDriveConfig> three_drives(std::int32_t p1 = 0, std::int32_t p2 = 0,
                                                         std::int32_t p3 = 0) {
  std::vector<sim_can::SimDriveConfig> v(3);
  const std::int32_t p[] = {p1, p2, p3};
  for (std::size_t i = 0; i < 3; ++i) {
    v[i].node_id = static_cast<std::uint8_t>(i + 1);
    v[i].initial_position = p[i];
  }
  return v;
}

class DriveRig {
 public:
  using Policy = std::function<void(const hal::AxisFeedbacks&, hal::AxisCommands&)>;

  explicit DriveRig(std::vector<sim_can::SimDriveConfig> nodes,
                    drivers::CanAxisPortConfig config = drivers::CanAxisPortConfig{})
      : master(net.add_endpoint()),
        drives(net.add_endpoint()),
        rack(drives, nodes),
        network(drivers::can_master_config(config), drivers::bus_count(config)),
        port(network, std::move(config)),
        clock(*this) {}

  drivers::Status configure() {
    rack.power_on(now_us);
    return drivers::bring_up(network, port, master, clock);
  }

  // Let `dt_us` of virtual time pass in 100 µs steps: the network delivers, the drives react.
  void advance(std::int64_t dt_us) {
    const std::int64_t end = now_us + dt_us;
    while (now_us < end) {
      now_us = std::min(end, now_us + 100);
      net.set_time(now_us);
      rack.step(now_us);
    }
  }

  // One RT cycle.
  void tick(const Policy& policy) {
    network.poll(tick_index);
    port.read_axes(tick_index, feedback, link);
    policy(feedback, commands);
    network.start_cycle(tick_index);
    port.write_axes(tick_index, commands);
    ++tick_index;
    advance(period_us());
  }
  std::int64_t period_us() const {
    return static_cast<std::int64_t>(port.config().cycle_period_s * 1e6 + 0.5);
  }

  // Every axis: request `r`; hold the target at the measured position.
  static Policy hold(hal::AxisRequest r) {
    return [r](const hal::AxisFeedbacks& fb, hal::AxisCommands& cmd) {
      for (std::size_t i = 0; i < cmd.size(); ++i) {
        cmd[i].request = r;
        cmd[i].target_position = fb[i].position;
      }
    };
  }
  bool all_in(hal::DriveState s) const {
    for (std::size_t i = 0; i < port.axis_count(); ++i) {
      if (feedback[i].state != s) return false;
    }
    return true;
  }
  // Tick with `policy` until `done` or `max_ticks`; returns the ticks used.
  int run_until(const Policy& policy, const std::function<bool()>& done, int max_ticks) {
    int n = 0;
    while (!done() && n < max_ticks) {
      tick(policy);
      ++n;
    }
    return n;
  }

  // RPDO1 frames the master sent to `node` from log index `from` on.
  std::vector<drivers::Rpdo1> rpdos_to(std::uint8_t node, std::size_t from = 0) const {
    std::vector<drivers::Rpdo1> out;
    for (std::size_t i = from; i < net.log().size(); ++i) {
      const auto& l = net.log()[i];
      if (l.from != 0) continue;
      if (auto r = drivers::unpack_rpdo1(l.frame, node)) out.push_back(*r);
    }
    return out;
  }

  using VirtualClock = RigClock<DriveRig>;

  FakeCanNetwork net;
  FakeCanNetwork::Endpoint& master;  // endpoint 0
  FakeCanNetwork::Endpoint& drives;  // endpoint 1
  sim_can::SimDriveRack rack;
  drivers::CanNetwork network;  // the rig's one bus
  drivers::CanAxisPort port;
  VirtualClock clock;
  std::int64_t now_us = 0;
  hal::Tick tick_index = 0;
  hal::AxisFeedbacks feedback{};
  hal::LinkStatus link{};
  hal::AxisCommands commands{};
};

}  // namespace loom::test

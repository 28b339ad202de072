// The CAN axis port's per-tick path allocates nothing: operator new is counted while read_axes and
// write_axes run over 20,000 ticks against simulated drives, including a heartbeat loss, a drive fault
// with EMCY and a fault reset; likewise the I/O node's read_io/write_io. (Its own executable: tests/support's
// counter replaces the global operator new.)
#include <gtest/gtest.h>

#include "alloc_counter.hpp"
#include "fake_can_network.hpp"
#include "loom/drivers/can_axis_port.hpp"
#include "loom/drivers/can_hal.hpp"
#include "loom/drivers/can_io_modules.hpp"
#include "loom/drivers/can_io_port.hpp"
#include "loom/hal/hal.hpp"
#include "loom/sim_can/sim_drive_rack.hpp"
#include "loom/sim_can/sim_io_node.hpp"
#include "relay_bus.hpp"

namespace loom::test {
namespace {

class Clock final : public drivers::ConfigureClock {
 public:
  Clock(FakeCanNetwork& net, sim_can::SimDriveRack& rack, std::int64_t& now)
      : net_(net), rack_(rack), now_(now) {}
  std::int64_t now_us() override { return now_; }
  void idle() override {
    now_ += 100;
    net_.set_time(now_);
    rack_.step(now_);
  }

 private:
  FakeCanNetwork& net_;
  sim_can::SimDriveRack& rack_;
  std::int64_t& now_;
};

TEST(CanAxisPortRt, TwentyThousandTicksWithoutAllocation) {
  FakeCanNetwork net;
  auto& master = net.add_endpoint();
  auto& drives = net.add_endpoint();
  std::vector<sim_can::SimDriveConfig> nodes(3);
  for (std::size_t i = 0; i < 3; ++i) nodes[i].node_id = static_cast<std::uint8_t>(i + 1);
  sim_can::SimDriveRack rack(drives, nodes);
  RelayBus relay(master);
  const drivers::CanAxisPortConfig config{};
  drivers::CanNetwork network(drivers::can_master_config(config), 1);
  drivers::CanAxisPort port(network, config);
  std::int64_t now = 0;
  Clock clock(net, rack, now);
  rack.power_on(now);
  ASSERT_TRUE(drivers::bring_up(network, port, relay, clock).is_ok());
  relay.set_passthrough(false);

  hal::AxisFeedbacks fb{};
  hal::LinkStatus link{};
  hal::AxisCommands cmd{};
  long worst = 0;
  bool saw_fault = false, saw_enabled = false;
  for (hal::Tick k = 0; k < 20'000; ++k) {
    if (k == 8'000) rack.node(2).inject_fault(0x2310);
    if (k == 15'000) rack.node(1).power_off();
    const long before = static_cast<long>(allocations());
    count_allocations(true);
    network.poll(k);
    port.read_axes(k, fb, link);
    for (std::size_t i = 0; i < 3; ++i) {
      cmd[i].request =
          fb[i].state == hal::DriveState::kFault ? hal::AxisRequest::kFaultReset : hal::AxisRequest::kEnable;
      cmd[i].target_position =
          fb[i].position + (fb[i].state == hal::DriveState::kOperationEnabled ? 1e-4 : 0.0);
    }
    network.start_cycle(k);
    port.write_axes(k, cmd);
    count_allocations(false);
    worst = std::max(worst, static_cast<long>(allocations()) - before);
    saw_fault = saw_fault || fb[2].fault;
    saw_enabled = saw_enabled || fb[0].state == hal::DriveState::kOperationEnabled;
    relay.exchange();
    for (int s = 0; s < 20; ++s) {
      now += 100;
      net.set_time(now);
      rack.step(now);
    }
    relay.exchange();
  }
  EXPECT_TRUE(saw_enabled);
  EXPECT_TRUE(saw_fault);
  EXPECT_TRUE(link.link_fault);  // the heartbeat loss was seen too
  EXPECT_EQ(allocations(), 0u);
  EXPECT_EQ(worst, 0);
}

// The I/O node's per-tick path (on_frame through the network's drain, read_io with both channels of
// every safety sensor, write_io) allocates nothing either, with the default wiring's three input bytes
// and a switch sticking and freeing on the way — through CanIoModules, as the machine runs it.
TEST(CanIoPortRt, FiveThousandTicksWithoutAllocation) {
  FakeCanNetwork net;
  auto& master = net.add_endpoint();
  auto& drives = net.add_endpoint();
  std::vector<sim_can::SimDriveConfig> nodes(3);
  for (std::size_t i = 0; i < 3; ++i) nodes[i].node_id = static_cast<std::uint8_t>(i + 1);
  sim_can::SimDriveRack rack(drives, nodes);
  sim_can::SimIoConfig io_cfg;
  sim_can::SimIoNode io(drives, io_cfg);
  rack.attach_io(io, {0, 2, drivers::kDefaultCountsPerRad, drivers::kDefaultCountsPerRad});
  RelayBus relay(master);
  drivers::CanAxisPortConfig axis_cfg;
  axis_cfg.other_frames_per_cycle[0] = drivers::io_frames_per_cycle(drivers::IoWiring{});
  drivers::CanNetwork network(drivers::can_master_config(axis_cfg), 1);
  drivers::CanAxisPort port(network, axis_cfg);
  drivers::CanIoPort io_port{drivers::CanIoConfig{}};
  ASSERT_TRUE(network.add(io_port));
  std::int64_t now = 0;
  Clock clock(net, rack, now);
  rack.power_on(now);
  ASSERT_TRUE(drivers::bring_up(network, port, relay, clock).is_ok());
  relay.set_passthrough(false);

  drivers::CanIoModules modules;
  modules.add(io_port);
  drivers::CanHal hal(network, port, modules);
  hal::HalInputs in{};
  hal::HalOutputs out{};
  long worst = 0;
  bool saw_disagreement = false;
  for (hal::Tick k = 0; k < 5'000; ++k) {
    rack.io_controls().stuck = {k >= 1'000 && k < 3'000, hal::SafetySensor::kShuttleAtRight, true, true};
    const long before = static_cast<long>(allocations());
    count_allocations(true);
    hal.read(k, in);
    for (std::size_t i = 0; i < 3; ++i) {
      out.axes[i].request = hal::AxisRequest::kEnable;
      out.axes[i].target_position = in.axes[i].position;
    }
    out.io.piston_a_extend = (k / 500) % 2 == 1;
    hal.write(k, out);
    count_allocations(false);
    worst = std::max(worst, static_cast<long>(allocations()) - before);
    saw_disagreement = saw_disagreement || in.io.second_channel[5] != in.io.shuttle_at_right;
    relay.exchange();
    for (int s = 0; s < 20; ++s) {
      now += 100;
      net.set_time(now);
      rack.step(now);
    }
    relay.exchange();
  }
  EXPECT_TRUE(saw_disagreement);
  EXPECT_FALSE(in.link.link_fault);
  EXPECT_EQ(in.io.refreshed, 4'999);
  EXPECT_EQ(worst, 0);
}

}  // namespace
}  // namespace loom::test

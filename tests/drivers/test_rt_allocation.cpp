// The CAN axis port's per-tick path allocates nothing: operator new is counted while read_axes and
// write_axes run over 20,000 ticks against simulated drives, including a heartbeat loss, a drive fault
// with EMCY and a fault reset. (Its own executable: tests/support's counter replaces the global operator new.)
#include <gtest/gtest.h>


#include "fake_can_network.hpp"
#include "loom/drivers/can_axis_port.hpp"
#include "loom/sim_can/sim_drive_rack.hpp"
#include "relay_bus.hpp"
#include "alloc_counter.hpp"

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
  drivers::CanAxisPort port{drivers::CanAxisPortConfig{}};
  std::int64_t now = 0;
  Clock clock(net, rack, now);
  rack.power_on(now);
  ASSERT_TRUE(port.configure(relay, clock).is_ok());
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
    port.read_axes(k, fb, link);
    for (std::size_t i = 0; i < 3; ++i) {
      cmd[i].request =
          fb[i].state == hal::DriveState::kFault ? hal::AxisRequest::kFaultReset : hal::AxisRequest::kEnable;
      cmd[i].target_position =
          fb[i].position + (fb[i].state == hal::DriveState::kOperationEnabled ? 1e-4 : 0.0);
    }
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

}  // namespace
}  // namespace loom::test

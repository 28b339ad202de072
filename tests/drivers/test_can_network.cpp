// An I/O module alone on a CanNetwork: no drive and no CanAxisPort on the bus. The network brings it up
// and polls it, CanIoPort reads and writes through it, and the link status (a lost module) comes from the
// network. The module's peer is sim_can::SimIoNode (its own object dictionary and frame layouts,
// independent of the master's codec) on the other endpoint of the fake CAN network, in virtual time.
#include <gtest/gtest.h>

#include <cstdint>

#include "fake_can_network.hpp"
#include "loom/drivers/can_io_port.hpp"
#include "loom/drivers/can_network.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/sim_can/sim_io_node.hpp"

namespace loom::test {
namespace {

constexpr std::int64_t kPeriodUs = 2000;

struct IoAloneRig {
  IoAloneRig()
      : master(net.add_endpoint()),
        module_end(net.add_endpoint()),
        module(module_end, sim_can::SimIoConfig{}),
        network(drivers::CanMasterConfig{}, 1),
        port(drivers::CanIoConfig{}),
        clock(*this) {}

  // Virtual time in 100 µs steps: the network delivers, the module takes its frames and steps its plant.
  void advance(std::int64_t dt_us) {
    const std::int64_t end = now_us + dt_us;
    while (now_us < end) {
      now_us = std::min(end, now_us + 100);
      net.set_time(now_us);
      drivers::CanFrame f;
      while (module_end.receive(f)) module.handle(f, now_us);
      module.step(now_us, plant);
    }
  }
  drivers::Status configure() {
    module.power_on(now_us);
    if (!network.add(port)) return drivers::Status::error("the module's node could not be registered");
    return network.configure(master, clock);
  }
  // One RT cycle as a loop with only this module runs it: the network polls, the port reads; the network
  // starts the cycle (SYNC), the port writes.
  void tick(const hal::DigitalOutputs& out = {}) {
    network.poll(now);
    network.read_link(now, link);
    port.read_io(now, hal::AxisFeedbacks{}, in);
    network.start_cycle(now);
    port.write_io(now, out);
    ++now;
    advance(kPeriodUs);
  }

  using VirtualClock = RigClock<IoAloneRig>;

  FakeCanNetwork net;
  FakeCanNetwork::Endpoint& master;
  FakeCanNetwork::Endpoint& module_end;
  sim_can::IoPlant plant{};
  sim_can::SimIoNode module;
  drivers::CanNetwork network;
  drivers::CanIoPort port;
  VirtualClock clock;
  std::int64_t now_us = 0;
  hal::Tick now = 0;
  hal::DigitalInputs in{};
  hal::LinkStatus link{};
};

TEST(CanNetwork, BringsUpAnIoModuleAloneAndReadsAndWritesThroughIt) {
  IoAloneRig r;
  const drivers::Status s = r.configure();
  ASSERT_TRUE(s) << s.message();
  EXPECT_TRUE(r.port.configured());
  EXPECT_EQ(r.module.nmt_state(), 0x05) << "the module is operational";
  for (int i = 0; i < 5; ++i) r.tick();
  EXPECT_FALSE(r.link.link_fault);
  EXPECT_EQ(r.link.recovery, hal::LinkRecovery::kHealthy);
  // Inputs: the module's TPDO after every SYNC; pistons at rest, shuttle at the left selvedge (helix 0).
  EXPECT_EQ(r.in.refreshed, r.now - 1);
  EXPECT_TRUE(r.in.estop_ok);
  EXPECT_TRUE(r.in.piston_a_retracted && r.in.piston_b_retracted);
  EXPECT_TRUE(r.in.shuttle_at_left);
  r.plant.button_start = true;
  for (int i = 0; i < 3; ++i) r.tick();
  EXPECT_TRUE(r.in.button_start);

  // Outputs: valve A and the green lamp reach the module's terminals, and A's piston extends.
  hal::DigitalOutputs out;
  out.piston_a_extend = true;
  out.lamp_green = true;
  for (int i = 0; i < 3; ++i) r.tick(out);
  EXPECT_EQ(r.module.outputs(0) & 0x13, 0x11);  // valve A (bit 0) and green (bit 4), not valve B
  for (int i = 0; i < 150; ++i) r.tick(out);
  EXPECT_TRUE(r.in.piston_a_extended);
  EXPECT_FALSE(r.in.piston_a_retracted);
}

TEST(CanNetwork, ALostModuleIsTheNetworksLinkFaultWithOneEvent) {
  IoAloneRig r;
  ASSERT_TRUE(r.configure());
  for (int i = 0; i < 5; ++i) r.tick();
  ASSERT_FALSE(r.link.link_fault);
  r.plant.silent = true;  // cable pulled
  int events = 0;
  for (int i = 0; i < 400 && !r.link.link_fault; ++i) {
    r.tick();
    events += r.link.fault_raised ? 1 : 0;
  }
  ASSERT_TRUE(r.link.link_fault) << "the module's heartbeat consumer never tripped";
  EXPECT_EQ(r.link.link_fault_kind, hal::FaultKind::kNodeLost);
  EXPECT_EQ(r.link.link_fault_code, drivers::fault_code::kHeartbeatLost);
  EXPECT_EQ(r.link.recovery, hal::LinkRecovery::kNodeSilent);
  EXPECT_EQ(r.link.silent_node, r.port.node_id());
  for (int i = 0; i < 20; ++i) {
    r.tick();
    events += r.link.fault_raised ? 1 : 0;
  }
  EXPECT_EQ(events, 1);
  EXPECT_TRUE(r.network.any_fault());
}

TEST(CanNetwork, NotConfiguredIsACommunicationFault) {
  IoAloneRig r;
  hal::LinkStatus link;
  r.network.read_link(0, link);
  EXPECT_TRUE(link.link_fault);
  EXPECT_EQ(link.link_fault_kind, hal::FaultKind::kCommunication);
  EXPECT_TRUE(link.fault_raised);
  r.network.read_link(1, link);
  EXPECT_FALSE(link.fault_raised) << "the same report is not a new event";
}

}  // namespace
}  // namespace loom::test

// The conformance suite (port_conformance.hpp) over the CAN ports as `--hal socketcan` joins them:
// drivers::CanAxisPort for three CiA 402 drives and drivers::CanIoModules over one drivers::CanIoPort,
// joined by drivers::CanHal on their drivers::CanNetwork, on the in-memory CAN network of tests/support
// with the simulated nodes of sim_hal/can_drive as the plant
// (their own object dictionaries and frame layouts: a peer that does not share the master's code). The
// port talks through a RelayBus with fixed arrays, so the allocation check measures the port alone (the
// in-memory network allocates as it queues); frames cross between ticks.
#include <cmath>
#include <memory>
#include <vector>

#include "../drivers/relay_bus.hpp"
#include "fake_can_network.hpp"
#include "loom/drivers/can_axis_port.hpp"
#include "loom/drivers/can_hal.hpp"
#include "loom/drivers/can_io_modules.hpp"
#include "loom/drivers/can_io_port.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/sim_can/sim_drive_rack.hpp"
#include "loom/sim_can/sim_io_node.hpp"
#include "port_conformance.hpp"

namespace loom::test {
namespace {

// The counts per SI unit of the default axes (beat crank, carriage, helix): the drives' plant is in counts.
constexpr std::array<double, hal::kCoreAxisCount> kCountsPerUnit{
    drivers::kDefaultCountsPerRad, drivers::kDefaultCountsPerM, drivers::kDefaultCountsPerRad};
constexpr std::uint8_t kIoNode = 4;  // sim_can::SimIoConfig's and drivers::CanIoConfig's default node id

}  // namespace

class CanPortRig final : public PortRig {
 public:
  void make(const PortPlan& plan) override {
    plan_ = plan;
    std::vector<sim_can::SimDriveConfig> nodes(hal::kCoreAxisCount);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      nodes[i].node_id = static_cast<std::uint8_t>(i + 1);
      nodes[i].initial_position = static_cast<std::int32_t>(std::llround(plan.start[i] * kCountsPerUnit[i]));
    }
    // Each piece is built here, in order, on the network the rig owns (they hold references to it).
    net_ = std::make_unique<FakeCanNetwork>();
    auto& master = net_->add_endpoint();
    auto& devices = net_->add_endpoint();
    rack_ = std::make_unique<sim_can::SimDriveRack>(devices, nodes);
    io_ = std::make_unique<sim_can::SimIoNode>(devices, sim_can::SimIoConfig{});
    rack_->attach_io(*io_, {0, 2, drivers::kDefaultCountsPerRad, drivers::kDefaultCountsPerRad});
    relay_ = std::make_unique<RelayBus>(master);
    drivers::CanAxisPortConfig axis_cfg;
    axis_cfg.other_frames_per_cycle[0] = drivers::io_frames_per_cycle(drivers::IoWiring{});
    network_ = std::make_unique<drivers::CanNetwork>(drivers::can_master_config(axis_cfg), 1);
    axes_ = std::make_unique<drivers::CanAxisPort>(*network_, axis_cfg);
    io_port_ = std::make_unique<drivers::CanIoPort>(drivers::CanIoConfig{});
    ASSERT_TRUE(network_->add(*io_port_));
    modules_ = std::make_unique<drivers::CanIoModules>();
    modules_->add(*io_port_);
    hal_ = std::make_unique<drivers::CanHal>(*network_, *axes_, *modules_);
    devices_ = &devices;
    rack_->power_on(now_us_);
    Clock clock(*this);
    const drivers::Status s = drivers::bring_up(*network_, *axes_, *relay_, clock);
    ASSERT_TRUE(s) << s.message();
    relay_->set_passthrough(false);
  }
  hal::Hal& hal() override { return *hal_; }
  std::size_t axis_count() const override { return axes_->axis_count(); }
  void between_ticks(hal::Tick now) override {
    relay_->exchange();  // what the port sent goes on the wire
    advance(static_cast<std::int64_t>(std::llround(axes_->config().cycle_period_s * 1e6)));
    if (plan_.event != PlantEvent::kNone && now + 1 == plan_.at) strike();
    relay_->exchange();  // what the devices answered waits for the next read
  }
  double plant_position(std::size_t slot) const override {
    return static_cast<double>(rack_->node(slot).position()) / kCountsPerUnit[slot];
  }
  std::array<double, 2> plant_pistons() const override { return {io_->piston_a(), io_->piston_b()}; }
  // The drives' heartbeat producer time (100 ms) plus the master's consumer time (250 ms), at 2 ms.
  int node_lost_within_ticks() const override { return 175 + 2; }
  const char* skip_reason(Check) const override { return nullptr; }

 private:
  class Clock final : public drivers::ConfigureClock {
   public:
    explicit Clock(CanPortRig& rig) : rig_(rig) {}
    std::int64_t now_us() override { return rig_.now_us_; }
    void idle() override { rig_.advance(100); }

   private:
    CanPortRig& rig_;
  };
  void advance(std::int64_t dt_us) {
    const std::int64_t end = now_us_ + dt_us;
    while (now_us_ < end) {
      now_us_ = std::min(end, now_us_ + 100);
      net_->set_time(now_us_);
      rack_->step(now_us_);
    }
  }
  void strike() {
    const auto node = static_cast<std::uint8_t>(plan_.axis + 1);
    switch (plan_.event) {
      case PlantEvent::kDriveFault:
        rack_->node(plan_.axis).inject_fault(plan_.code);
        break;
      case PlantEvent::kEmcy:  // the drive reports, and stays enabled
        devices_->send(drivers::make_emcy(node, plan_.code, 0x03));
        break;
      case PlantEvent::kAxisSilent:
        rack_->node(plan_.axis).power_off();
        break;
      case PlantEvent::kIoSilent:
        rack_->io_controls().silent = true;
        break;
      case PlantEvent::kIoEmcy:
        devices_->send(drivers::make_emcy(kIoNode, plan_.code, 0x01));
        break;
      case PlantEvent::kIoUnsupervised:  // its heartbeats are lost on the wire; its PDOs still pass
        net_->drop = [](const drivers::CanFrame& f) { return f.id == 0x700u + kIoNode; };
        break;
      case PlantEvent::kNone:
        break;
    }
    net_->set_time(now_us_);
  }

  PortPlan plan_;
  std::int64_t now_us_ = 0;
  std::unique_ptr<FakeCanNetwork> net_;
  FakeCanNetwork::Endpoint* devices_ = nullptr;
  std::unique_ptr<sim_can::SimDriveRack> rack_;
  std::unique_ptr<sim_can::SimIoNode> io_;
  std::unique_ptr<RelayBus> relay_;
  std::unique_ptr<drivers::CanNetwork> network_;
  std::unique_ptr<drivers::CanAxisPort> axes_;
  std::unique_ptr<drivers::CanIoPort> io_port_;
  std::unique_ptr<drivers::CanIoModules> modules_;
  std::unique_ptr<drivers::CanHal> hal_;
};

// ctest names each case PortConformance.<case><loom::test::CanPortRig>.
INSTANTIATE_TYPED_TEST_SUITE_P(PortConformance, PortConformance, ::testing::Types<CanPortRig>);

}  // namespace loom::test

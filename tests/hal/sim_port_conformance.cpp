// The conformance suite (port_conformance.hpp) over the simulated loom: one SimWorld as both the axis port
// and the I/O port, as `--hal sim` joins it, with the scene's injected faults as the plant's events.
#include <cmath>
#include <memory>

#include "loom/sim_hal/sim_world.hpp"
#include "port_conformance.hpp"

namespace loom::test {

class SimPortRig final : public PortRig {
 public:
  void make(const PortPlan& plan) override {
    sim_hal::SceneSpec scene;  // "ideal": the axes track their targets exactly
    if (plan.event != PlantEvent::kNone) {
      sim_hal::FaultInjection f;
      f.at_s = static_cast<double>(plan.at) * machine_.period_s;
      f.axis = plan.axis;
      f.axis_name = hal::core_axis_layout().name(plan.axis);
      f.code = plan.code;
      f.kind = plan.event == PlantEvent::kDriveFault ? sim_hal::InjectedFault::kDriveFault
               : plan.event == PlantEvent::kEmcy     ? sim_hal::InjectedFault::kEmcy
                                                     : sim_hal::InjectedFault::kHeartbeatLoss;
      scene.faults.push_back(f);
    }
    world_ = std::make_unique<sim_hal::SimWorld>(machine_, scene);
    hal::AxisFeedbacks at{};
    for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i) at[i].position = plan.start[i];
    world_->set_initial_state(at, {0.0, 0.0});
    hal_ = std::make_unique<hal::PortHal>(*world_, *world_);
  }
  hal::Hal& hal() override { return *hal_; }
  std::size_t axis_count() const override { return machine_.axis_count; }
  void between_ticks(hal::Tick) override {}  // write() integrated the period already
  double plant_position(std::size_t slot) const override { return world_->axis(slot).position; }
  std::array<double, 2> plant_pistons() const override { return world_->pistons(); }
  int node_lost_within_ticks() const override {
    return static_cast<int>(std::ceil(sim_hal::kSimHeartbeatTimeoutS / machine_.period_s)) + 1;
  }
  const char* skip_reason(Check check) const override {
    switch (check) {
      case Check::kIoSilent:
      case Check::kIoEmcy:
        return "the simulated I/O node cannot fall silent or report a fault: no scene fault does that (its "
               "e-stop and sensor faults are inputs, not device faults)";
      case Check::kIoFaultSafeOutputs:
        return "the simulated I/O node is always supervised (it cannot be lost), so there is no case in "
               "which "
               "this port must replace the loop's outputs: the sequencer's stop path writes the safe outputs";
      case Check::kHoldsTargetUntilEnabled:
        return "a simulated drive enables in the tick it is asked and follows that tick's target: holding "
               "the target at the read position on enable is the sequencer's job here (the README's "
               "promise of the CAN port only)";
      default:
        return nullptr;
    }
  }

 private:
  sim_hal::SimMachine machine_{};
  std::unique_ptr<sim_hal::SimWorld> world_;
  std::unique_ptr<hal::PortHal> hal_;  // the world as both ports, as the machine joins them
};

// ctest names each case PortConformance.<case><loom::test::SimPortRig>.
INSTANTIATE_TYPED_TEST_SUITE_P(PortConformance, PortConformance, ::testing::Types<SimPortRig>);

}  // namespace loom::test

// Cost of one RT tick of CanAxisPort (read_axes draining 3 TPDO1 frames + write_axes packing SYNC and
// 3 RPDOs) with the bus replaced by fixed arrays, i.e. the driver's own work without socket syscalls.
#include <benchmark/benchmark.h>

#include "fake_can_network.hpp"
#include "loom/drivers/can_axis_port.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/sim_can/sim_drive_rack.hpp"
#include "relay_bus.hpp"

namespace {

class Clock final : public loom::drivers::ConfigureClock {
 public:
  Clock(loom::test::FakeCanNetwork& net, loom::sim_can::SimDriveRack& rack) : net_(net), rack_(rack) {}
  std::int64_t now_us() override { return now_; }
  void idle() override {
    now_ += 100;
    net_.set_time(now_);
    rack_.step(now_);
  }

 private:
  loom::test::FakeCanNetwork& net_;
  loom::sim_can::SimDriveRack& rack_;
  std::int64_t now_ = 0;
};

void BM_CanAxisPortTick(benchmark::State& state) {
  using namespace loom;
  test::FakeCanNetwork net;
  auto& master = net.add_endpoint();
  auto& drives = net.add_endpoint();
  std::vector<sim_can::SimDriveConfig> nodes(3);
  for (std::size_t i = 0; i < 3; ++i) nodes[i].node_id = static_cast<std::uint8_t>(i + 1);
  sim_can::SimDriveRack rack(drives, nodes);
  test::RelayBus relay(master);
  const drivers::CanAxisPortConfig config{};
  drivers::CanNetwork network(drivers::can_master_config(config), 1);
  drivers::CanAxisPort port(network, config);
  Clock clock(net, rack);
  rack.power_on(0);
  if (!drivers::bring_up(network, port, relay, clock).is_ok()) {
    state.SkipWithError("configure failed");
    return;
  }
  relay.set_passthrough(false);
  const drivers::CanFrame tpdo[3] = {drivers::pack_tpdo1(1, {0x1237, 100}),
                                     drivers::pack_tpdo1(2, {0x1237, 200}),
                                     drivers::pack_tpdo1(3, {0x1237, 300})};
  hal::AxisFeedbacks fb{};
  hal::LinkStatus link{};
  hal::AxisCommands cmd{};
  for (auto& c : cmd) c.request = hal::AxisRequest::kEnable;
  hal::Tick k = 0;
  for (auto _ : state) {
    for (const auto& f : tpdo) relay.push_rx(f);
    network.poll(k);
    port.read_axes(k, fb, link);
    for (std::size_t i = 0; i < 3; ++i) cmd[i].target_position = fb[i].position + 1e-3;
    network.start_cycle(k);
    port.write_axes(k, cmd);
    relay.clear_tx();
    ++k;
    if (k % 40 == 0) {  // keep the heartbeat consumer fed (every 80 ms of ticks)
      for (std::uint8_t n = 1; n <= 3; ++n)
        relay.push_rx(drivers::make_heartbeat(n, drivers::NmtState::kOperational));
    }
    benchmark::DoNotOptimize(fb);
  }
}
BENCHMARK(BM_CanAxisPortTick);

}  // namespace

BENCHMARK_MAIN();

// libFuzzer harness: the receive path of drivers::CanAxisPort (the RT master of the three servo axes)
// fed an arbitrary sequence of frames between its ticks.
//
// Once per process the port is brought up for real — NMT + SDO against simulated CiA 402 drives over the
// in-memory CAN network of the driver tests — and ticked until every drive is in Operation Enabled. That
// port is the template: each input starts from a copy of it, now on a bus the input alone feeds (the
// simulated drives are gone), and plays operations read from the input:
//   any frame (any COB-ID, data, error or RTR frame, DLC 0..8);
//   a well-formed TPDO1 or heartbeat of one of the three drives with fuzzed contents (reaches deep states);
//   a tick (read_axes → hold the measured position with a fuzzed request, homing included → write_axes);
//   a gap of several ticks; a full transmit queue for a few sends.
// The helix (node 3) is referenced by CiA 402 homing (an incremental encoder, index-pulse method 34): its
// PDOs carry the mode (0x6060 / 0x6061) as a seventh byte, and a fuzzed TPDO1 of it may claim any mode
// and any homing status bits. Besides crashes and sanitizer reports it checks what the sequencer relies
// on: feedback is always finite, a bus-off error frame, once read, latches the link fault, and an axis
// never reads referenced and in homing error at once.
#include <fuzzer/FuzzedDataProvider.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "drive_rig.hpp"
#include "fuzzed_frame.hpp"
#include "loom/drivers/can_error_frame.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/drivers/pdo.hpp"

namespace {

using namespace loom;

[[noreturn]] void fail(const char* what, std::size_t axis, double value) {
  std::fprintf(stderr, "CanAxisPort property violated: %s (axis %zu, value %g)\n", what, axis, value);
  std::abort();
}

constexpr int kMaxOps = 512;

// The port's bus. During bring-up it relays to the simulated drives' network; afterwards it delivers
// only what the input queues, and accepts (or, while "full", refuses) what the port sends.
class FuzzBus final : public drivers::CanBus {
 public:
  drivers::CanBus* relay = nullptr;
  int tx_full = 0;

  drivers::SendResult send(const drivers::CanFrame& f) noexcept override {
    if (relay != nullptr) return relay->send(f);
    if (tx_full > 0) {
      --tx_full;
      return drivers::SendResult::kWouldBlock;
    }
    return drivers::SendResult::kOk;
  }
  bool receive(drivers::CanFrame& f) noexcept override {
    if (relay != nullptr) return relay->receive(f);
    if (head_ == tail_) return false;
    f = queue_[head_++ % queue_.size()];
    return true;
  }
  // False (frame lost, as on a real controller's full rx FIFO) when the queue is full.
  bool queue(const drivers::CanFrame& f) {
    if (tail_ - head_ == queue_.size()) return false;
    queue_[tail_++ % queue_.size()] = f;
    return true;
  }
  std::size_t pending() const { return tail_ - head_; }
  void reset() {
    head_ = tail_ = 0;
    tx_full = 0;
  }

 private:
  std::array<drivers::CanFrame, 256> queue_{};
  std::size_t head_ = 0, tail_ = 0;
};

std::vector<sim_can::SimDriveConfig> drives() {
  std::vector<sim_can::SimDriveConfig> v = test::three_drives(1000, -2000, 3000);
  v[2].supports_homing = true;
  v[2].index_every = 65536;
  v[2].power_up_seed = 12345;  // fixed: the template is the same in every run
  return v;
}
drivers::CanAxisPortConfig config() {
  drivers::CanAxisPortConfig c;
  c.axes[2].homing_method = 34;
  c.axes[2].home_offset = 0.5;
  c.axes[2].homing_speed = 20.0;
  c.axes[2].homing_accel = 200.0;
  return c;
}

struct Template {
  test::DriveRig rig{drives(), config()};
  FuzzBus bus;
  hal::Tick tick = 0;

  Template() {
    rig.rack.power_on(rig.now_us);
    bus.relay = &rig.master;
    const drivers::Status s = drivers::bring_up(rig.network, rig.port, bus, rig.clock);
    if (!s.is_ok()) {
      std::fprintf(stderr, "bring-up against the simulated drives failed: %s\n", s.message().c_str());
      std::abort();
    }
    rig.run_until(
        test::DriveRig::hold(hal::AxisRequest::kEnable),
        [&] { return rig.all_in(hal::DriveState::kOperationEnabled); }, 100);
    if (!rig.all_in(hal::DriveState::kOperationEnabled)) {
      std::fprintf(stderr, "the simulated drives did not reach Operation Enabled\n");
      std::abort();
    }
    bus.relay = nullptr;
    tick = rig.tick_index;
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Template* const tmpl = new Template();  // process lifetime; never freed (libFuzzer exits)
  FuzzBus& bus = tmpl->bus;
  bus.reset();
  // The configured network (bound to `bus`) and port with the drives enabled, copied: the copy's node
  // tables are its own port's axes.
  drivers::CanNetwork network = tmpl->rig.network;
  network.clear_nodes();
  drivers::CanAxisPort port(tmpl->rig.port, network);
  hal::Tick now = tmpl->tick;
  hal::AxisFeedbacks feedback{};
  hal::LinkStatus link{};
  hal::AxisCommands commands{};
  bool bus_off_queued = false;

  FuzzedDataProvider in(data, size);
  for (int op = 0; op < kMaxOps && in.remaining_bytes() > 0; ++op) {
    switch (in.ConsumeIntegralInRange<int>(0, 5)) {
      case 0: {  // any frame
        const drivers::CanFrame f = fuzz::any_frame(in);
        if (bus.queue(f) && f.is_error() && drivers::decode_error_frame(f).bus_off) bus_off_queued = true;
        break;
      }
      case 1: {  // a TPDO1 of one of the drives (the homing drive's with its mode display byte)
        const auto node = in.ConsumeIntegralInRange<std::uint8_t>(1, 3);
        drivers::Tpdo1 p;
        p.statusword = in.ConsumeIntegral<std::uint16_t>();
        p.position_actual = in.ConsumeIntegral<std::int32_t>();
        drivers::CanFrame f = drivers::pack_tpdo1(node, p);
        if (node == 3) {
          f.dlc = 7;
          f.data[6] = in.ConsumeBool() ? std::uint8_t{6} : in.ConsumeIntegral<std::uint8_t>();
        }
        (void)bus.queue(f);
        break;
      }
      case 2: {  // a heartbeat / boot-up of one of the drives, any state byte
        drivers::CanFrame f = drivers::make_heartbeat(in.ConsumeIntegralInRange<std::uint8_t>(1, 3),
                                                      drivers::NmtState::kOperational);
        f.data[0] = in.ConsumeIntegral<std::uint8_t>();
        (void)bus.queue(f);
        break;
      }
      case 3: {  // one RT cycle
        const auto request = static_cast<hal::AxisRequest>(in.ConsumeIntegralInRange<int>(0, 4));
        network.poll(now);
        port.read_axes(now, feedback, link);
        for (std::size_t i = 0; i < feedback.size(); ++i) {
          const auto& fb = feedback[i];
          if (!std::isfinite(fb.position)) fail("position not finite", i, fb.position);
          if (!std::isfinite(fb.velocity)) fail("velocity not finite", i, fb.velocity);
          if (!std::isfinite(fb.effort)) fail("effort not finite", i, fb.effort);
          if (fb.referenced && fb.homing_error)
            fail("referenced and in homing error at once", i, fb.position);
        }
        if (bus_off_queued && bus.pending() == 0 && !link.link_fault)
          fail("bus-off read but no link fault", 0, 0.0);
        test::DriveRig::hold(request)(feedback, commands);
        network.start_cycle(now);
        port.write_axes(now, commands);
        ++now;
        break;
      }
      case 4:  // ticks without a cycle (a stalled loop)
        now += in.ConsumeIntegralInRange<int>(1, 1000);
        break;
      case 5:
        bus.tx_full = in.ConsumeIntegralInRange<int>(0, 8);
        break;
    }
  }
  return 0;
}

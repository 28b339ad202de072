// In-memory CAN network for driver tests: any number of endpoints (each a drivers::CanBus) joined like
// sockets on one vcan — a frame sent by one endpoint reaches every other endpoint — plus fault
// injection (drop by predicate, fixed latency, transmit queue full, bus-off) and a log of every frame.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <vector>

#include "loom/drivers/can_frame.hpp"
#include "loom/drivers/configure_clock.hpp"

namespace loom::test {

// Virtual time for a bring-up on a fake network: every idle() lets 100 µs pass on the rig (its network and
// the simulated nodes behind it). `Rig` has `std::int64_t now_us` and `advance(std::int64_t dt_us)`.
template <typename Rig>
class RigClock final : public drivers::ConfigureClock {
 public:
  explicit RigClock(Rig& rig) : rig_(rig) {}
  std::int64_t now_us() override { return rig_.now_us; }
  void idle() override { rig_.advance(100); }

 private:
  Rig& rig_;
};

class FakeCanNetwork {
 public:
  class Endpoint final : public drivers::CanBus {
   public:
    Endpoint(FakeCanNetwork& net, std::size_t id) : net_(net), id_(id) {}
    drivers::SendResult send(const drivers::CanFrame& frame) noexcept override {
      return net_.transmit(id_, frame);
    }
    bool receive(drivers::CanFrame& frame) noexcept override {
      if (rx_.empty()) return false;
      frame = rx_.front();
      rx_.pop_front();
      return true;
    }
    std::size_t pending() const { return rx_.size(); }

   private:
    friend class FakeCanNetwork;
    FakeCanNetwork& net_;
    std::size_t id_;
    std::deque<drivers::CanFrame> rx_;
  };

  struct Logged {
    std::int64_t time_us;
    std::size_t from;
    drivers::CanFrame frame;
    bool dropped;
  };

  Endpoint& add_endpoint();
  // Advance the network clock; frames whose latency has elapsed are delivered.
  void set_time(std::int64_t now_us);
  std::int64_t now_us() const { return now_us_; }

  // ---- fault injection --------------------------------------------------------------------------
  // Frames for which this returns true are lost on the wire (logged as dropped).
  std::function<bool(const drivers::CanFrame&)> drop;
  std::int64_t latency_us = 0;
  // The next `n` send() calls report a full transmit queue and lose the frame.
  void fill_tx_queue(int n) { would_block_ = n; }
  // Bus-off: every endpoint receives an error frame; sends fail until restart(), which (as the kernel
  // does after restart-ms) tells every endpoint with a CAN_ERR_RESTARTED error frame.
  void bus_off();
  void restart();

  const std::vector<Logged>& log() const { return log_; }

 private:
  struct InFlight {
    std::int64_t due_us;
    std::size_t from;
    drivers::CanFrame frame;
  };
  drivers::SendResult transmit(std::size_t from, const drivers::CanFrame& frame);
  void deliver(std::size_t from, const drivers::CanFrame& frame);

  std::vector<std::unique_ptr<Endpoint>> endpoints_;
  std::deque<InFlight> in_flight_;
  std::vector<Logged> log_;
  std::int64_t now_us_ = 0;
  int would_block_ = 0;
  bool bus_off_ = false;
};

}  // namespace loom::test

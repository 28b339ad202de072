// A CanBus with fixed-size queues for measuring the RT path alone: in pass-through mode it forwards to
// an inner bus (used during configure()); in held mode send/receive touch only its own arrays, and the
// test moves frames to and from the inner bus between ticks, outside the measured region.
#pragma once

#include <array>
#include <cstddef>

#include "loom/drivers/can_frame.hpp"

namespace loom::test {

class RelayBus final : public drivers::CanBus {
 public:
  explicit RelayBus(drivers::CanBus& inner) : inner_(inner) {}

  void set_passthrough(bool on) { passthrough_ = on; }

  drivers::SendResult send(const drivers::CanFrame& f) noexcept override {
    if (passthrough_) return inner_.send(f);
    if (ntx_ == tx_.size()) return drivers::SendResult::kWouldBlock;
    tx_[ntx_++] = f;
    return drivers::SendResult::kOk;
  }
  bool receive(drivers::CanFrame& f) noexcept override {
    if (passthrough_) return inner_.receive(f);
    if (rx_head_ == rx_tail_) return false;
    f = rx_[rx_head_++ % rx_.size()];
    return true;
  }

  // Outside the measured region: flush what the port sent, fetch what arrived.
  void exchange() {
    for (std::size_t i = 0; i < ntx_; ++i) inner_.send(tx_[i]);
    ntx_ = 0;
    drivers::CanFrame f;
    while (rx_tail_ - rx_head_ < rx_.size() && inner_.receive(f)) push_rx(f);
  }
  void push_rx(const drivers::CanFrame& f) { rx_[rx_tail_++ % rx_.size()] = f; }
  void clear_tx() { ntx_ = 0; }
  std::size_t tx_count() const { return ntx_; }

 private:
  drivers::CanBus& inner_;
  bool passthrough_ = true;
  std::array<drivers::CanFrame, 64> tx_{};
  std::size_t ntx_ = 0;
  std::array<drivers::CanFrame, 256> rx_{};
  std::size_t rx_head_ = 0;
  std::size_t rx_tail_ = 0;
};

}  // namespace loom::test

// In-memory CAN network with fault injection (see fake_can_network.hpp).
#include "fake_can_network.hpp"

#include "loom/drivers/can_error_frame.hpp"

namespace loom::test {

FakeCanNetwork::Endpoint& FakeCanNetwork::add_endpoint() {
  endpoints_.push_back(std::make_unique<Endpoint>(*this, endpoints_.size()));
  return *endpoints_.back();
}

drivers::SendResult FakeCanNetwork::transmit(std::size_t from, const drivers::CanFrame& frame) {
  if (bus_off_) return drivers::SendResult::kError;
  if (would_block_ > 0) {
    --would_block_;
    return drivers::SendResult::kWouldBlock;
  }
  const bool lost = drop && drop(frame);
  log_.push_back({now_us_, from, frame, lost});
  if (lost) return drivers::SendResult::kOk;  // the sender cannot tell
  if (latency_us <= 0) {
    deliver(from, frame);
  } else {
    in_flight_.push_back({now_us_ + latency_us, from, frame});
  }
  return drivers::SendResult::kOk;
}

void FakeCanNetwork::deliver(std::size_t from, const drivers::CanFrame& frame) {
  for (auto& ep : endpoints_) {
    if (ep->id_ != from) ep->rx_.push_back(frame);
  }
}

void FakeCanNetwork::set_time(std::int64_t now_us) {
  now_us_ = now_us;
  while (!in_flight_.empty() && in_flight_.front().due_us <= now_us_) {
    deliver(in_flight_.front().from, in_flight_.front().frame);
    in_flight_.pop_front();
  }
}

void FakeCanNetwork::bus_off() {
  bus_off_ = true;
  for (auto& ep : endpoints_) ep->rx_.push_back(drivers::make_bus_off_error_frame());
}

void FakeCanNetwork::restart() {
  bus_off_ = false;
  for (auto& ep : endpoints_) ep->rx_.push_back(drivers::make_restarted_error_frame());
}

}  // namespace loom::test

// Supervision of one remote node (see node_supervisor.hpp). RT-safe: fixed fields, no allocation.
#include "loom/drivers/node_supervisor.hpp"

#include "loom/drivers/emcy.hpp"
#include "loom/drivers/nmt.hpp"

namespace loom::drivers {

void NodeSupervisor::arm(std::uint32_t consumer_ticks) {
  *this = NodeSupervisor{};
  armed_ = true;
  consumer_ticks_ = consumer_ticks;
}

bool NodeSupervisor::on_heartbeat(hal::Tick now, const CanFrame& frame) noexcept {
  const auto hb = parse_heartbeat(frame);
  if (!hb) return false;
  last_heartbeat_ = now;
  if (hb->state == NmtState::kBootUp) booted_ = true;
  if (link_fault_ == 0 && hb->state == NmtState::kBootUp) link_fault_ = fault_code::kNodeRebooted;
  if (link_fault_ == 0 && hb->state != NmtState::kOperational && hb->state != NmtState::kBootUp) {
    link_fault_ = fault_code::kNodeNotOperational;
  }
  return true;
}

bool NodeSupervisor::on_emcy(const CanFrame& frame) noexcept {
  const auto e = parse_emcy(frame);
  if (!e) return false;
  if (e->code != 0) {
    emcy_code_ = e->code;
    acknowledged_ = false;
  } else if (acknowledged_) {
    emcy_code_ = 0;
  }
  return true;
}

void NodeSupervisor::supervise(hal::Tick now) noexcept {
  if (!armed_) return;
  // Heartbeats during bring-up carry no tick: the consumer starts counting at the first tick.
  if (last_heartbeat_ == hal::kNeverTick) last_heartbeat_ = now;
  if (link_fault_ == 0 && now - last_heartbeat_ > static_cast<hal::Tick>(consumer_ticks_)) {
    link_fault_ = fault_code::kHeartbeatLost;
  }
}

void NodeSupervisor::acknowledge(bool still_in_fault) noexcept {
  acknowledged_ = true;
  if (!still_in_fault) emcy_code_ = 0;
}

bool NodeSupervisor::heard_again(hal::Tick now) const noexcept {
  return booted_ || (last_heartbeat_ != hal::kNeverTick &&
                     now - last_heartbeat_ <= static_cast<hal::Tick>(consumer_ticks_));
}

}  // namespace loom::drivers

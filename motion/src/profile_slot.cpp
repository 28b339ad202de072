// The profile hand-over. Ordering: publish() releases the fully built set with its exchange, the
// loop's exchange acquires it; the loop releases the retired set, collect() acquires it before
// deleting. A retired set is only handed back once the previous one was collected, so each pointer
// has exactly one owner at every instant.
#include "loom/motion/profile_slot.hpp"

#include "loom/motion/errors.hpp"

namespace loom::motion {

ProfileSlot::ProfileSlot(std::unique_ptr<const ProfileSet> initial) : active_(initial.get()) {
  if (!active_) throw MotionError(ErrorCode::kInvalidInput, "profile slot needs an initial profile set");
  initial.release();
}

ProfileSlot::~ProfileSlot() {
  delete active_;
  delete pending_.load(std::memory_order_acquire);
  delete retired_.load(std::memory_order_acquire);
}

bool ProfileSlot::swap_at_row_boundary() noexcept {
  if (retired_.load(std::memory_order_acquire) != nullptr) return false;
  const ProfileSet* next = pending_.exchange(nullptr, std::memory_order_acq_rel);
  if (next == nullptr) return false;
  retired_.store(active_, std::memory_order_release);
  active_ = next;
  return true;
}

void ProfileSlot::publish(std::unique_ptr<const ProfileSet> next) {
  if (!next) throw MotionError(ErrorCode::kInvalidInput, "profile slot: cannot publish a null profile set");
  delete pending_.exchange(next.release(), std::memory_order_acq_rel);
}

bool ProfileSlot::collect() {
  const ProfileSet* old = retired_.exchange(nullptr, std::memory_order_acq_rel);
  delete old;
  return old != nullptr;
}

}  // namespace loom::motion

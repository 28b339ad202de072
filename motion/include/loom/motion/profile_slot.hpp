// Hands a new ProfileSet (a new recipe) to the running loop without stopping it. A non-RT thread
// publishes a fully built set; the loop adopts it at a row boundary with two atomic pointer
// exchanges — no lock, no allocation, no free — and hands the old set back, which the non-RT side
// deletes. Exactly one loop thread and one non-RT thread use a slot.
#pragma once

#include <atomic>
#include <memory>

#include "loom/motion/profile_set.hpp"

namespace loom::motion {

class ProfileSlot {
 public:
  // Configure-time only. The set the loop starts with (must not be null: throws MotionError).
  explicit ProfileSlot(std::unique_ptr<const ProfileSet> initial);
  ~ProfileSlot();
  ProfileSlot(const ProfileSlot&) = delete;
  ProfileSlot& operator=(const ProfileSlot&) = delete;

  // RT-safe, loop thread only. The set in use; valid until the loop's next swap_at_row_boundary().
  const ProfileSet& active() const noexcept { return *active_; }

  // RT-safe, loop thread only; call between rows. Adopts the newest published set, unless none is
  // waiting or the set retired by the previous swap has not been collected yet (then it keeps the
  // current set and tries again at the next row). Returns true when it switched.
  bool swap_at_row_boundary() noexcept;

  // Non-RT thread only. Offer a new set; one still waiting (never seen by the loop) is deleted here.
  // Throws MotionError for a null set.
  void publish(std::unique_ptr<const ProfileSet> next);
  // Non-RT thread only. Delete the set the loop retired, if any; true when one was deleted.
  bool collect();
  // Either thread: a published set is waiting for the loop.
  bool pending() const noexcept { return pending_.load(std::memory_order_acquire) != nullptr; }

 private:
  const ProfileSet* active_;                         // owned; touched by the loop thread only
  std::atomic<const ProfileSet*> pending_{nullptr};  // owned; non-RT → loop
  std::atomic<const ProfileSet*> retired_{nullptr};  // owned; loop → non-RT
  static_assert(std::atomic<const ProfileSet*>::is_always_lock_free);
};

}  // namespace loom::motion

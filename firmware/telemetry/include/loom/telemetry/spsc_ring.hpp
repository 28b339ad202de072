// A lock-free single-producer single-consumer ring: the only channel from the RT loop to the telemetry
// thread. The producer never blocks and never allocates; when the ring is full it refuses (and the
// caller may count a drop), so a slow publisher can never stall the loop.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>

namespace loom::telemetry {

// A fixed 64 rather than std::hardware_destructive_interference_size: GCC warns that the latter is
// ABI-unstable across tuning flags, and 64 is the line size of the x86-64 and arm64 targets we ship on.
inline constexpr std::size_t kCacheLineBytes = 64;

template <typename T, std::size_t N>
class SpscRing {
  static_assert(N >= 2 && (N & (N - 1)) == 0, "SpscRing capacity must be a power of two >= 2");
  static_assert(std::is_trivially_copyable_v<T>, "SpscRing slots are copied, never constructed");

 public:
  // Configure-time only. All N slots are value-initialised here, which also touches every page, so
  // the RT producer never takes a first-touch page fault on the ring.
  SpscRing() = default;
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  static constexpr std::size_t capacity() noexcept { return N; }

  // RT-safe (producer thread only). Copies `value` in; false when full, and nothing is changed.
  bool try_push(const T& value) noexcept {
    return try_push(value, [](T& slot, const T& v) { slot = v; });
  }

  // RT-safe (producer thread only). Like try_push, but `copy(slot, value)` fills the slot: for a record
  // only part of which is in use (a telemetry snapshot's axis slots beyond the machine's axes).
  template <typename Copy>
  bool try_push(const T& value, Copy&& copy) noexcept {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_seen_ == N) {
      tail_seen_ = tail_.load(std::memory_order_acquire);
      if (head - tail_seen_ == N) return false;
    }
    copy(slots_[head & kMask], value);
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  // RT-safe (producer thread only). try_push, and when the ring is full count the loss in dropped().
  bool push_or_drop(const T& value) noexcept {
    return push_or_drop(value, [](T& slot, const T& v) { slot = v; });
  }
  template <typename Copy>
  bool push_or_drop(const T& value, Copy&& copy) noexcept {
    if (try_push(value, copy)) return true;
    // Only the producer writes the counter, so a relaxed read-modify-store cannot lose increments.
    dropped_.store(dropped_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    return false;
  }

  // RT-safe (consumer thread only). Copies the oldest element out; false when empty.
  bool try_pop(T& out) noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (head_seen_ == tail) {
      head_seen_ = head_.load(std::memory_order_acquire);
      if (head_seen_ == tail) return false;
    }
    out = slots_[tail & kMask];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  // RT-safe (consumer thread only). Copies up to out.size() oldest elements out in order and frees their
  // slots with a single release, so a consumer catching up pays one index handshake per batch, not per item.
  std::size_t try_pop_many(std::span<T> out) noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    head_seen_ = head_.load(std::memory_order_acquire);
    const std::size_t n = static_cast<std::size_t>(
        std::min<std::uint64_t>(head_seen_ - tail, static_cast<std::uint64_t>(out.size())));
    for (std::size_t i = 0; i < n; ++i) out[i] = slots_[(tail + i) & kMask];
    if (n > 0) tail_.store(tail + n, std::memory_order_release);
    return n;
  }

  // RT-safe, any thread. Elements refused by push_or_drop() since construction.
  std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }

  // RT-safe, any thread. Elements waiting; exact only when neither side is moving, otherwise a snapshot.
  std::size_t size_approx() const noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_acquire);
    const std::uint64_t head = head_.load(std::memory_order_acquire);
    return head >= tail ? static_cast<std::size_t>(head - tail) : 0;
  }

 private:
  static constexpr std::uint64_t kMask = N - 1;

  // Indices count up forever (2^64 ticks outlives any loom) and are masked on use, so full and empty
  // are told apart without a wasted slot. Each side keeps a private cached copy of the other side's
  // index and re-reads the shared one only when the cache says full/empty: fewer cache-line transfers.
  alignas(kCacheLineBytes) std::atomic<std::uint64_t> head_{0};  // written by the producer
  std::uint64_t tail_seen_ = 0;                                  // producer's cache of tail_
  std::atomic<std::uint64_t> dropped_{0};                        // written by the producer
  alignas(kCacheLineBytes) std::atomic<std::uint64_t> tail_{0};  // written by the consumer
  std::uint64_t head_seen_ = 0;                                  // consumer's cache of head_
  alignas(kCacheLineBytes) std::array<T, N> slots_{};
};

}  // namespace loom::telemetry

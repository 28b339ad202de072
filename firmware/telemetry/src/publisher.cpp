// The publishing thread: ring → schedule → encode → lcm publish. Runs off the RT path, so it may
// allocate and make syscalls; it only has to keep up, which batching the ring reads helps it do.
#include "loom/telemetry/publisher.hpp"

#include <algorithm>
#include <cmath>
#include <lcm/lcm-cpp.hpp>
#include <span>
#include <stdexcept>

#include "loom/sequencer/knot_program.hpp"
#include "loom/telemetry/encode.hpp"
#include "loom/telemetry/identity.hpp"

namespace loom::telemetry {

namespace {

std::int64_t wall_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

PublisherConfig validated(const PublisherConfig& cfg) {
  if (auto e = loom_id_error(cfg.loom_id); !e.empty()) throw std::invalid_argument("telemetry " + e);
  if (auto e = channel_prefix_error(cfg.channel_prefix); !e.empty()) {
    throw std::invalid_argument("telemetry " + e);
  }
  if (auto e = decimation_error(cfg.decimation); !e.empty()) throw std::invalid_argument(e);
  if (cfg.batch < 1) throw std::invalid_argument("telemetry batch = 0 must be >= 1");
  if (cfg.idle_sleep.count() < 0) {
    throw std::invalid_argument("telemetry idle_sleep = " + std::to_string(cfg.idle_sleep.count()) +
                                " us must be >= 0");
  }
  if (!std::isfinite(cfg.max_messages_per_s) || cfg.max_messages_per_s < 0.0) {
    throw std::invalid_argument("telemetry max_messages_per_s = " + std::to_string(cfg.max_messages_per_s) +
                                " must be a finite number >= 0 (0 = unpaced)");
  }
  return cfg;
}

}  // namespace

Publisher::Publisher(const PublisherConfig& cfg, SnapshotRing& ring, EventRing& events)
    : ring_(ring),
      events_(events),
      cfg_(validated(cfg)),
      channels_(channel_names(cfg_.channel_prefix, cfg_.loom_id)),
      schedule_(cfg_.decimation),
      lcm_(std::make_unique<lcm::LCM>(cfg_.lcm_url)),
      batch_(cfg_.batch),
      publish_gap_(cfg_.max_messages_per_s > 0.0
                       ? std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / cfg_.max_messages_per_s))
                       : std::chrono::nanoseconds(0)) {
  if (!lcm_->good()) {
    throw std::invalid_argument("telemetry lcm_url '" + cfg_.lcm_url +
                                "' could not be opened by LCM (check the scheme udpm:// memq:// "
                                "file://, the address and port, and that a multicast route exists)");
  }
}

Publisher::~Publisher() {
  stop();
}

void Publisher::start() {
  if (thread_.joinable()) return;
  stop_requested_.store(false, std::memory_order_relaxed);
  running_.store(true, std::memory_order_release);
  thread_ = std::thread([this] { run(); });
}

void Publisher::stop() {
  if (!thread_.joinable()) return;
  stop_requested_.store(true, std::memory_order_release);
  thread_.join();
  running_.store(false, std::memory_order_release);
}

PublisherStats Publisher::stats() const noexcept {
  PublisherStats s;
  s.snapshots = n_snapshots_.load(std::memory_order_relaxed);
  s.status = n_status_.load(std::memory_order_relaxed);
  s.axes = n_axes_.load(std::memory_order_relaxed);
  s.rt = n_rt_.load(std::memory_order_relaxed);
  s.beat = n_beat_.load(std::memory_order_relaxed);
  s.fault = n_fault_.load(std::memory_order_relaxed);
  s.row = n_row_.load(std::memory_order_relaxed);
  s.design = n_design_.load(std::memory_order_relaxed);
  s.weaver = n_weaver_.load(std::memory_order_relaxed);
  s.knots = n_knots_.load(std::memory_order_relaxed);
  s.events = s.beat + s.fault + s.row + s.weaver;
  s.publish_errors = n_errors_.load(std::memory_order_relaxed);
  return s;
}

void Publisher::run() {
  while (!stop_requested_.load(std::memory_order_acquire)) drain_once_or_nap();
  // The producer may have pushed right up to stop(): publish all of it so the last row is not lost.
  // Only what is there now, though — a loop still pushing must not keep stop() from returning.
  std::size_t left = ring_.size_approx();
  while (left > 0) {
    const std::size_t n = drain_batch();
    if (n == 0) break;
    left -= std::min(n, left);
  }
  // Every event queued so far goes out, even one whose tick's snapshot was dropped.
  publish_events_up_to(hal::kNeverTick);
}

void Publisher::drain_once_or_nap() {
  if (drain_batch() == 0) std::this_thread::sleep_for(cfg_.idle_sleep);
}

std::size_t Publisher::drain_batch() {
  const std::size_t n = ring_.try_pop_many(std::span<Snapshot>(batch_));
  for (std::size_t i = 0; i < n; ++i) {
    // Events of a tick are pushed before that tick's snapshot, so everything up to and including
    // this snapshot's tick is already in the event ring.
    publish_events_up_to(batch_[i].tick + 1);
    publish(batch_[i]);
  }
  n_snapshots_.fetch_add(n, std::memory_order_relaxed);
  return n;
}

void Publisher::pace() {
  if (publish_gap_.count() == 0) return;
  const auto now = std::chrono::steady_clock::now();
  if (next_publish_ > now) {
    std::this_thread::sleep_until(next_publish_);
    next_publish_ += publish_gap_;
  } else {
    // Idle time is not saved up as credit for a later burst.
    next_publish_ = now + publish_gap_;
  }
}

void Publisher::publish_events_up_to(hal::Tick tick) {
  for (;;) {
    if (!have_pending_) have_pending_ = events_.try_pop(pending_);
    if (!have_pending_) return;
    if (tick != hal::kNeverTick && pending_.tick >= tick) return;
    publish_event(pending_);
    have_pending_ = false;
  }
}

template <typename Msg>
void Publisher::send(const std::string& channel, const Msg& msg, std::atomic<std::uint64_t>& counter) {
  pace();
  if (lcm_->publish(channel, &msg) == 0) {
    counter.fetch_add(1, std::memory_order_relaxed);
  } else {
    n_errors_.fetch_add(1, std::memory_order_relaxed);
  }
}

void Publisher::publish_event(const Event& e) {
  const std::int64_t utime = wall_utime();
  try {
    switch (e.kind) {
      case Event::Kind::kBeat:
        send(channels_.beat, to_beat(e, cfg_.loom_id, utime), n_beat_);
        break;
      case Event::Kind::kFault:
        send(channels_.fault, to_fault(e, cfg_.loom_id, utime, cfg_.axes), n_fault_);
        break;
      case Event::Kind::kRow:
        send(channels_.row, to_row(e, cfg_.loom_id, utime), n_row_);
        break;
      case Event::Kind::kWeaver:
        send(channels_.weaver, to_weaver_request(e, cfg_.knot_program, cfg_.loom_id, utime), n_weaver_);
        break;
    }
  } catch (const std::exception&) {
    n_errors_.fetch_add(1, std::memory_order_relaxed);
  }
}

// With STATUS: when the design row changed, and at most once a second otherwise (a panel opened late
// learns the row within a second; an unchanged row is not re-sent at STATUS's rate).
void Publisher::publish_design(const Snapshot& s, std::int64_t utime) {
  if (!cfg_.design) return;
  const std::uint64_t rows = design::rows_woven(cfg_.design_rows_at_start, cfg_.counter_rows_at_start, s.row);
  const auto now = std::chrono::steady_clock::now();
  if (rows == design_rows_sent_ && now - design_sent_at_ < std::chrono::seconds(1)) return;
  send(channels_.design, to_design(*cfg_.design, rows, cfg_.loom_id, utime), n_design_);
  design_rows_sent_ = rows;
  design_sent_at_ = now;
}

void Publisher::publish(const Snapshot& s) {
  const ChannelSet due = schedule_.decide(s);
  if (!due.status && !due.axes && !due.rt) return;
  const std::int64_t utime = wall_utime();
  try {
    if (due.status) {
      send(channels_.status, to_status(s, cfg_.loom_id, utime, cfg_.axes), n_status_);
      publish_design(s, utime);
      if (cfg_.knot_program != nullptr && cfg_.knot_program->heads() > 0 && s.knots.heads > 0) {
        send(channels_.knots, to_knots(s, *cfg_.knot_program, cfg_.loom_id, utime), n_knots_);
      }
      const auto now = std::chrono::steady_clock::now();
      if (now - identity_sent_at_ >= std::chrono::seconds(1)) {
        send(channels_.identity, this_process_identity(cfg_.loom_id, utime), n_identity_);
        identity_sent_at_ = now;
      }
    }
    if (due.axes) send(channels_.axes, to_axes(s, cfg_.loom_id, utime, cfg_.axes), n_axes_);
    if (due.rt) {
      send(channels_.rt,
           to_rt_stats(s, cfg_.loom_id, utime, ring_.dropped(), ring_.size_approx(), events_.dropped()),
           n_rt_);
    }
  } catch (const std::exception&) {
    // Out of memory while encoding: lose this message, keep the thread (and the loop) alive.
    n_errors_.fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace loom::telemetry

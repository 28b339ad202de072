// The loop runner. The reporter thread exists only in real time: printing and fsync-ing counters must
// never delay a tick, so the RT thread hands events over through an SPSC ring and goes on.
#include "loom/firmware/runner.hpp"

#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <thread>

#include "loom/telemetry/spsc_ring.hpp"

namespace loom::firmware {
namespace {

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

timespec to_timespec(std::int64_t ns) {
  return timespec{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
}

// Tick-cost histogram: 100 ns buckets up to 1 ms; enough to report a median without allocating.
class CostHistogram {
 public:
  void add(std::int64_t ns) noexcept {
    const std::int64_t b = std::min<std::int64_t>(ns / 100, kBuckets - 1);
    ++bins_[static_cast<std::size_t>(std::max<std::int64_t>(b, 0))];
    ++count_;
  }
  std::int64_t median() const noexcept {
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < bins_.size(); ++i) {
      seen += bins_[i];
      if (2 * seen >= count_) return static_cast<std::int64_t>(i) * 100 + 50;
    }
    return 0;
  }

 private:
  static constexpr std::int64_t kBuckets = 10000;
  std::array<std::uint64_t, kBuckets> bins_{};
  std::uint64_t count_ = 0;
};

}  // namespace

RtSetup setup_realtime(int fifo_priority) {
  RtSetup r;
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
    r.memory_locked = true;
  } else {
    r.problems += std::string("mlockall failed: ") + std::strerror(errno) + "; ";
  }
  sched_param sp{};
  sp.sched_priority = fifo_priority;
  if (sched_setscheduler(0, SCHED_FIFO, &sp) == 0) {
    r.fifo = true;
  } else {
    r.problems += std::string("SCHED_FIFO failed: ") + std::strerror(errno) + "; ";
  }
  return r;
}

RunResult run_loop(ControlLoop& loop, sequencer::Sequencer& seq, const RunOptions& opt, const EventHandler& on_event) {
  RunResult result;
  auto hist = std::make_unique<CostHistogram>();
  telemetry::SpscRing<RunEvent, 256> events;
  std::atomic<bool> reporter_done{false};
  std::thread reporter;
  if (opt.realtime) {
    reporter = std::thread([&] {
      RunEvent e;
      for (;;) {
        const bool last = reporter_done.load(std::memory_order_acquire);
        while (events.try_pop(e)) on_event(e);
        if (last) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    });
  }
  const auto emit = [&](const RunEvent& e) {
    if (opt.realtime) {
      events.try_push(e);  // 256 events of room; rows complete seconds apart
    } else {
      on_event(e);
    }
  };

  const std::int64_t period_ns = static_cast<std::int64_t>(opt.period_s * 1e9 / opt.pace);
  const std::int64_t start = now_ns();
  std::int64_t deadline = start;
  std::uint32_t rows_seen = seq.counters().rows;
  std::uint32_t picks_seen = seq.counters().picks;
  hal::Tick finished_at = -1;
  bool stop_sent = false;
  bool was_paused = false;
  LoopStats& stats = loop.stats();
  hal::Tick tick = 0;
  for (;; ++tick) {
    if (opt.max_ticks > 0 && tick >= opt.max_ticks) break;
    if (opt.realtime) {
      const timespec ts = to_timespec(deadline);
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
      }
    }
    if (opt.stop_flag != nullptr && !stop_sent && opt.stop_flag->load(std::memory_order_relaxed)) {
      seq.request_stop_at_row_end();
      stop_sent = true;
    }
    if (opt.pause_flag != nullptr) {
      const bool want_pause = opt.pause_flag->load(std::memory_order_relaxed);
      want_pause ? seq.request_pause() : seq.request_resume();
    }
    const std::int64_t t0 = now_ns();
    loop.cycle(tick);
    const std::int64_t cost = now_ns() - t0;
    stats.last_tick_cost_ns = cost;
    stats.max_tick_cost_ns = std::max(stats.max_tick_cost_ns, cost);
    hist->add(cost);

    if (seq.counters().rows != rows_seen || seq.counters().picks != picks_seen) {
      const bool row_done = seq.counters().rows != rows_seen;
      rows_seen = seq.counters().rows;
      picks_seen = seq.counters().picks;
      RunEvent e;
      e.kind = row_done ? RunEvent::Kind::kRowDone : RunEvent::Kind::kPickDone;
      e.tick = tick;
      e.row = seq.last_row();
      e.counters = seq.counters();
      e.state = seq.state();
      emit(e);
    }
    const bool paused = seq.state() == sequencer::State::kPaused;
    if (paused != was_paused) {
      was_paused = paused;
      RunEvent e;
      e.kind = paused ? RunEvent::Kind::kPaused : RunEvent::Kind::kResumed;
      e.tick = tick;
      e.counters = seq.counters();
      e.state = seq.state();
      emit(e);
    }
    if (seq.finished() && finished_at < 0) finished_at = tick;
    if (finished_at >= 0 && tick - finished_at >= opt.grace_ticks) break;

    if (opt.realtime) {
      deadline += period_ns;
      const std::int64_t after = now_ns();
      if (after > deadline) {
        // Missed the next deadline: count it and re-phase from now instead of bursting to catch up.
        ++stats.overruns;
        deadline = after + period_ns - (after - deadline) % period_ns;
      }
    }
  }
  RunEvent fin;
  fin.kind = RunEvent::Kind::kFinished;
  fin.tick = tick;
  fin.counters = seq.counters();
  fin.state = seq.state();
  emit(fin);
  if (opt.realtime) {
    reporter_done.store(true, std::memory_order_release);
    reporter.join();
  }
  result.ticks = tick;
  result.wall_s = static_cast<double>(now_ns() - start) * 1e-9;
  result.overruns = stats.overruns;
  result.max_tick_cost_ns = stats.max_tick_cost_ns;
  result.median_tick_cost_ns = hist->median();
  return result;
}

}  // namespace loom::firmware

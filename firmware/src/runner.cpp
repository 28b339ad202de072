// The loop runner. In real time the loop gets its own thread with explicit attributes and the caller's
// thread becomes the reporter: printing and fsync-ing counters must never delay a tick, so the loop
// hands events over through a heap-allocated SPSC ring and goes on (drop and count when full).
#include "loom/firmware/runner.hpp"

#include <alloca.h>
#include <malloc.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <thread>

#include "loom/firmware/latency_histogram.hpp"
#include "loom/firmware/sim_weaver.hpp"
#include "loom/sequencer/operator_requests.hpp"
#include "loom/telemetry/spsc_ring.hpp"
#include "loom/telemetry/telemetry.hpp"

namespace loom::firmware {

// ---------------------------------------------------------------------------------------------------
// Clock
// ---------------------------------------------------------------------------------------------------
std::int64_t MonotonicClock::now_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void MonotonicClock::sleep_until(std::int64_t deadline_ns) noexcept {
  const timespec ts{static_cast<time_t>(deadline_ns / 1'000'000'000),
                    static_cast<long>(deadline_ns % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

namespace {

// ---------------------------------------------------------------------------------------------------
// Thread attributes
// ---------------------------------------------------------------------------------------------------
// Fills `attr` for the loop thread: explicit scheduling (never inherited from the creator), the policy
// and priority asked for, the stack size, and an optional CPU. Returns an errno-style code.
int make_attrs(pthread_attr_t& attr, int policy, int priority, std::size_t stack_bytes, int cpu) {
  int rc = pthread_attr_init(&attr);
  if (rc != 0) return rc;
  if ((rc = pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED)) != 0) return rc;
  if ((rc = pthread_attr_setschedpolicy(&attr, policy)) != 0) return rc;
  sched_param sp{};
  sp.sched_priority = policy == SCHED_FIFO ? priority : 0;
  if ((rc = pthread_attr_setschedparam(&attr, &sp)) != 0) return rc;
  if ((rc = pthread_attr_setstacksize(&attr, std::max<std::size_t>(stack_bytes, PTHREAD_STACK_MIN))) != 0)
    return rc;
  if (cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<unsigned>(cpu), &set);
    if ((rc = pthread_attr_setaffinity_np(&attr, sizeof(set), &set)) != 0) return rc;
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------------
// Everything the loop touches, allocated (and its pages touched) before the first tick. What only real
// time needs — the reporter's event ring (~2 MB) and the wake-up histogram — is allocated only then:
// in virtual time the handler runs in place and nobody sleeps.
// ---------------------------------------------------------------------------------------------------
using EventRing = telemetry::SpscRing<RunEvent, kEventRingCapacity>;

struct RealTimeParts {
  LatencyHistogram wake;
  EventRing events;
};

struct Runtime {
  Runtime(ControlLoop& l, sequencer::Sequencer& s, const RunOptions& o, LoopClock& c, const EventHandler& h)
      : loop(l),
        seq(s),
        opt(o),
        clock(c),
        on_event(h),
        rt_parts(o.realtime ? std::make_unique<RealTimeParts>() : nullptr) {}
  ControlLoop& loop;
  sequencer::Sequencer& seq;
  const RunOptions& opt;
  LoopClock& clock;
  const EventHandler& on_event;
  LatencyHistogram cost;
  std::unique_ptr<RealTimeParts> rt_parts;  // real time only (value-initialised: pages touched)
  std::atomic<bool> loop_done{false};
  RunResult result;
};

// A tick pushes at most one snapshot and this many events (a beat, a row, a first fault or diagnosis,
// a device fault per axis, a link fault): the room the runner waits for before a virtual-time tick.
constexpr std::size_t kMaxEventsPerTick = 5 + hal::kMaxAxes;

class LoopBody {
 public:
  explicit LoopBody(Runtime& rt)
      : rt_(rt),
        seq_(rt.seq),
        opt_(rt.opt),
        stats_(rt.loop.stats()),
        telemetry_(rt.loop.lossless_telemetry()) {}

  // The loop. RT-safe after its first statement: no allocation, no locks, no syscalls but the clock's.
  void run() noexcept {
    RunResult& res = rt_.result;
    const std::int64_t period_ns =
        std::max<std::int64_t>(1, std::llround(opt_.period_s * 1e9 / (opt_.realtime ? opt_.pace : 1.0)));
    const hal::Tick refresh_every = std::max<hal::Tick>(1, static_cast<hal::Tick>(1.0 / opt_.period_s));
    const hal::Tick poll_every = std::max<hal::Tick>(1, static_cast<hal::Tick>(0.1 / opt_.period_s));
    const std::int64_t begin = rt_.clock.now_ns();
    std::int64_t deadline = begin + period_ns;
    std::uint32_t consecutive = 0;
    hal::Tick finished_at = -1;
    hal::Tick tick = 0;
    res.end = RunResult::End::kFinished;
    for (;; ++tick) {
      if (opt_.max_ticks > 0 && tick >= opt_.max_ticks) {
        res.end = RunResult::End::kMaxTicks;
        break;
      }
      if (opt_.realtime) {
        rt_.clock.sleep_until(deadline);
        const std::int64_t late = rt_.clock.now_ns() - deadline;
        rt_.rt_parts->wake.add(late);
        stats_.last_wake_latency_ns = late;
        stats_.max_wake_latency_ns = std::max(stats_.max_wake_latency_ns, late);
      }
      if (take_commands(tick)) break;  // a command ended the session
      if (telemetry_ != nullptr) wait_for_telemetry_room();

      const std::int64_t t0 = rt_.clock.now_ns();
      rt_.loop.cycle(tick);
      const std::int64_t t1 = rt_.clock.now_ns();
      const std::int64_t cost = t1 - t0;
      stats_.last_tick_cost_ns = cost;
      stats_.max_tick_cost_ns = std::max(stats_.max_tick_cost_ns, cost);
      rt_.cost.add(cost);

      report_events(tick);
      publish_status(tick);
      // Virtual time: the loop runs on the caller's thread, so the reporter's poll (retries of a failed save)
      // is called here between ticks, every 100 ms of machine time; real time calls it from the reporter.
      if (!opt_.realtime && opt_.reporter_poll && tick % poll_every == 0) opt_.reporter_poll();
      if (tick % refresh_every == 0) {
        // Bounded (two scans of a fixed histogram), once a second, in the tick's slack.
        if (rt_.rt_parts) {
          stats_.wake_latency_p50_ns = rt_.rt_parts->wake.percentile(0.5);
          stats_.wake_latency_p99_ns = rt_.rt_parts->wake.percentile(0.99);
          stats_.events_dropped = static_cast<std::uint32_t>(rt_.rt_parts->events.dropped());
        }
        stats_.wake_latency_max_ns = stats_.max_wake_latency_ns;
        stats_.tick_cost_p999_ns = rt_.cost.percentile(0.999);
      }

      if (seq_.finished() && finished_at < 0) finished_at = tick;
      if (!opt_.hold_when_finished && finished_at >= 0 && tick - finished_at >= opt_.grace_ticks &&
          !seq_.diagnosis_pending(tick)) {
        break;
      }
      if (exit_pending_ && quiet_state()) {
        res.end = RunResult::End::kExitRequested;
        break;
      }

      if (opt_.realtime) {
        const std::int64_t next = deadline + period_ns;
        const std::int64_t after = rt_.clock.now_ns();
        if (after > next) {
          // Missed the next deadline: count it and re-phase onto the period grid after now, instead of
          // bursting to catch up (the tick index still advances by one: motion stretches, never jumps).
          ++stats_.overruns;
          ++consecutive;
          res.max_consecutive_overruns = std::max(res.max_consecutive_overruns, consecutive);
          deadline = next + ((after - next) / period_ns + 1) * period_ns;
          if (opt_.overrun_stop_after > 0 && consecutive >= opt_.overrun_stop_after && !res.overrun_stop) {
            res.overrun_stop = true;
            seq_.request_safe_stop(sequencer::Fault::kLoopOverrun);
            RunEvent e = base_event(RunEvent::Kind::kOverrunStop, tick);
            emit(e);
          }
        } else {
          consecutive = 0;
          deadline = next;
        }
      }
    }
    RunEvent fin = base_event(RunEvent::Kind::kFinished, tick);
    emit(fin);
    res.ticks = tick;
    // The loop's own time (thread start-up and the reporter's last drain are not the loop's pace).
    res.wall_s = static_cast<double>(rt_.clock.now_ns() - begin) * 1e-9;
  }

 private:
  // Virtual time, lossless telemetry: wait (yielding to the publisher) until this tick's snapshot and
  // events fit, so the tick itself never waits; the wait is timed and counted apart from the tick.
  // The clock is read only when the ring is actually full.
  void wait_for_telemetry_room() noexcept {
    if (telemetry_->has_room(kMaxEventsPerTick) || !telemetry_->publishing()) return;
    RunResult& res = rt_.result;
    const std::int64_t w0 = rt_.clock.now_ns();
    while (!telemetry_->has_room(kMaxEventsPerTick) && telemetry_->publishing()) {
      std::this_thread::yield();
      ++res.telemetry_wait_yields;
    }
    const std::int64_t waited = rt_.clock.now_ns() - w0;
    ++res.telemetry_wait_ticks;
    res.telemetry_wait_total_ns += waited;
    res.telemetry_wait_max_ns = std::max(res.telemetry_wait_max_ns, waited);
  }

  // Takes the tick's operator commands — the control socket's, the I/O module's presses, weave's signals —
  // and applies what operator_policy.hpp decides of them. True when the session ends here.
  bool take_commands(hal::Tick tick) noexcept {
    std::uint32_t cmds = 0;
    if (opt_.link != nullptr && opt_.link->pending.load(std::memory_order_relaxed) != 0) {
      cmds = opt_.link->pending.exchange(0, std::memory_order_acquire);
    }
    cmds |= take_presses(tick);
    cmds |= take_signals();
    if (opt_.sim_weaver != nullptr) opt_.sim_weaver->on_tick(seq_);
    bool last_save_failed = false;
    if (opt_.row_saves != nullptr) {
      const std::uint32_t on_disk = opt_.row_saves->rows_on_disk.load(std::memory_order_acquire);
      last_save_failed = opt_.row_saves->last_save_failed.load(std::memory_order_acquire);
      seq_.note_rows_saved(on_disk, last_save_failed);
      const std::uint64_t knots = opt_.row_saves->knots_on_disk.load(std::memory_order_acquire);
      seq_.note_knots_saved(static_cast<std::uint32_t>(knots >> 32),
                            static_cast<std::uint32_t>(knots & 0xFFFFFFFFu));
    }
    if (cmds == 0) return false;
    PolicyInputs in;
    in.commands = cmds;
    in.state = seq_.state();
    in.held_session = opt_.hold_when_finished;
    in.estop_ok = rt_.loop.inputs().io.estop_ok;
    in.link_recovery = rt_.loop.inputs().link.recovery;
    in.last_save_failed = last_save_failed;
    in.nothing_to_weave = opt_.nothing_to_weave;
    Decision d = decide(in);
    // serve: the session's first start from idle against a change of the armed job
    // (OperatorLink::queue_gate): when the change came first, the start re-arms from the changed queue
    // instead (then starts).
    if (d.start && in.held_session && in.state == sequencer::State::kIdle && opt_.link != nullptr &&
        !opt_.link->take_start()) {
      d.start = false;
      d.end = Decision::End::kStartRequested;
    }
    apply(d, seq_);
    if ((cmds & static_cast<std::uint32_t>(Command::kReload)) != 0) take_reloads(d.reload, tick);
    RunResult& res = rt_.result;
    res.commands_overridden += d.overridden != 0 ? 1u : 0u;
    switch (d.refusal) {
      case Decision::Refusal::kAckLinkDown:
      case Decision::Refusal::kAckEStopOpen:
        ++res.acks_refused;
        break;
      case Decision::Refusal::kAckCountersUnsaved:
        ++res.acks_refused_unsaved;
        break;
      case Decision::Refusal::kStartNothingToWeave:
      case Decision::Refusal::kNone:
        break;
    }
    exit_pending_ = exit_pending_ || d.exit_when_quiet;
    switch (d.end) {
      case Decision::End::kNone:
        return false;
      case Decision::End::kStopped:
        res.end = RunResult::End::kExitRequested;
        return true;
      case Decision::End::kStartRequested:
        res.end = RunResult::End::kStartRequested;
        return true;
      case Decision::End::kAckRequested:
        res.end = RunResult::End::kAckRequested;
        return true;
      case Decision::End::kRearmRequested:
        res.end = RunResult::End::kRearmRequested;
        return true;
    }
    return false;
  }

  // weave's signals as the commands of the same words, each once, when it changes: SIGINT/SIGTERM is a stop
  // (the second a stop now, applied at once: a safe stop never moves anything), SIGUSR1/SIGUSR2 pause and
  // resume. Held level every tick, the pause flag would cancel a pause press at the next tick (and re-pause a
  // loom a start press resumed): the last operator act wins, whatever its station.
  std::uint32_t take_signals() noexcept {
    std::uint32_t cmds = 0;
    if (opt_.stop_flag != nullptr && !stop_sent_ && opt_.stop_flag->load(std::memory_order_relaxed)) {
      cmds |= static_cast<std::uint32_t>(Command::kStop);
      stop_sent_ = true;
    }
    if (opt_.stop_now_flag != nullptr && !stop_now_sent_ &&
        opt_.stop_now_flag->load(std::memory_order_relaxed)) {
      seq_.request_stop_now();
      stop_now_sent_ = true;
    }
    if (opt_.pause_flag != nullptr) {
      const bool pause = opt_.pause_flag->load(std::memory_order_relaxed);
      if (pause != pause_flag_was_)
        cmds |= static_cast<std::uint32_t>(pause ? Command::kPause : Command::kResume);
      pause_flag_was_ = pause;
    }
    return cmds;
  }

  // The presses the sequencer saw in the last tick (debounced, one event per press) as the commands of the
  // same words: from here on a press goes the way a command from the socket goes. Each press is audited once
  // (audit_buttons), in the state the tick that saw it began in: that is the state the press was judged in
  // (an ack press counts only if the fault was latched before it).
  std::uint32_t take_presses(hal::Tick tick) noexcept {
    std::uint32_t cmds = 0;
    const sequencer::TickEvents& events = seq_.events();
    for (const sequencer::TickEvent& ev : events) {  // bounded: TickEvents::kCapacity
      if (ev.kind != sequencer::EventKind::kButton) continue;
      const sequencer::OperatorRequest r = sequencer::request_of(ev.button, events.began_in());
      cmds |= static_cast<std::uint32_t>(command_of(r));
      if (!opt_.audit_buttons) continue;
      RunEvent e = base_event(RunEvent::Kind::kButton, tick);
      e.button = command_of_button(ev.button);
      e.state = events.began_in();
      e.request = seq_.weaver_request();  // the request open as the press is taken: the one it answers
      emit(e);
    }
    return cmds;
  }

  // The command a button stands for in the audit: its request as if the press counted (an ack press is
  // audited as ack even when it acknowledges nothing: its verdict says so); the pedal is the weaver's `next`.
  static Command command_of_button(sequencer::Button b) noexcept {
    return command_of(sequencer::request_of(b, sequencer::State::kFault));
  }

  static Command command_of(sequencer::OperatorRequest r) noexcept {
    switch (r) {
      case sequencer::OperatorRequest::kStart:
        return Command::kStart;
      case sequencer::OperatorRequest::kPause:
        return Command::kPause;
      case sequencer::OperatorRequest::kAcknowledge:
        return Command::kAck;
      case sequencer::OperatorRequest::kRowKnotted:
        return Command::kNext;
      case sequencer::OperatorRequest::kNone:
        break;
    }
    return Command{};
  }

  // Nothing is moving towards a goal: leaving the loop here loses no row in progress.
  bool quiet_state() const noexcept { return quiet(seq_.state()); }

  RunEvent base_event(RunEvent::Kind kind, hal::Tick tick) const noexcept {
    RunEvent e;
    e.kind = kind;
    e.tick = tick;
    e.counters = seq_.counters();
    e.state = seq_.state();
    e.fault = seq_.first_fault();
    e.stopped_by = seq_.stopped_by();
    e.fault_axis = seq_.fault_axis();
    e.fault_detail = seq_.fault_detail();
    e.fault_sensor = seq_.fault_sensor();
    e.carriage_miss = seq_.knotter().carriage_miss();
    return e;
  }

  void emit(const RunEvent& e) noexcept {
    if (opt_.realtime) {
      rt_.rt_parts->events.push_or_drop(e);
    } else {
      // Virtual time: the loop runs on the caller's thread, so the handler is called in place.
      try {
        rt_.on_event(e);
      } catch (...) {
        // A handler's failure must not tear the loop down; the handler reports its own errors.
      }
    }
  }

  // The weaver's reloads posted since the last tick: each taken off the link (so none is applied later by
  // surprise); applied unless a stopping command of the same tick overrode them (the weaver gives it
  // again: the level stays as the loom counted it, low, never high). One kReloaded event with the levels
  // after them, which the reporter keeps with the magazines.
  void take_reloads(bool apply_them, hal::Tick tick) noexcept {
    if (opt_.link == nullptr) return;
    bool taken = false;
    for (int h = 0; h < sequencer::kMaxKnottingHeads; ++h) {
      for (int sl = 0; sl < sequencer::kMaxMagazineSlots; ++sl) {
        const std::optional<std::int32_t> knots = opt_.link->take_reload(h, sl);
        if (!knots || !apply_them || !seq_.reload_magazine(h, sl, *knots)) continue;
        taken = true;
        if (opt_.sim_weaver != nullptr) opt_.sim_weaver->reloaded(h, sl, *knots);
      }
    }
    if (!taken) return;
    RunEvent e = base_event(RunEvent::Kind::kReloaded, tick);
    fill_stock(e);
    emit(e);
  }

  // The magazines' levels as the loom counts them now (unknown before the first row or without heads).
  void fill_stock(RunEvent& e) const noexcept {
    const sequencer::RowKnotter& k = seq_.knotter();
    e.stock_known = k.stock(0, 0) >= 0;
    for (int h = 0; e.stock_known && h < sequencer::kMaxKnottingHeads; ++h) {
      for (int sl = 0; sl < sequencer::kMaxMagazineSlots; ++sl) {
        e.stock[static_cast<std::size_t>(h)][static_cast<std::size_t>(sl)] = k.stock(h, sl);
      }
    }
  }

  // The sequencer's events of this tick as run events, in the reporter's order: the row or pick (saved with
  // the counters), the knots, the weaver's request, a pause or resume, the fault. Each carries the counters
  // and the fault as they are at the end of the tick.
  void report_events(hal::Tick tick) noexcept {
    const sequencer::TickEvents& ev = seq_.events();
    if (ev.empty()) return;  // the usual tick
    using sequencer::EventKind;
    if (ev.has(EventKind::kRow)) {
      RunEvent e = base_event(RunEvent::Kind::kRowDone, tick);
      e.row = seq_.last_row();
      fill_stock(e);
      emit(e);
    } else if (ev.has(EventKind::kPick)) {
      emit(base_event(RunEvent::Kind::kPickDone, tick));
    }
    if (ev.has(EventKind::kKnotProgress)) emit(base_event(RunEvent::Kind::kKnotProgress, tick));
    if (ev.has(EventKind::kWeaverRequest)) {
      const sequencer::WeaverRequest& r = seq_.weaver_request();
      if (r.ask != sequencer::WeaverAsk::kNone) {
        RunEvent e = base_event(RunEvent::Kind::kWeaverRequest, tick);
        e.request = r;
        emit(e);
        if (opt_.sim_weaver != nullptr) opt_.sim_weaver->answer(r);
      }
    }
    // A pause and its resume in one tick (never seen) cancel out, as the state shows.
    const bool paused = ev.has(EventKind::kPaused), resumed = ev.has(EventKind::kResumed);
    if (paused != resumed)
      emit(base_event(paused ? RunEvent::Kind::kPaused : RunEvent::Kind::kResumed, tick));
    if (ev.has(EventKind::kFaultLatched)) emit(base_event(RunEvent::Kind::kFault, tick));
  }

  void publish_status(hal::Tick tick) noexcept {
    OperatorLink* l = opt_.link;
    if (l == nullptr) return;
    constexpr auto r = std::memory_order_relaxed;
    l->state.store(static_cast<std::uint8_t>(seq_.state()), r);
    l->first_fault.store(static_cast<std::uint8_t>(seq_.first_fault()), r);
    l->rows.store(seq_.counters().rows, r);
    l->picks.store(seq_.counters().picks, r);
    l->beats.store(seq_.counters().beats, r);
    l->overruns.store(stats_.overruns, r);
    l->max_wake_latency_ns.store(stats_.max_wake_latency_ns, r);
    l->link_recovery.store(static_cast<std::uint8_t>(rt_.loop.inputs().link.recovery), r);
    l->silent_node.store(rt_.loop.inputs().link.silent_node, r);
    l->estop_ok.store(rt_.loop.inputs().io.estop_ok, r);
    l->weaver_ask.store(static_cast<std::uint8_t>(seq_.weaver_request().ask), r);
    l->tick.store(tick, std::memory_order_release);
  }

  Runtime& rt_;
  sequencer::Sequencer& seq_;
  const RunOptions& opt_;
  LoopStats& stats_;
  telemetry::Telemetry* telemetry_;  // non-null: virtual time, lossless telemetry (wait before the tick)
  bool stop_sent_ = false, stop_now_sent_ = false, exit_pending_ = false;
  bool pause_flag_was_ = false;  // pause_flag as last seen
};

// Touches `bytes` of this thread's stack so the loop never takes a first-touch page fault on it.
__attribute__((noinline)) void prefault_stack(std::size_t bytes) {
  auto* p = static_cast<volatile unsigned char*>(alloca(bytes));
  for (std::size_t i = 0; i < bytes; i += 4096) p[i] = 0;
}

void* loop_thread_main(void* arg) {
  auto& rt = *static_cast<Runtime*>(arg);
  pthread_setname_np(pthread_self(), "loom-rt");
  int policy = -1;
  sched_param sp{};
  if (pthread_getschedparam(pthread_self(), &policy, &sp) == 0) {
    rt.result.loop_policy = policy;
    rt.result.loop_priority = sp.sched_priority;
  }
  // Pre-fault what is left of this thread's stack below here, minus a margin for the loop's own frames.
  // Measured from the thread's real stack bounds, not from the size asked for: the C library and
  // sanitizers take part of the stack for themselves (ThreadSanitizer faulted on the size asked for).
  pthread_attr_t attr;
  if (pthread_getattr_np(pthread_self(), &attr) == 0) {
    void* low = nullptr;
    std::size_t size = 0;
    if (pthread_attr_getstack(&attr, &low, &size) == 0) {
      const auto here = reinterpret_cast<std::uintptr_t>(__builtin_frame_address(0));
      const auto bottom = reinterpret_cast<std::uintptr_t>(low);
      constexpr std::uintptr_t kMargin = 64u << 10;
      if (here > bottom + 2 * kMargin) prefault_stack(static_cast<std::size_t>(here - bottom - kMargin));
    }
    pthread_attr_destroy(&attr);
  }
  LoopBody(rt).run();
  rt.loop_done.store(true, std::memory_order_release);
  return nullptr;
}

void drain_events(Runtime& rt) {
  RunEvent e;
  while (rt.rt_parts->events.try_pop(e)) {
    try {
      rt.on_event(e);
    } catch (...) {
      // The loop thread is still running on `rt`: a handler's exception must not unwind past it.
    }
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Process-wide preparation
// ---------------------------------------------------------------------------------------------------
RtSetup setup_realtime(int fifo_priority, std::size_t heap_prefault_bytes) {
  RtSetup r;
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
    r.memory_locked = true;
    // Keep freed heap in the process and serve large blocks from it, not from fresh mmaps, then
    // touch a block once: later configure-time allocations land on pages that are already resident.
    mallopt(M_TRIM_THRESHOLD, -1);
    mallopt(M_MMAP_MAX, 0);
    if (heap_prefault_bytes > 0) {
      auto* block = static_cast<volatile unsigned char*>(std::malloc(heap_prefault_bytes));
      if (block != nullptr) {
        for (std::size_t i = 0; i < heap_prefault_bytes; i += 4096) block[i] = 0;
        std::free(const_cast<unsigned char*>(block));
      }
    }
  } else {
    r.problems += std::string("mlockall failed: ") + std::strerror(errno) + "; ";
  }
  // Probe with a real thread created the way the loop's will be: the process itself never changes policy.
  pthread_attr_t attr;
  int rc = make_attrs(attr, SCHED_FIFO, fifo_priority, PTHREAD_STACK_MIN + (64u << 10), -1);
  pthread_t th{};
  if (rc == 0)
    rc = pthread_create(
        &th, &attr, [](void*) -> void* { return nullptr; }, nullptr);
  pthread_attr_destroy(&attr);
  if (rc == 0) {
    pthread_join(th, nullptr);
    r.fifo = true;
  } else {
    r.problems += "SCHED_FIFO " + std::to_string(fifo_priority) + " not granted: " + std::strerror(rc) + "; ";
  }
  return r;
}

// ---------------------------------------------------------------------------------------------------
// The runner
// ---------------------------------------------------------------------------------------------------
RunResult run_loop(ControlLoop& loop, sequencer::Sequencer& seq, const RunOptions& opt,
                   const EventHandler& on_event) {
  MonotonicClock monotonic;
  LoopClock& clock = opt.clock != nullptr ? *opt.clock : monotonic;
  // Configure-time: the histograms (and in real time the ~2 MB event ring) live on the heap,
  // value-initialised, which touches every page before the loop starts.
  auto rt = std::make_unique<Runtime>(loop, seq, opt, clock, on_event);

  if (!opt.realtime) {
    LoopBody(*rt).run();
  } else {
    const bool want_fifo = opt.fifo_priority > 0;
    pthread_attr_t attr;
    int rc =
        make_attrs(attr, want_fifo ? SCHED_FIFO : SCHED_OTHER, opt.fifo_priority, opt.stack_bytes, opt.cpu);
    pthread_t th{};
    if (rc == 0) rc = pthread_create(&th, &attr, loop_thread_main, rt.get());
    pthread_attr_destroy(&attr);
    if (rc == EPERM && want_fifo && !opt.require_fifo) {
      // Not allowed SCHED_FIFO: run anyway at SCHED_OTHER (simulation), and say so in the result.
      rt->result.fifo_refused = true;
      rc = make_attrs(attr, SCHED_OTHER, 0, opt.stack_bytes, opt.cpu);
      if (rc == 0) rc = pthread_create(&th, &attr, loop_thread_main, rt.get());
      pthread_attr_destroy(&attr);
    }
    if (rc != 0) {
      rt->result.end = RunResult::End::kError;
      rt->result.fifo_refused = rc == EPERM && want_fifo;
      rt->result.error = std::string("cannot start the loop thread") +
                         (want_fifo ? " at SCHED_FIFO " + std::to_string(opt.fifo_priority) : std::string()) +
                         (opt.cpu >= 0 ? " on CPU " + std::to_string(opt.cpu) : std::string()) + ": " +
                         std::strerror(rc);
      return rt->result;
    }
    // The caller's thread (SCHED_OTHER) is the reporter.
    while (!rt->loop_done.load(std::memory_order_acquire)) {
      drain_events(*rt);
      if (opt.reporter_poll) opt.reporter_poll();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    pthread_join(th, nullptr);
    drain_events(*rt);
  }

  RunResult res = rt->result;
  const LoopStats& stats = loop.stats();
  res.overruns = stats.overruns;
  res.max_tick_cost_ns = stats.max_tick_cost_ns;
  res.median_tick_cost_ns = rt->cost.percentile(0.5);
  res.p999_tick_cost_ns = rt->cost.percentile(0.999);
  if (rt->rt_parts) {
    res.wake_latency_p50_ns = rt->rt_parts->wake.percentile(0.5);
    res.wake_latency_p99_ns = rt->rt_parts->wake.percentile(0.99);
    res.wake_latency_max_ns = rt->rt_parts->wake.max();
    res.events_dropped = rt->rt_parts->events.dropped();
  }
  loop.stats().events_dropped = static_cast<std::uint32_t>(res.events_dropped);
  const double machine_s = static_cast<double>(res.ticks) * opt.period_s;
  res.achieved_ratio = machine_s / std::max(res.wall_s, 1e-9);
  res.fell_behind = opt.realtime && res.ticks > 0 && res.achieved_ratio < 0.97 * opt.pace;
  return res;
}

}  // namespace loom::firmware

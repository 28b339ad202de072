// Drives ControlLoop::cycle at the fixed rate: in virtual time as fast as the machine allows, or paced
// in real time with absolute-deadline sleeps (overruns counted and re-phased onto the period grid, never
// caught up in a burst; N in a row → safe stop). In real time the loop runs on its own thread created
// with explicit attributes (the LinuxCNC uspace way): SCHED_FIFO at the configured priority,
// PTHREAD_EXPLICIT_SCHED so nothing is inherited, optional CPU affinity, a pre-faulted stack. Every other
// thread — the LCM publisher, the reporter (the caller's thread), the control socket — stays
// SCHED_OTHER. Only this module and main read the clock, through the injectable LoopClock.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "loom/firmware/control_loop.hpp"
#include "loom/firmware/operator_policy.hpp"
#include "loom/sequencer/sequencer.hpp"

namespace loom::firmware {

// ---------------------------------------------------------------------------------------------------
// Time: injected so overrun handling and re-phasing are tested with a fake clock.
// ---------------------------------------------------------------------------------------------------
class LoopClock {
 public:
  virtual ~LoopClock() = default;
  // RT-safe. Monotonic nanoseconds.
  virtual std::int64_t now_ns() noexcept = 0;
  // RT-safe (the one wait the loop makes). Sleep until the absolute time `deadline_ns`.
  virtual void sleep_until(std::int64_t deadline_ns) noexcept = 0;
};

// CLOCK_MONOTONIC with clock_nanosleep(TIMER_ABSTIME): absolute deadlines never drift.
class MonotonicClock final : public LoopClock {
 public:
  std::int64_t now_ns() noexcept override;
  void sleep_until(std::int64_t deadline_ns) noexcept override;
};

// ---------------------------------------------------------------------------------------------------
// Process-wide real-time preparation (configure-time only).
// ---------------------------------------------------------------------------------------------------
struct RtSetup {
  bool memory_locked = false;  // mlockall(MCL_CURRENT | MCL_FUTURE) and a pre-faulted heap
  bool fifo = false;           // a thread may be created at SCHED_FIFO `fifo_priority` (probed, not taken)
  std::string problems;        // "" when both succeeded
  bool ok() const { return memory_locked && fifo; }
};
// Locks memory, pre-faults `heap_prefault_bytes` of heap (and keeps glibc from returning it or serving
// big blocks by mmap), and probes — by creating and joining a short-lived thread with explicit SCHED_FIFO
// attributes — that the loop thread will get its priority. It does NOT change this process' scheduling:
// threads started afterwards (telemetry, reporter) stay SCHED_OTHER. Says what failed instead of throwing.
RtSetup setup_realtime(int fifo_priority, std::size_t heap_prefault_bytes = 8u << 20);

// ---------------------------------------------------------------------------------------------------
// Operator commands into the loop and live status out of it (the control socket's side of the loop).
// ---------------------------------------------------------------------------------------------------
// Command: operator_policy.hpp (what each command does, in one place).

// Shared between the loop thread and any number of non-RT threads. Commands are bits in one atomic word
// (set with fetch_or, taken with exchange: lock-free, no lost commands, nothing allocated); status is a
// set of relaxed atomics the loop stores every tick, each field individually consistent.
struct OperatorLink {
  std::atomic<std::uint32_t> pending{0};
  void post(Command c) noexcept {
    pending.fetch_or(static_cast<std::uint32_t>(c), std::memory_order_release);
  }
  // The weaver reloaded slot `slot` of head `head` (0-based) with `knots` knots (negative: full): stored
  // per slot before Command::kReload is posted, so two reloads of different slots are both taken, and a
  // second of the same slot before the loop's next tick replaces the first (the weaver's latest word).
  void post_reload(int head, int slot, std::int32_t knots) noexcept {
    if (head < 0 || head >= static_cast<int>(hal::kMaxKnottingHeads) || slot < 0 ||
        slot >= static_cast<int>(sequencer::kMaxMagazineSlots)) {
      return;
    }
    reloads[static_cast<std::size_t>(head)][static_cast<std::size_t>(slot)].store(
        knots < 0 ? kReloadFull : knots + kReloadOffset, std::memory_order_relaxed);
    post(Command::kReload);
  }
  // The loop's side: the reload waiting for a slot, taken (nullopt: none; -1: full; else the knots).
  std::optional<std::int32_t> take_reload(int head, int slot) noexcept {
    const std::int32_t v = reloads[static_cast<std::size_t>(head)][static_cast<std::size_t>(slot)].exchange(
        kNoReload, std::memory_order_acquire);
    if (v == kNoReload) return std::nullopt;
    return v == kReloadFull ? -1 : v - kReloadOffset;
  }
  // Stored as 0 (none: a default-constructed atomic), 1 (full) or knots + 2.
  static constexpr std::int32_t kNoReload = 0, kReloadFull = 1, kReloadOffset = 2;
  std::array<std::array<std::atomic<std::int32_t>, sequencer::kMaxMagazineSlots>, hal::kMaxKnottingHeads>
      reloads{};

  // The armed job against this session's start (serve). The service opens the gate at each arming; the
  // loop's first start from idle closes it as kStarted; a change of the job queue that touches the armed
  // job (ctl job remove/start-over) closes it as kQueueChanged, and from then on no start is taken in this
  // session: a start ends it for the service to arm again from the changed queue (then start). One
  // compare-exchange decides which came first, so a job is never changed under a loom that began it, and
  // a loom never begins a job that was changed after it was armed.
  enum Gate : std::uint8_t { kGateOpen = 0, kGateStarted = 1, kGateQueueChanged = 2 };
  std::atomic<std::uint8_t> queue_gate{kGateOpen};
  // The loop's side: a start from idle is about to be taken; false when the queue changed first.
  bool take_start() noexcept {
    std::uint8_t open = kGateOpen;
    return queue_gate.compare_exchange_strong(open, kGateStarted, std::memory_order_acq_rel) ||
           open == kGateStarted;
  }
  // The service's side: close the gate for a change of the armed job; false when the loom started it.
  bool close_for_queue_change() noexcept {
    std::uint8_t open = kGateOpen;
    return queue_gate.compare_exchange_strong(open, kGateQueueChanged, std::memory_order_acq_rel) ||
           open == kGateQueueChanged;
  }

  std::atomic<std::uint8_t> state{0};        // sequencer::State
  std::atomic<std::uint8_t> first_fault{0};  // sequencer::Fault
  std::atomic<std::uint32_t> rows{0}, picks{0}, beats{0};
  std::atomic<std::uint32_t> overruns{0};
  std::atomic<std::int64_t> max_wake_latency_ns{0};
  std::atomic<std::uint8_t> link_recovery{0};  // hal::LinkRecovery: whether an acknowledgement can re-arm
  std::atomic<std::uint8_t> silent_node{0};    // the lost node still silent (kNodeSilent)
  std::atomic<bool> estop_ok{true};            // the e-stop chain is closed (an acknowledgement can re-arm)
  std::atomic<std::uint8_t> weaver_ask{
      0};  // sequencer::WeaverAsk: the knotting heads' open request (next answers it)
  std::atomic<std::int64_t> tick{0};
};

// ---------------------------------------------------------------------------------------------------
// Events for the non-RT side.
// ---------------------------------------------------------------------------------------------------
struct RunEvent {
  // kKnotProgress: the knotting heads' counters moved (a knot cycle started or done, knots tied): saved like
  // a pick. kWeaverRequest: the loom asks the weaver (`request`).
  enum class Kind : std::uint8_t {
    kRowDone,
    kPickDone,
    kPaused,
    kResumed,
    kFault,
    kOverrunStop,
    kFinished,
    kButton,
    kKnotProgress,
    kWeaverRequest,
    kReloaded,  // the weaver's reloads were taken: `stock` holds the magazines' levels after them
  };
  Kind kind = Kind::kRowDone;
  hal::Tick tick = 0;
  sequencer::RowStats row{};
  sequencer::Counters counters{};
  sequencer::State state =
      sequencer::State::kIdle;  // at the end of the tick; kButton: the tick the press was seen in began in
  sequencer::Fault fault = sequencer::Fault::kNone;  // kFault: the first fault
  sequencer::Fault stopped_by = sequencer::Fault::kNone;
  int fault_axis = -1;
  std::uint16_t fault_detail = 0;
  int fault_sensor = -1;                    // hal::SafetySensor the fault names (sensor_discrepancy), or -1
  sequencer::CarriageMiss carriage_miss{};  // carriage_not_at_knot: the knot, how far off, the tolerance
  Command button =
      Command::kStart;  // kButton: the I/O module's button pressed (audit_buttons); kNext: the pedal
  sequencer::WeaverRequest request{};  // kWeaverRequest; kButton: the request open when it was taken
  // kRowDone (and kReloaded) on a loom with knotting heads: the magazines' levels as the loom counts them at
  // the row's end (kept in the state directory, so a restart starts from them).
  bool stock_known = false;
  sequencer::MagazineLevels stock{};
};
// Run events waiting for the reporter (real time only: in virtual time the handler runs in place and no
// ring is allocated). An event is at most one per row, pick, pause, resume or fault,
// and a pick is never shorter than a shed change (hundreds of ms), so 1024 pending events cover a
// reporter stalled for minutes (e.g. an fsync on a slow SD card). Overflow is counted, never waited on;
// the next event carries the full counters again, so a counter save is never lost for long.
inline constexpr std::size_t kEventRingCapacity = 1024;

// The reporter's side of the row-boundary handshake (SequencerConfig::await_row_saved): after each save
// it stores the rows now on disk, or that the save failed; the loop hands both to the sequencer every
// tick, and no row starts before the one before it is on disk. Written by one thread, read by the loop.
struct RowSaves {
  std::atomic<std::uint32_t> rows_on_disk{0};
  std::atomic<bool> last_save_failed{false};
  void saved(std::uint32_t rows) noexcept {
    last_save_failed.store(false, std::memory_order_relaxed);
    rows_on_disk.store(rows, std::memory_order_release);
  }
  void failed() noexcept { last_save_failed.store(true, std::memory_order_release); }
  // The knotting heads' write-ahead: the counters on disk say `started` knot cycles of the row after `rows`
  // production rows were begun (no cycle starts before its start is on disk).
  std::atomic<std::uint64_t> knots_on_disk{0};
  void saved_knots(std::uint32_t rows, std::uint32_t started) noexcept {
    knots_on_disk.store(static_cast<std::uint64_t>(rows) << 32 | started, std::memory_order_release);
  }
};

class SimWeaver;

struct RunOptions {
  double period_s = 0.002;
  bool realtime = false;        // pace at the tick rate (always true with hardware)
  double pace = 1.0;            // with realtime: run this many times faster than real time (sim only)
  hal::Tick max_ticks = 0;      // 0 = no limit
  hal::Tick grace_ticks = 100;  // ticks run after the sequencer finishes (quick stop reaches the drives;
                                // longer while a symptom's root cause may still be diagnosed)
  const std::atomic<bool>* stop_flag = nullptr;  // set asynchronously → a stop (Command::kStop)
  const std::atomic<bool>* stop_now_flag =
      nullptr;                                    // set asynchronously → safe stop at once (stop_requested)
  const std::atomic<bool>* pause_flag = nullptr;  // true → pause at the next safe point, false → resume
  RowSaves* row_saves = nullptr;                  // the counters-file handshake, when one is kept
  // Simulation: the simulated weaver (sim_weaver.hpp), called each tick and with every request the loom
  // makes of the weaver (on the loop's thread, RT-safe). Null: the weaver is a person at the panel.
  SimWeaver* sim_weaver = nullptr;

  // Real-time thread (realtime only).
  int fifo_priority = 80;     // SCHED_FIFO priority of the loop thread; 0 = SCHED_OTHER
  bool require_fifo = false;  // true: refuse to run (RunResult::error) when SCHED_FIFO is not granted
  int cpu = -1;               // pin the loop thread to this CPU (an isolated one); -1 = any
  std::size_t stack_bytes = 512u << 10;  // loop thread stack, pre-faulted before the first tick
  // Overrun policy: this many consecutive overruns latch loop_overrun (safe stop). 0 = count only.
  std::uint32_t overrun_stop_after = 0;

  // Operator commands and live status (serve). With `hold_when_finished` the loop keeps cycling after
  // the sequencer is done or faulted (drives held / quick-stopped) until a command ends the session.
  OperatorLink* link = nullptr;
  // The I/O module's presses (the sequencer's kButton events) act in every run, through the commands of the
  // same words (sequencer/operator_requests.hpp); with this set each press — start, pause, ack and the
  // weaver's row-knotted pedal — is also audited as a RunEvent::kButton (serve).
  bool audit_buttons = false;
  bool hold_when_finished = false;
  // The carpet job queue has nothing to weave: a start from idle is refused (PolicyInputs).
  bool nothing_to_weave = false;
  // Called on the reporter thread every few milliseconds in real time, between ticks every 100 ms of
  // machine time in virtual time (the service's watchdog, failed saves tried again). Never from the RT loop.
  std::function<void()> reporter_poll;

  LoopClock* clock = nullptr;  // nullptr = MonotonicClock
};

struct RunResult {
  enum class End : std::uint8_t {
    kFinished,
    kMaxTicks,
    kExitRequested,
    kStartRequested,
    kAckRequested,
    kRearmRequested,  // the service's job queue changed while the loom stood: arm again, no start
    kError
  };
  End end = End::kFinished;
  std::string error;  // kError: why the loop could not start (e.g. SCHED_FIFO refused)
  hal::Tick ticks = 0;
  double wall_s = 0.0;
  std::uint32_t overruns = 0;
  std::uint32_t max_consecutive_overruns = 0;
  bool overrun_stop = false;  // the overrun policy latched loop_overrun
  // The tick's own work (read inputs, sequencer, write outputs, queue telemetry), never a wait.
  std::int64_t max_tick_cost_ns = 0;
  std::int64_t median_tick_cost_ns = 0;  // from a fixed-size histogram, no allocation while running
  std::int64_t p999_tick_cost_ns = 0;
  // Virtual time with lossless telemetry only: before a tick whose snapshot or events would not fit,
  // the loop waits (yielding) for the LCM publisher to free ring space. That wait is the publisher's
  // pace, not the tick's cost, so it is measured and reported apart. Real time never waits (drops).
  std::uint64_t telemetry_wait_ticks = 0;  // ticks that had to wait
  std::int64_t telemetry_wait_total_ns = 0;
  std::int64_t telemetry_wait_max_ns = 0;
  std::uint64_t telemetry_wait_yields = 0;  // sched_yield calls while waiting
  // Real time only: how late the loop woke after each deadline.
  std::int64_t wake_latency_p50_ns = 0, wake_latency_p99_ns = 0, wake_latency_max_ns = 0;
  std::uint64_t events_dropped = 0;
  std::uint32_t acks_refused = 0;          // acknowledgements while the link could not be re-armed yet
  std::uint32_t acks_refused_unsaved = 0;  // acknowledgements while the counters still could not be saved
  std::uint32_t commands_overridden = 0;   // ticks whose starting commands a stopping one overrode
  // What the loop thread actually ran at (realtime only; read back with pthread_getschedparam inside it).
  int loop_policy = -1;  // SCHED_FIFO, SCHED_OTHER, ...; -1 = ran on the caller (virtual time)
  int loop_priority = 0;
  bool fifo_refused = false;  // SCHED_FIFO was requested and refused; the loop ran at SCHED_OTHER
  // Achieved speed against the request: machine seconds per wall second (pace in real time).
  double achieved_ratio = 0.0;
  bool fell_behind = false;  // realtime and the achieved ratio is below 97 % of the requested pace
};

// Non-RT callback for row completions, faults and the end of the run. In virtual time it is called
// between ticks; in real time on the caller's thread (SCHED_OTHER), fed through a lock-free ring.
using EventHandler = std::function<void(const RunEvent&)>;

// Runs the loop until the sequencer finishes (plus grace), max_ticks, or — with a link — a command ends
// the session. In real time the caller's thread becomes the reporter while a new thread runs the loop.
RunResult run_loop(ControlLoop& loop, sequencer::Sequencer& seq, const RunOptions& opt,
                   const EventHandler& on_event);

}  // namespace loom::firmware

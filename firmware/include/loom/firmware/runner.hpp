// Drives ControlLoop::cycle at the fixed rate: in virtual time as fast as the machine allows, or paced
// in real time with absolute-deadline sleeps (clock_nanosleep TIMER_ABSTIME; overruns counted and
// re-phased, never caught up in a burst). Only this module and main read the clock.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

#include "loom/firmware/control_loop.hpp"
#include "loom/sequencer/sequencer.hpp"

namespace loom::firmware {

// Configure-time only. Lock memory and switch to SCHED_FIFO; says what failed instead of throwing.
struct RtSetup {
  bool memory_locked = false;
  bool fifo = false;
  std::string problems;  // "" when both succeeded
  bool ok() const { return memory_locked && fifo; }
};
RtSetup setup_realtime(int fifo_priority);

struct RunEvent {
  enum class Kind : std::uint8_t { kRowDone, kPickDone, kPaused, kResumed, kFinished } kind = Kind::kRowDone;
  hal::Tick tick = 0;
  sequencer::RowStats row{};
  sequencer::Counters counters{};
  sequencer::State state = sequencer::State::kIdle;
};

struct RunOptions {
  double period_s = 0.002;
  bool realtime = false;         // pace at the tick rate (always true with hardware)
  double pace = 1.0;             // with realtime: run this many times faster than real time (sim only)
  hal::Tick max_ticks = 0;       // 0 = no limit
  hal::Tick grace_ticks = 100;   // ticks run after the sequencer finishes (quick stop reaches the drives)
  const std::atomic<bool>* stop_flag = nullptr;   // set asynchronously → stop at row end
  const std::atomic<bool>* pause_flag = nullptr;  // true → pause at the next safe point, false → resume
};

struct RunResult {
  hal::Tick ticks = 0;
  double wall_s = 0.0;
  std::uint32_t overruns = 0;
  std::int64_t max_tick_cost_ns = 0;
  std::int64_t median_tick_cost_ns = 0;  // from a fixed-size histogram, no allocation while running
};

// Non-RT callback for row completions and the end of the run. In virtual time it is called between
// ticks; in real time from a separate reporter thread fed through a lock-free ring.
using EventHandler = std::function<void(const RunEvent&)>;

RunResult run_loop(ControlLoop& loop, sequencer::Sequencer& seq, const RunOptions& opt, const EventHandler& on_event);

}  // namespace loom::firmware

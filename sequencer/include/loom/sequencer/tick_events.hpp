// What happened in one tick, said by the sequencer where it happens: step() clears the list and every
// transition that is news (a beat, a pick, a row, a fault, a pause …) appends one entry. Telemetry and the
// run reporter forward this list; nobody rebuilds events by comparing polled state with the last tick's.
// Enums and numbers only: names and texts are made at the text edge (publisher, reporter, logs).
// Fixed capacity, no allocation: RT-safe.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "loom/sequencer/faults.hpp"

namespace loom::sequencer {

enum class State : std::uint8_t;

// One beat as the technician sees it: reported once per beat, when the beater has left the warp after
// passing the fell (its peak force is then final).
struct BeatEvent {
  std::uint32_t row = 0;      // 1-based row being woven
  std::uint16_t index = 0;    // 0-based beat within the row
  float x_m = 0.0f;           // carriage position (beater's left edge from the left selvedge)
  float peak_force_n = 0.0f;  // 0 when no load cell
  bool force_measured = false;
  bool in_band = false;      // force_measured and within [beat_force_min_n, beat_force_max_n]
  float speed_scale = 1.0f;  // the beat's crank speed over the recipe's (the beat regulator's; 1 open loop)
};

// The I/O module's buttons (debounced, one event per press; only reported: see operator_requests.hpp).
enum class Button : std::uint8_t { kStart, kPause, kAck, kRowKnotted };

enum class EventKind : std::uint8_t {
  kBeat,              // `beat` says which
  kPick,              // a pick completed (counters().picks counted it; also the pick recovered at arming)
  kRow,               // a row completed (Sequencer::last_row() holds its statistics)
  kFaultLatched,      // the first fault latched (fault, axis, detail, sensor)
  kDiagnosisRefined,  // within the diagnosis window a root cause replaced the symptom (fault, axis, detail)
  kPaused,            // the state became paused
  kResumed,           // the state left paused (resumed, or a fault while paused)
  kKnotProgress,   // the knotting heads' counters moved (a cycle started or done, a knot tied, the row reset)
  kWeaverRequest,  // the knotting heads asked the weaver (Sequencer::knotter().request())
  kButton,         // an operator button was pressed (`button`)
};

struct TickEvent {
  EventKind kind = EventKind::kBeat;
  Button button = Button::kStart;  // kButton
  Fault fault = Fault::kNone;      // kFaultLatched, kDiagnosisRefined
  std::int8_t axis = -1;           // the fault's axis, -1 when not axis-specific
  std::int8_t sensor = -1;         // the safety sensor the fault names, -1 when none
  std::uint16_t detail = 0;        // the fault's device code (EMCY)
  BeatEvent beat{};                // kBeat
};

// This tick's events in the order they happened. More than kCapacity in one tick is impossible in the row
// cycle (a tick has at most a beat, a pick or a row, a knot step, a request, a pause or resume, a fault, a
// diagnosis and a few button presses); were it ever reached, later events are counted in `lost`, never
// written past the end.
class TickEvents {
 public:
  static constexpr std::size_t kCapacity = 16;

  void clear(State began_in) noexcept {
    count_ = 0;
    began_in_ = began_in;
  }
  TickEvent& add(EventKind kind) noexcept {
    if (count_ == kCapacity) {
      ++lost_;
      spare_ = TickEvent{};
      return spare_;
    }
    TickEvent& e = items_[count_++];
    e = TickEvent{};
    e.kind = kind;
    return e;
  }

  std::size_t size() const noexcept { return count_; }
  bool empty() const noexcept { return count_ == 0; }
  const TickEvent* begin() const noexcept { return items_.data(); }
  const TickEvent* end() const noexcept { return items_.data() + count_; }
  const TickEvent& operator[](std::size_t i) const noexcept { return items_[i]; }
  // The first event of `kind` this tick, or nullptr.
  const TickEvent* find(EventKind kind) const noexcept {
    for (std::size_t i = 0; i < count_; ++i) {
      if (items_[i].kind == kind) return &items_[i];
    }
    return nullptr;
  }
  bool has(EventKind kind) const noexcept { return find(kind) != nullptr; }
  // The state the tick began in (a fault event's "state just before the fault").
  State began_in() const noexcept { return began_in_; }
  // Events that did not fit since construction (0 in every scene and test; kept so an overflow is visible).
  std::uint32_t lost() const noexcept { return lost_; }

 private:
  std::array<TickEvent, kCapacity> items_{};
  std::size_t count_ = 0;
  State began_in_{};
  std::uint32_t lost_ = 0;
  TickEvent spare_{};
};

}  // namespace loom::sequencer

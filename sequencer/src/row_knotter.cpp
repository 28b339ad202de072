// The knotting heads tying a row (see row_knotter.hpp).
#include "loom/sequencer/row_knotter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "loom/motion/angles.hpp"

namespace loom::sequencer {

const char* weaver_ask_name(WeaverAsk a) {
  switch (a) {
    case WeaverAsk::kNone:
      return "none";
    case WeaverAsk::kTieByHand:
      return "tie_by_hand";
    case WeaverAsk::kReload:
      return "reload";
    case WeaverAsk::kCheckKnot:
      return "check_knot";
  }
  return "?";
}

std::string describe(const WeaverRequest& r, const KnotProgram& p) {
  const std::string colour = r.slot >= 0 && r.slot < p.slots() ? p.slot_colour(r.slot) : "?";
  const std::string head = "head " + std::to_string(r.head + 1);
  const std::string where =
      "row " + std::to_string(r.row) + " (design row " + std::to_string(r.design_row + 1) + "): ";
  const std::string knot = "knot " + std::to_string(r.knot + 1) + " (" + head + ")";
  switch (r.ask) {
    case WeaverAsk::kNone:
      return "nothing";
    case WeaverAsk::kTieByHand:
      return where + "tie " + knot + " by hand in colour " + colour +
             " (the head missed it twice: look at slot " + std::to_string(r.slot) +
             "'s yarn and the gripper)";
    case WeaverAsk::kReload:
      if (r.knots_needed > 0) {
        return where + "reload colour " + colour + " into slot " + std::to_string(r.slot) + " of " + head +
               " before the row: it needs " + std::to_string(r.knots_needed) + " knots of it, " +
               std::to_string(r.knots_left) + " left";
      }
      return where + "reload colour " + colour + " into slot " + std::to_string(r.slot) + " of " + head;
    case WeaverAsk::kCheckKnot:
      return where + "check " + knot +
             " (the power failed while it was tied): finish or tie it by hand in colour " + colour;
  }
  return "?";
}

std::string describe(const CarriageMiss& m) {
  if (m.cycle < 0) return "";
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "the carriage measured %.1f mm %s of the knot of knot cycle %d (each head's knot %d of its "
                "stripe), tolerance %.1f mm",
                std::abs(m.error_m) * 1e3, m.error_m < 0.0 ? "left" : "right", m.cycle + 1, m.cycle + 1,
                m.tolerance_m * 1e3);
  return buf;
}

KnotGuard knot_guard(const KnottingConfig& heads) {
  // Where the gripper is inside the warp, as knotting-servo angles: the cycle's in-warp window, sampled
  // (a one-degree-of-freedom linkage puts its gripper in the same place at the same servo angle).
  const motion::KnotCycle& c = *heads.cycle;
  KnotGuard g;
  g.heads = heads.program->heads();
  for (int h = 0; h < g.heads; ++h) {
    g.knotter[static_cast<std::size_t>(h)] =
        static_cast<std::int8_t>(heads.knotter_axis[static_cast<std::size_t>(h)]);
    g.selector[static_cast<std::size_t>(h)] =
        static_cast<std::int8_t>(heads.selector_axis[static_cast<std::size_t>(h)]);
  }
  g.take_position_rad = heads.take_position_rad;
  g.full_turn = c.end_offset_rad() != 0.0;
  double lo = 1e300, hi = -1e300;
  const motion::KnotCycle::Window w = c.in_warp();
  constexpr int kSamples = 256;
  for (int i = 0; i <= kSamples; ++i) {
    double a = c.sample(w.begin_s + (w.end_s - w.begin_s) * i / kSamples).angle_rad;
    if (g.full_turn) a = motion::wrap_two_pi(a);
    lo = std::min(lo, a);
    hi = std::max(hi, a);
  }
  // Closed at the ends (the stroke turns round inside the warp, at PULL) and a milliradian wider: the guard
  // errs on the side of "in the warp".
  constexpr double kMarginRad = 1e-3;
  g.in_warp_from_rad = lo - kMarginRad;
  g.in_warp_to_rad = hi + kMarginRad;
  return g;
}

void RowKnotter::configure(const KnottingConfig& k, const KnotGuard* guard, double period_s,
                           double carriage_home_m, const motion::JerkLimits& carriage,
                           double feedback_age_s) {
  k_ = k;
  tolerance_m_ = k.placement_tolerance_m > 0.0 || k.program == nullptr
                     ? k.placement_tolerance_m
                     : default_placement_tolerance_m(k.program->pitch_m());
  // (rounded up to whole ticks)
  arrival_ticks_ = static_cast<hal::Tick>(std::ceil(carriage_arrival_s(k, feedback_age_s) / period_s - 1e-9));
  guard_ = guard;
  period_s_ = period_s;
  carriage_home_m_ = carriage_home_m;
  carriage_ = carriage;
  heads_ = fitted() ? k_.program->heads() : 0;
  stripe_ = fitted() ? k_.program->stripe() : 0;
  slot_.fill(-1);
  stock_known_ = false;
  phase_ = Phase::kDone;
}

void RowKnotter::restore_stock(const MagazineLevels& levels) noexcept {
  if (!fitted()) return;
  const std::int32_t full = k_.program->knots_per_slot();
  for (int h = 0; h < heads_; ++h) {
    for (int s = 0; s < kMaxMagazineSlots; ++s) {
      const std::int32_t v = levels[static_cast<std::size_t>(h)][static_cast<std::size_t>(s)];
      stock_[static_cast<std::size_t>(h)][static_cast<std::size_t>(s)] = v < 0 ? 0 : (v > full ? full : v);
    }
  }
  stock_known_ = true;
}

bool RowKnotter::reload(int head, int slot, std::int32_t knots) noexcept {
  if (!fitted() || head < 0 || head >= heads_ || slot < 0 || slot >= k_.program->slots()) return false;
  const std::int32_t full = k_.program->knots_per_slot();
  if (!stock_known_) {  // before the first row: the other slots are the full magazines loaded at the start
    for (int h = 0; h < heads_; ++h) stock_[static_cast<std::size_t>(h)].fill(full);
    stock_known_ = true;
  }
  stock_[static_cast<std::size_t>(head)][static_cast<std::size_t>(slot)] =
      knots < 0 || knots > full ? full : knots;
  if (request_.ask == WeaverAsk::kReload && request_.head == head && request_.slot == slot) {
    reload_answered_ = true;
  }
  return true;
}

double RowKnotter::rest_behind(double position) const noexcept {
  if (!fitted()) return position;
  const double turn = k_.cycle->end_offset_rad();
  if (turn == 0.0) return k_.take_position_rad;  // the cycle swings back: one rest pose
  // A servo that turns on by `turn` per knot rests at take + n·turn; back to the one behind it.
  const double n = std::floor((position - k_.take_position_rad) / turn + 1e-9);
  return k_.take_position_rad + n * turn;
}

double RowKnotter::selector_goal(int slot, double from) const noexcept {
  // Slot s sits at zero + s·pitch; the selector turns the short way round to it.
  const double pitch = motion::kTwoPi / k_.program->slots();
  return from + motion::wrap_pi(k_.selector_zero_rad + slot * pitch - from);
}

void RowKnotter::begin(std::uint32_t row0, const KnotCounters& progress, double return_to_m, hal::Tick now,
                       const hal::HalOutputs& cmd) noexcept {
  row0_ = row0;
  return_to_m_ = return_to_m;
  fault_ = Fault::kNone;
  fault_axis_ = -1;
  miss_ = CarriageMiss{};
  row_ = RowKnots{};
  // A row resumed after a power cut: its knots tied before the cut are the row's too.
  row_.tied = static_cast<int>(progress.row_tied);
  row_.retried = static_cast<int>(progress.row_retried);
  row_.by_hand = static_cast<int>(progress.row_by_hand);
  row_since_ = now;
  request_ = WeaverRequest{};
  if (!stock_known_) {
    // Full magazines are loaded before weaving starts; from then on every knot cycle counts its yarn down.
    for (int h = 0; h < heads_; ++h) stock_[static_cast<std::size_t>(h)].fill(k_.program->knots_per_slot());
    stock_known_ = true;
  }
  for (int h = 0; h < heads_; ++h) {
    const auto hh = static_cast<std::size_t>(h);
    knotter_origin_[hh] = cmd.axes[static_cast<std::size_t>(k_.knotter_axis[hh])].target_position;
    selector_move_[hh].active = false;
    slot_[hh] = -1;  // where a selector stands is read back from its command when it is next sent
  }
  next_carriage_ = next_selectors_ = false;
  disk_wait_since_ = hal::kNeverTick;
  // A cycle started and not finished: the power failed while its knots were being tied. Whether they are
  // is not known; tying again could tie one twice, so the weaver checks them (kCheck asks).
  interrupted_ = progress.cycles_started > progress.cycles_done &&
                 progress.cycles_done < static_cast<std::uint32_t>(stripe_);
  heads_done_at_cut_ = interrupted_ ? progress.cycle_heads_done : 0;
  forecast_due_ = true;
  enter_cycle(static_cast<int>(progress.cycles_done), now, cmd);
}

void RowKnotter::plan_carriage(int j, hal::Tick now, const hal::HalOutputs& cmd) noexcept {
  const double from = cmd.axes[hal::index(hal::CoreAxis::kCarriage)].target_position;
  const double goal = carriage_home_m_ + k_.program->carriage_at(j);
  carriage_move_ = {true, false, now, from, motion::JerkMove::plan(goal - from, carriage_)};
}

void RowKnotter::plan_selectors(int j, hal::Tick now, const hal::HalOutputs& cmd) noexcept {
  for (int h = 0; h < heads_; ++h) {
    const auto hh = static_cast<std::size_t>(h);
    const int k = k_.program->knot_of(h, j);
    if (k < 0) continue;
    const int s = k_.program->slot(row0_, k);
    if (s == slot_[hh]) continue;
    const double at = cmd.axes[static_cast<std::size_t>(k_.selector_axis[hh])].target_position;
    selector_move_[hh] = {true, true, now, at,
                          motion::JerkMove::plan(selector_goal(s, at) - at, k_.selector)};
    slot_[hh] = s;
  }
}

void RowKnotter::plan_travel(int j, hal::Tick now, const hal::HalOutputs& cmd) noexcept {
  if (!next_carriage_) plan_carriage(j, now, cmd);
  if (!next_selectors_) plan_selectors(j, now, cmd);
  next_carriage_ = next_selectors_ = false;
}

void RowKnotter::enter_cycle(int j, hal::Tick now, const hal::HalOutputs& cmd) noexcept {
  j_ = j;
  attempt_ = 0;
  if (j_ >= stripe_) {  // the row is knotted: the carriage goes back to the row's start selvedge
    const double from = cmd.axes[hal::index(hal::CoreAxis::kCarriage)].target_position;
    carriage_move_ = {true, false, now, from,
                      motion::JerkMove::plan(carriage_home_m_ + return_to_m_ - from, carriage_)};
    phase_ = Phase::kReturn;
    phase_since_ = now;
    return;
  }
  plan_travel(j_, now, cmd);  // what did not start inside the cycle before
  for (int h = 0; h < heads_; ++h) {
    const auto hh = static_cast<std::size_t>(h);
    active_[hh] = k_.program->knot_of(h, j_) >= 0;
    seen_[hh] = false;
    missed_[hh] = false;
  }
  phase_ = Phase::kTravel;
  phase_since_ = now;
}

bool RowKnotter::play(Move& m, hal::Tick now, double& target) const noexcept {
  if (!m.active) return false;
  const double t = seconds(now - m.t0);
  target = m.origin + m.move.at(t).position;
  if (t >= m.move.duration()) m.active = false;
  return true;  // it wrote a target this tick (its last one, perhaps): nothing else may start in this tick
}

bool RowKnotter::fail(Fault f, int axis) noexcept {
  fault_ = f;
  fault_axis_ = axis;
  return false;
}

void RowKnotter::ask(WeaverAsk a, int head, int knot, int slot, hal::Tick now) noexcept {
  request_.ask = a;
  request_.row = row0_ + 1;
  request_.design_row = k_.program->design_row(row0_);
  request_.knot = knot;
  request_.head = head;
  request_.slot = slot;
  request_.knots_needed = request_.knots_left = 0;
  reload_answered_ = false;
  weaver_since_ = now;
  ++requests_;
}

void RowKnotter::start_cycle(hal::Tick now) noexcept {
  for (int h = 0; h < heads_; ++h) {
    const auto hh = static_cast<std::size_t>(h);
    if (active_[hh]) --stock_[hh][static_cast<std::size_t>(slot_[hh])];  // the gripper takes yarn at TAKE
    seen_[hh] = false;
  }
  cycle_t0_ = now;
  phase_ = Phase::kCycle;
  phase_since_ = now;
}

RowKnotter::Status RowKnotter::check(hal::Tick now, const hal::HalInputs& in, const hal::HalOutputs& cmd,
                                     KnotCounters& counters, const StepInputs& s) noexcept {
  // Every servo where it was sent (a drive trails its command by a few ticks: settle_s; a selector whose
  // drive runs its own profile, selector_settle_s).
  const double since = seconds(now - phase_since_);
  const bool settled = since >= k_.settle_s;
  const bool selector_settled = since >= (k_.selector_settle_s > 0.0 ? k_.selector_settle_s : k_.settle_s);
  for (int h = 0; h < heads_; ++h) {
    const auto hh = static_cast<std::size_t>(h);
    const auto sel = static_cast<std::size_t>(k_.selector_axis[hh]);
    const auto kn = static_cast<std::size_t>(k_.knotter_axis[hh]);
    const bool sel_off =
        std::abs(in.axes[sel].position - cmd.axes[sel].target_position) > k_.servo_tolerance_rad;
    const bool kn_off =
        std::abs(in.axes[kn].position - cmd.axes[kn].target_position) > k_.servo_tolerance_rad;
    if (!sel_off && !kn_off) continue;
    if ((sel_off && !selector_settled) || (kn_off && !settled)) return Status::kRunning;
    fail(sel_off ? Fault::kSelectorJam : Fault::kKnotServoLag, static_cast<int>(sel_off ? sel : kn));
    return Status::kFault;
  }
  // The carriage at the knot as measured, not as commanded: a drive that trails its profile, or whose
  // feedback arrives late, holds the cycle back (grippers open) until it is within the placement tolerance;
  // one still outside it when the bound is up did not arrive.
  const std::size_t car = hal::index(hal::CoreAxis::kCarriage);
  const double off = in.axes[car].position - (carriage_home_m_ + k_.program->carriage_at(j_));
  if (!(std::abs(off) <= tolerance_m_)) {  // (a NaN reading is never "there")
    if (now - phase_since_ < arrival_ticks_) return Status::kRunning;
    miss_ = {j_, off, tolerance_m_};
    fail(Fault::kCarriageNotAtKnot, static_cast<int>(car));
    return Status::kFault;
  }
  if (interrupted_) {  // the power failed inside this cycle: the weaver checks its knots first
    interrupted_ = false;
    // (but not those the counters already hold: each knot is counted once, by the head or by the weaver)
    for (int h = 0; h < heads_; ++h) {
      const auto hh = static_cast<std::size_t>(h);
      missed_[hh] = active_[hh] && (heads_done_at_cut_ & (1u << h)) == 0;
    }
    hand_ask_ = WeaverAsk::kCheckKnot;
    ask_head_ = 0;
    phase_ = Phase::kWeaver;
    return Status::kAwaitingWeaver;
  }
  // Before the row's first knot cycle (and again after each reload): a slot that cannot give the rest of
  // the row its knots is reloaded now, the heads at rest, not when it runs dry in the middle of the row.
  if (forecast_due_) {
    if (ask_reload_for_row(now)) {
      phase_ = Phase::kWeaver;
      return Status::kAwaitingWeaver;
    }
    forecast_due_ = false;
  }
  for (int h = 0; h < heads_; ++h) {
    const auto hh = static_cast<std::size_t>(h);
    if (!active_[hh]) continue;
    // Yarn for the knot: a slot that ran dry all the same (a retried knot takes yarn twice) is reloaded
    // before the knot that needs it.
    if (stock_[hh][static_cast<std::size_t>(slot_[hh])] <= 0) {
      ask(WeaverAsk::kReload, h, -1, slot_[hh], now);
      phase_ = Phase::kWeaver;
      return Status::kAwaitingWeaver;
    }
    // The knot position must be empty: a switch already on is stuck, or a knot is already there.
    if (in.io.yarn_present[hh]) {
      fail(Fault::kYarnSensorStuck, k_.knotter_axis[hh]);
      return Status::kFault;
    }
  }
  // A stop or a pause holds here, between two cycles: before "cycle j started" is written ahead, so the
  // next run (or the resume) begins cycle j afresh and no knot is asked of the weaver for nothing.
  if (s.hold && counters.cycles_started < static_cast<std::uint32_t>(j_ + 1)) return Status::kHeld;
  // Write-ahead: "cycle j started" is on disk before the cycle starts, so a power cut inside it is known
  // after the restart and its knots are never tied a second time.
  if (counters.cycles_started < static_cast<std::uint32_t>(j_ + 1)) {
    counters.cycles_started = static_cast<std::uint32_t>(j_ + 1);
    counters_moved_ = true;
  }
  if (s.await_disk && s.on_disk_started < counters.cycles_started) {
    // The save has a deadline like every other wait on the disk: a full or failing disk is the fault
    // counters_not_saved (quick stop, red lamp), never a loom standing mid-row for ever.
    if (disk_wait_since_ == hal::kNeverTick) disk_wait_since_ = now;
    if (s.disk_timeout_ticks > 0 && now - disk_wait_since_ > s.disk_timeout_ticks) {
      fail(Fault::kCountersNotSaved, -1);
      return Status::kFault;
    }
    return Status::kRunning;
  }
  disk_wait_since_ = hal::kNeverTick;
  start_cycle(now);
  return Status::kRunning;
}

void RowKnotter::run_cycle(hal::Tick now, const hal::HalInputs& in, hal::HalOutputs& cmd,
                           KnotCounters& counters) noexcept {
  const motion::KnotCycle& c = *k_.cycle;
  const double t = seconds(now - cycle_t0_);
  const motion::KnotCycle::Sample s = c.sample(t);
  bool all_seen = true;
  for (int h = 0; h < heads_; ++h) {
    const auto hh = static_cast<std::size_t>(h);
    if (!active_[hh]) continue;
    cmd.axes[static_cast<std::size_t>(k_.knotter_axis[hh])].target_position =
        knotter_origin_[hh] + s.angle_rad;
    cmd.io.gripper_close[hh] = c.gripper_closed().contains(t);
    cmd.io.cutter[hh] = c.cutter().contains(t);
    if (c.yarn_sample().contains(t) && in.io.yarn_present[hh]) seen_[hh] = true;
    all_seen &= seen_[hh];
  }
  // The next knot's moves start inside this cycle once this position cannot be needed again (every knot
  // verified: no retry): the selectors as soon as the yarn is released (they never turn under a closed
  // gripper), the carriage once every gripper is out of the warp.
  const bool verified = all_seen && j_ + 1 < stripe_ && t >= c.yarn_sample().end_s;
  if (verified && !next_selectors_ && t >= c.gripper_closed().end_s) {
    plan_selectors(j_ + 1, now, cmd);
    next_selectors_ = true;
  }
  if (verified && !next_carriage_ && t >= c.in_warp().end_s) {
    plan_carriage(j_ + 1, now, cmd);
    next_carriage_ = true;
  }
  if (t >= c.duration_s()) finish_cycle(now, cmd, counters);
}

void RowKnotter::finish_cycle(hal::Tick now, const hal::HalOutputs& cmd, KnotCounters& counters) noexcept {
  bool retry = false, missed = false;
  for (int h = 0; h < heads_; ++h) {
    const auto hh = static_cast<std::size_t>(h);
    if (!active_[hh]) continue;
    knotter_origin_[hh] += k_.cycle->end_offset_rad();  // the servo is at rest again, a cycle on
    if (seen_[hh]) {
      ++counters.tied;
      ++counters.row_tied;
      counters.cycle_heads_done |= 1u << h;
      ++row_.tied;
      counters_moved_ = true;
      active_[hh] = false;
    } else if (attempt_ == 0) {
      ++counters.retried;
      ++counters.row_retried;
      ++row_.retried;
      counters_moved_ = true;
      retry = true;  // stays active: ties again
    } else {
      missed_[hh] = true;
      active_[hh] = false;
      missed = true;
    }
  }
  if (retry) {
    attempt_ = 1;
    start_cycle(now);
    return;
  }
  if (missed) {
    hand_ask_ = WeaverAsk::kTieByHand;
    ask_head_ = 0;
    phase_ = Phase::kWeaver;
    return;
  }
  cycle_done(now, cmd, counters);
}

void RowKnotter::cycle_done(hal::Tick now, const hal::HalOutputs& cmd, KnotCounters& counters) noexcept {
  const KnotCounters was = counters;
  counters.cycles_done = static_cast<std::uint32_t>(j_ + 1);
  counters.cycles_started = std::max(counters.cycles_started, counters.cycles_done);
  counters.cycle_heads_done = 0;
  counters_moved_ |= counters.cycles_done != was.cycles_done ||
                     counters.cycles_started != was.cycles_started || was.cycle_heads_done != 0;
  enter_cycle(j_ + 1, now, cmd);
}

RowKnotter::Status RowKnotter::weaver(hal::Tick now, const hal::HalOutputs& cmd, KnotCounters& counters,
                                      bool weaver_done) noexcept {
  if (request_.ask != WeaverAsk::kNone) {
    if (!weaver_done && !reload_answered_) return Status::kAwaitingWeaver;
    row_.weaver_ticks += now - weaver_since_;
    const WeaverAsk done = request_.ask;
    request_.ask = WeaverAsk::kNone;
    if (done == WeaverAsk::kReload) {  // check the cycle (and the row's yarn) again
      // The pedal or `next` says the slot was filled; a reload() said how much it now holds.
      if (!reload_answered_) {
        stock_[static_cast<std::size_t>(request_.head)][static_cast<std::size_t>(request_.slot)] =
            k_.program->knots_per_slot();
      }
      reload_answered_ = false;
      phase_ = Phase::kCheck;
      phase_since_ = now;
      return Status::kRunning;
    }
    ++counters.by_hand;  // tied (or checked and finished) by the weaver
    ++counters.row_by_hand;
    counters.cycle_heads_done |= 1u << request_.head;
    ++row_.by_hand;
    counters_moved_ = true;
    missed_[static_cast<std::size_t>(request_.head)] = false;
  }
  for (; ask_head_ < heads_; ++ask_head_) {  // one request at a time, head by head
    if (!missed_[static_cast<std::size_t>(ask_head_)]) continue;
    const int k = k_.program->knot_of(ask_head_, j_);
    ask(hand_ask_, ask_head_, k, k_.program->slot(row0_, k), now);
    return Status::kAwaitingWeaver;
  }
  cycle_done(now, cmd, counters);  // every knot of the cycle is tied, by the heads or by hand
  return Status::kRunning;
}

bool RowKnotter::ask_reload_for_row(hal::Tick now) noexcept {
  // Bounded: one pass over the row's remaining knots (at most knots_per_row lookups), once per row and
  // once per reload answered.
  const std::int32_t full = k_.program->knots_per_slot();
  const int slots = k_.program->slots();
  for (int h = 0; h < heads_; ++h) {
    std::array<std::int32_t, kMaxMagazineSlots> need{};
    for (int j = j_; j < stripe_; ++j) {
      const int k = k_.program->knot_of(h, j);
      if (k >= 0) ++need[static_cast<std::size_t>(k_.program->slot(row0_, k))];
    }
    for (int s = 0; s < slots; ++s) {
      const std::int32_t left = stock_[static_cast<std::size_t>(h)][static_cast<std::size_t>(s)];
      // A full slot is never asked for again: a stripe that needs more than a slot holds is reloaded
      // when it runs dry.
      if (need[static_cast<std::size_t>(s)] <= left || left >= full) continue;
      ask(WeaverAsk::kReload, h, -1, s, now);
      request_.knots_needed = need[static_cast<std::size_t>(s)];
      request_.knots_left = left;
      return true;
    }
  }
  return false;
}

RowKnotter::Status RowKnotter::step(hal::Tick now, const hal::HalInputs& in, hal::HalOutputs& cmd,
                                    KnotCounters& counters, const StepInputs& s) noexcept {
  counters_moved_ = false;
  if (!fitted()) return Status::kDone;
  // Every tick: the moves in flight write their targets; grippers and cutters are open unless a running
  // cycle closes them. A carriage move waits at its origin while any gripper is measured in the warp (the
  // servo trails its command by a tick or two when the cycle leaves the warp).
  if (carriage_move_.active && !carriage_move_.started) {
    bool inside = false;
    for (int h = 0; h < heads_ && guard_ != nullptr; ++h) {
      inside |= gripper_in_warp(
          *guard_, in.axes[static_cast<std::size_t>(k_.knotter_axis[static_cast<std::size_t>(h)])].position);
    }
    if (inside) {
      carriage_move_.t0 = now;
    } else {
      carriage_move_.started = true;
    }
  }
  const bool carriage_moving =
      play(carriage_move_, now, cmd.axes[hal::index(hal::CoreAxis::kCarriage)].target_position);
  bool selectors_moving = false;
  for (int h = 0; h < heads_; ++h) {
    const auto hh = static_cast<std::size_t>(h);
    hal::AxisCommand& sel = cmd.axes[static_cast<std::size_t>(k_.selector_axis[hh])];
    const bool playing = play(selector_move_[hh], now, sel.target_position);
    // The move's end, for a drive that takes one set-point per move (profile position); none otherwise.
    sel.move_end = playing ? selector_move_[hh].origin + selector_move_[hh].move.distance()
                           : std::numeric_limits<double>::quiet_NaN();
    selectors_moving |= playing;
    cmd.io.gripper_close[hh] = false;
    cmd.io.cutter[hh] = false;
  }
  switch (phase_) {
    case Phase::kTravel:
      if (carriage_moving || selectors_moving) return Status::kRunning;
      phase_ = Phase::kCheck;
      phase_since_ = now;
      [[fallthrough]];
    case Phase::kCheck: {
      const Status st = check(now, in, cmd, counters, s);
      if (st != Status::kRunning || phase_ != Phase::kCycle) return st;
      [[fallthrough]];
    }
    case Phase::kCycle:
      run_cycle(now, in, cmd, counters);
      break;
    case Phase::kWeaver:
      return weaver(now, cmd, counters, s.weaver_done);
    case Phase::kReturn:
      if (carriage_moving) return Status::kRunning;
      phase_ = Phase::kDone;
      row_.ticks = now - row_since_ - row_.weaver_ticks;
      return Status::kDone;
    case Phase::kDone:
      return Status::kDone;
  }
  return phase_ == Phase::kWeaver ? Status::kAwaitingWeaver : Status::kRunning;
}

}  // namespace loom::sequencer

// The row cycle. Order inside a tick is fixed: faults first (a fault this tick wins over any plan),
// then the state machine, then the profiles are sampled into targets, then the interlocks judge the
// result before it is written.
#include "loom/sequencer/sequencer.hpp"

#include <cmath>

#include "loom/motion/angles.hpp"

namespace loom::sequencer {
namespace {
using hal::Axis;
using hal::AxisRequest;
using hal::DriveState;
using hal::index;
constexpr std::uint16_t kHeartbeatCode = 0x8130;  // CiA 301 EMCY "life guard / heartbeat error"

void request_all(hal::HalOutputs& o, AxisRequest r) {
  for (auto& a : o.axes) a.request = r;
}
}  // namespace

const char* state_name(State s) {
  switch (s) {
    case State::kIdle: return "idle";
    case State::kEnabling: return "enabling";
    case State::kPositioning: return "positioning";
    case State::kShed: return "shed";
    case State::kPick: return "pick";
    case State::kBeatSweep: return "beat_sweep";
    case State::kPaused: return "paused";
    case State::kDone: return "done";
    case State::kFault: return "fault";
  }
  return "?";
}

Sequencer::Sequencer(motion::ProfileSlot& slot, const SequencerConfig& cfg, Counters resume)
    : Sequencer(slot.active(), cfg, resume) {
  slot_ = &slot;
}

Sequencer::Sequencer(const motion::ProfileSet& profiles, const SequencerConfig& cfg, Counters resume)
    : profiles_(&profiles), cfg_(cfg), counters_(resume) {
  interlock_ctx_.warp = &profiles_->beatup().warp();
  interlock_ctx_.crank_park_position = cfg_.crank_park_position_rad;
}

hal::Tick Sequencer::ticks(double seconds) const noexcept {
  return static_cast<hal::Tick>(std::ceil(seconds / cfg_.period_s));
}

double Sequencer::seconds_since(hal::Tick now, hal::Tick t0) const noexcept {
  return static_cast<double>(now - t0) * cfg_.period_s;
}

double Sequencer::commanded_crank_phase() const noexcept {
  return motion::wrap_two_pi(cmd_.axes[index(Axis::kBeatCrank)].target_position - cfg_.crank_park_position_rad);
}

double Sequencer::commanded_rocker_angle() const noexcept {
  return profiles_->rocker().at(commanded_crank_phase()).value;
}

void Sequencer::latch(Fault f, hal::Tick now, int axis, std::uint16_t detail) noexcept {
  if (first_fault_ == Fault::kNone) {
    first_fault_ = stopped_by_ = f;
    fault_axis_ = axis;
    fault_detail_ = detail;
    fault_tick_ = now;
  }
  crank_move_.active = carriage_move_.active = helix_move_.active = false;
  sweeping_ = false;
  enter(State::kFault, now);
}

void Sequencer::enter(State s, hal::Tick now) noexcept {
  state_ = s;
  state_since_ = now;
}

bool Sequencer::check_faults(hal::Tick now, const hal::HalInputs& in) noexcept {
  if (!in.io.estop_ok) {
    latch(Fault::kEStop, now);
    return true;
  }
  for (std::size_t i = 0; i < hal::kAxisCount; ++i) {
    const hal::AxisFeedback& a = in.axes[i];
    if (a.fault || a.state == DriveState::kFault || a.state == DriveState::kFaultReactionActive) {
      latch(a.fault_code == kHeartbeatCode ? Fault::kHeartbeatLost : Fault::kDriveFault, now, static_cast<int>(i),
            a.fault_code);
      return true;
    }
  }
  if (in.link.link_fault) {
    latch(in.link.link_fault_code == kHeartbeatCode ? Fault::kHeartbeatLost : Fault::kLinkFault, now, -1,
          in.link.link_fault_code);
    return true;
  }
  // Data never seen counts as old as the time since arming: the first PDOs of a freshly started bus
  // legitimately arrive a few cycles after the first SYNC.
  const hal::Tick stale = ticks(cfg_.stale_timeout_s);
  const auto too_old = [&](hal::Tick refreshed) {
    return now - (refreshed == hal::kNeverTick ? armed_since_ : refreshed) > stale;
  };
  for (std::size_t i = 0; i < hal::kAxisCount; ++i) {
    if (too_old(in.axes[i].refreshed)) {
      latch(Fault::kStaleFeedback, now, static_cast<int>(i));
      return true;
    }
  }
  if (too_old(in.io.refreshed)) {
    latch(Fault::kStaleFeedback, now);
    return true;
  }
  return false;
}

bool Sequencer::is_symptom(Fault f) noexcept {
  return f == Fault::kStaleFeedback || f == Fault::kCarriageInWarp || f == Fault::kPickWithoutShed ||
         f == Fault::kShedWithShuttle;
}

void Sequencer::refine_diagnosis(hal::Tick now, const hal::HalInputs& in) noexcept {
  if (!is_symptom(first_fault_) || now - fault_tick_ > ticks(cfg_.diagnosis_window_s)) return;
  for (std::size_t i = 0; i < hal::kAxisCount; ++i) {
    const hal::AxisFeedback& a = in.axes[i];
    if (a.fault || a.state == DriveState::kFault || a.state == DriveState::kFaultReactionActive) {
      first_fault_ = a.fault_code == kHeartbeatCode ? Fault::kHeartbeatLost : Fault::kDriveFault;
      fault_axis_ = static_cast<int>(i);
      fault_detail_ = a.fault_code;
      return;
    }
  }
  if (in.link.link_fault) {
    first_fault_ = in.link.link_fault_code == kHeartbeatCode ? Fault::kHeartbeatLost : Fault::kLinkFault;
    fault_axis_ = -1;
    fault_detail_ = in.link.link_fault_code;
  }
}

void Sequencer::debounce(const hal::DigitalInputs& raw) noexcept {
  const std::array<bool, 6> r{raw.piston_a_extended, raw.piston_a_retracted, raw.piston_b_extended,
                              raw.piston_b_retracted, raw.shuttle_at_left,  raw.shuttle_at_right};
  std::array<bool*, 6> v{&io_.piston_a_extended, &io_.piston_a_retracted, &io_.piston_b_extended,
                         &io_.piston_b_retracted, &io_.shuttle_at_left,  &io_.shuttle_at_right};
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (!io_primed_ || r[i] == *v[i]) {
      *v[i] = r[i];
      disagree_[i] = 0;
    } else if (++disagree_[i] >= cfg_.debounce_ticks) {
      *v[i] = r[i];
      disagree_[i] = 0;
    }
  }
  io_primed_ = true;
  io_.estop_ok = raw.estop_ok;  // never filtered: an opened e-stop chain acts at once
  io_.refreshed = raw.refreshed;
}

void Sequencer::begin_shed(hal::Tick now) noexcept {
  if (!row_started_) {
    row_started_ = true;
    row_start_ = now;
    row_beats_ = 0;
    beats_published_ = 0;
    const std::uint32_t row = counters_.rows + 1;
    row_ = RowStats{};
    row_.row = row;
  }
  // The shed may only change with the shuttle out of it: a shuttle seen at neither selvedge is lost
  // (stuck in the shed, or its sensor failed) and needs an operator, not a shed change.
  if (!shuttle_at_selvedge(io_)) {
    latch(Fault::kShuttleLost, now);
    return;
  }
  // Alternate the shed every pick: even picks lift frame A, odd picks frame B.
  const bool a_up = counters_.picks % 2 == 0;
  cmd_.io.piston_a_extend = a_up;
  cmd_.io.piston_b_extend = !a_up;
  shed_.start(a_up, !a_up, {io_.piston_a_extended, io_.piston_a_retracted},
              {io_.piston_b_extended, io_.piston_b_retracted});
  phase_start_ = now;
  enter(State::kShed, now);
}

void Sequencer::begin_row(hal::Tick now) noexcept {
  if (slot_ != nullptr && slot_->swap_at_row_boundary()) {
    // A new recipe: its warp window guards the interlocks from now on, and the machine re-arms from
    // its measured positions (crank to park, carriage to a selvedge of the new width) before the row.
    profiles_ = &slot_->active();
    interlock_ctx_.warp = &profiles_->beatup().warp();
    ++recipe_changes_;
    enter(State::kPositioning, now);
    return;
  }
  begin_shed(now);
}

void Sequencer::begin_sweep(hal::Tick now, const hal::HalInputs& in) noexcept {
  if (!row_started_) {  // resumed after a restart with every pick of the row already done
    row_started_ = true;
    row_start_ = now;
    row_ = RowStats{};
    row_.row = counters_.rows + 1;
  }
  // The crank turns `beats` full turns from park; the carriage rides the cam on it, starting from the
  // selvedge it stands at, so successive rows sweep in alternating directions.
  const double rel = in.axes[index(Axis::kCarriage)].position - cfg_.carriage_home_m;
  carriage_sweep_dir_ = rel < 0.5 * profiles_->carriage_travel_m() ? 1.0 : -1.0;
  carriage_sweep_origin_ = cmd_.axes[index(Axis::kCarriage)].target_position;
  crank_sweep_origin_ = cmd_.axes[index(Axis::kBeatCrank)].target_position;
  crank_move_ = {true, now, crank_sweep_origin_, profiles_->crank_sweep()};
  sweeping_ = true;
  row_beats_ = 0;
  beats_published_ = 0;
  phase_start_ = now;
  enter(State::kBeatSweep, now);
}

void Sequencer::track_beat_force(const hal::HalInputs& in) noexcept {
  if (!sweeping_ || !in.analog.beat_force_valid) return;
  // Beat k is the k-th passage through the warp; its peak is recorded while the beater is in the warp.
  const double phi = in.axes[index(Axis::kBeatCrank)].position - crank_sweep_origin_;
  const int k = static_cast<int>(std::floor(phi / motion::kTwoPi));
  if (k < 0 || k >= profiles_->beats_per_row() || k >= kMaxBeatsPerRow) return;
  if (!beater_in_warp(interlock_ctx_, in.axes[index(Axis::kBeatCrank)].position)) return;
  BeatRecord& b = row_.beat[static_cast<std::size_t>(k)];
  b.peak_force_n = std::max(b.peak_force_n, static_cast<float>(in.analog.beat_force_n));
  row_.force_measured = true;
}

void Sequencer::advance(hal::Tick now, const hal::HalInputs& in) noexcept {
  const auto& crank_fb = in.axes[index(Axis::kBeatCrank)];
  const auto& carriage_fb = in.axes[index(Axis::kCarriage)];
  switch (state_) {
    case State::kIdle:
      request_all(cmd_, AxisRequest::kDisable);
      for (std::size_t i = 0; i < hal::kAxisCount; ++i) cmd_.axes[i].target_position = in.axes[i].position;
      // Valves hold the frames where the end sensors see them: starting up (or restarting after a power
      // loss) never moves a frame, so a shuttle left in the shed is never clamped.
      cmd_.io.piston_a_extend = io_.piston_a_extended;
      cmd_.io.piston_b_extend = io_.piston_b_extended;
      if (start_requested_) {
        start_requested_ = false;
        armed_since_ = now;
        enter(State::kEnabling, now);
      }
      break;

    case State::kEnabling: {
      request_all(cmd_, AxisRequest::kEnable);
      // Until every drive is enabled the targets follow the measured positions: enabling never jumps.
      bool all = true;
      for (std::size_t i = 0; i < hal::kAxisCount; ++i) {
        cmd_.axes[i].target_position = in.axes[i].position;
        all = all && in.axes[i].state == DriveState::kOperationEnabled;
      }
      if (all) {
        enabled_outputs_ = true;
        // Re-arm from measured positions: crank to the nearest park, then carriage to the nearest selvedge.
        const double phase = motion::wrap_pi(crank_fb.position - cfg_.crank_park_position_rad);
        crank_move_ = {true, now, cmd_.axes[index(Axis::kBeatCrank)].target_position,
                       motion::JerkMove::plan(-phase, profiles_->spec().crank)};
        // Valves hold whatever the frames show now, so re-arming never moves a frame over the shuttle.
        cmd_.io.piston_a_extend = io_.piston_a_extended;
        cmd_.io.piston_b_extend = io_.piston_b_extended;
        enter(State::kPositioning, now);
      } else if (now - state_since_ > ticks(cfg_.enable_timeout_s)) {
        latch(Fault::kEnableTimeout, now);
      }
      break;
    }

    case State::kPositioning:
      if (crank_move_.active || carriage_move_.active) break;
      {
        const double rel = carriage_fb.position - cfg_.carriage_home_m;
        const double travel = profiles_->carriage_travel_m();
        const double goal = rel < 0.5 * travel ? 0.0 : travel;
        if (std::abs(rel - goal) > cfg_.selvedge_tolerance_m) {
          carriage_move_ = {true, now, cmd_.axes[index(Axis::kCarriage)].target_position,
                            motion::JerkMove::plan(goal - rel, cfg_.carriage)};
          break;
        }
      }
      // Power lost mid-pick: the shuttle is in the open shed on its carrier. Finish that pick rather than
      // start a new one (nothing repeated, nothing lost); without an open shed it needs an operator.
      if (!shuttle_at_selvedge(io_)) {
        if (!shed_confirmed(io_)) {
          latch(Fault::kShuttleLost, now);
          break;
        }
        pick_to_right_ = counters_.picks % 2 == 0;  // the shuttle starts at the left: even picks go right
        const double goal =
            cfg_.helix_left_position_rad + (pick_to_right_ ? profiles_->pick().distance() : 0.0);
        const double from = cmd_.axes[index(Axis::kHelix)].target_position;
        helix_move_ = {true, now, from, motion::JerkMove::plan(goal - from, profiles_->helix_limits())};
        if (!row_started_) {
          row_started_ = true;
          row_start_ = now;
          row_ = RowStats{};
          row_.row = counters_.rows + 1;
        }
        phase_start_ = now;
        enter(State::kPick, now);
        break;
      }
      // A pick that completed just before a power loss may not have reached the counters file: the
      // shuttle's side tells (it starts at the left, so an even pick count means left).
      if (shuttle_at_selvedge(io_) && io_.shuttle_at_left != (counters_.picks % 2 == 0) &&
          counters_.picks_in_row < cfg_.picks_per_row) {
        ++counters_.picks;
        ++counters_.picks_in_row;
      }
      if (counters_.picks_in_row >= cfg_.picks_per_row) {
        begin_sweep(now, in);
      } else {
        begin_shed(now);
      }
      break;

    case State::kShed: {
      // The end sensors must confirm inside the profiles' window (not faster than a stroke, frames
      // off their start sensors early, by the timeout), then the frames settle before the pick.
      const motion::ShedVerdict v = shed_.update(profiles_->shed(), seconds_since(now, state_since_),
                                                 {io_.piston_a_extended, io_.piston_a_retracted},
                                                 {io_.piston_b_extended, io_.piston_b_retracted});
      if (v == motion::ShedVerdict::kOpen) {
        if (!shuttle_at_selvedge(io_)) {
          latch(Fault::kShuttleLost, now);
          break;
        }
        pick_to_right_ = io_.shuttle_at_left;
        helix_move_ = {true, now, cmd_.axes[index(Axis::kHelix)].target_position,
                       pick_to_right_ ? profiles_->pick() : profiles_->pick_back()};
        row_.shed_ticks += now - phase_start_;
        phase_start_ = now;
        enter(State::kPick, now);
      } else if (v == motion::ShedVerdict::kTooEarly) {
        latch(Fault::kShedSensorEarly, now);
      } else if (v == motion::ShedVerdict::kNotReleased) {
        latch(Fault::kShedNotReleased, now);
      } else if (v == motion::ShedVerdict::kTimeout) {
        latch(Fault::kShedTimeout, now);
      }
      break;
    }

    case State::kPick: {
      const bool arrived = pick_to_right_ ? io_.shuttle_at_right : io_.shuttle_at_left;
      if (!helix_move_.active && arrived) {
        ++counters_.picks;
        ++counters_.picks_in_row;
        row_.pick_ticks += now - phase_start_;
        if (counters_.picks_in_row < cfg_.picks_per_row) {
          if (pause_requested_) {
            enter(State::kPaused, now);
          } else {
            begin_shed(now);
          }
        } else {
          begin_sweep(now, in);
        }
      } else if (seconds_since(now, state_since_) > profiles_->pick().duration() + cfg_.pick_timeout_margin_s) {
        latch(Fault::kShuttleNotArrived, now);
      }
      break;
    }

    case State::kBeatSweep:
      if (!crank_move_.active) {
        sweeping_ = false;
        while (beats_published_ < row_beats_) publish_beat(beats_published_);
        ++counters_.rows;
        counters_.picks_in_row = 0;
        row_started_ = false;
        row_.beat_ticks = now - phase_start_;
        row_.total_ticks = now - row_start_;
        row_.beats = row_beats_;
        row_.carriage_steps = profiles_->cam().steps();
        if (row_.force_measured && row_beats_ > 0) {
          double lo = 1e300, hi = 0.0, sum = 0.0;
          for (int k = 0; k < row_beats_; ++k) {
            const double f = row_.beat[static_cast<std::size_t>(k)].peak_force_n;
            lo = std::min(lo, f);
            hi = std::max(hi, f);
            sum += f;
          }
          row_.force_min_n = lo;
          row_.force_max_n = hi;
          row_.force_mean_n = sum / row_beats_;
        }
        last_row_ = row_;
        const bool enough = cfg_.rows_to_weave != 0 && counters_.rows >= cfg_.rows_to_weave;
        if (enough || stop_requested_) {
          enter(State::kDone, now);
        } else if (pause_requested_) {
          enter(State::kPaused, now);
        } else {
          begin_row(now);
        }
      }
      break;

    case State::kPaused:
      // Paused between the picks of a row resumes that row; paused at a row's end starts the next.
      if (!pause_requested_) row_started_ ? begin_shed(now) : begin_row(now);
      break;

    case State::kDone:
    case State::kFault:
      break;
  }
}

void Sequencer::play_moves(hal::Tick now) noexcept {
  const auto play = [&](ActiveMove& m, Axis axis) {
    if (!m.active) return;
    const double t = seconds_since(now, m.t0);
    cmd_.axes[index(axis)].target_position = m.origin + m.move.at(t).position;
    if (t >= m.move.duration()) m.active = false;
  };
  const double sweep_t = seconds_since(now, crank_move_.t0);  // before play() may end the move
  play(crank_move_, Axis::kBeatCrank);
  play(carriage_move_, Axis::kCarriage);
  play(helix_move_, Axis::kHelix);
  if (sweeping_) {
    // The sweep move is the master phase; the crank follows the speed law (constant: the same).
    const motion::Phase master = motion::Phase::from_rad(crank_move_.move.at(sweep_t).position);
    const double phi = profiles_->crank_at(master).phase;
    cmd_.axes[index(Axis::kBeatCrank)].target_position = crank_sweep_origin_ + phi;
    cmd_.axes[index(Axis::kCarriage)].target_position =
        carriage_sweep_origin_ + carriage_sweep_dir_ * profiles_->cam().at(phi).position;
    // A beat is delivered when the commanded crank passes the fell of turn k.
    const double fell = profiles_->beatup().warp().fell;
    while (row_beats_ < profiles_->beats_per_row() && phi >= motion::kTwoPi * row_beats_ + fell) {
      if (row_beats_ < kMaxBeatsPerRow) {
        row_.beat[static_cast<std::size_t>(row_beats_)].x_m = static_cast<float>(
            cmd_.axes[index(Axis::kCarriage)].target_position - cfg_.carriage_home_m);
      }
      ++row_beats_;
      ++counters_.beats;
    }
    // A counted beat is published once the beater has left the warp (its peak force is final then).
    const double exit = profiles_->beatup().warp().exit;
    while (beats_published_ < row_beats_ && phi >= motion::kTwoPi * beats_published_ + exit) {
      publish_beat(beats_published_);
    }
  }
}

void Sequencer::publish_beat(int k) noexcept {
  BeatEvent e;
  e.row = counters_.rows + 1;
  e.index = static_cast<std::uint16_t>(k);
  if (k < kMaxBeatsPerRow) {
    const BeatRecord& b = row_.beat[static_cast<std::size_t>(k)];
    e.x_m = b.x_m;
    e.peak_force_n = b.peak_force_n;
  }
  e.force_measured = row_.force_measured;
  e.in_band = e.force_measured && e.peak_force_n >= cfg_.beat_force_min_n && e.peak_force_n <= cfg_.beat_force_max_n;
  last_beat_ = e;
  ++beat_events_;
  beats_published_ = k + 1;
}

void Sequencer::step(hal::Tick now, const hal::HalInputs& raw, hal::HalOutputs& out) noexcept {
  debounce(raw.io);
  hal::HalInputs in = raw;  // the sequencer and its interlocks see debounced sensors
  in.io = io_;
  if (state_ != State::kIdle && state_ != State::kFault) check_faults(now, in);
  if (external_fault_ != Fault::kNone && state_ != State::kFault) latch(external_fault_, now);
  if (state_ == State::kFault) refine_diagnosis(now, in);
  if (state_ == State::kIdle && start_requested_ && !in.io.estop_ok) {
    start_requested_ = false;
    latch(Fault::kEStop, now);
  }
  advance(now, in);
  if (state_ == State::kFault) {
    // Quick stop, hold the last targets, valves keep their state (a stopped shuttle is never clamped).
    request_all(cmd_, AxisRequest::kQuickStop);
  } else {
    play_moves(now);
    track_beat_force(in);
    if (enabled_outputs_) {
      const Fault f = check_interlocks(interlock_ctx_, in, prev_cmd_, cmd_);
      if (f != Fault::kNone) {
        cmd_ = prev_cmd_;
        latch(f, now);
        request_all(cmd_, AxisRequest::kQuickStop);
      }
    }
  }
  prev_cmd_ = cmd_;
  out = cmd_;
}

}  // namespace loom::sequencer

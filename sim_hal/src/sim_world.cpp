// Simulated devices. Drive power states change in one tick (a real drive takes a few; the CAN drive
// node models that). Positions only follow targets in Operation Enabled. Sensors are computed from the
// true state, then stuck-sensor faults override them, then noise flips them.
#include "loom/sim_hal/sim_world.hpp"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "loom/motion/angles.hpp"
#include "loom/sim_hal/effects.hpp"

namespace loom::sim_hal {

double SimRandom::uniform() noexcept {
  std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53;
}

SimWorld::SimWorld(const SimMachine& machine, const SceneSpec& scene)
    : m_(machine), scene_(scene), rng_(scene.seed) {
  if (m_.axis_count < hal::kCoreAxisCount || m_.axis_count > hal::kMaxAxes) {
    throw std::invalid_argument("simulated machine: " + std::to_string(m_.axis_count) + " axes (3.." +
                                std::to_string(hal::kMaxAxes) + ")");
  }
  n_axes_ = m_.axis_count;
  silent_since_.fill(-1);
  const bool latency = std::any_of(scene_.faults.begin(), scene_.faults.end(), [](const FaultInjection& f) {
    return f.kind == InjectedFault::kCanLatency;
  });
  history_ticks_ = latency ? kHistory : 1;
  // Power-up: a homed axis' incremental encoder starts at an arbitrary count (drawn from the scene's
  // seed, so a run replays), an absolute one reads the machine position.
  SimRandom power_up(scene_.seed ^ 0x5EEDF00Dull);
  for (std::size_t i = 0; i < n_axes_; ++i) {
    const SimReferencing& ref = m_.referencing[i];
    if (ref.method == 0) continue;
    const double span = ref.index_pitch > 0.0 ? 40.0 * ref.index_pitch : 100.0;
    axes_[i].offset = (power_up.uniform() - 0.5) * span;
    axes_[i].referenced = false;
  }
  for (const FaultInjection& f : scene_.faults) {
    const bool names_axis = f.kind == InjectedFault::kDriveFault || f.kind == InjectedFault::kHeartbeatLoss ||
                            f.kind == InjectedFault::kEmcy || f.kind == InjectedFault::kEncoderGlitch;
    if (names_axis && f.axis >= n_axes_) {
      throw std::invalid_argument("fault on axis '" + f.axis_name +
                                  "': the simulated machine has no such axis");
    }
  }
  history_.resize(history_ticks_ * n_axes_);
  for (const std::string& e : scene_.effects) {
    if (e == kEffectIdeal) continue;  // ideal tracking is the absence of axis effects
    if (e == kEffectServoLag) {
      const ServoLag lag = scene_.servo_lag.value_or(ServoLag{});
      for (std::size_t i = 0; i < n_axes_; ++i) axes_[i].effects.push_back(make_servo_lag(lag));
      continue;
    }
    // Device effects: their parameter blocks are what switches them on; default them if absent.
    if (e == kEffectPneumatics) {
      if (!scene_.pneumatics) scene_.pneumatics = Pneumatics{};
    } else if (e == kEffectShuttleSlip) {
      if (!scene_.shuttle_slip) scene_.shuttle_slip = ShuttleSlip{};
    } else if (e == kEffectSensorNoise) {
      if (!scene_.sensor_noise) scene_.sensor_noise = SensorNoise{};
    } else if (e == kEffectBeatContact) {
      if (!scene_.beat_contact) scene_.beat_contact = BeatContact{};
    } else if (e == kEffectInertia) {
      if (!scene_.inertia) scene_.inertia = Inertia{};
      const bool friction = std::find(scene_.effects.begin(), scene_.effects.end(), kEffectJointFriction) !=
                            scene_.effects.end();
      if (friction && !scene_.joint_friction) scene_.joint_friction = JointFriction{};
      axes_[hal::index(hal::CoreAxis::kBeatCrank)].effects.push_back(
          make_crank_inertia(m_, *scene_.inertia, friction ? &*scene_.joint_friction : nullptr));
    } else if (e == kEffectKnotter) {
      if (m_.knotting.heads < 1) {
        throw std::invalid_argument(
            "effect 'knotter' simulates the knotting heads: the loom has none (knotting.mode = \"heads\")");
      }
      if (!scene_.knotter) scene_.knotter = Knotter{};
      knotter_ = std::make_unique<SimKnotter>(m_.knotting, *scene_.knotter, m_.period_s);
    } else if (e == kEffectWarpTension) {
      if (std::find(scene_.effects.begin(), scene_.effects.end(), kEffectBeatContact) ==
          scene_.effects.end()) {
        throw std::invalid_argument(
            "effect 'warp_tension' scales the beat's force on the load cell: name 'beat_contact' too");
      }
      if (!scene_.warp_tension) scene_.warp_tension = WarpTension{};
      warp_tension_ = std::make_unique<WarpTensionModel>(*scene_.warp_tension, m_, scene_.seed);
    } else if (e == kEffectJointFriction) {
      if (std::find(scene_.effects.begin(), scene_.effects.end(), kEffectInertia) == scene_.effects.end()) {
        throw std::invalid_argument(
            "effect 'joint_friction' acts on the crank's dynamics: name 'inertia' too");
      }
    } else {
      throw std::invalid_argument("unknown simulation effect '" + e + "'");
    }
  }
  // The valves' fill per tick depends only on the period and the time constant: one exp here, not two a tick.
  if (scene_.pneumatics) pressure_fill_ = 1.0 - std::exp(-m_.period_s / scene_.pneumatics->fill_tau_s);
  beatup_ = std::make_unique<motion::BeatUp>(m_.beatup);
  if (scene_.beat_contact) bracket_contact();
  // Each fault strikes at the first tick whose time reaches at_s (a power cut: at its own tick).
  const auto strike = [&](const FaultInjection& f) {
    if (f.kind == InjectedFault::kPowerCut) return f.at_tick;
    return static_cast<hal::Tick>(std::ceil(f.at_s / m_.period_s - 1e-9));
  };
  std::stable_sort(scene_.faults.begin(), scene_.faults.end(),
                   [&](const FaultInjection& a, const FaultInjection& b) { return strike(a) < strike(b); });
  for (const FaultInjection& f : scene_.faults) fault_tick_.push_back(strike(f));
}

SimWorld::~SimWorld() = default;

std::size_t SimWorld::effect_count() const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < n_axes_; ++i) n += axes_[i].effects.size();
  n += scene_.pneumatics.has_value() + scene_.shuttle_slip.has_value() + scene_.sensor_noise.has_value() +
       scene_.beat_contact.has_value() + scene_.joint_friction.has_value() + (warp_tension_ != nullptr);
  return n;
}

void SimWorld::set_initial_state(const hal::AxisFeedbacks& axes, std::array<double, 2> pistons) {
  for (std::size_t i = 0; i < n_axes_; ++i) axes_[i].position = axes_[i].target = axes[i].position;
  piston_ = pistons;
  for (std::size_t i = 0; i < 2; ++i) pressure_[i] = pistons[i] > 0.5 ? 1.0 : -1.0;
  const double helix = axes_[hal::index(hal::CoreAxis::kHelix)].position;
  shuttle_x_ = carrier_x_prev_ = helix * m_.helix_lead_m / motion::kTwoPi;
}

void SimWorld::attach_state_file(SimStateFile& file) {
  PersistedMachine pm;
  if (file.load(pm)) {
    hal::AxisFeedbacks axes{};
    for (std::size_t i = 0; i < pm.axis_position.size(); ++i) axes[i].position = pm.axis_position[i];
    for (std::size_t i = 0; i < pm.added_axis_position.size(); ++i)
      axes[hal::kCoreAxisCount + i].position = pm.added_axis_position[i];
    set_initial_state(axes, pm.piston);
    shuttle_x_ = pm.shuttle_x;
    // A shuttle cut mid-pick is still carrying its weft: its arrival at either selvedge locks the knots.
    const double win = m_.selvedge_sensor_window_m;
    shuttle_side_ = shuttle_x_ <= win ? -1 : shuttle_x_ >= m_.width_m - win ? 1 : kMidPick;
  }
  state_file_ = &file;
}

void SimWorld::persist_carpet(std::uint32_t counter_rows, std::optional<std::uint32_t> carpet_began) {
  if (knotter_ && state_file_ != nullptr && state_file_->carpet() != nullptr) {
    knotter_->persist_in(*state_file_->carpet(), counter_rows, carpet_began);
  } else if (knotter_) {
    knotter_->start_at_row(counter_rows);
  }
}

bool SimWorld::beater_in_warp() const {
  const double phase = axes_[hal::index(hal::CoreAxis::kBeatCrank)].position - m_.crank_park_position_rad;
  const motion::WarpWindow& w = beatup_->warp();
  const double p = motion::wrap_two_pi(phase);
  return p > w.enter && p < w.exit;
}

void SimWorld::apply_injected_faults(hal::Tick now) noexcept {
  const auto ticks = [&](double seconds) {
    return seconds > 0.0 ? now + static_cast<hal::Tick>(std::ceil(seconds / m_.period_s - 1e-9))
                         : std::numeric_limits<hal::Tick>::max();
  };
  while (next_fault_ < scene_.faults.size() && fault_tick_[next_fault_] <= now) {
    const FaultInjection& f = scene_.faults[next_fault_++];
    const std::size_t ax = f.axis;  // checked in the constructor
    switch (f.kind) {
      case InjectedFault::kEStop:
        estop_ok_ = false;
        break;
      case InjectedFault::kDriveFault:
        axes_[ax].state = hal::DriveState::kFault;
        axes_[ax].fault_code = f.code;
        break;
      case InjectedFault::kStuckPiston:
        piston_stuck_[static_cast<std::size_t>(f.piston)] = true;
        break;
      case InjectedFault::kStuckSensor:
        stuck_sensor_[static_cast<std::size_t>(f.sensor)] = f.stuck_value;
        sensor_until_[static_cast<std::size_t>(f.sensor)] = std::numeric_limits<hal::Tick>::max();
        break;
      case InjectedFault::kIntermittentSensor:
        stuck_sensor_[static_cast<std::size_t>(f.sensor)] = f.stuck_value;
        sensor_until_[static_cast<std::size_t>(f.sensor)] = ticks(f.duration_s);
        break;
      case InjectedFault::kCanFrameLoss:
        frame_loss_p_ = f.probability;
        frame_loss_until_ = ticks(f.duration_s);
        break;
      case InjectedFault::kCanLatency:
        latency_ticks_ = std::min(static_cast<hal::Tick>(std::llround(f.latency_s / m_.period_s)),
                                  static_cast<hal::Tick>(history_ticks_ - 1));
        latency_until_ = ticks(f.duration_s);
        break;
      case InjectedFault::kBusOff:
        bus_off_ = true;
        break;
      case InjectedFault::kHeartbeatLoss:
        silent_since_[ax] = now;
        break;
      case InjectedFault::kEmcy:
        axes_[ax].fault_code = f.code;
        break;  // still Operation Enabled
      case InjectedFault::kEncoderGlitch:
        glitch_left_[ax] = std::max(1, f.ticks);
        glitch_jump_[ax] = f.jump;
        break;
      case InjectedFault::kLoadCellFailure:
        load_cell_failed_ = f.load_cell;
        break;
      case InjectedFault::kAirLoss:
        air_lost_ = true;
        break;
      case InjectedFault::kLoopStall:
        stall_until_ = now + std::max(1, f.ticks);
        injected_overruns_ += static_cast<std::uint32_t>(std::max(1, f.ticks));
        break;
      case InjectedFault::kSelectorJam:
        if (knotter_ && f.head >= 0 && f.head < m_.knotting.heads)
          jammed_[m_.knotting.selector_axis[static_cast<std::size_t>(f.head)]] = true;
        break;
      case InjectedFault::kYarnOut:
        if (knotter_) knotter_->yarn_out(f.head, f.slot);
        break;
      case InjectedFault::kAxisJam:
        jammed_[ax] = true;
        break;
      case InjectedFault::kPowerCut:
        powered_off_ = true;
        if (power_cut_handler_ == nullptr) std::raise(SIGKILL);  // as if killed: nothing more is written
        power_cut_handler_(power_cut_ctx_);
        return;
    }
  }
  // Until a fault strikes, nothing below has anything to recover (the per-tick cost of an unfaulted scene).
  if (next_fault_ == 0) return;
  for (std::size_t i = 0; i < sensor_until_.size(); ++i) {
    if (stuck_sensor_[i] && now >= sensor_until_[i])
      stuck_sensor_[i].reset();  // an intermittent fault recovers
  }
  if (now >= frame_loss_until_) frame_loss_p_ = 0.0;
  if (now >= latency_until_) latency_ticks_ = 0;
}

namespace {
// One axis' feedback as its drive reports it; `jump` is an encoder glitch's offset (0.0 outside one: adding
// it also turns a -0.0 sum into +0.0, the same on every path).
// Written field by field into its place (every field: no event here, SimWorld::raise_fault_events sets it),
// not built aside and copied: the loop's cheapest tick reads the axes this way.
inline void feedback_into(hal::AxisFeedback& fb, const SimAxis& s, double jump, hal::Tick now) noexcept {
  fb.state = s.state;
  fb.position = s.position + s.offset + jump;
  fb.velocity = s.velocity;
  fb.effort = 0.0;
  fb.fault = s.state == hal::DriveState::kFault;
  fb.fault_code = s.fault_code;
  fb.fault_kind = fb.fault            ? hal::FaultKind::kDrive
                  : s.fault_code != 0 ? hal::FaultKind::kEmcy
                                      : hal::FaultKind::kNone;
  fb.following_error = false;
  fb.referenced = s.referenced;
  fb.homing_error = false;
  fb.fault_raised = false;
  fb.refreshed = now;
}
}  // namespace

void SimWorld::read_axes(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) noexcept {
  // (the call only when a fault strikes now or has struck: before, it would do nothing)
  if (next_fault_ != 0 || (!fault_tick_.empty() && fault_tick_[0] <= now)) apply_injected_faults(now);
  if (powered_off_ || stalled(now)) {  // nothing refreshed: the values keep their old ticks
    raise_fault_events(axes, link);
    return;
  }
  // Until a fault strikes (no frame lost, no node silent, no bus-off) and without CAN latency, every
  // frame arrives as sampled: sample straight into `axes`, not into the history and then across.
  const bool direct = history_ticks_ == 1 && next_fault_ == 0;
  if (direct) {
    // No fault has struck, so no encoder glitch either (glitch_left_ is all 0): the loop below, on `axes`,
    // without the glitch's test and count.
    // Nor a device fault: no event, and the edges stay clear.
    for (std::size_t i = 0; i < n_axes_; ++i) feedback_into(axes[i], axes_[i], 0.0, now);
    link = hal::LinkStatus{};
    return;
  }
  read_struck(now, axes, link);
  raise_fault_events(axes, link);
}

void SimWorld::raise_fault_events(hal::AxisFeedbacks& axes, hal::LinkStatus& link) noexcept {
  for (std::size_t i = 0; i < n_axes_; ++i) fault_edges_[i].raise(axes[i]);
  link_edge_.raise(link);
}

void SimWorld::read_struck(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) noexcept {
  hal::AxisFeedback* truth = &history_[static_cast<std::size_t>(now) % history_ticks_ * n_axes_];
  for (std::size_t i = 0; i < n_axes_; ++i) {
    feedback_into(truth[i], axes_[i], glitch_left_[i] > 0 ? glitch_jump_[i] : 0.0, now);
    if (glitch_left_[i] > 0) --glitch_left_[i];
  }
  link = hal::LinkStatus{};
  if (bus_off_) {  // no frame gets through any more, and the simulated controller never restarts
    link.link_fault = true;
    link.link_fault_kind = hal::FaultKind::kBusOff;
    link.link_fault_code = kEmcyBusOff;
    link.recovery = hal::LinkRecovery::kBusOff;
    return;
  }
  // Latency: what arrives now was sampled `latency_ticks_` ago and carries that sample's tick.
  const hal::Tick delay = std::min<hal::Tick>(latency_ticks_, now);
  const hal::AxisFeedback* arrived =
      &history_[static_cast<std::size_t>(now - delay) % history_ticks_ * n_axes_];
  for (std::size_t i = 0; i < n_axes_; ++i) {
    if (silent_since_[i] >= 0) {
      // A silent node sends nothing; its heartbeat consumer reports it after the heartbeat time.
      if (now - silent_since_[i] >= static_cast<hal::Tick>(std::ceil(kSimHeartbeatTimeoutS / m_.period_s))) {
        axes[i].fault = true;
        axes[i].fault_code = kEmcyHeartbeat;
        axes[i].fault_kind = hal::FaultKind::kNodeLost;
      }
      continue;
    }
    if (frame_loss_p_ > 0.0 && rng_.uniform() < frame_loss_p_) continue;  // this frame was lost
    axes[i] = arrived[i];
  }
}

void SimWorld::step_axis(std::size_t slot, const hal::AxisCommand& cmd) noexcept {
  using hal::AxisRequest;
  using hal::DriveState;
  SimAxis& ax = axes_[slot];
  const double before = ax.position;
  // The drive follows its target in Operation Enabled (commands are in the drive's reading); a jammed axis
  // (scene fault selector_jam) stays where it is.
  const auto follow = [&] {
    if (jammed_[slot]) return;
    ax.target = cmd.target_position - ax.offset;
    double actual = ax.target;
    if (!ax.effects.empty()) {
      actual = ax.position;
      for (auto& e : ax.effects) actual = e->step(ax.target, actual, m_.period_s);
    }
    ax.position = actual;
  };
  if (ax.state == DriveState::kOperationEnabled && cmd.request == AxisRequest::kEnable) {
    // The usual tick: enabled and asked to stay so. No power-state change, no homing run.
    ax.homing = false;
    follow();
    ax.velocity = (ax.position - before) / m_.period_s;
    return;
  }
  if (ax.state == DriveState::kFault) {
    if (cmd.request == AxisRequest::kFaultReset) {
      ax.state = DriveState::kSwitchOnDisabled;
      ax.fault_code = 0;
    }
  } else {
    switch (cmd.request) {
      case AxisRequest::kDisable:
        ax.state = DriveState::kSwitchOnDisabled;
        break;
      case AxisRequest::kEnable:
      case AxisRequest::kHome:
        if (ax.state != DriveState::kQuickStopActive) ax.state = DriveState::kOperationEnabled;
        break;
      case AxisRequest::kQuickStop:
        if (ax.state == DriveState::kOperationEnabled) ax.state = DriveState::kQuickStopActive;
        break;
      case AxisRequest::kFaultReset:
        break;
    }
  }
  // A homing run moves the axis by itself (the drive's mode 6) until its reference point; anything but
  // kHome while enabled ends it, referenced or not.
  const bool homing = ax.state == DriveState::kOperationEnabled && cmd.request == AxisRequest::kHome &&
                      m_.referencing[slot].method != 0 && !ax.referenced;
  if (!homing) ax.homing = false;
  if (homing) {
    step_homing(slot);
  } else if (ax.state == DriveState::kOperationEnabled) {
    follow();
  }
  ax.velocity = (ax.position - before) / m_.period_s;
}

void SimWorld::step_homing(std::size_t slot) noexcept {
  SimAxis& ax = axes_[slot];
  const SimReferencing& ref = m_.referencing[slot];
  if (!ax.homing) {  // the run starts: where is the reference point from here?
    const double home = ref.home_offset;
    const double pitch = ref.index_pitch;
    switch (ref.method) {
      case 19:  // switch active on the positive side: its edge, approached from either side
      case 21:
        ax.homing_goal = home;
        break;
      case 33:
        ax.homing_goal = home + std::floor((ax.position - home) / pitch) * pitch;
        break;
      case 34:
        ax.homing_goal = home + std::ceil((ax.position - home) / pitch) * pitch;
        break;
      default:
        ax.homing_goal = ax.position;
        break;  // 37: here
    }
    ax.homing = true;
  }
  const double step = ref.speed * m_.period_s;
  const double to_go = ax.homing_goal - ax.position;
  if (std::abs(to_go) > step) {
    ax.position += std::copysign(step, to_go);
    return;
  }
  // At the reference point: the drive sets its reading to the home offset there.
  ax.position = ax.homing_goal;
  ax.offset = ref.home_offset - ax.homing_goal;
  ax.target = ax.position;
  ax.referenced = true;
  ax.homing = false;
}

void SimWorld::write_axes(hal::Tick, const hal::AxisCommands& axes) noexcept {
  if (powered_off_) return;
  drives_simulated_ = true;
  for (std::size_t i = 0; i < n_axes_; ++i) {
    SimAxis& ax = axes_[i];
    const hal::AxisCommand& cmd = axes[i];
    if (ax.state == hal::DriveState::kOperationEnabled && cmd.request == hal::AxisRequest::kEnable &&
        !jammed_[i]) {
      // The usual tick, here rather than through step_axis (its power-state and homing decisions cost
      // more than this): enabled, asked to stay so, following its target. The same steps as there.
      const double before = ax.position;
      ax.homing = false;
      ax.target = cmd.target_position - ax.offset;
      double actual = ax.target;
      if (!ax.effects.empty()) {
        actual = ax.position;
        for (auto& e : ax.effects) actual = e->step(ax.target, actual, m_.period_s);
      }
      ax.position = actual;
      ax.velocity = (ax.position - before) / m_.period_s;
      continue;
    }
    step_axis(i, cmd);
  }
}

void SimWorld::bracket_contact() {
  // The tip's distance from the fell falls monotonically from the warp's entry to the fell and grows again
  // to its exit (beatup.cpp). Bisect each side for the last phase still farther than the contact depth,
  // then widen by a margin far above the solve's rounding (1e-6 rad moves the tip by ~1e-8 m where the
  // bracket lies, by ≥ 1e-13 m even at the fell itself; the solve rounds at ~1e-16 m), so that no phase
  // outside the bracket can be in contact. Its own test sweeps the warp window to check exactly that.
  const motion::WarpWindow& w = beatup_->warp();
  const double depth = scene_.beat_contact->contact_depth_m;
  const auto away = [&](double phase) { return beatup_->at(phase).from_fell_m > depth; };
  // far: an end at which the tip is farther than the depth; near: the fell. Returns the last far phase found.
  const auto last_far = [&](double far, double near) {
    if (!away(far)) return far;  // the contact reaches the warp's edge: no narrowing on this side
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (far + near);
      if (mid == far || mid == near) break;
      (away(mid) ? far : near) = mid;
    }
    return far;
  };
  contact_from_ = std::max(w.enter, last_far(w.enter, w.fell) - kContactMarginRad);
  contact_to_ = std::min(w.exit, last_far(w.exit, w.fell) + kContactMarginRad);
}

void SimWorld::step_beat_contact(double crank_position, double omega, const hal::AxisFeedbacks& fb) noexcept {
  const double alpha = (omega - crank_v_prev_) / m_.period_s;
  crank_v_prev_ = omega;
  beat_force_n_ = 0.0;
  const double phase = motion::wrap_two_pi(crank_position - m_.crank_park_position_rad);
  const motion::WarpWindow& w = beatup_->warp();
  if (!(phase > w.enter && phase < w.exit)) return;  // the exact solve is only needed near the fell
  if (!(phase >= contact_from_ && phase <= contact_to_)) return;  // and only where contact is possible
  const motion::BeaterState s = beatup_->at(phase);
  if (s.from_fell_m > scene_.beat_contact->contact_depth_m) return;
  // Tangential tip acceleration from the kinematic coefficients: L·(θ4'' ω² + θ4' α).
  const double a_t = m_.beatup.beater_arm_m * (s.d2 * omega * omega + s.d1 * alpha);
  beat_force_n_ = scene_.beat_contact->beater_mass_kg * std::abs(a_t);
  if (warp_tension_) {  // in contact only: a scene without the effect pays nothing here
    const auto turn =
        static_cast<std::int64_t>(std::floor((crank_position - m_.crank_park_position_rad) / motion::kTwoPi));
    const std::size_t c = hal::index(hal::CoreAxis::kCarriage);
    beat_force_n_ *=
        warp_tension_->factor(turn, drives_simulated_ ? axes_[c].position + axes_[c].offset : fb[c].position);
  }
}

void SimWorld::read_analog(hal::Tick now, hal::AnalogInputs& analog) noexcept {
  if (powered_off_ || stalled(now)) return;
  analog.beat_force_valid = scene_.beat_contact.has_value();
  analog.beat_force_n = beat_force_n_;
  if (load_cell_failed_ == LoadCellMode::kNan) analog.beat_force_n = std::numeric_limits<double>::quiet_NaN();
  if (load_cell_failed_ == LoadCellMode::kLost) analog.beat_force_valid = false;
  analog.refreshed = now;
}

void SimWorld::step_shuttle(double helix) noexcept {
  const double carrier = helix * m_.helix_lead_m / motion::kTwoPi;
  if (!scene_.shuttle_slip) {
    shuttle_x_ = carrier;
    return;
  }
  const double dt = m_.period_s;
  const double v = carrier_primed_ ? (carrier - carrier_x_prev_) / dt : 0.0;
  const double a = carrier_primed_ ? (v - carrier_v_prev_) / dt : 0.0;
  carrier_primed_ = true;
  carrier_x_prev_ = carrier;
  carrier_v_prev_ = v;
  const ShuttleSlip& p = *scene_.shuttle_slip;
  if (shuttle_coupled_) {
    if (std::abs(a) * p.shuttle_mass_kg > p.carrier_force_n) {
      shuttle_coupled_ = false;  // the magnet lets go: the shuttle slides on with its own speed
      shuttle_v_ = v;
    } else {
      shuttle_x_ = carrier;
      return;
    }
  }
  const double dv = p.race_friction_m_s2 * dt;
  shuttle_v_ = std::abs(shuttle_v_) <= dv ? 0.0 : shuttle_v_ - std::copysign(dv, shuttle_v_);
  shuttle_x_ = std::clamp(shuttle_x_ + shuttle_v_ * dt, 0.0, m_.width_m);
  // The carrier picks the shuttle up again when it passes over it at rest (after the operator clears it).
  if (shuttle_v_ == 0.0 && std::abs(carrier - shuttle_x_) < 1e-3) shuttle_coupled_ = true;
}

void SimWorld::read_io(hal::Tick now, const hal::AxisFeedbacks& axes, hal::DigitalInputs& io) noexcept {
  if (powered_off_ || stalled(now)) return;
  // The shuttle rides the carrier on the helix shaft: one lead of travel per shaft turn. Taken from the
  // HAL's fresh helix feedback, so this I/O node also works beside real (CAN) drives.
  // When this world also simulates the drives, the shuttle and the beater follow the true axes, not
  // what the (possibly delayed or glitched) feedback says.
  const auto pos = [&](hal::CoreAxis a) {
    return drives_simulated_ ? axes_[hal::index(a)].position : axes[hal::index(a)].position;
  };
  const auto vel = [&](hal::CoreAxis a) {
    return drives_simulated_ ? axes_[hal::index(a)].velocity : axes[hal::index(a)].velocity;
  };
  step_shuttle(pos(hal::CoreAxis::kHelix));
  if (knotter_) {
    // A weft locks the knots tied so far into their row: the shuttle arrived at the other selvedge.
    const int side = shuttle_x_ <= m_.selvedge_sensor_window_m                ? -1
                     : shuttle_x_ >= m_.width_m - m_.selvedge_sensor_window_m ? 1
                                                                              : 0;
    if (side != 0 && shuttle_side_ != 0 && side != shuttle_side_) knotter_->on_weft();
    if (side != 0) shuttle_side_ = side;
    std::array<double, hal::kMaxAxes> at{};
    readings(at);
    knotter_->inputs(at, io);
  }
  // The load cell rides the beater, which the crank drives: real (CAN) or simulated.
  if (scene_.beat_contact)
    step_beat_contact(pos(hal::CoreAxis::kBeatCrank), vel(hal::CoreAxis::kBeatCrank), axes);
  constexpr std::size_t n = hal::kSafetySensorCount;
  const std::array<bool, n> truth{piston_[0] >= 1.0,
                                  piston_[0] <= 0.0,
                                  piston_[1] >= 1.0,
                                  piston_[1] <= 0.0,
                                  shuttle_x_ <= m_.selvedge_sensor_window_m,
                                  shuttle_x_ >= m_.width_m - m_.selvedge_sensor_window_m};
  if (next_fault_ == 0 && !scene_.sensor_noise) {
    // No sensor fault has struck and no bounce is simulated: every switch reads the truth (the loop
    // below, without its per-switch checks). A second switch the machine does not have reads false.
    // (bools are bytes 0 or 1: one AND of the six bytes is the six &&)
    static_assert(sizeof(bool) == 1 && n <= sizeof(std::uint64_t));
    std::uint64_t fitted = 0, seen = 0;
    std::memcpy(&fitted, m_.second_channel.data(), n);
    std::memcpy(&seen, truth.data(), n);
    const std::uint64_t second = fitted & seen;
    std::memcpy(io.second_channel.data(), &second, n);
    hal::set_safety_sensors(io, truth);
    io.estop_ok = estop_ok_;
    io.refreshed = now;
    return;
  }
  // Each switch (first channels 0..5, second channels 6..11) sees the truth, then its own faults, then
  // its own bounce. A second switch the machine does not have reads false and draws no noise.
  std::array<bool, kSensorCount> v{};
  for (std::size_t i = 0; i < v.size(); ++i) {
    const bool fitted = i < n || m_.second_channel[i - n];
    if (!fitted) continue;
    v[i] = truth[i % n];
    if (stuck_sensor_[i]) v[i] = *stuck_sensor_[i];
    if (scene_.sensor_noise && rng_.uniform() < scene_.sensor_noise->flip_probability) v[i] = !v[i];
  }
  std::array<bool, n> first{};
  for (std::size_t i = 0; i < n; ++i) first[i] = v[i], io.second_channel[i] = v[n + i];
  hal::set_safety_sensors(io, first);
  io.estop_ok = estop_ok_;
  io.refreshed = now;
}

void SimWorld::readings(std::array<double, hal::kMaxAxes>& out) const noexcept {
  for (std::size_t i = 0; i < n_axes_; ++i) out[i] = axes_[i].position + axes_[i].offset;
}

void SimWorld::write_io(hal::Tick, const hal::DigitalOutputs& io) noexcept {
  if (powered_off_) return;
  if (knotter_) {
    std::array<double, hal::kMaxAxes> at{};
    readings(at);
    knotter_->on_outputs(io, at, rng_);
  }
  const std::array<bool, 2> valve{io.piston_a_extend, io.piston_b_extend};
  const double dt = m_.period_s;
  const double full_speed = dt / m_.piston_travel_s;  // fraction of stroke per tick at full pressure
  for (std::size_t i = 0; i < 2; ++i) {
    const double goal = valve[i] ? 1.0 : -1.0;
    double step = goal * full_speed;
    if (scene_.pneumatics) {
      const Pneumatics& p = *scene_.pneumatics;
      pressure_[i] += (goal - pressure_[i]) * pressure_fill_;  // 1 - exp(-dt / p.fill_tau_s)
      const double margin = (std::abs(pressure_[i]) - p.breakaway) / (1.0 - p.breakaway);
      step = margin > 0.0 ? std::copysign(margin * full_speed, pressure_[i]) : 0.0;
    }
    if (!piston_stuck_[i] && !air_lost_) piston_[i] = std::clamp(piston_[i] + step, 0.0, 1.0);
  }
  if (state_file_ != nullptr) {
    PersistedMachine pm;
    pm.magic = PersistedMachine::kMagic;
    for (std::size_t i = 0; i < pm.axis_position.size(); ++i) pm.axis_position[i] = axes_[i].position;
    for (std::size_t i = hal::kCoreAxisCount; i < n_axes_; ++i)
      pm.added_axis_position[i - hal::kCoreAxisCount] = axes_[i].position;
    pm.piston = piston_;
    pm.shuttle_x = shuttle_x_;
    state_file_->store(pm);
  }
}

}  // namespace loom::sim_hal

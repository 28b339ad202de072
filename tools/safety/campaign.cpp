// The campaign: scene generation, one checked run, and the runs spread over threads.
#include "campaign.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <random>
#include <sstream>
#include <thread>

#include "loom/firmware/machine.hpp"
#include "loom/firmware/operator_policy.hpp"
#include "loom/hal/motion_outputs.hpp"
#include "loom/motion/errors.hpp"
#include "loom/motion/knot_cycle.hpp"
#include "loom/sequencer/operator_requests.hpp"

namespace loom::safety {
namespace {

std::uint64_t mix(std::uint64_t z) {  // splitmix64 finaliser: independent streams per run
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

using sim_hal::InjectedFault;

void ensure_effect(sim_hal::SceneSpec& s, const char* effect) {
  if (std::find(s.effects.begin(), s.effects.end(), effect) == s.effects.end()) s.effects.push_back(effect);
}

// A switch the machine has, drawn from `first` (first-channel sensors, SafetySensor order) and their
// second channels where fitted; uniform over the candidates.
sim_hal::Sensor random_switch(std::mt19937_64& rng, std::initializer_list<hal::SafetySensor> first,
                              const std::array<bool, hal::kSafetySensorCount>& second_channel) {
  std::array<sim_hal::Sensor, sim_hal::kSensorCount> candidates{};
  std::size_t n = 0;
  for (const hal::SafetySensor f : first) {
    const auto i = static_cast<std::size_t>(f);
    candidates[n++] = static_cast<sim_hal::Sensor>(i);
    if (second_channel[i]) candidates[n++] = static_cast<sim_hal::Sensor>(hal::kSafetySensorCount + i);
  }
  return candidates[std::uniform_int_distribution<std::size_t>(0, n - 1)(rng)];
}

constexpr std::initializer_list<hal::SafetySensor> kAllSensors = {
    hal::SafetySensor::kPistonAExtended, hal::SafetySensor::kPistonARetracted,
    hal::SafetySensor::kPistonBExtended, hal::SafetySensor::kPistonBRetracted,
    hal::SafetySensor::kShuttleAtLeft,   hal::SafetySensor::kShuttleAtRight};

// The kinds a loom without knotting heads can suffer (the heads' own faults come after them in the enum),
// and with them; axis_jam, after the heads' faults, is drawn only when asked (--axis-jams), so that the
// campaign's draws stay those it had before it existed.
constexpr int kFaultKindsWithoutHeads = static_cast<int>(InjectedFault::kSelectorJam);
constexpr int kFaultKindsWithHeads = static_cast<int>(InjectedFault::kYarnOut) + 1;

sim_hal::FaultInjection random_fault(std::mt19937_64& rng, sim_hal::SceneSpec& s,
                                     const std::array<bool, hal::kSafetySensorCount>& second_channel,
                                     int heads, int slots, bool axis_jams, std::ostringstream& d) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  sim_hal::FaultInjection f;
  const int kinds = heads > 0 ? kFaultKindsWithHeads : kFaultKindsWithoutHeads;
  const int drawn = static_cast<int>(u(rng) * (kinds + (axis_jams ? 1 : 0)));
  f.kind = drawn == kinds ? InjectedFault::kAxisJam : static_cast<InjectedFault>(drawn);
  f.head = heads > 0 ? static_cast<int>(u(rng) * heads) : 0;
  f.slot = slots > 0 ? static_cast<int>(u(rng) * slots) : 0;
  f.at_s = 16.0 * u(rng);
  f.axis = static_cast<std::size_t>(u(rng) * 3);
  f.axis_name = hal::axis_name(static_cast<hal::CoreAxis>(f.axis));
  f.piston = u(rng) < 0.5 ? 0 : 1;
  f.sensor = random_switch(rng, kAllSensors, second_channel);
  f.stuck_value = u(rng) < 0.5;
  switch (f.kind) {
    case InjectedFault::kIntermittentSensor:
      f.duration_s = 0.002 + 0.5 * u(rng);
      break;
    case InjectedFault::kCanFrameLoss:
      f.probability = u(rng) < 0.3 ? 1.0 : 0.05 + 0.95 * u(rng);
      f.duration_s = 0.01 + u(rng);
      break;
    case InjectedFault::kCanLatency:
      f.latency_s = 0.002 + 0.1 * u(rng);
      f.duration_s = 0.05 + 2.0 * u(rng);
      break;
    case InjectedFault::kEmcy:
      f.code = static_cast<std::uint16_t>(0x1000 + static_cast<int>(u(rng) * 0xE000));
      break;
    case InjectedFault::kEncoderGlitch: {
      const double scale = f.axis == hal::index(hal::CoreAxis::kCarriage) ? 0.1 : 2.0;
      f.jump = (u(rng) < 0.5 ? -1.0 : 1.0) * scale * (0.005 + u(rng));
      f.ticks = 1 + static_cast<int>(u(rng) * 5);
      break;
    }
    case InjectedFault::kLoadCellFailure:
      ensure_effect(s, sim_hal::kEffectBeatContact);
      if (!s.beat_contact) s.beat_contact = sim_hal::BeatContact{};
      f.load_cell = u(rng) < 0.5 ? sim_hal::LoadCellMode::kNan : sim_hal::LoadCellMode::kLost;
      break;
    case InjectedFault::kLoopStall:
      f.ticks = 1 + static_cast<int>(u(rng) * 100);
      break;
    case InjectedFault::kPowerCut:
      f.at_tick = static_cast<hal::Tick>(u(rng) * (heads > 0 ? 30000.0 : 8000.0));
      break;
    case InjectedFault::kSelectorJam:
    case InjectedFault::kYarnOut:
      f.at_s = 40.0 * u(rng);
      break;  // anywhere in the knotting of the first row
    case InjectedFault::kAxisJam:
      if (heads > 0) f.at_s = 40.0 * u(rng);  // the carriage's steps between knots too
      break;
    default:
      break;
  }
  d << sim_hal::injected_fault_name(f.kind);
  if (f.kind == InjectedFault::kPowerCut) {
    d << " at tick " << f.at_tick;
  } else {
    d << " at " << f.at_s << " s";
  }
  d << "; ";
  return f;
}

constexpr double kMotionEpsilon = 1e-6;  // m or rad per tick
bool moved(double a, double b) {
  return std::abs(a - b) > kMotionEpsilon;
}
bool shed_open(const std::array<double, 2>& p) {
  return (p[0] >= 1.0 && p[1] <= 0.0) || (p[0] <= 0.0 && p[1] >= 1.0);
}

}  // namespace

sim_hal::SceneSpec random_scene(std::uint64_t seed, std::uint64_t run,
                                const std::array<bool, hal::kSafetySensorCount>& second_channel, int heads,
                                int slots, std::string& description, bool axis_jams) {
  std::mt19937_64 rng(mix(seed ^ mix(run)));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  sim_hal::SceneSpec s;
  s.name = "safety-" + std::to_string(seed) + "-" + std::to_string(run);
  s.seed = rng() & 0x7FFFFFFFFFFFFFFFull;
  s.effects = {sim_hal::kEffectIdeal};
  std::ostringstream d;
  if (u(rng) < 0.5) {
    s.effects.push_back(sim_hal::kEffectServoLag);
    s.servo_lag = sim_hal::ServoLag{0.001 + 0.007 * u(rng)};
    d << "servo_lag(" << s.servo_lag->tau_s << ") ";
  }
  if (u(rng) < 0.5) {
    s.effects.push_back(sim_hal::kEffectPneumatics);
    s.pneumatics = sim_hal::Pneumatics{0.01 + 0.08 * u(rng), 0.1 + 0.5 * u(rng)};
    d << "pneumatics ";
  }
  if (u(rng) < 0.3) {
    s.effects.push_back(sim_hal::kEffectSensorNoise);
    s.sensor_noise = sim_hal::SensorNoise{0.01 * u(rng)};
    d << "noise(" << s.sensor_noise->flip_probability << ") ";
  }
  if (u(rng) < 0.25) {
    s.effects.push_back(sim_hal::kEffectShuttleSlip);
    s.shuttle_slip = sim_hal::ShuttleSlip{10.0 + 15.0 * u(rng), 0.4, 4.0};
    d << "slip(" << s.shuttle_slip->carrier_force_n << " N) ";
  }
  if (u(rng) < 0.3) {
    s.effects.push_back(sim_hal::kEffectBeatContact);
    s.beat_contact = sim_hal::BeatContact{};
    d << "beat_contact ";
    // Half the time an uneven, drifting warp behind it, so the beat regulator has work to do (it acts on
    // every measured beat). Drawn from a stream of its own: the other draws, and so every scene drawn
    // before this effect existed, stay as they were for the same seed and run.
    std::mt19937_64 wrng(mix(seed ^ mix(run) ^ 0x7E45105Eull));
    if (u(wrng) < 0.5) {
      s.effects.push_back(sim_hal::kEffectWarpTension);
      s.warp_tension = sim_hal::WarpTension{.centre_ratio = 0.75 + 0.4 * u(wrng),
                                            .points = {},
                                            .drift_per_row = -0.01 + 0.03 * u(wrng),
                                            .noise = 0.03 * u(wrng)};
      d << "warp_tension(" << s.warp_tension->centre_ratio << ", " << s.warp_tension->drift_per_row
        << "/row) ";
    }
  }
  if (u(rng) < 0.02) {
    s.effects.push_back(sim_hal::kEffectInertia);
    s.inertia = sim_hal::Inertia{};
    d << "inertia ";
  }
  if (heads > 0) {
    // The heads are always simulated on a loom that has them: knots slip now and then, the weaver answers
    // after a while.
    s.effects.push_back(sim_hal::kEffectKnotter);
    s.knotter = sim_hal::Knotter{u(rng) < 0.5 ? 0.0 : 0.2 * u(rng), 0.05 + 3.0 * u(rng), 8};
    d << "knotter(miss " << s.knotter->miss_probability << ", weaver " << s.knotter->weaver_s << " s) ";
  }
  d << "| ";
  const double pick = u(rng);
  if (pick < 0.08) {
    // Shuttle slip with a stuck arrival sensor: the combination that once let a frame close on the shuttle.
    if (!s.shuttle_slip) {
      s.effects.push_back(sim_hal::kEffectShuttleSlip);
      s.shuttle_slip = sim_hal::ShuttleSlip{10.0 + 8.0 * u(rng), 0.4, 4.0};
    }
    sim_hal::FaultInjection f;
    f.kind = InjectedFault::kStuckSensor;
    f.at_s = 16.0 * u(rng);
    f.sensor = random_switch(rng, {hal::SafetySensor::kShuttleAtLeft, hal::SafetySensor::kShuttleAtRight},
                             second_channel);
    f.stuck_value = true;
    s.faults.push_back(f);
    d << "slip + stuck " << sim_hal::sensor_name(f.sensor) << " at " << f.at_s << " s";
  } else if (pick < 0.16) {
    // A stuck end sensor, early in the run where the shed changes are.
    sim_hal::FaultInjection f;
    f.kind = InjectedFault::kStuckSensor;
    f.at_s = (u(rng) < 0.5 ? 2.0 : 16.0) * u(rng);
    f.sensor = random_switch(rng,
                             {hal::SafetySensor::kPistonAExtended, hal::SafetySensor::kPistonARetracted,
                              hal::SafetySensor::kPistonBExtended, hal::SafetySensor::kPistonBRetracted},
                             second_channel);
    f.stuck_value = u(rng) < 0.7;
    s.faults.push_back(f);
    d << "stuck " << sim_hal::sensor_name(f.sensor) << " = " << f.stuck_value << " at " << f.at_s << " s";
  } else {
    const double n = u(rng);
    const int count = n < 0.15 ? 0 : n < 0.8 ? 1 : 2;
    for (int i = 0; i < count; ++i)
      s.faults.push_back(random_fault(rng, s, second_channel, heads, slots, axis_jams, d));
    // One power cut per scene.
    if (count == 2 && s.faults[0].kind == InjectedFault::kPowerCut &&
        s.faults[1].kind == InjectedFault::kPowerCut) {
      s.faults.pop_back();
    }
    if (count == 0) d << "no fault";
  }
  description = d.str();
  return s;
}

const char* stopping_act_name(StoppingAct::Kind k) {
  switch (k) {
    case StoppingAct::Kind::kStop:
      return "stop";
    case StoppingAct::Kind::kPause:
      return "pause";
    case StoppingAct::Kind::kExit:
      return "exit";
    case StoppingAct::Kind::kStopNow:
      return "stop now";
  }
  return "?";
}

std::vector<StoppingAct> random_stopping_acts(std::uint64_t seed, std::uint64_t run, int heads,
                                              std::string& description) {
  // An independent stream from the scene's (a different mix), so adding acts changed no scene.
  std::mt19937_64 rng(mix(mix(seed ^ 0x5709u) ^ mix(run)));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<StoppingAct> acts;
  const double n = u(rng);
  const int count = n < 0.5 ? 0 : n < 0.85 ? 1 : 2;
  const double horizon = heads > 0 ? 60000.0 : 9000.0;  // ticks: about two rows
  std::ostringstream d;
  for (int i = 0; i < count; ++i) {
    StoppingAct a;
    a.at = static_cast<hal::Tick>(u(rng) * horizon);
    a.kind = static_cast<StoppingAct::Kind>(static_cast<int>(u(rng) * 4));
    a.held_session = u(rng) < 0.5;
    acts.push_back(a);
  }
  std::sort(acts.begin(), acts.end(), [](const StoppingAct& a, const StoppingAct& b) { return a.at < b.at; });
  for (std::size_t i = 0; i < acts.size(); ++i) {
    const StoppingAct& a = acts[i];
    d << (i == 0 ? " | " : ", ") << stopping_act_name(a.kind) << (a.held_session ? " (serve)" : " (weave)")
      << " at tick " << a.at;
  }
  description += d.str();
  return acts;
}

namespace {
void note_power_cut(void* flag) {
  *static_cast<bool*>(flag) = true;
}

// Gives `a` as its owner does: the runner's operator policy, or (stop now) the sequencer's safe stop.
void give(firmware::Machine& m, const StoppingAct& a) {
  if (a.kind == StoppingAct::Kind::kStopNow) {
    m.sequencer().request_stop_now();
    return;
  }
  firmware::PolicyInputs in;
  in.commands = static_cast<std::uint32_t>(a.kind == StoppingAct::Kind::kStop    ? firmware::Command::kStop
                                           : a.kind == StoppingAct::Kind::kPause ? firmware::Command::kPause
                                                                                 : firmware::Command::kExit);
  in.state = m.sequencer().state();
  in.held_session = a.held_session;
  in.estop_ok = m.loop().inputs().io.estop_ok;
  firmware::apply(firmware::decide(in), m.sequencer());
}

// Where the loom stands after a stopping command: nothing it commands may start moving from here.
bool standing(const sequencer::Sequencer& seq) {
  const sequencer::State s = seq.state();
  return s == sequencer::State::kPaused || s == sequencer::State::kDone || s == sequencer::State::kFault ||
         s == sequencer::State::kIdle || s == sequencer::State::kAwaitKnotting ||
         (s == sequencer::State::kKnotting && seq.weaver_request().ask != sequencer::WeaverAsk::kNone);
}
}  // namespace

RunOutcome run_one(const firmware::LoomConfig& cfg, const sim_hal::SceneSpec& spec, std::uint32_t rows,
                   const std::vector<StoppingAct>& acts) {
  firmware::Scene scene;
  scene.spec = spec;
  firmware::MachineOptions opt;
  opt.telemetry = false;
  opt.rows = rows;
  firmware::Machine m(cfg, scene, opt, {});
  bool cut = false;
  m.sim().on_power_cut(note_power_cut, &cut);
  m.sequencer().request_start();
  const auto& sim = m.sim();
  const double window = cfg.machine.selvedge_sensor_window_m;
  RunOutcome o;
  std::ostringstream why;
  double carriage = sim.axis(hal::CoreAxis::kCarriage).position,
         helix = sim.axis(hal::CoreAxis::kHelix).position;
  double crank = sim.axis(hal::CoreAxis::kBeatCrank).position;
  std::array<double, 2> pistons = sim.pistons();
  // The heads' servos (true positions) and where a gripper is in the warp (the machine's geometry).
  const sim_hal::SimKnotting& kn = cfg.machine.knotting;
  const auto heads_axes = [&](std::array<double, 2 * hal::kMaxKnottingHeads>& at) {
    for (int h = 0; h < kn.heads; ++h) {
      at[static_cast<std::size_t>(2 * h)] = sim.axis(kn.knotter_axis[static_cast<std::size_t>(h)]).position;
      at[static_cast<std::size_t>(2 * h + 1)] =
          sim.axis(kn.selector_axis[static_cast<std::size_t>(h)]).position;
    }
  };
  std::array<double, 2 * hal::kMaxKnottingHeads> head_at{};
  heads_axes(head_at);
  const sim_hal::SimKnotter* knotter = sim.knotter();
  // Whether a gripper is in the warp, judged independently of the interlock (whose angle interval is
  // sampled from the cycle's time window): the linkage's forward kinematics at the servo's true angle,
  // against the warp's entry line.
  const motion::KnotCycle* cycle = m.knot_cycle();
  const auto in_warp = [&](int h, double servo) {
    try {
      const double crank_abs = cycle->take_angle_rad() + (servo - kn.take_position_rad);
      return cycle->dynamics_at(crank_abs).gripper_x_m >= cycle->spec().warp_entry_x_m;
    } catch (const motion::MotionError&) {
      return knotter->gripper_in_warp(h, servo);  // off the linkage's range: the simulator's own reading
    }
  };
  hal::Tick fault_at = -1;
  hal::Tick t = 0;
  const hal::Tick max_ticks = kn.heads > 0 ? 200000 : 60000;
  std::size_t next_act = 0;
  hal::Tick standing_ticks = 0;
  bool stopped = false;       // a stopping command was given and no starting command since
  bool stood_before = false;  // ... and the loom stood at the end of the last tick
  hal::HalOutputs out_before = m.loop().outputs();
  const std::size_t n_axes = m.sequencer().axes().count;
  for (; t < max_ticks; ++t) {
    // A run ends once the loom is done or faulted — or, after a stopping command, once it has stood a while.
    if (m.sequencer().finished() && (fault_at < 0 || t > fault_at + 300)) break;
    if (stopped && stood_before && next_act >= acts.size() &&
        m.sequencer().state() != sequencer::State::kKnotting &&
        m.sequencer().state() != sequencer::State::kAwaitKnotting && standing_ticks > 2000) {
      break;
    }
    while (next_act < acts.size() && acts[next_act].at <= t) {
      give(m, acts[next_act++]);
      stopped = true;
    }
    const bool warp_before = sim.beater_in_warp();
    bool gripper_before = false;
    for (int h = 0; h < kn.heads; ++h) gripper_before |= in_warp(h, head_at[static_cast<std::size_t>(2 * h)]);
    std::array<bool, hal::kMaxKnottingHeads> holding{};
    for (int h = 0; h < kn.heads; ++h) holding[static_cast<std::size_t>(h)] = knotter->gripper_closed(h);
    const bool shed_before = shed_open(pistons);
    const double x = sim.shuttle_x();
    const bool shuttle_in_shed = x > window && x < cfg.machine.width_m - window;
    m.loop().cycle(t);
    // The campaign owns the loop, as the runner does in a weave: the pedal the simulated weaver presses
    // becomes request_row_knotted() here (the sequencer only reports presses).
    sequencer::apply_presses(m.sequencer());
    if (m.sequencer().events().has(sequencer::EventKind::kButton))
      stopped = false;  // a starting press (the pedal)
    if (stopped && stood_before) {
      if (const hal::MotionChange mc =
              hal::motion_started(out_before, m.loop().outputs(), n_axes, kn.heads)) {
        why << hal::motion_change_name(mc.what) << " (index " << mc.index
            << ") after a stopping command, the loom "
            << "standing, at tick " << t;
      }
    }
    stood_before = stopped && standing(m.sequencer());
    standing_ticks = stood_before ? standing_ticks + 1 : 0;
    out_before = m.loop().outputs();
    if (m.sequencer().events().has(
            sequencer::EventKind::kWeaverRequest)) {  // the simulated weaver answers, as in a weave
      if (m.sequencer().weaver_request().ask != sequencer::WeaverAsk::kNone) {
        firmware::Machine::simulated_weaver_sink(&m, m.sequencer().weaver_request());
      }
    }
    if (cut) {
      o.power_cut = true;
      break;
    }
    const double c2 = sim.axis(hal::CoreAxis::kCarriage).position,
                 h2 = sim.axis(hal::CoreAxis::kHelix).position;
    const double k2 = sim.axis(hal::CoreAxis::kBeatCrank).position;
    const auto p2 = sim.pistons();
    std::array<double, 2 * hal::kMaxKnottingHeads> head2{};
    heads_axes(head2);
    bool gripper_now = false, knotter_moved = false, head_moved = false;
    int selector_with_yarn = -1;
    for (int h = 0; h < kn.heads; ++h) {
      const auto k = static_cast<std::size_t>(2 * h), sel = k + 1;
      gripper_now |= in_warp(h, head2[k]);
      knotter_moved |= moved(head2[k], head_at[k]);
      head_moved |= moved(head2[k], head_at[k]) || moved(head2[sel], head_at[sel]);
      if (moved(head2[sel], head_at[sel]) &&
          (holding[static_cast<std::size_t>(h)] || knotter->gripper_closed(h)))
        selector_with_yarn = h;
    }
    const bool frames_moved = moved(p2[0], pistons[0]) || moved(p2[1], pistons[1]);
    if (!why.str().empty()) {
      // already found (a stopping command's standing loom set moving)
    } else if (gripper_before && gripper_now && (moved(c2, carriage) || moved(k2, crank) || frames_moved)) {
      why << (moved(c2, carriage) ? "carriage"
              : moved(k2, crank)  ? "beater crank"
                                  : "heald frame")
          << " moved while a knotting gripper was in the warp at tick " << t;
    } else if (knotter_moved && warp_before && sim.beater_in_warp()) {
      why << "a knotting servo moved while the beater was in the warp at tick " << t;
    } else if (selector_with_yarn >= 0) {
      why << "the selector of head " << selector_with_yarn + 1
          << " turned while its gripper held yarn at tick " << t;
    } else if (fault_at >= 0 && t > fault_at + 1 && head_moved) {
      why << "a knotting head's axis moved after the fault ("
          << sequencer::fault_name(m.sequencer().first_fault()) << ") at tick " << t;
    } else if (moved(c2, carriage) && warp_before && sim.beater_in_warp()) {
      why << "carriage moved " << (c2 - carriage) << " m while the beater was in the warp at tick " << t;
    } else if (moved(h2, helix) && !(shed_before && shed_open(p2))) {
      why << "pick motion (helix " << (h2 - helix) << " rad) without an open shed (frames " << p2[0] << ", "
          << p2[1] << ") at tick " << t;
    } else if ((moved(p2[0], pistons[0]) || moved(p2[1], pistons[1])) && shuttle_in_shed) {
      why << "heald frame moved over the shuttle (x = " << x << " m) at tick " << t;
    } else if (fault_at >= 0 && t > fault_at + 1 &&
               (moved(c2, carriage) || moved(h2, helix) || moved(k2, crank))) {
      why << "an axis moved after the fault (" << sequencer::fault_name(m.sequencer().first_fault())
          << ") at tick " << t;
    }
    if (!why.str().empty()) {
      o.violated = true;
      o.what = why.str() + " (state " + sequencer::state_name(m.sequencer().state()) + ", first fault " +
               sequencer::fault_name(m.sequencer().first_fault()) + ")";
      break;
    }
    if (fault_at < 0 && m.sequencer().state() == sequencer::State::kFault) fault_at = t;
    carriage = c2, helix = h2, crank = k2, pistons = p2;
    head_at = head2;
  }
  // The carpet: no knot tied twice, and every row the counters say is woven fully knotted (nothing skipped
  // in silence). A power cut ends the run where it struck; what was tied until then must still hold.
  if (!o.violated && knotter != nullptr) {
    const std::uint32_t woven = m.sequencer().counters().rows;
    for (int r = 0; r < knotter->rows() && !o.violated; ++r) {
      for (int k = 0; k < knotter->knots_per_row(); ++k) {
        const sim_hal::KnotCell& c = knotter->cell(r, k);
        if (c.ties > 1 || (static_cast<std::uint32_t>(r) < woven && c.ties == 0)) {
          o.violated = true;
          o.what =
              "knot " + std::to_string(k + 1) + " of carpet row " + std::to_string(r + 1) +
              (c.ties > 1 ? " tied " + std::to_string(c.ties) + " times" : " never tied in a woven row") +
              " (first fault " + sequencer::fault_name(m.sequencer().first_fault()) + ")";
          break;
        }
      }
    }
  }
  o.faulted = m.sequencer().state() == sequencer::State::kFault;
  o.completed = m.sequencer().state() == sequencer::State::kDone;
  o.first_fault = sequencer::fault_name(m.sequencer().first_fault());
  if (const int sensor = m.sequencer().fault_sensor(); sensor >= 0) {
    o.fault_sensor = hal::safety_sensor_name(static_cast<hal::SafetySensor>(sensor));
  }
  return o;
}

CampaignResult run_campaign(const CampaignOptions& opt) {
  const firmware::LoomConfig cfg =
      opt.config_path.empty() ? firmware::default_loom_config() : firmware::load_loom_config(opt.config_path);
  std::atomic<std::uint64_t> next{0};
  std::mutex mu;
  CampaignResult result;
  const auto worker = [&] {
    const firmware::LoomConfig local = cfg;
    for (;;) {
      if (opt.stop != nullptr && opt.stop->load()) return;
      const std::uint64_t run = next.fetch_add(1);
      if (run >= opt.runs) return;
      std::string description;
      const bool with_heads = local.knotting.mode == sequencer::KnottingMode::kHeads;
      const sim_hal::SceneSpec scene = random_scene(
          opt.seed, run, local.sequencer.second_channel, with_heads ? local.knotting.heads : 0,
          with_heads ? static_cast<int>(local.knotting.slot_colours.size()) : 0, description, opt.axis_jams);
      const std::vector<StoppingAct> acts =
          random_stopping_acts(opt.seed, run, with_heads ? local.knotting.heads : 0, description);
      const RunOutcome o = run_one(local, scene, opt.rows, acts);
      const std::lock_guard<std::mutex> lock(mu);
      ++result.runs;
      result.faulted += o.faulted;
      result.completed += o.completed;
      result.power_cuts += o.power_cut;
      if (o.violated)
        result.violations.push_back(
            {run, description, o.what, firmware::scene_to_toml(scene, opt.config_path)});
      if (opt.on_run) opt.on_run(result, o.violated ? &result.violations.back() : nullptr);
    }
  };
  std::vector<std::thread> threads;
  for (int i = 1; i < std::max(1, opt.threads); ++i) threads.emplace_back(worker);
  worker();
  for (auto& th : threads) th.join();
  std::sort(result.violations.begin(), result.violations.end(),
            [](const Violation& a, const Violation& b) { return a.run < b.run; });
  return result;
}

}  // namespace loom::safety

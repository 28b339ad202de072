// The simulated loom behind the HAL: its servo axes (the three core axes and any the machine adds), two
// pistons with end sensors, the shuttle on its magnetic carrier with arrival sensors, the e-stop chain, and
// (when named) the beater's load cell. Stepped in virtual time by the loop's own tick (write() integrates one
// period), so it runs as fast as the machine allows. Every effect is built only if the scene names it.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "loom/hal/fault_events.hpp"
#include "loom/hal/hal.hpp"
#include "loom/motion/beatup.hpp"
#include "loom/sim_hal/knotter.hpp"
#include "loom/sim_hal/random.hpp"
#include "loom/sim_hal/scene.hpp"
#include "loom/sim_hal/sim_state_file.hpp"
#include "loom/sim_hal/warp_tension.hpp"

namespace loom::sim_hal {

// One effect acting on an axis' commanded position each tick (servo lag, later inertia, friction...).
class AxisEffect {
 public:
  virtual ~AxisEffect() = default;
  // RT-safe. Turn the drive's commanded target into the new actual position after dt.
  virtual double step(double target, double actual, double dt) noexcept = 0;
};

struct SimAxis {
  hal::DriveState state = hal::DriveState::kSwitchOnDisabled;
  double position = 0.0;  // the machine's true position (SI)
  double velocity = 0.0;
  double target = 0.0;  // true position commanded
  std::uint16_t fault_code = 0;
  // The drive's reading is position + offset: 0 for an absolute encoder; for a homed axis a random
  // count from power-up until a homing run references it.
  double offset = 0.0;
  bool referenced = true;
  bool homing = false;                               // a homing run is under way
  double homing_goal = 0.0;                          // the true position of its reference point
  std::vector<std::unique_ptr<AxisEffect>> effects;  // built once from the scene
};

class SimWorld final : public hal::AxisPort, public hal::IoPort {
 public:
  // Configure-time only: builds exactly the effects the scene names. Throws std::invalid_argument on an
  // unknown effect name (the firmware checks names earlier and reports file and line).
  SimWorld(const SimMachine& machine, const SceneSpec& scene);
  ~SimWorld() override;

  void read_axes(hal::Tick now, hal::AxisFeedbacks& axes,
                 hal::LinkStatus& link) noexcept override;                          // RT-safe
  void write_axes(hal::Tick now, const hal::AxisCommands& axes) noexcept override;  // RT-safe
  void read_io(hal::Tick now, const hal::AxisFeedbacks& axes,
               hal::DigitalInputs& io) noexcept override;                         // RT-safe
  void write_io(hal::Tick now, const hal::DigitalOutputs& io) noexcept override;  // RT-safe
  void read_analog(hal::Tick now, hal::AnalogInputs& analog) noexcept override;   // RT-safe

  // Start the machine where a previous run left it (restart after a power loss): axis positions in SI
  // and the heald frames' positions (0 retracted … 1 extended). Configure-time only.
  void set_initial_state(const hal::AxisFeedbacks& axes, std::array<double, 2> pistons);
  // Configure-time. Start from the state in `file` if it holds one, and keep it updated every tick.
  void attach_state_file(SimStateFile& file);
  // Configure-time, after attach_state_file (if any). The knotting heads' carpet begins (or, kept in the
  // state file from before a power cut, carries on) at production row `counter_rows`.
  // `carpet_began`: see SimKnotter::persist_in (a carpet job's first row).
  void persist_carpet(std::uint32_t counter_rows, std::optional<std::uint32_t> carpet_began = std::nullopt);

  // Ground truth for tests and reports (not what the controller sees).
  const SimAxis& axis(hal::CoreAxis a) const { return axes_[hal::index(a)]; }
  const SimAxis& axis(std::size_t slot) const { return axes_[slot]; }
  double shuttle_x() const { return shuttle_x_; }
  bool shuttle_coupled() const { return shuttle_coupled_; }
  std::array<double, 2> pistons() const { return piston_; }
  bool beater_in_warp() const;  // true tip position vs the warp, from the true crank position
  std::size_t effect_count() const;

  // Power cut (scene fault power_cut at tick N). By default the process dies there as if killed
  // (SIGKILL): counters and the machine state file keep what they had, as after a real power loss.
  // In-process users (tests, loom-safety) install a handler instead; the world then freezes (nothing
  // moves, no input is refreshed) and power_cut() tells. Configure-time only.
  void on_power_cut(void (*handler)(void* ctx), void* ctx) {
    power_cut_handler_ = handler, power_cut_ctx_ = ctx;
  }
  bool power_cut() const { return powered_off_; }
  // Overruns injected by loop_stall faults (the ticks the loop was stalled), for the loop's statistics.
  std::uint32_t injected_overruns() const { return injected_overruns_; }
  // The knotting heads (scene effect "knotter"; null without it): the carpet as knotted, for reports and
  // tests.
  const SimKnotter* knotter() const { return knotter_.get(); }
  // The warp's tension (scene effect "warp_tension"; null without it): rows counted, the last beat's factor.
  const WarpTensionModel* warp_tension() const { return warp_tension_.get(); }
  // RT-safe. The loom asks the weaver (the panel's request): the simulated weaver does it after a while and
  // presses the pedal. Ignored without the knotter effect.
  void ask_weaver(const WeaverTask& t) noexcept {
    if (knotter_) knotter_->ask(t);
  }
  // RT-safe. The operator said a slot was reloaded (`ctl reload`): in simulation the yarn is put there.
  void reload_slot(int head, int slot, std::int32_t knots) noexcept {
    if (knotter_) knotter_->reload(head, slot, knots);
  }

  // The crank phases (from park) inside which beat_contact solves the linkage for the load cell (both
  // 0 without beat_contact). Outside them the tip is never within the contact depth of the fell.
  std::pair<double, double> contact_bracket() const noexcept { return {contact_from_, contact_to_}; }

 private:
  void apply_injected_faults(hal::Tick now) noexcept;
  // read_axes once a fault has struck (or with CAN latency): through the history, losses and silences.
  void read_struck(hal::Tick now, hal::AxisFeedbacks& axes, hal::LinkStatus& link) noexcept;
  // The device-fault events of what read_axes hands out (fault_events.hpp): a drive's fault report begins
  // or changes its code, the link's begins. A value the read left untouched is the same report.
  void raise_fault_events(hal::AxisFeedbacks& axes, hal::LinkStatus& link) noexcept;
  bool stalled(hal::Tick now) const noexcept { return now < stall_until_; }
  void step_axis(std::size_t slot, const hal::AxisCommand& cmd) noexcept;
  void step_homing(std::size_t slot) noexcept;
  void step_shuttle(double helix_position) noexcept;
  // `fb`: the HAL's feedback, for the carriage when the drives are real (warp_tension only).
  void step_beat_contact(double crank_position, double crank_velocity, const hal::AxisFeedbacks& fb) noexcept;
  void bracket_contact();  // configure time: contact_from_, contact_to_
  void readings(std::array<double, hal::kMaxAxes>& out) const noexcept;  // every axis as its drive reads it

  SimMachine m_;
  SceneSpec scene_;
  std::array<SimAxis, hal::kMaxAxes> axes_{};
  std::size_t n_axes_ = hal::kCoreAxisCount;  // m_.axis_count
  std::array<double, 2> piston_{0.0, 0.0};    // 0 retracted … 1 extended
  std::array<double, 2> pressure_{0.0, 0.0};  // net drive −1 … 1 (pneumatics)
  double pressure_fill_ = 0.0;                // pneumatics: 1 - exp(-period / fill_tau_s), the fill per tick
  std::array<bool, 2> piston_stuck_{false, false};
  std::array<std::optional<bool>, kSensorCount> stuck_sensor_{};
  double shuttle_x_ = 0.0, shuttle_v_ = 0.0;
  bool shuttle_coupled_ = true;
  double carrier_x_prev_ = 0.0, carrier_v_prev_ = 0.0;
  bool carrier_primed_ = false;
  bool estop_ok_ = true;
  std::size_t next_fault_ = 0;
  std::vector<hal::Tick> fault_tick_;  // the tick each scene fault strikes (sorted like the faults)
  // State of the injected faults (see InjectedFault).
  std::array<hal::Tick, kSensorCount> sensor_until_{};  // intermittent: stuck until then (-1: for ever)
  double frame_loss_p_ = 0.0;
  hal::Tick frame_loss_until_ = 0;
  hal::Tick latency_ticks_ = 0, latency_until_ = 0;
  // Axis feedback as sampled, the last kHistory ticks of it when the scene injects CAN latency (slot
  // t % kHistory, n_axes_ entries each), else only this tick's: what a scene does not name costs nothing.
  static constexpr std::size_t kHistory = 512;
  std::size_t history_ticks_ = 1;
  std::vector<hal::AxisFeedback> history_;
  bool bus_off_ = false;
  std::array<hal::Tick, hal::kMaxAxes> silent_since_{};  // heartbeat loss (-1: heard; set in the constructor)
  std::array<hal::AxisFaultEdge, hal::kMaxAxes> fault_edges_{};  // the drives' last fault reports
  hal::LinkFaultEdge link_edge_;                                 // and the link's
  std::array<int, hal::kMaxAxes> glitch_left_{};
  std::array<double, hal::kMaxAxes> glitch_jump_{};
  std::optional<LoadCellMode> load_cell_failed_;
  bool air_lost_ = false;
  hal::Tick stall_until_ = 0;
  std::uint32_t injected_overruns_ = 0;
  bool powered_off_ = false;
  std::unique_ptr<SimKnotter> knotter_;             // scene effect "knotter"
  std::unique_ptr<WarpTensionModel> warp_tension_;  // scene effect "warp_tension"
  std::array<bool, hal::kMaxAxes> jammed_{};        // a jammed axis no longer follows its target
  int shuttle_side_ = 0;              // the selvedge it last arrived at: -1 left, +1 right, 0 none yet
  static constexpr int kMidPick = 2;  // restarted with the shuttle in the shed: any arrival is a weft
  bool drives_simulated_ = false;     // this world's axes are the drives (not real ones beside it)
  void (*power_cut_handler_)(void*) = nullptr;
  void* power_cut_ctx_ = nullptr;
  SimRandom rng_;
  std::unique_ptr<motion::BeatUp> beatup_;  // built for beat_contact and for the ground-truth warp test
  double beat_force_n_ = 0.0;
  double crank_v_prev_ = 0.0;
  // beat_contact: the crank phases (from park) outside which the tip is surely farther from the fell than
  // the contact depth (a configure-time bracket, widened by kContactMarginRad): there the exact solve,
  // ~1,300 instructions, would only find "no contact". Inside, the solve decides, as everywhere before.
  static constexpr double kContactMarginRad = 1e-6;
  double contact_from_ = 0.0, contact_to_ = 0.0;
  SimStateFile* state_file_ = nullptr;
};

}  // namespace loom::sim_hal

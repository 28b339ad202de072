// One knot of a knotting head: the servo-driven four-bar that carries the gripper through the three
// precision positions of the knot (TAKE the yarn at the colour selector, WRAP it round the warp pair,
// PULL it down to the fell), and the timed cycle around it — close the gripper, TAKE→WRAP, WRAP→PULL,
// cut, release, back to TAKE. Each move is the time-optimal move under the servo's torque–speed line
// (servo_envelope.hpp: drive on the line, brake at the peak torque), planned for the largest inertia the
// linkage reflects to the servo over the move and the largest load torque it adds there (the
// velocity-squared term of the equation of motion, gravity): the cycle time follows from the drive's
// facts and the links' mass properties, it is not a constant.
//
// The linkage is given explicitly (what `loom-synth knotter` prints) and checked against the
// precision positions at configure time: the gripper must pass through every point with the coupler
// at the prescribed gripper-link angle, on one assembly branch, reached in the order TAKE, WRAP, PULL
// turning one way, with no toggle within the stroke. build() is configure-time and throws MotionError
// naming what is wrong; sample() evaluates the six closed-form pieces, O(1) and RT-safe. (A phase table
// cannot carry the move: its acceleration jumps where the drive switches from driving to braking.)
//
// Frames: the knot frame is the precision points' frame (x towards the fell side, y up: gravity acts
// along −y). Servo angles are crank angles in the knot frame (from +x, counter-clockwise).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "loom/motion/errors.hpp"
#include "loom/motion/fourbar.hpp"
#include "loom/motion/servo_envelope.hpp"

namespace loom::motion {

// One precision position of the gripper (knot frame): where it is, and the angle of the gripper link
// (the coupler line through both moving pivots, on which the synthesis puts the gripper).
struct KnotPoint {
  double x_m = 0.0;
  double y_m = 0.0;
  double gripper_rad = 0.0;
};

struct KnotLinkSpec {
  double length_m = 0.0;  // pivot to pivot
  double mass_kg = 0.0;
  double cg_m = 0.0;           // from its first pivot, along the link (may be negative: overhang)
  double inertia_kg_m2 = 0.0;  // about its cg
};

struct KnotCycleSpec {
  // The three precision positions: take, wrap, pull.
  std::array<KnotPoint, 3> points{};
  double theta0_rad = 0.0;  // the synthesis' fixed-link direction (kept for the record and the tools)

  // The linkage (knot frame). The crank is the side link the servo drives; it need not turn fully.
  double crank_pivot_x_m = 0.0, crank_pivot_y_m = 0.0;
  double rocker_pivot_x_m = 0.0, rocker_pivot_y_m = 0.0;
  KnotLinkSpec crank, coupler, rocker;
  // The gripper point in the coupler frame: origin the crank-coupler joint, x towards the
  // coupler-rocker joint, y 90° counter-clockwise from x.
  double gripper_along_m = 0.0, gripper_normal_m = 0.0;
  Branch branch = Branch::kPositive;
  double warp_entry_x_m = 0.0;  // the gripper is inside the warp while its x >= this
  // Least transmission angle (min(μ, π − μ)) allowed within the stroke TAKE→PULL.
  double min_transmission_rad = 0.0;
  double gravity_m_s2 = 9.81;  // along −y of the knot frame; 0 for a horizontal head

  // The knotting servo at its output shaft (ServoDrive's output facts: the motor through its gearbox).
  double no_load_speed_rad_s = 0.0;   // the torque–speed line falls to 0 here
  double peak_torque_nm = 0.0;        // at standstill; the cap when braking
  double continuous_torque_nm = 0.0;  // the cycle's rms torque must stay within it
  double rotor_inertia_kg_m2 = 0.0;   // motor rotor and gears, reflected to the output shaft
  double max_speed_rad_s = 0.0;       // an explicit speed cap below the no-load speed; 0 = none

  // Dwells (s): the gripper closing at TAKE, the cutter at PULL, the gripper opening after the cut.
  double grip_s = 0.0, cut_s = 0.0, release_s = 0.0;
};

// Seed 001's knotting design, synthesised right (see motion/README.md "Knot cycle"): the two
// three-point chains through (0, 0, 10°), (25, 15, 3°), (30, 1, −25°) mm with θ0 = 275° share the
// coupler; the servo drives the shorter side link. Delrin links 6 × 5 mm; the coupler with its
// holder and gripper keeps the seed's 1.641 g and I_G = 208.94e-9 kg m²; crank and rocker use the
// seed's V·ρ and I_G = m(6² + L²)/12 formulas on the correct lengths.
// Configure-time. A side link of seed 001's Delrin (ρ = 1415.9 kg/m³), 6 × 5 mm section, `length_m` pivot to
// pivot: m = w·h·L·ρ, cg at mid-length, I_G = m (w² + L²)/12 (the seed's formulas).
// The servo: a 100 W class AC servo behind a 10:1 planetary (shipped_knotter_drive()).
KnotLinkSpec delrin_link(double length_m);
KnotCycleSpec seed001_knot_cycle_spec();
// The knotting head's drive as firmware/config/knotting_loom.toml ships it (the figures and their source
// are there and in servo_envelope.cpp's caller, knot_cycle.cpp): a 100 W, 3000 rpm class AC servo behind a
// 10:1 planetary gearbox.
ServoDrive shipped_knotter_drive();
// Configure-time: put the drive's output facts into the spec's servo fields (not the speed cap).
void set_servo(KnotCycleSpec& spec, const ServoDrive& drive);

// What bounds a segment of the cycle.
enum class KnotLimit : std::uint8_t {
  kDwell,            // a timed dwell (gripper, cutter)
  kSpeedCap,         // the move cruises at the explicit speed cap (below what the drive could reach)
  kTorqueSpeedLine,  // it drives on the torque–speed line and brakes at the peak torque throughout
};
// RT-safe. "dwell", "speed cap", "torque-speed line".
const char* knot_limit_name(KnotLimit l);

struct KnotCycleReport {
  struct Segment {
    const char* name = "";  // "grip", "take_to_wrap", "wrap_to_pull", "cut", "release", "return"
    double begin_s = 0.0, end_s = 0.0;
    double distance_rad = 0.0;  // signed servo travel (0 for a dwell)
    double peak_speed_rad_s = 0.0;
    // Where the move's acceleration jumps inside it: driving ends (the speed cap reached, or braking
    // starts), and braking starts (== switch_s without a cruise). Both begin_s for a dwell.
    double switch_s = 0.0, brake_s = 0.0;
    KnotLimit bound = KnotLimit::kDwell;
  };
  std::array<Segment, 6> segments{};
  std::array<double, 3> crank_angles_rad{};  // absolute crank angle at take, wrap, pull
  double closure_residual_m = 0.0;           // max over the points of the linkage's miss
  GrashofClass grashof = GrashofClass::kTripleRocker;
  bool full_turn = false;                    // the crank turns on through the turn to return
  double stroke_rad = 0.0;                   // signed TAKE→PULL travel
  double min_transmission_rad = 0.0;         // min over the stroke of min(μ, π − μ)
  double min_transmission_at_rad = 0.0;      // absolute crank angle where it is least
  double min_transmission_return_rad = 0.0;  // the same over the return (differs when turning on)
  double peak_torque_nm = 0.0;               // max |τ| over the cycle (signed value at that instant)
  double peak_torque_t_s = 0.0;
  double peak_torque_angle_rad = 0.0;  // relative to TAKE
  double max_inertia_kg_m2 = 0.0;      // largest effective inertia at the servo over the stroke
  double min_inertia_kg_m2 = 0.0;
  double rms_torque_nm = 0.0;     // over the cycle: what heats the motor (within the continuous torque)
  double peak_speed_rad_s = 0.0;  // max |ω| over the cycle (of the no-load speed)
  // The least ratio over the cycle of the torque the drive has left to what it gives at that speed:
  // min (available(ω) − |τ|) / available(ω); 0 means the move touches the envelope.
  double envelope_margin = 0.0;
  struct PathSample {
    double t_s = 0.0, servo_rad = 0.0, x_m = 0.0, y_m = 0.0;  // servo relative to TAKE
  };
  std::vector<PathSample> path;  // the gripper over the cycle, for plots (256 samples)
};

// The spec fact a refusal of KnotCycle::build is about, for a caller that maps it to its own input
// (loom-synth's options) without reading the message: the warp entry, the minimum transmission angle, the
// servo's torque, or (everything else) the linkage itself.
enum class KnotCycleField : std::uint8_t { kLinkage, kWarpEntry, kMinTransmission, kMaxTorque };

// What KnotCycle::build throws: a MotionError (code and message as documented there) with its field.
class KnotCycleError : public MotionError {
 public:
  KnotCycleError(ErrorCode code, KnotCycleField field, const std::string& what)
      : MotionError(code, what), field_(field) {}
  KnotCycleField field() const noexcept { return field_; }

 private:
  KnotCycleField field_;
};

class KnotCycle {
 public:
  // Configure-time only. Checks the spec and the linkage against the points and plans the cycle.
  // Throws KnotCycleError (a MotionError; its field() says which fact to change):
  //   kInvalidInput    a field non-finite, negative or zero where it must be positive (names it);
  //                    the warp entry not between TAKE and WRAP along x
  //   kNotAssemblable  the linkage misses a precision point, or the gripper angle there
  //   kWrongBranch     branch defect: a point lies on the other assembly branch
  //   kOutOfBounds     order defect (PULL before WRAP turning one way), the servo cannot hold
  //                    the linkage against gravity, or the cycle's rms torque exceeds the continuous
  //   kSingular        a toggle / dead centre, or a transmission angle below the minimum, within
  //                    the stroke (or a toggle on a full-turn return)
  static KnotCycle build(const KnotCycleSpec& spec);

  struct Sample {
    double angle_rad = 0.0, velocity_rad_s = 0.0, accel_rad_s2 = 0.0;
  };
  // RT-safe, O(1), no allocation. Servo angle relative to TAKE at t into the cycle; t is clamped to
  // [0, duration]; a NaN t reads t = 0 (the rest pose), +inf the end.
  Sample sample(double t_s) const noexcept;
  // The same (kept for the tools that name the reference evaluation).
  Sample exact(double t_s) const noexcept { return sample(t_s); }

  double duration_s() const noexcept { return duration_; }
  // Angle at the end relative to the start: 0 when it swings back, ±2π when it turns on.
  double end_offset_rad() const noexcept { return end_offset_; }
  double take_angle_rad() const noexcept { return take_angle_; }  // absolute crank angle at TAKE

  struct Window {
    double begin_s = 0, end_s = 0;
    bool contains(double t) const noexcept { return t >= begin_s && t < end_s; }
  };
  Window gripper_closed() const noexcept { return gripper_closed_; }  // closing at TAKE .. cut done
  Window cutter() const noexcept { return cutter_; }                  // the cut dwell at PULL
  Window yarn_sample() const noexcept { return yarn_sample_; }        // at PULL, cut and release
  Window in_warp() const noexcept { return in_warp_; }                // carriage must not move

  const KnotCycleReport& report() const noexcept { return report_; }
  const KnotCycleSpec& spec() const noexcept { return spec_; }

  // Configure-time: the dynamics the planner uses, for checks and tools. At absolute crank angle θ
  // (throws MotionError off the linkage's range or at a toggle).
  struct Dynamics {
    double inertia_kg_m2 = 0.0;  // J(θ): rotor + links reflected to the servo
    double dinertia = 0.0;       // dJ/dθ
    double gravity_nm = 0.0;     // dV/dθ: torque that holds the links against gravity
    double gripper_x_m = 0.0, gripper_y_m = 0.0;
    double transmission_rad = 0.0;  // μ
  };
  Dynamics dynamics_at(double crank_abs_rad) const;
  // τ = J α + ½ J' ω² + dV/dθ.
  double torque_at(double crank_abs_rad, double omega, double alpha) const;

 private:
  struct Piece {
    double t0 = 0.0, t1 = 0.0, start_rad = 0.0;  // relative to TAKE
    EnvelopeMove move;                           // zero-length for a dwell
  };
  KnotCycleSpec spec_{};
  FourBar fourbar_{};
  double ground_angle_ = 0.0;  // direction crank pivot → rocker pivot (knot frame)
  std::array<Piece, 6> pieces_{};
  double duration_ = 0.0, end_offset_ = 0.0, take_angle_ = 0.0;
  Window gripper_closed_{}, cutter_{}, yarn_sample_{}, in_warp_{};
  KnotCycleReport report_{};
};

}  // namespace loom::motion

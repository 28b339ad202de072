// Shaking-force and shaking-moment balancing of a linkage with prescribed motion (seed 003): minimise
// z = w1·RMS(force)/RMS0(force) + w2·RMS(moment)/RMS0(moment) by counterweights on the links pivoted
// on the frame, or by redistributing each link's mass (003's equimomental point-mass design
// variables), under bounds, with NLopt's SLSQP and analytic gradients. Normalising by the unbalanced
// RMS values (instead of 003 eqn 13's reference link) makes the weights mean "relative importance".
// Configure-time/offline only: allocates, calls the optimiser.
#pragma once

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "loom/motion/dynamics.hpp"
#include "loom/motion/dynamics_body.hpp"
#include "loom/motion/mass_properties.hpp"

namespace loom::motion {

// One moving link as the balancer sees it.
struct BalancingLink {
  std::string name;
  PlanarInertia body;     // the link's own mass: redistributable, and where counterweights go
  PlanarInertia payload;  // carried mass that stays as it is (the beater); zero if none
  double length_m = 0.0;  // a_i: bound on a counterweight's radius and on the centre's distance
  bool grounded = false;  // pivoted on the frame at its origin: counterweights allowed (003 §4.1)
};

// The prescribed motion of every link at δ instants equally spaced in time over one period.
struct LinkageMotionSamples {
  std::vector<BalancingLink> links;
  std::vector<BodyMotion> motion;  // motion[s * links.size() + i]: link i at sample s
  std::size_t samples = 0;
  Eigen::Vector2d moment_about_m = Eigen::Vector2d::Zero();  // shaking-moment reference (003: O1)
};

// Configure-time only. The beat-up at constant crank speed ω: crank, coupler, rocker (payload: the
// beater), moments about the crank pivot A0. Throws kInvalidInput for samples < 3 or ω <= 0.
LinkageMotionSamples beatup_balancing_samples(const BeatUpDynamics& d, double omega_rad_s, int samples);

// A link's mass parameters q = (m, m·c_x, m·c_y, I_O) in its link frame (I_O about the origin): the
// shaking load is linear in them.
using MassParameters = Eigen::Vector4d;
// RT-safe.
MassParameters mass_parameters(const PlanarInertia& body);

// Shaking load as a linear map of every link's mass parameters, precomputed per sample.
class ShakingModel {
 public:
  // Configure-time only (allocates). Throws kInvalidInput for inconsistent samples.
  explicit ShakingModel(const LinkageMotionSamples& s);
  // RT-safe (no allocation). q holds 4 parameters per link, in link order.
  ShakingLoad load(std::size_t sample, std::span<const double> q) const;
  // RT-safe (no allocation). RMS force and moment over the samples; optional gradients d(RMS)/dq
  // (same layout as q).
  ShakingRms rms(std::span<const double> q, std::span<double> d_force = {},
                 std::span<double> d_moment = {}) const;
  // RT-safe accessors.
  std::size_t links() const { return links_; }
  std::size_t samples() const { return samples_; }

 private:
  std::size_t links_ = 0, samples_ = 0;
  // Per sample and link: rows fx, fy, n of the 3×4 map q -> (force, moment).
  std::vector<Eigen::Matrix<double, 3, 4>> map_;
};

struct BalanceOptions {
  double w1 = 0.5;                     // weight of the RMS shaking force
  double w2 = 0.5;                     // weight of the RMS shaking moment
  double counterweight_max_kg = 10.0;  // per counterweight (003 leaves it open; 4× the beater)
  // Counterweights are cast-iron discs of this thickness: a disc of mass m has its own central
  // inertia m²/(2πtρ), so a heavy counterweight cannot hide at a tiny radius as a point mass could.
  double counterweight_thickness_m = 0.02;
  double counterweight_density_kg_m3 = kCastIronDensity_kg_m3;
  double mass_factor_max = 5.0;    // redistribution: m0 <= m <= factor·m0 (003 §4.1)
  double radius_factor_min = 0.5;  // redistribution: factor·l0 <= l ... (003 §4.1)
  double radius_factor_max = 1.5;  // ... <= factor·l0
  // Tie-break: every kilogram added costs this much objective. Some directions leave the shaking load
  // unchanged (at constant crank speed a counterweight's mass on the crank matters only through its
  // first moment), and this picks the lightest of the equally good designs. Small enough that the
  // reported RMS values do not notice (objective ~1).
  double added_mass_cost_per_kg = 1e-4;
  double xtol_rel = 1e-10;  // SLSQP stop on relative design-variable change
  double ftol_rel = 1e-14;  // ... and on relative objective change
  int max_evaluations = 4000;
};

struct Counterweight {
  std::string link;
  double mass_kg = 0.0;
  double radius_m = 0.0;       // of its centre from the link's frame pivot
  double angle_rad = 0.0;      // from the link's x axis (the line to its next joint)
  double disc_radius_m = 0.0;  // of the cast-iron disc (BalanceOptions thickness and density)
  double inertia_kg_m2 = 0.0;  // about its own centre
};

struct OptimiserStep {
  int evaluation = 0;
  double objective = 0.0;
  ShakingRms rms;
};

struct BalanceResult {
  std::string method;  // "counterweight" or "redistribution"
  ShakingRms before, after;
  double objective_before = 0.0, objective_after = 0.0;  // w1·F/F0 + w2·N/N0 (without the tie-break)
  std::vector<Counterweight> counterweights;             // counterweight method
  std::vector<PlanarInertia> links_after;                // every link's own body after balancing (no payload)
  std::vector<OptimiserStep> trace;                      // every objective evaluation of the kept run
  int evaluations = 0;                                   // over all starts
  int nlopt_code = 0;
  std::string stop_reason;
  bool converged = false;  // SLSQP stopped on a tolerance (not on the budget or an error)
  double force_reduction() const { return before.force_n > 0 ? 1.0 - after.force_n / before.force_n : 0.0; }
  double moment_reduction() const {
    return before.moment_nm > 0 ? 1.0 - after.moment_nm / before.moment_nm : 0.0;
  }
};

// Configure-time only. Throws MotionError kInvalidInput for bad options/samples (naming the field),
// kNoConvergence when SLSQP fails outright (negative NLopt code other than round-off limited).
BalanceResult balance_with_counterweights(const LinkageMotionSamples& s, const BalanceOptions& o = {});
BalanceResult balance_by_redistribution(const LinkageMotionSamples& s, const BalanceOptions& o = {});

}  // namespace loom::motion

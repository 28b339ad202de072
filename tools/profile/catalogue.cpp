// Exact references. The rocker comes from the linkage solve, the crank law from the gear's closed
// form, the carriage cam from the smooth step (turn 1 of a sweep, where steps precede and follow),
// and the pick from the S-curve with time mapped onto one turn of phase.
#include "catalogue.hpp"

#include <algorithm>
#include <cmath>

#include "loom/motion/angles.hpp"

namespace loom::profile {

motion::ProfileSpec default_spec() {
  return motion::ProfileSpec{};
}

motion::ProfileSpec elliptic_spec() {
  motion::ProfileSpec s;
  s.crank_law.kind = motion::CrankLawKind::kElliptic;
  return s;
}

Catalogue default_catalogue() {
  using motion::kTwoPi;
  Catalogue c;
  c.set = std::make_shared<const motion::ProfileSet>(elliptic_spec());
  const motion::ProfileSet* p = c.set.get();
  const double omega = p->spec().crank.velocity;

  c.profiles.push_back({.name = "rocker",
                        .unit = "rad",
                        .what = "beater (rocker) angle vs crank phase",
                        .requirement = 1e-9,
                        .phase_rate = omega,
                        .rise = 0.0,
                        .exact =
                            [p](double phi) {
                              const motion::BeaterState s = p->beatup().at(phi);
                              return motion::PhaseExact{s.rocker_angle, s.d1, s.d2};
                            },
                        .closed_form = [p](double phi) { return p->beatup().at(phi).rocker_angle; }});

  c.profiles.push_back({.name = "crank_elliptic",
                        .unit = "rad",
                        .what = "crank vs master phase, elliptic law e = 0.2",
                        .requirement = 1e-9,
                        .phase_rate = omega,
                        .rise = 0.0,
                        .exact =
                            [p](double phi) {
                              const motion::CrankLawExact e = p->crank_law().exact(phi);
                              return motion::PhaseExact{e.offset, e.d1 - 1.0, e.d2};
                            },
                        .closed_form = [p](double phi) { return p->crank_law().exact(phi).offset; }});

  const double pitch = p->cam().pitch();
  c.profiles.push_back({.name = "carriage_cam",
                        .unit = "m",
                        .what = "carriage vs crank phase, a step per turn",
                        .requirement = 1e-8,
                        .phase_rate = omega,
                        .rise = pitch,
                        .exact =
                            [p, pitch](double phi) {
                              const motion::CamSample s = p->cam().at(phi + kTwoPi);
                              return motion::PhaseExact{s.position - pitch, s.d1, s.d2};
                            },
                        .closed_form = [p](double phi) { return p->cam().at(phi + kTwoPi).position; }});

  const motion::JerkMove& pick = p->pick();
  const double scale = pick.duration() / kTwoPi;  // seconds per rad of phase
  c.profiles.push_back(
      {.name = "helix_pick",
       .unit = "rad",
       .what = "helix angle over one pick (phase = time share)",
       .requirement = 1e-7,
       .phase_rate = 1.0 / scale,
       .rise = pick.distance(),
       .exact =
           [&pick, scale](double phi) {
             const motion::MoveSample m = pick.at(phi * scale);
             return motion::PhaseExact{m.position, m.velocity * scale, m.acceleration * scale * scale};
           },
       .closed_form = [&pick, scale](double phi) { return pick.at(phi * scale).position; }});
  // The knotting servo over one knot (seed 001's head, default micro servo): the cycle's exact
  // piecewise jerk moves with time mapped onto one turn of phase, as the knot cycle tabulates it.
  c.knot =
      std::make_shared<const motion::KnotCycle>(motion::KnotCycle::build(motion::seed001_knot_cycle_spec()));
  const motion::KnotCycle* knot = c.knot.get();
  const double knot_scale = knot->duration_s() / kTwoPi;
  c.profiles.push_back(
      {.name = "knot_cycle",
       .unit = "rad",
       .what = "knotting servo angle over one knot (phase = time share)",
       .requirement = 1e-7,
       .phase_rate = 1.0 / knot_scale,
       .rise = knot->end_offset_rad(),
       .exact =
           [knot, knot_scale](double phi) {
             const motion::KnotCycle::Sample m = knot->exact(phi * knot_scale);
             return motion::PhaseExact{m.angle_rad, m.velocity_rad_s * knot_scale,
                                       m.accel_rad_s2 * knot_scale * knot_scale};
           },
       .closed_form = [knot, knot_scale](double phi) { return knot->exact(phi * knot_scale).angle_rad; }});
  for (ReportProfile& prof : c.profiles) {
    for (int i = 0; i < 8192; ++i) {
      const motion::PhaseExact e = prof.exact(kTwoPi * i / 8192.0);
      prof.peak_vel = std::max(prof.peak_vel, std::abs(e.d1) * prof.phase_rate);
      prof.peak_acc = std::max(prof.peak_acc, std::abs(e.d2) * prof.phase_rate * prof.phase_rate);
    }
  }
  return c;
}

}  // namespace loom::profile

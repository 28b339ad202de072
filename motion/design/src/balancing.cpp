// Shaking balance by SLSQP (NLopt's C API). Each link's contribution to the shaking force and moment
// is linear in its mass parameters q = (m, m·c, I_O), so the objective and its exact gradient cost a
// few multiply-adds per sample; design variables are mapped to q (counterweight m, r, φ or 003's
// equimomental m1..m3, l) and scaled to the unit box so one relative tolerance fits them all.
#include "loom/motion/design/balancing.hpp"

#include <nlopt.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include "loom/motion/angles.hpp"
#include "loom/motion/design/equimomental.hpp"
#include "loom/motion/errors.hpp"

namespace loom::motion {

namespace {

[[noreturn]] void invalid(const std::string& what) {
  throw MotionError(ErrorCode::kInvalidInput, "balancing: " + what);
}

Eigen::Vector2d perp(const Eigen::Vector2d& v) {
  return {-v.y(), v.x()};
}

const char* nlopt_result_name(nlopt_result r) {
  switch (r) {
    case NLOPT_SUCCESS:
      return "success";
    case NLOPT_STOPVAL_REACHED:
      return "stopval reached";
    case NLOPT_FTOL_REACHED:
      return "ftol reached";
    case NLOPT_XTOL_REACHED:
      return "xtol reached";
    case NLOPT_MAXEVAL_REACHED:
      return "evaluation budget spent";
    case NLOPT_MAXTIME_REACHED:
      return "time budget spent";
    case NLOPT_FAILURE:
      return "generic failure";
    case NLOPT_INVALID_ARGS:
      return "invalid arguments";
    case NLOPT_OUT_OF_MEMORY:
      return "out of memory";
    case NLOPT_ROUNDOFF_LIMITED:
      return "round-off limited";
    case NLOPT_FORCED_STOP:
      return "forced stop";
    default:
      return "unknown";
  }
}

void check_options(const BalanceOptions& o) {
  std::ostringstream os;
  const auto bad = [&](const char* field, double v, const char* rule) {
    os << field << " = " << v << ": " << rule;
    invalid(os.str());
  };
  if (!(o.w1 >= 0.0) || !std::isfinite(o.w1)) bad("w1", o.w1, "must be finite and >= 0");
  if (!(o.w2 >= 0.0) || !std::isfinite(o.w2)) bad("w2", o.w2, "must be finite and >= 0");
  if (!(o.w1 + o.w2 > 0.0)) bad("w1 + w2", o.w1 + o.w2, "must be > 0");
  if (!(o.counterweight_max_kg > 0.0) || !std::isfinite(o.counterweight_max_kg))
    bad("counterweight_max_kg", o.counterweight_max_kg, "must be finite and > 0");
  if (!(o.counterweight_thickness_m > 0.0) || !std::isfinite(o.counterweight_thickness_m))
    bad("counterweight_thickness_m", o.counterweight_thickness_m, "must be finite and > 0");
  if (!(o.counterweight_density_kg_m3 > 0.0) || !std::isfinite(o.counterweight_density_kg_m3))
    bad("counterweight_density_kg_m3", o.counterweight_density_kg_m3, "must be finite and > 0");
  if (!(o.mass_factor_max >= 1.0) || !std::isfinite(o.mass_factor_max))
    bad("mass_factor_max", o.mass_factor_max, "must be finite and >= 1");
  if (!(o.radius_factor_min > 0.0) || !(o.radius_factor_min <= 1.0))
    bad("radius_factor_min", o.radius_factor_min, "must be in (0, 1]");
  if (!(o.radius_factor_max >= 1.0) || !std::isfinite(o.radius_factor_max))
    bad("radius_factor_max", o.radius_factor_max, "must be finite and >= 1");
  if (!(o.added_mass_cost_per_kg >= 0.0) || !std::isfinite(o.added_mass_cost_per_kg))
    bad("added_mass_cost_per_kg", o.added_mass_cost_per_kg, "must be finite and >= 0");
  if (!(o.xtol_rel > 0.0) || !(o.xtol_rel < 1.0)) bad("xtol_rel", o.xtol_rel, "must be in (0, 1)");
  if (!(o.ftol_rel >= 0.0) || !(o.ftol_rel < 1.0)) bad("ftol_rel", o.ftol_rel, "must be in [0, 1)");
  if (o.max_evaluations < 1) bad("max_evaluations", o.max_evaluations, "must be >= 1");
}

void check_samples(const LinkageMotionSamples& s) {
  if (s.links.empty() || s.samples < 3 || s.motion.size() != s.samples * s.links.size()) {
    std::ostringstream os;
    os << "motion samples: " << s.links.size() << " links, " << s.samples << " samples, " << s.motion.size()
       << " motions: need >= 1 link, >= 3 samples and samples x links motions";
    invalid(os.str());
  }
}

// A design problem: design variables x (in physical units, with bounds) mapped onto the per-link
// mass parameters q, plus optional inequality constraints c(x) <= 0.
struct Problem {
  const ShakingModel* model = nullptr;
  std::vector<double> q_fixed;  // mass parameters that the design does not change
  std::vector<double> lb, ub;
  double w1 = 0.5, w2 = 0.5;
  ShakingRms ref;            // the unbalanced RMS values (normalisation)
  std::vector<double> cost;  // per design variable: objective per unit (the added-mass tie-break)
  // q(x) added to q_fixed, and the Jacobian dq/dx (rows: q index, cols: x index) into `jac`.
  virtual void map(const std::vector<double>& x, std::vector<double>& q, Eigen::MatrixXd& jac) const = 0;
  virtual ~Problem() = default;

  std::vector<OptimiserStep> trace;
  int evaluations = 0;

  std::vector<double> to_x(const double* u) const {
    std::vector<double> x(lb.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = lb[i] + u[i] * (ub[i] - lb[i]);
    return x;
  }

  double objective(const std::vector<double>& x, std::vector<double>* grad_x) const {
    std::vector<double> q;
    Eigen::MatrixXd jac;
    map(x, q, jac);
    std::vector<double> df(q.size()), dn(q.size());
    const ShakingRms r = model->rms(q, df, dn);
    const double sf = w1 / std::max(ref.force_n, 1e-300), sn = w2 / std::max(ref.moment_nm, 1e-300);
    double tie = 0.0;
    for (std::size_t j = 0; j < cost.size() && j < x.size(); ++j) tie += cost[j] * x[j];
    if (grad_x != nullptr) {
      grad_x->assign(x.size(), 0.0);
      for (std::size_t j = 0; j < x.size(); ++j) {
        double g = j < cost.size() ? cost[j] : 0.0;
        for (std::size_t k = 0; k < q.size(); ++k)
          g += (sf * df[k] + sn * dn[k]) * jac(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j));
        (*grad_x)[j] = g;
      }
    }
    return sf * r.force_n + sn * r.moment_nm + tie;
  }

  // The reported objective: w1·F/F0 + w2·N/N0.
  double shaking_objective(const ShakingRms& r) const {
    return w1 * r.force_n / std::max(ref.force_n, 1e-300) +
           w2 * r.moment_nm / std::max(ref.moment_nm, 1e-300);
  }

  ShakingRms rms_at(const std::vector<double>& x) const {
    std::vector<double> q;
    Eigen::MatrixXd jac;
    map(x, q, jac);
    return model->rms(q);
  }
};

double nlopt_objective(unsigned n, const double* u, double* grad, void* data) {
  Problem& p = *static_cast<Problem*>(data);
  const std::vector<double> x = p.to_x(u);
  std::vector<double> gx;
  const double z = p.objective(x, grad != nullptr ? &gx : nullptr);
  if (grad != nullptr) {
    for (unsigned i = 0; i < n; ++i) grad[i] = gx[i] * (p.ub[i] - p.lb[i]);
  }
  ++p.evaluations;
  const ShakingRms r = p.rms_at(x);
  p.trace.push_back({p.evaluations, p.shaking_objective(r), r});
  return z;
}

// An inequality constraint c(x) <= 0 with its gradient in physical units.
struct Constraint {
  const Problem* problem;
  std::function<double(const std::vector<double>&, std::vector<double>&)> f;
};

double nlopt_constraint(unsigned n, const double* u, double* grad, void* data) {
  const Constraint& c = *static_cast<const Constraint*>(data);
  const std::vector<double> x = c.problem->to_x(u);
  std::vector<double> gx(n, 0.0);
  const double v = c.f(x, gx);
  if (grad != nullptr) {
    for (unsigned i = 0; i < n; ++i) grad[i] = gx[i] * (c.problem->ub[i] - c.problem->lb[i]);
  }
  return v;
}

struct RunResult {
  std::vector<double> x;
  double z = std::numeric_limits<double>::infinity();
  nlopt_result code = NLOPT_FAILURE;
  std::vector<OptimiserStep> trace;
};

RunResult run_slsqp(Problem& p, const std::vector<double>& x0, std::vector<Constraint>& constraints,
                    const BalanceOptions& o) {
  const unsigned n = static_cast<unsigned>(x0.size());
  nlopt_opt opt = nlopt_create(NLOPT_LD_SLSQP, n);
  std::vector<double> lo(n, 0.0), hi(n, 1.0), u(n);
  for (unsigned i = 0; i < n; ++i) {
    const double span = p.ub[i] - p.lb[i];
    u[i] = span > 0.0 ? std::clamp((x0[i] - p.lb[i]) / span, 0.0, 1.0) : 0.0;
  }
  nlopt_set_lower_bounds(opt, lo.data());
  nlopt_set_upper_bounds(opt, hi.data());
  nlopt_set_min_objective(opt, nlopt_objective, &p);
  for (Constraint& c : constraints) nlopt_add_inequality_constraint(opt, nlopt_constraint, &c, 1e-12);
  nlopt_set_xtol_rel(opt, o.xtol_rel);
  nlopt_set_ftol_rel(opt, o.ftol_rel);
  nlopt_set_maxeval(opt, o.max_evaluations);
  p.trace.clear();
  RunResult r;
  double z = 0.0;
  r.code = nlopt_optimize(opt, u.data(), &z);
  nlopt_destroy(opt);
  r.x = p.to_x(u.data());
  r.z = p.objective(r.x, nullptr);
  r.trace = p.trace;
  return r;
}

std::vector<double> fixed_parameters(const LinkageMotionSamples& s, bool include_bodies) {
  std::vector<double> q(4 * s.links.size(), 0.0);
  for (std::size_t i = 0; i < s.links.size(); ++i) {
    MassParameters p = mass_parameters(s.links[i].payload);
    if (include_bodies) p += mass_parameters(s.links[i].body);
    for (int k = 0; k < 4; ++k) q[4 * i + static_cast<std::size_t>(k)] = p(k);
  }
  return q;
}

void finish(BalanceResult& b, const Problem& p, const RunResult& best, int evaluations) {
  if (best.x.empty()) {
    throw MotionError(
        ErrorCode::kNoConvergence,
        "balancing: no optimiser start reached a finite objective (the shaking load overflows)");
  }
  b.after = p.rms_at(best.x);
  b.objective_after = p.shaking_objective(b.after);
  b.trace = best.trace;
  b.evaluations = evaluations;
  b.nlopt_code = static_cast<int>(best.code);
  b.stop_reason = nlopt_result_name(best.code);
  b.converged = best.code == NLOPT_SUCCESS || best.code == NLOPT_FTOL_REACHED ||
                best.code == NLOPT_XTOL_REACHED || best.code == NLOPT_STOPVAL_REACHED;
  if (best.code < 0 && best.code != NLOPT_ROUNDOFF_LIMITED) {
    std::ostringstream os;
    os << "balancing (" << b.method << "): SLSQP failed: " << b.stop_reason << " (NLopt code " << b.nlopt_code
       << ")";
    throw MotionError(ErrorCode::kNoConvergence, os.str());
  }
}

// ---- counterweights -------------------------------------------------------------------------------

// A cast-iron disc of mass m and thickness t: central inertia ½mR² with πR²tρ = m, i.e. m²/(2πtρ).
double disc_inertia(double m, double thickness, double density) {
  return m * m / (2.0 * kPi * thickness * density);
}

struct CounterweightProblem : Problem {
  std::vector<std::size_t> link_of;  // per counterweight: the link it sits on
  double thickness = 0.02, density = kCastIronDensity_kg_m3;
  void map(const std::vector<double>& x, std::vector<double>& q, Eigen::MatrixXd& jac) const override {
    q = q_fixed;
    jac = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(q.size()), static_cast<Eigen::Index>(x.size()));
    for (std::size_t c = 0; c < link_of.size(); ++c) {
      const double m = x[3 * c], r = x[3 * c + 1], phi = x[3 * c + 2];
      const double cs = std::cos(phi), sn = std::sin(phi);
      const std::size_t base = 4 * link_of[c];
      q[base] += m;
      q[base + 1] += m * r * cs;
      q[base + 2] += m * r * sn;
      q[base + 3] += m * r * r + disc_inertia(m, thickness, density);
      const auto J = [&](std::size_t k, std::size_t j) -> double& {
        return jac(static_cast<Eigen::Index>(base + k), static_cast<Eigen::Index>(3 * c + j));
      };
      J(0, 0) = 1.0;
      J(1, 0) = r * cs;
      J(2, 0) = r * sn;
      J(3, 0) = r * r + 2.0 * m / (2.0 * kPi * thickness * density);
      J(1, 1) = m * cs;
      J(2, 1) = m * sn;
      J(3, 1) = 2.0 * m * r;
      J(1, 2) = -m * r * sn;
      J(2, 2) = m * r * cs;
    }
  }
};

// ---- mass redistribution --------------------------------------------------------------------------

struct RedistributionProblem : Problem {
  // x = (m1, m2, m3, l) per link, points at angles 0, 2π/3, 4π/3 of the link frame (003 eqn 18a).
  void map(const std::vector<double>& x, std::vector<double>& q, Eigen::MatrixXd& jac) const override {
    q = q_fixed;
    jac = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(q.size()), static_cast<Eigen::Index>(x.size()));
    const std::size_t links = q.size() / 4;
    for (std::size_t i = 0; i < links; ++i) {
      const double l = x[4 * i + 3];
      Eigen::Vector2d su = Eigen::Vector2d::Zero();
      double msum = 0.0;
      const auto J = [&](std::size_t k, std::size_t j) -> double& {
        return jac(static_cast<Eigen::Index>(4 * i + k), static_cast<Eigen::Index>(4 * i + j));
      };
      for (std::size_t j = 0; j < 3; ++j) {
        const double th = kTwoPi * static_cast<double>(j) / 3.0;
        const Eigen::Vector2d u(std::cos(th), std::sin(th));
        const double mj = x[4 * i + j];
        msum += mj;
        su += mj * u;
        J(0, j) = 1.0;
        J(1, j) = l * u.x();
        J(2, j) = l * u.y();
        J(3, j) = l * l;
      }
      q[4 * i] += msum;
      q[4 * i + 1] += l * su.x();
      q[4 * i + 2] += l * su.y();
      q[4 * i + 3] += l * l * msum;
      J(1, 3) = su.x();
      J(2, 3) = su.y();
      J(3, 3) = 2.0 * l * msum;
    }
  }
};

}  // namespace

MassParameters mass_parameters(const PlanarInertia& b) {
  return {b.mass_kg, b.mass_kg * b.centre_m.x(), b.mass_kg * b.centre_m.y(),
          b.inertia_about(Eigen::Vector2d::Zero())};
}

ShakingModel::ShakingModel(const LinkageMotionSamples& s) : links_(s.links.size()), samples_(s.samples) {
  check_samples(s);
  map_.resize(links_ * samples_);
  for (std::size_t k = 0; k < samples_; ++k) {
    for (std::size_t i = 0; i < links_; ++i) {
      const BodyMotion& m = s.motion[k * links_ + i];
      const double c = std::cos(m.angle_rad), sn = std::sin(m.angle_rad);
      Eigen::Matrix2d R;
      R << c, -sn, sn, c;
      Eigen::Matrix2d E;
      E << 0, -1, 1, 0;
      // force = m a_o + K μ_world-from-local, K = (αE − ω²)R; moment about P:
      // (o−P)×force + (Rμ)×a_o + α I_O.
      const Eigen::Matrix2d K =
          (m.alpha_rad_s2 * E - m.omega_rad_s * m.omega_rad_s * Eigen::Matrix2d::Identity()) * R;
      const Eigen::Vector2d r = m.origin_m - s.moment_about_m;
      const Eigen::Vector2d a = m.origin_acc_m_s2;
      Eigen::Matrix<double, 3, 4> M = Eigen::Matrix<double, 3, 4>::Zero();
      M.block<2, 1>(0, 0) = a;
      M.block<2, 2>(0, 1) = K;
      M(2, 0) = cross2(r, a);
      const Eigen::Vector2d mu_row = K.transpose() * perp(r) + R.transpose() * Eigen::Vector2d(a.y(), -a.x());
      M(2, 1) = mu_row.x();
      M(2, 2) = mu_row.y();
      M(2, 3) = m.alpha_rad_s2;
      map_[k * links_ + i] = M;
    }
  }
}

ShakingLoad ShakingModel::load(std::size_t sample, std::span<const double> q) const {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < links_ && 4 * i + 3 < q.size(); ++i) {
    const Eigen::Vector4d qi(q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]);
    out += map_[sample * links_ + i] * qi;
  }
  return {out.head<2>(), out(2)};
}

ShakingRms ShakingModel::rms(std::span<const double> q, std::span<double> d_force,
                             std::span<double> d_moment) const {
  const bool grad_f = d_force.size() >= 4 * links_, grad_n = d_moment.size() >= 4 * links_;
  if (grad_f) std::fill(d_force.begin(), d_force.end(), 0.0);
  if (grad_n) std::fill(d_moment.begin(), d_moment.end(), 0.0);
  double f2 = 0.0, n2 = 0.0;
  for (std::size_t k = 0; k < samples_; ++k) {
    const ShakingLoad l = load(k, q);
    f2 += l.force_n.squaredNorm();
    n2 += l.moment_nm * l.moment_nm;
    for (std::size_t i = 0; i < links_; ++i) {
      const Eigen::Matrix<double, 3, 4>& M = map_[k * links_ + i];
      for (int j = 0; j < 4; ++j) {
        const std::size_t idx = 4 * i + static_cast<std::size_t>(j);
        if (grad_f) d_force[idx] += l.force_n.x() * M(0, j) + l.force_n.y() * M(1, j);
        if (grad_n) d_moment[idx] += l.moment_nm * M(2, j);
      }
    }
  }
  const double inv = 1.0 / static_cast<double>(samples_);
  ShakingRms r{std::sqrt(f2 * inv), std::sqrt(n2 * inv)};
  // d sqrt(Σx²/δ) = (Σ x dx)/(δ·RMS); a zero RMS has no direction, its gradient is left at zero.
  for (std::size_t idx = 0; idx < 4 * links_; ++idx) {
    if (grad_f) d_force[idx] = r.force_n > 0.0 ? d_force[idx] * inv / r.force_n : 0.0;
    if (grad_n) d_moment[idx] = r.moment_nm > 0.0 ? d_moment[idx] * inv / r.moment_nm : 0.0;
  }
  return r;
}

LinkageMotionSamples beatup_balancing_samples(const BeatUpDynamics& d, double omega, int samples) {
  if (samples < 3) invalid("samples = " + std::to_string(samples) + ": must be >= 3");
  if (!(omega > 0.0) || !std::isfinite(omega)) {
    std::ostringstream os;
    os << "crank speed = " << omega << " rad/s: must be finite and > 0";
    invalid(os.str());
  }
  const BeatUpGeometry& g = d.head().geometry();
  const BeatUpMasses& m = d.masses();
  LinkageMotionSamples s;
  s.links = {
      {"crank", m.crank, {}, g.bar.crank, true},
      {"coupler", m.coupler, {}, g.bar.coupler, false},
      {"rocker",
       m.rocker,
       {m.beater_kg, m.beater_at_m, 0.0},
       std::max(g.bar.rocker, m.beater_at_m.norm()),
       true},
  };
  s.samples = static_cast<std::size_t>(samples);
  s.motion.reserve(s.samples * s.links.size());
  for (int k = 0; k < samples; ++k) {
    const std::array<BodyMotion, 3> mo = d.motion({kTwoPi * k / samples, omega, 0.0});
    s.motion.insert(s.motion.end(), mo.begin(), mo.end());
  }
  s.moment_about_m = Eigen::Vector2d::Zero();
  return s;
}

BalanceResult balance_with_counterweights(const LinkageMotionSamples& s, const BalanceOptions& o) {
  check_options(o);
  const ShakingModel model(s);
  CounterweightProblem p;
  p.model = &model;
  p.w1 = o.w1;
  p.w2 = o.w2;
  p.q_fixed = fixed_parameters(s, true);
  p.thickness = o.counterweight_thickness_m;
  p.density = o.counterweight_density_kg_m3;
  BalanceResult b;
  b.method = "counterweight";
  b.before = model.rms(p.q_fixed);
  p.ref = b.before;
  for (std::size_t i = 0; i < s.links.size(); ++i) {
    if (!s.links[i].grounded) continue;
    if (!(s.links[i].length_m > 0.0)) invalid("link '" + s.links[i].name + "' length must be > 0");
    p.link_of.push_back(i);
    p.lb.insert(p.lb.end(), {0.0, 0.0, -kTwoPi});
    p.ub.insert(p.ub.end(), {o.counterweight_max_kg, s.links[i].length_m, kTwoPi});
    p.cost.insert(p.cost.end(), {o.added_mass_cost_per_kg, 0.0, 0.0});
  }
  if (p.link_of.empty()) invalid("no link is pivoted on the frame: nowhere to put a counterweight");
  b.objective_before = p.shaking_objective(b.before);
  if (!std::isfinite(b.before.force_n) || !std::isfinite(b.before.moment_nm) ||
      !std::isfinite(b.objective_before)) {
    std::ostringstream os;
    os << "the unbalanced shaking load is not finite (RMS force " << b.before.force_n << " N, moment "
       << b.before.moment_nm << " N m): the motion (crank speed) is beyond what double precision can balance";
    invalid(os.str());
  }
  // Starts: for each link, the counterweight that cancels its own first moment (mass and payload) at
  // half its length, clamped into [5 %, 50 %] of the mass bound; then that angle turned by ±90° and
  // 180°. A counterweight's angle makes the problem multimodal and a start at zero mass is a trap
  // (no gradient in radius or angle there), so the starts cover the circle with a real mass.
  RunResult best;
  int evaluations = 0;
  std::vector<Constraint> none;
  for (const double turn : {0.0, 0.5 * kPi, -0.5 * kPi, kPi}) {
    std::vector<double> x0;
    for (const std::size_t i : p.link_of) {
      const BalancingLink& link = s.links[i];
      const MassParameters q = mass_parameters(link.body) + mass_parameters(link.payload);
      const Eigen::Vector2d mu(q(1), q(2));
      const double r0 = 0.5 * link.length_m;
      const double m0 =
          std::clamp(mu.norm() / r0, 0.05 * o.counterweight_max_kg, 0.5 * o.counterweight_max_kg);
      const double phi0 = mu.norm() > 0.0 ? std::atan2(-mu.y(), -mu.x()) : kPi;
      x0.insert(x0.end(), {m0, r0, wrap_pi(phi0 + turn)});
    }
    p.evaluations = 0;
    RunResult r = run_slsqp(p, x0, none, o);
    evaluations += p.evaluations;
    if (r.z < best.z) best = std::move(r);
  }
  finish(b, p, best, evaluations);
  for (std::size_t c = 0; c < p.link_of.size(); ++c) {
    const BalancingLink& link = s.links[p.link_of[c]];
    Counterweight cw{link.name, best.x[3 * c], best.x[3 * c + 1], wrap_pi(best.x[3 * c + 2]), 0.0, 0.0};
    cw.inertia_kg_m2 = disc_inertia(cw.mass_kg, p.thickness, p.density);
    cw.disc_radius_m = std::sqrt(cw.mass_kg / (kPi * p.thickness * p.density));
    b.counterweights.push_back(cw);
  }
  for (std::size_t i = 0; i < s.links.size(); ++i) {
    PlanarInertia body = s.links[i].body;
    for (const Counterweight& cw : b.counterweights) {
      if (cw.link == s.links[i].name) {
        body = combine(
            body, {cw.mass_kg, cw.radius_m * Eigen::Vector2d(std::cos(cw.angle_rad), std::sin(cw.angle_rad)),
                   cw.inertia_kg_m2});
      }
    }
    b.links_after.push_back(body);
  }
  return b;
}

BalanceResult balance_by_redistribution(const LinkageMotionSamples& s, const BalanceOptions& o) {
  check_options(o);
  const ShakingModel model(s);
  RedistributionProblem p;
  p.model = &model;
  p.w1 = o.w1;
  p.w2 = o.w2;
  BalanceResult b;
  b.method = "redistribution";
  const std::vector<double> q_all = fixed_parameters(s, true);
  p.q_fixed = fixed_parameters(s, false);  // payloads only; the bodies become design variables
  b.before = model.rms(q_all);
  p.ref = b.before;
  std::vector<double> x0;
  std::vector<Constraint> constraints;
  for (std::size_t i = 0; i < s.links.size(); ++i) {
    const BalancingLink& link = s.links[i];
    if (!(link.body.mass_kg > 0.0)) invalid("link '" + link.name + "' has no mass to redistribute");
    if (!(link.length_m > 0.0)) invalid("link '" + link.name + "' length must be > 0");
    const EquimomentalSystem e = equimomental_three(link.body, 0.0);
    if (!e.all_positive)
      invalid("link '" + link.name + "': its equimomental masses at 0/120/240 deg are not all >= 0");
    const double m0 = link.body.mass_kg, l0 = e.radius_m;
    for (const PointMass& pm : e.points) x0.push_back(pm.mass_kg);
    x0.push_back(l0);
    p.lb.insert(p.lb.end(), {0.0, 0.0, 0.0, o.radius_factor_min * l0});
    const double mmax = o.mass_factor_max * m0;
    p.ub.insert(p.ub.end(), {mmax, mmax, mmax, o.radius_factor_max * l0});
    p.cost.insert(p.cost.end(),
                  {o.added_mass_cost_per_kg, o.added_mass_cost_per_kg, o.added_mass_cost_per_kg, 0.0});
    const std::size_t base = 4 * i;
    // m0 <= Σm_j <= factor·m0 (003 eqn 20b), scaled by m0.
    constraints.push_back({&p, [base, m0](const std::vector<double>& x, std::vector<double>& g) {
                             for (std::size_t j = 0; j < 3; ++j) g[base + j] = -1.0 / m0;
                             return (m0 - x[base] - x[base + 1] - x[base + 2]) / m0;
                           }});
    constraints.push_back({&p, [base, m0, mmax](const std::vector<double>& x, std::vector<double>& g) {
                             for (std::size_t j = 0; j < 3; ++j) g[base + j] = 1.0 / m0;
                             return (x[base] + x[base + 1] + x[base + 2] - mmax) / m0;
                           }});
    // Centre within the link length: |μ|² <= a²m² (003 eqn 20d), scaled by a²m0².
    const double a = link.length_m;
    constraints.push_back({&p, [base, m0, a](const std::vector<double>& x, std::vector<double>& g) {
                             const double l = x[base + 3];
                             Eigen::Vector2d su = Eigen::Vector2d::Zero();
                             double m = 0.0;
                             std::array<Eigen::Vector2d, 3> u;
                             for (std::size_t j = 0; j < 3; ++j) {
                               const double th = kTwoPi * static_cast<double>(j) / 3.0;
                               u[j] = {std::cos(th), std::sin(th)};
                               su += x[base + j] * u[j];
                               m += x[base + j];
                             }
                             const double scale = 1.0 / (a * a * m0 * m0);
                             for (std::size_t j = 0; j < 3; ++j) {
                               g[base + j] = (2.0 * l * l * su.dot(u[j]) - 2.0 * a * a * m) * scale;
                             }
                             g[base + 3] = 2.0 * l * su.squaredNorm() * scale;
                             return (l * l * su.squaredNorm() - a * a * m * m) * scale;
                           }});
  }
  b.objective_before = p.shaking_objective(b.before);
  if (!std::isfinite(b.before.force_n) || !std::isfinite(b.before.moment_nm) ||
      !std::isfinite(b.objective_before)) {
    std::ostringstream os;
    os << "the unbalanced shaking load is not finite (RMS force " << b.before.force_n << " N, moment "
       << b.before.moment_nm << " N m): the motion (crank speed) is beyond what double precision can balance";
    invalid(os.str());
  }
  // Starts: the link as it is, then each link's mass doubled and moved 80 % onto one of its three
  // points (the same point index on every link); SLSQP is local and the objective is not convex.
  std::vector<std::vector<double>> starts{x0};
  for (std::size_t heavy = 0; heavy < 3; ++heavy) {
    std::vector<double> x = x0;
    for (std::size_t i = 0; i < s.links.size(); ++i) {
      const double m2 = std::min(2.0, o.mass_factor_max) * s.links[i].body.mass_kg;
      for (std::size_t j = 0; j < 3; ++j) x[4 * i + j] = (j == heavy ? 0.8 : 0.1) * m2;
    }
    starts.push_back(x);
  }
  RunResult best;
  int evaluations = 0;
  for (const std::vector<double>& start : starts) {
    p.evaluations = 0;
    RunResult r = run_slsqp(p, start, constraints, o);
    evaluations += p.evaluations;
    if (r.z < best.z) best = std::move(r);
  }
  finish(b, p, best, evaluations);
  for (std::size_t i = 0; i < s.links.size(); ++i) {
    const std::array<PointMass, 3> pts =
        equimomental_points(best.x[4 * i], best.x[4 * i + 1], best.x[4 * i + 2], best.x[4 * i + 3], 0.0);
    b.links_after.push_back(from_point_masses(pts));
  }
  return b;
}

}  // namespace loom::motion

// `loom-synth knotter`: seed 001's knotting linkage as the machine builds it. The three-point synthesis
// gives two chains A0_k → O1_k → O2_k → P with the same prescribed last-link motion (P_i, θ2_i); both
// last links therefore lie on one rigid body, the coupler, which carries both moving pivots
// O2_k = P_i − a2_k·u(θ2_i) and the gripper P. The four-bar is: ground A0_1A0_2 (on the θ0 line),
// the two side links a1_1 and a1_2, coupler |a2_1 − a2_2|. (Subtracting the chains' lengths as
// scalars, as the seed does, builds a different linkage that reaches none of the points.)
// The knot cycle then checks branch, order, transmission and toggles and times the cycle; the output
// is the [knotting.linkage] config section, SI, with comments.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/design/three_point.hpp"
#include "loom/motion/knot_cycle.hpp"

namespace loom::synth {

namespace {

using motion::KnotCycleSpec;
using motion::ThreePointSolution;

// The seed's coupler (link 2 with holder and gripper): mass, I_G, cg 13.337 mm from the gripper.
constexpr double kCouplerMassKg = 1.641e-3, kCouplerInertia = 208.94e-9, kCouplerCgFromGripper_m = 0.013337;

motion::KnotLinkSpec side_link(double length_m) {
  return motion::delrin_link(length_m);
}  // seed 001's Delrin links

// The four-bar from the driven chain d and the other chain o (lengths in mm from the synthesis).
KnotCycleSpec linkage_from(const std::array<motion::PrecisionPoint, 3>& pts, double theta0,
                           const ThreePointSolution& d, const ThreePointSolution& o,
                           const KnotCycleSpec& base) {
  KnotCycleSpec s = base;
  const double mm = 1e-3;
  for (std::size_t i = 0; i < 3; ++i) s.points[i] = {pts[i].x * mm, pts[i].y * mm, pts[i].theta2_rad};
  s.theta0_rad = theta0;
  s.crank_pivot_x_m = d.a0 * mm * std::cos(theta0);
  s.crank_pivot_y_m = d.a0 * mm * std::sin(theta0);
  s.rocker_pivot_x_m = o.a0 * mm * std::cos(theta0);
  s.rocker_pivot_y_m = o.a0 * mm * std::sin(theta0);
  s.crank = side_link(d.a1 * mm);
  s.rocker = side_link(o.a1 * mm);
  // Coupler frame: origin O2_d, x towards O2_o = sign(a2_d − a2_o)·u(θ2); the gripper is a2_d·u(θ2) from
  // O2_d.
  const double sign = d.a2 - o.a2 >= 0.0 ? 1.0 : -1.0;
  const double coupler = std::fabs(d.a2 - o.a2) * mm;
  s.gripper_along_m = sign * d.a2 * mm;
  s.gripper_normal_m = 0.0;
  // The coupler body runs from the gripper to the farther moving pivot; the seed's cg sits 13.337 mm
  // from the gripper towards it.
  const double far = std::fabs(s.gripper_along_m) > std::fabs(s.gripper_along_m - coupler) ? 0.0 : coupler;
  const double cg = s.gripper_along_m + std::copysign(kCouplerCgFromGripper_m, far - s.gripper_along_m);
  s.coupler = {coupler, kCouplerMassKg, cg, kCouplerInertia};
  // The branch the linkage is assembled in at TAKE (the knot cycle checks WRAP and PULL against it).
  const double t2 = pts[0].theta2_rad;
  const double ax = pts[0].x * mm - d.a2 * mm * std::cos(t2), ay = pts[0].y * mm - d.a2 * mm * std::sin(t2);
  const double bx = pts[0].x * mm - o.a2 * mm * std::cos(t2), by = pts[0].y * mm - o.a2 * mm * std::sin(t2);
  s.branch = motion::branch_of(std::atan2(by - ay, bx - ax),
                               std::atan2(by - s.rocker_pivot_y_m, bx - s.rocker_pivot_x_m));
  return s;
}

// The shortest text that reads back as the same double: pasted config lines rebuild exactly this linkage.
std::string g(double v) {
  char b[64];
  const auto r = std::to_chars(b, b + sizeof b, v == 0.0 ? 0.0 : v);  // no "-0"
  return std::string(b, r.ptr);
}

void key(std::ostream& out, const std::string& k, const std::string& v, const std::string& comment) {
  std::string line = k + " = " + v;
  if (line.size() < 40) line.resize(40, ' ');
  out << line << "  # " << comment << "\n";
}

}  // namespace

void run_knotter(const KnotterArgs& args, std::ostream& out, std::ostream& err) {
  if (args.points.size() != 3) {
    throw ArgError("--point: give exactly three precision points TAKE, WRAP, PULL (got " +
                   std::to_string(args.points.size()) + ")");
  }
  if (!std::isfinite(args.theta0_deg))
    throw ArgError("--theta0-deg " + input_value(args.theta0_deg) + ": must be a finite angle in degrees");
  if (!std::isfinite(args.warp_entry_mm))
    throw ArgError("--warp-entry-mm " + input_value(args.warp_entry_mm) + ": must be finite");
  if (!(args.min_transmission_deg >= 0.0 && args.min_transmission_deg < 90.0)) {
    throw ArgError("--min-transmission-deg " + input_value(args.min_transmission_deg) +
                   ": must be in [0, 90)");
  }
  if (args.drive != "auto" && args.drive != "first" && args.drive != "second") {
    throw ArgError("--drive " + args.drive + ": must be auto, first or second");
  }
  std::array<motion::PrecisionPoint, 3> pts{};
  for (int i = 0; i < 3; ++i)
    pts[static_cast<std::size_t>(i)] = parse_precision_point(args.points[static_cast<std::size_t>(i)], i);
  const std::string point_args =
      "--point " + args.points[0] + " --point " + args.points[1] + " --point " + args.points[2];
  const double theta0 = motion::rad(args.theta0_deg);
  motion::ThreePointResult r;
  try {
    r = motion::three_point_synthesis(pts, theta0);
  } catch (const motion::MotionError& e) {
    throw ArgError(point_args + ": " + e.what());
  }
  if (r.solutions.size() != 2) {
    throw ArgError(point_args + " --theta0-deg " + input_value(args.theta0_deg) + ": the synthesis has " +
                   std::to_string(r.solutions.size()) + " real chain(s); the four-bar needs two");
  }

  KnotCycleSpec base = motion::seed001_knot_cycle_spec();
  base.warp_entry_x_m = args.warp_entry_mm * 1e-3;
  base.min_transmission_rad = motion::rad(args.min_transmission_deg);
  auto servo = [](const char* opt, double v, double& field) {
    if (v == 0.0) return;  // keep the default
    if (!std::isfinite(v) || !(v > 0.0))
      throw ArgError(std::string(opt) + " " + input_value(v) + ": must be finite and > 0");
    field = v;
  };
  servo("--max-speed-rad-s", args.max_speed_rad_s, base.max_speed_rad_s);
  servo("--no-load-speed-rad-s", args.no_load_speed_rad_s, base.no_load_speed_rad_s);
  servo("--max-torque-nm", args.max_torque_nm, base.peak_torque_nm);
  base.continuous_torque_nm = std::min(base.continuous_torque_nm, base.peak_torque_nm);

  // Try each chain's side link as the driven one; keep the checked one with the best transmission.
  struct Candidate {
    std::size_t driven;
    std::optional<motion::KnotCycle> cycle;
    std::string refusal;
    motion::KnotCycleField refused_for =
        motion::KnotCycleField::kLinkage;  // the spec fact the refusal is about
  };
  std::vector<Candidate> cands;
  for (std::size_t k = 0; k < 2; ++k) {
    if ((args.drive == "first" && k != 0) || (args.drive == "second" && k != 1)) continue;
    Candidate c{k, std::nullopt, "", motion::KnotCycleField::kLinkage};
    const ThreePointSolution& d = r.solutions[k];
    const ThreePointSolution& o = r.solutions[1 - k];
    if (std::fabs(d.a2 - o.a2) <= 1e-9 * std::max(std::fabs(d.a2), std::fabs(o.a2))) {
      c.refusal = "both chains put the moving pivot at the same place on the gripper link: no coupler";
    } else {
      try {
        c.cycle = motion::KnotCycle::build(linkage_from(pts, theta0, d, o, base));
      } catch (const motion::KnotCycleError& e) {
        c.refusal = e.what();
        c.refused_for = e.field();
      } catch (const motion::MotionError& e) {
        c.refusal = e.what();
      }
    }
    cands.push_back(std::move(c));
  }
  const Candidate* best = nullptr;
  for (const Candidate& c : cands) {
    if (c.cycle && (best == nullptr ||
                    c.cycle->report().min_transmission_rad > best->cycle->report().min_transmission_rad))
      best = &c;
  }
  auto chain_name = [](std::size_t k) { return k == 0 ? "first" : "second"; };
  if (best == nullptr) {
    std::string why;
    for (const Candidate& c : cands)
      why += std::string(why.empty() ? "" : "; ") + "driving the " + chain_name(c.driven) +
             " chain's side link: " + c.refusal;
    // The option to blame is the refused fact's (KnotCycleError::field), never read from the message.
    const auto refused_for = [&](motion::KnotCycleField f) {
      return std::any_of(cands.begin(), cands.end(), [f](const Candidate& c) { return c.refused_for == f; });
    };
    if (refused_for(motion::KnotCycleField::kWarpEntry)) {
      throw ArgError("--warp-entry-mm " + input_value(args.warp_entry_mm) + ": " + why);
    }
    if (refused_for(motion::KnotCycleField::kMaxTorque)) {
      throw ArgError("--max-torque-nm " + input_value(args.max_torque_nm) + ": " + why);
    }
    std::string blamed = point_args + " --theta0-deg " + input_value(args.theta0_deg);
    if (refused_for(motion::KnotCycleField::kMinTransmission)) {
      blamed += " --min-transmission-deg " + input_value(args.min_transmission_deg);
    }
    throw ArgError(blamed + ": no usable knotting linkage: " + why);
  }
  for (const Candidate& c : cands) {
    if (&c != best && !c.cycle)
      err << "loom-synth: note: driving the " << chain_name(c.driven)
          << " chain's side link refused: " << c.refusal << "\n";
  }

  const motion::KnotCycle& kc = *best->cycle;
  const KnotCycleSpec& s = kc.spec();
  const motion::KnotCycleReport& rep = kc.report();
  const ThreePointSolution& d = r.solutions[best->driven];
  const ThreePointSolution& o = r.solutions[1 - best->driven];
  out << "# loom-synth knotter: the knotting four-bar from the two three-point chains\n"
      << "#   driven (crank) chain: a0 = " << g(d.a0) << " mm, a1 = " << g(d.a1) << " mm, a2 = " << g(d.a2)
      << " mm (lambda " << g(d.lambda) << ")\n"
      << "#   other (rocker) chain: a0 = " << g(o.a0) << " mm, a1 = " << g(o.a1) << " mm, a2 = " << g(o.a2)
      << " mm (lambda " << g(o.lambda) << ")\n"
      << "#   Grashof class " << motion::grashof_class_name(rep.grashof) << ": "
      << (rep.full_turn ? "the crank turns on through the turn to return" : "the servo swings back to return")
      << "\n"
      << "#   crank angles TAKE/WRAP/PULL: " << g(motion::deg(rep.crank_angles_rad[0])) << " / "
      << g(motion::deg(rep.crank_angles_rad[1])) << " / " << g(motion::deg(rep.crank_angles_rad[2]))
      << " deg; stroke " << g(motion::deg(rep.stroke_rad)) << " deg\n"
      << "#   min transmission angle in the stroke " << g(motion::deg(rep.min_transmission_rad))
      << " deg at crank " << g(motion::deg(rep.min_transmission_at_rad)) << " deg; closure residual "
      << g(rep.closure_residual_m) << " m\n";
  out << "#   cycle " << g(kc.duration_s())
      << " s, the time-optimal moves under the servo's torque-speed line (" << g(s.no_load_speed_rad_s)
      << " rad/s no-load, " << g(s.peak_torque_nm) << " N m peak, rotor and gears "
      << g(s.rotor_inertia_kg_m2) << " kg m2 at the output"
      << (s.max_speed_rad_s > 0.0 ? ", capped at " + g(s.max_speed_rad_s) + " rad/s" : std::string()) << "):";
  for (const auto& seg : rep.segments)
    out << " " << seg.name << " " << g(seg.end_s - seg.begin_s) << " s ("
        << motion::knot_limit_name(seg.bound) << ")";
  out << "\n#   peak servo torque " << g(rep.peak_torque_nm) << " N m at t = " << g(rep.peak_torque_t_s)
      << " s\n";
  out << "[knotting.linkage]\n";
  static constexpr std::array<const char*, 3> kName{"take", "wrap", "pull"};
  static constexpr std::array<const char*, 3> kWhat{
      "TAKE the yarn at the colour selector", "WRAP it round the warp pair", "PULL it down to the fell"};
  for (std::size_t i = 0; i < 3; ++i) {
    const std::string n(kName[i]);
    key(out, n + "_x_m", g(s.points[i].x_m), std::string(kWhat[i]) + ": gripper x (knot frame)");
    key(out, n + "_y_m", g(s.points[i].y_m), "gripper y");
    key(out, n + "_gripper_deg", g(motion::deg(s.points[i].gripper_rad)), "gripper-link angle there");
  }
  key(out, "theta0_deg", g(args.theta0_deg),
      "the synthesis' fixed-link direction (both ground pivots on it)");
  key(out, "crank_pivot_x_m", g(s.crank_pivot_x_m), "servo shaft (crank ground pivot)");
  key(out, "crank_pivot_y_m", g(s.crank_pivot_y_m), "a0 of the driven chain along theta0");
  key(out, "rocker_pivot_x_m", g(s.rocker_pivot_x_m), "rocker ground pivot");
  key(out, "rocker_pivot_y_m", g(s.rocker_pivot_y_m), "a0 of the other chain along theta0");
  key(out, "crank_m", g(s.crank.length_m), "servo-driven side link");
  key(out, "coupler_m", g(s.coupler.length_m), "between the moving pivots, gripper on its line");
  key(out, "rocker_m", g(s.rocker.length_m), "other side link");
  key(out, "gripper_along_m", g(s.gripper_along_m),
      "gripper in the coupler frame: from the crank joint towards the rocker joint");
  key(out, "gripper_normal_m", g(s.gripper_normal_m), "and 90 deg counter-clockwise of that");
  key(out, "branch",
      std::string("\"") + (s.branch == motion::Branch::kPositive ? "positive" : "negative") + "\"",
      "assembly branch, the same at all three points");
  const std::array<std::pair<const char*, const motion::KnotLinkSpec*>, 3> links{
      {{"crank", &s.crank}, {"coupler", &s.coupler}, {"rocker", &s.rocker}}};
  for (const auto& [n, l] : links) {
    const std::string p(n);
    key(out, p + "_mass_kg", g(l->mass_kg),
        p == "coupler" ? "seed 001's link with holder and gripper" : "Delrin 6 x 5 mm, seed's V rho");
    key(out, p + "_cg_m", g(l->cg_m), "from its first pivot along the link");
    key(out, p + "_inertia_kg_m2", g(l->inertia_kg_m2), "about its cg");
  }
  key(out, "warp_entry_x_m", g(s.warp_entry_x_m), "gripper inside the warp while its x >= this");
}

}  // namespace loom::synth

// loom-profile: what profile accuracy costs, and a recipe's profiles as golden files.
//   loom-profile report --out DIR   accuracy.csv, pareto.svg and summary.md in DIR; defaults printed
//   loom-profile dump --config FILE --out DIR   the recipe's profiles as CSV (tests diff them)
// Bad arguments, unreadable configs and infeasible recipes: one line on stderr, exit 2.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include "accuracy.hpp"
#include "catalogue.hpp"
#include "chart.hpp"
#include "dump.hpp"
#include "loom/cli/numbers.hpp"
#include "loom/config/config.hpp"
#include "loom/motion/angles.hpp"
#include "loom/motion/errors.hpp"
#include "summary.hpp"

namespace {

constexpr int kExitBadInput = 2;

struct ReportArgs {
  std::string out;
  std::vector<std::size_t> sizes;
  double min_time_s = 0.05;
  int repetitions = 3;
  std::size_t check_points = std::size_t{1} << 18;
};

struct DumpArgs {
  std::string config, out;
  std::string crank_law, interp, precision;
  double ellipse_e = -1.0, ellipse_phi02_deg = NAN;
  int ellipse_lobes = 0;
  std::size_t table_size = 0;
};

bool make_dir(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    std::fprintf(stderr, "loom-profile: --out %s: cannot create directory (%s)\n", dir.c_str(),
                 ec.message().c_str());
    return false;
  }
  return true;
}

bool write_text(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  f << text;
  f.close();
  if (!f) {
    std::fprintf(stderr, "loom-profile: %s: cannot write\n", path.c_str());
    return false;
  }
  return true;
}

int run_report(const ReportArgs& a) {
  using namespace loom::profile;
  if (!make_dir(a.out)) return kExitBadInput;
  const Catalogue cat = default_catalogue();
  AccuracyOptions opt;
  opt.sizes = a.sizes;
  opt.check_points = a.check_points;
  opt.timing = {.min_time_s = a.min_time_s, .repetitions = a.repetitions};
  const std::vector<AccuracyRow> rows = measure_accuracy(cat, opt);
  std::string csv = std::string(kAccuracyHeader) + "\n";
  for (const AccuracyRow& r : rows) csv += csv_line(r) + "\n";
  const BuildTimes build = measure_build_times();
  const std::string md = summary_markdown(cat, rows, build);
  if (!write_text(a.out + "/accuracy.csv", csv) ||
      !write_text(a.out + "/pareto.svg", pareto_svg(cat, rows)) || !write_text(a.out + "/summary.md", md)) {
    return kExitBadInput;
  }
  std::printf("loom-profile: %zu rows in %s/accuracy.csv, chart %s/pareto.svg, summary %s/summary.md\n",
              rows.size(), a.out.c_str(), a.out.c_str(), a.out.c_str());
  std::printf("default choice per profile:\n");
  for (const ReportProfile& p : cat.profiles) {
    const Choice c = choose_default(p, rows);
    std::printf("  %-15s %s (%s)\n", p.name.c_str(), c.row ? choice_label(*c.row).c_str() : "none",
                c.why.c_str());
  }
  std::printf("\n%s", md.c_str());
  return 0;
}

// Options given on the command line replace the config's profile settings (tables, crank law).
bool apply_overrides(const DumpArgs& a, loom::motion::ProfileSpec& s) {
  using namespace loom::motion;
  if (!a.crank_law.empty()) parse_crank_law(a.crank_law.c_str(), s.crank_law.kind);
  if (!a.interp.empty()) parse_interp(a.interp.c_str(), s.table_interp);
  if (!a.precision.empty()) parse_precision(a.precision.c_str(), s.table_precision);
  if (a.ellipse_e >= 0.0) s.crank_law.ellipse_e = a.ellipse_e;
  if (a.ellipse_lobes > 0) s.crank_law.ellipse_lobes = a.ellipse_lobes;
  if (std::isfinite(a.ellipse_phi02_deg)) s.crank_law.ellipse_phi02_rad = rad(a.ellipse_phi02_deg);
  if (a.table_size > 0) s.table_size = a.table_size;
  return true;
}

int run_dump(const DumpArgs& a) {
  loom::firmware::LoomConfig cfg;
  try {
    cfg = loom::firmware::load_loom_config(a.config);
  } catch (const loom::firmware::ConfigError& e) {
    std::fprintf(stderr, "loom-profile: %s\n", e.what());
    return kExitBadInput;
  }
  apply_overrides(a, cfg.profile);
  try {
    const loom::motion::ProfileSet set(cfg.profile);
    if (!make_dir(a.out)) return kExitBadInput;
    loom::profile::write_dump(set, cfg.sequencer.period_s, a.out);
  } catch (const loom::motion::MotionError& e) {
    std::fprintf(stderr, "loom-profile: %s: motion profiles cannot be built: %s\n", a.config.c_str(),
                 e.what());
    return kExitBadInput;
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "loom-profile: %s\n", e.what());
    return kExitBadInput;
  }
  std::printf("loom-profile: dumped %s to %s\n", a.config.c_str(), a.out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "loom-profile: profile-table accuracy against lookup time, and golden dumps of a recipe's profiles"};
  app.require_subcommand(1);

  ReportArgs rep;
  CLI::App* report = app.add_subcommand("report", "Measure every profile table against the exact kinematics");
  report->add_option("--out", rep.out, "Output directory (created)")->required();
  report->add_option("--sizes", rep.sizes, "Table sizes (default 64 128 ... 65536)")
      ->check(CLI::Range(4, 1 << 24));
  report->add_option("--min-time", rep.min_time_s, "Google Benchmark minimum time per repetition, s")
      ->check(loom::cli::finite_range(1e-4, 10.0))
      ->capture_default_str();
  report->add_option("--repetitions", rep.repetitions, "Benchmark repetitions (the fastest counts)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  report->add_option("--check-points", rep.check_points, "Phases at which errors are measured")
      ->check(CLI::Range(16, 1 << 24))
      ->capture_default_str();

  DumpArgs dump;
  CLI::App* dump_cmd = app.add_subcommand("dump", "Write a recipe's profiles as CSV (golden files)");
  dump_cmd->add_option("--config", dump.config, "Loom config (TOML), e.g. firmware/config/default_loom.toml")
      ->required();
  dump_cmd->add_option("--out", dump.out, "Output directory (created)")->required();
  dump_cmd->add_option("--crank-law", dump.crank_law, "Override: crank speed law")
      ->check(CLI::IsMember({"constant", "elliptic"}));
  dump_cmd->add_option("--ellipse-e", dump.ellipse_e, "Override: eccentricity of the elliptic law, [0, 1)")
      ->check(loom::cli::finite_range(0.0, 0.999999));
  dump_cmd->add_option("--ellipse-lobes", dump.ellipse_lobes, "Override: lobes of the elliptic pitch curves")
      ->check(CLI::Range(1, 16));
  dump_cmd
      ->add_option("--ellipse-phi02-deg", dump.ellipse_phi02_deg,
                   "Override: driven-pinion angle at the fell, deg")
      ->check(loom::cli::finite_range(-360.0, 360.0));
  dump_cmd->add_option("--table-size", dump.table_size, "Override: knots per turn")
      ->check(CLI::Range(4, 1 << 24));
  dump_cmd->add_option("--interp", dump.interp, "Override: interpolation")
      ->check(CLI::IsMember({"linear", "cubic", "quintic"}));
  dump_cmd->add_option("--precision", dump.precision, "Override: knot precision")
      ->check(CLI::IsMember({"double", "float32"}));

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : kExitBadInput;
  }
  if (report->parsed()) return run_report(rep);
  return run_dump(dump);
}

// loom-kin: kinematics of any four-bar or offset slider-crank, the tufting-needle six-bar (002) and
// the elliptic-gear batten drive (004) over one turn, as CSV on stdout. Bad arguments and impossible
// designs are reported on stderr, naming the argument, with exit status 2; --help exits 0.
#include <CLI/CLI.hpp>

#include "batten_cmd.hpp"
#include "fourbar_cmd.hpp"
#include "loom/cli/run.hpp"
#include "needle_cmd.hpp"
#include "slider_crank_cmd.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "loom-kin: four-bar, slider-crank, needle six-bar (002) and elliptic-gear batten drive (004) "
      "kinematics as CSV"};
  app.require_subcommand(1);
  loom::kin::FourBarArgs fourbar;
  loom::kin::SliderCrankArgs slider;
  loom::kin::NeedleArgs needle;
  loom::kin::BattenArgs batten;
  loom::kin::BattenArgs phase;
  phase.samples = 720;  // turning points are refined by bisection, so a coarse sweep suffices
  CLI::App* fourbar_cmd = loom::kin::add_fourbar_command(app, fourbar);
  CLI::App* slider_cmd = loom::kin::add_slider_crank_command(app, slider);
  CLI::App* needle_cmd = loom::kin::add_needle_command(app, needle);
  CLI::App* batten_cmd = loom::kin::add_batten_command(app, batten);
  CLI::App* phase_cmd = loom::kin::add_batten_phase_command(app, phase);
  return loom::cli::run_cli("loom-kin", app, argc, argv, [&] {
    if (fourbar_cmd->parsed()) loom::kin::run_fourbar(fourbar);
    if (slider_cmd->parsed()) loom::kin::run_slider_crank(slider);
    if (needle_cmd->parsed()) loom::kin::run_needle(needle);
    if (batten_cmd->parsed()) loom::kin::run_batten(batten);
    if (phase_cmd->parsed()) loom::kin::run_batten_phase(phase);
  });
}

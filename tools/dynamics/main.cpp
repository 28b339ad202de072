// loom-dynamics: dynamics and balancing of the loom's linkages as CSV on stdout (SI units, header
// first) with optional SVG plots. Bad arguments and impossible designs are reported on stderr naming
// the argument or quantity, with exit status 2; --help exits 0.
#include <CLI/CLI.hpp>

#include "commands.hpp"

int main(int argc, char** argv) {
  using namespace loom::dyncli;
  CLI::App app{
      "loom-dynamics: beat-up forces and crank speed, needle reactions (002), batten gain (004), "
      "shaking balance (003), link mass properties, equimomental point masses (003)"};
  app.require_subcommand(1);
  BeatupArgs beatup;
  NeedleArgs needle;
  BattenArgs batten;
  BalanceArgs balance;
  CLI::App* beatup_cmd = add_beatup(app, beatup);
  CLI::App* needle_cmd = add_needle(app, needle);
  CLI::App* batten_cmd = add_batten(app, batten);
  CLI::App* balance_cmd = add_balance(app, balance);
  CLI::App* mass_cmd = add_mass(app);
  EquimomentalArgs equimomental;
  CLI::App* equimomental_cmd = add_equimomental(app, equimomental);
  return loom::cli::run_cli("loom-dynamics", app, argc, argv, [&] {
    if (beatup_cmd->parsed()) run_beatup(*beatup_cmd, beatup);
    if (needle_cmd->parsed()) run_needle(needle);
    if (batten_cmd->parsed()) run_batten(*batten_cmd, batten);
    if (balance_cmd->parsed()) run_balance(*balance_cmd, balance);
    if (mass_cmd->parsed()) run_mass();
    if (equimomental_cmd->parsed()) run_equimomental(*equimomental_cmd, equimomental);
  });
}

// loom-synth as a loom builder runs it: CSV headers and rows, the thesis' tables, the 12 cm / 169°
// round trip to Table 4.3, and bad input → stderr naming the argument, exit code 2.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "table_rows.hpp"
#include "thesis_tables.hpp"

namespace {

struct CliRun {
  int exit_code = -1;
  std::string out;
  std::string err;
};

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

#ifndef LOOM_SYNTH_EXE
#error "LOOM_SYNTH_EXE must name the loom-synth executable under test"
#endif

CliRun run(const std::string& args) {
  // One pair of files per test and process: ctest runs these tests in parallel.
  const std::string stem = ::testing::TempDir() + "/loom_synth_" +
                           ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" +
                           std::to_string(::getpid());
  const std::string out = stem + ".out", err = stem + ".err";
  const std::string cmd = std::string("'") + LOOM_SYNTH_EXE + "' " + args + " >'" + out + "' 2>'" + err + "'";
  const int status = std::system(cmd.c_str());
  CliRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  std::remove(out.c_str());
  std::remove(err.c_str());
  return r;
}

std::vector<std::vector<std::string>> csv(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    std::vector<std::string> cells;
    std::istringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

class LoomSynthCli : public ::testing::Test {
 protected:
  void SetUp() override {
#ifndef LOOM_SYNTH_EXE
    GTEST_SKIP() << "loom-synth not built";
#endif
  }
};

TEST_F(LoomSynthCli, SliderCrankTableIsTable42) {
  const CliRun r = run("slider-crank --phi-range 90:179");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = csv(r.out);
  ASSERT_EQ(rows.size(), 91u);
  EXPECT_EQ(r.out.substr(0, r.out.find('\n')), "phi_deg,a,b,c,mu_min_deg,lambda");
  const auto printed = loom::test::table_rows(loom::test::kTable42);
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const auto& p = printed[i - 1];
    EXPECT_EQ(rows[i], (std::vector<std::string>{p[0], p[1], p[2], p[3], p[4], p[6]}));
  }
  EXPECT_NE(r.err.find("phi_deg=90"), std::string::npos);  // the change-point row is noted
}

TEST_F(LoomSynthCli, SliderCrankOneDesignWithStrokeAndLambda) {
  const CliRun r = run("slider-crank --phi 169 --stroke 12");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "phi_deg,a,b,c,mu_min_deg,lambda\n169,5.745801,18.921801,5.168067,54.78,0.3037\n");
  const CliRun given = run("slider-crank --phi 169 --lambda 0.3");
  ASSERT_EQ(given.exit_code, 0) << given.err;
  EXPECT_NE(given.out.find("\n169,"), std::string::npos);
  EXPECT_NE(given.out.find(",0.3000\n"), std::string::npos);
}

TEST_F(LoomSynthCli, DesignRoundTripGivesTable43Lengths) {
  const CliRun r = run("design --stroke 12 --phi 169");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = csv(r.out);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0][0], "mechanism");
  EXPECT_EQ(rows[1][0], "slider-crank");
  EXPECT_EQ(rows[1][8], "crank-slider");
  const auto& col = loom::test::kTable43[0];  // λ = 0.3, φ = 169°
  EXPECT_NEAR(std::stod(rows[1][3]), std::stod(col.a_cm), 6e-6);
  EXPECT_NEAR(std::stod(rows[1][4]), std::stod(col.b_cm), 6e-6);
  EXPECT_NEAR(std::stod(rows[1][5]), std::stod(col.c_cm), 6e-6);
  EXPECT_EQ(rows[1][7], col.mu_min_deg);
  // The thesis' own rounding procedure gives the printed digits exactly.
  const CliRun t = run("design --stroke 12 --phi 169 --thesis-rounding");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  const auto trow = csv(t.out)[1];
  EXPECT_EQ(trow[3], col.a_cm);
  EXPECT_EQ(trow[4], col.b_cm);
  EXPECT_EQ(trow[5], col.c_cm);
}

TEST_F(LoomSynthCli, CrankRockerTableIsTable48) {
  const CliRun r = run("crank-rocker --psi 30 --phi 180");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = csv(r.out);
  ASSERT_EQ(rows.size(), 77u);
  EXPECT_EQ(r.out.substr(0, r.out.find('\n')), "beta_deg,a,b,c,mu_min_deg");
  const auto printed = loom::test::table_rows(loom::test::kTable48);
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const auto& p = printed[i - 1];
    EXPECT_EQ(rows[i][0], p[0]);
    for (int k = 1; k <= 3; ++k) EXPECT_TRUE(loom::test::same_at_decimals(std::stod(rows[i][static_cast<std::size_t>(k)]), p[static_cast<std::size_t>(k)], 6)) << rows[i][0];
  }
  EXPECT_EQ(rows.back(), (std::vector<std::string>{"0", "0.000000", "1.000000", "0.000000", "0.00"}));
  EXPECT_NE(r.err.find("beta_deg=0"), std::string::npos);
  EXPECT_NE(r.err.find("beta_deg=75"), std::string::npos);
}

TEST_F(LoomSynthCli, CrankRockerRowsRunFromUpperToLowerBound) {
  const CliRun r = run("crank-rocker --psi 30 --phi 120");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = csv(r.out);
  ASSERT_EQ(rows.size(), 17u);  // β = 75 … 60
  EXPECT_EQ(rows[1][0], "75");
  EXPECT_EQ(rows.back()[0], "60");
  EXPECT_EQ(rows[1][4], "0.00");
  EXPECT_EQ(rows.back()[4], "0.00");
  const CliRun one = run("crank-rocker --psi 30 --phi 180 --beta 48 --ground 10");
  ASSERT_EQ(one.exit_code, 0) << one.err;
  EXPECT_EQ(one.out, "beta_deg,a,b,c,mu_min_deg\n48,1.991251,6.691306,7.693601,67.24\n");
  const CliRun special = run("crank-rocker --psi 30 --phi 210");
  ASSERT_EQ(special.exit_code, 0) << special.err;
  EXPECT_EQ(csv(special.out).size(), 2u);
}

TEST_F(LoomSynthCli, DesignCrankRockerFromSwing) {
  const CliRun r = run("design --swing 30 --phi 160 --ground 0.213");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = csv(r.out);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1][0], "crank-rocker");
  EXPECT_EQ(rows[1][10], "crank-rocker");
  EXPECT_EQ(rows[1][7], "0.213000");
  const CliRun ratio = run("design --swing 30 --phi 180 --lambda 0.3");
  ASSERT_EQ(ratio.exit_code, 0) << ratio.err;
  EXPECT_EQ(csv(ratio.out)[1][8], "0.3000");
  const CliRun none = run("design --swing 30 --phi 180");
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_NE(none.err.find("--phi 180"), std::string::npos) << none.err;
}

TEST_F(LoomSynthCli, BadInputNamesTheArgumentAndExits2) {
  struct Case {
    const char* args;
    const char* names;
  };
  const Case cases[] = {
      {"crank-rocker --psi 30 --phi 120 --beta 80", "--beta 80"},
      {"crank-rocker --psi 30 --phi 100", "--phi 100"},
      {"crank-rocker --psi 0 --phi 180", "--psi 0"},
      {"crank-rocker --psi 30", "--phi"},
      {"crank-rocker --psi 30 --phi 180 --ground -1", "--ground"},
      {"slider-crank --phi 180", "--phi 180"},
      {"slider-crank --phi-range 90:180", "--phi 180"},
      {"slider-crank --phi-range 90:x", "--phi-range"},
      {"slider-crank --phi abc", "--phi"},
      {"slider-crank", "--phi"},
      {"slider-crank --phi 169 --lambda 2", "--lambda 2"},
      {"slider-crank --phi 169 --stroke 0", "--stroke"},
      {"design --phi 169", "--stroke"},
      {"design --stroke 12 --swing 30 --phi 169", "--stroke"},
      {"frobnicate", "subcommand"},
  };
  for (const Case& c : cases) {
    const CliRun r = run(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args;
    EXPECT_NE(r.err.find(c.names), std::string::npos) << c.args << " → " << r.err;
    EXPECT_TRUE(r.out.empty()) << c.args << " printed " << r.out;
  }
  EXPECT_EQ(run("--help").exit_code, 0);
}

}  // namespace

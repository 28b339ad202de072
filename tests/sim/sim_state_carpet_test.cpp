// The simulated knotter's carpet in the sim-state file: sized at arm time to the run's carpet (no row cap),
// kept across a restart and grown when the next run weaves further, a refusal (file untouched) when the
// disk will not give the room, and a file that is not ours refused without being touched.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "loom/sim_hal/knotter.hpp"
#include "loom/sim_hal/sim_state_file.hpp"

namespace {
using loom::sim_hal::Knotter;
using loom::sim_hal::PersistedMachine;
using loom::sim_hal::SimKnotter;
using loom::sim_hal::SimKnotting;
using loom::sim_hal::SimStateFile;

// As the simulated machine does every tick: the machine's state stored (a file without it is not reopened).
void store_machine(SimStateFile& file) {
  PersistedMachine pm;
  pm.magic = PersistedMachine::kMagic;
  file.store(pm);
}

SimKnotting heads(int knots_per_row, std::uint32_t last_row) {
  SimKnotting m;
  m.heads = 6;
  m.knots_per_row = knots_per_row;
  m.stripe = knots_per_row / 6;
  m.slots = 3;
  m.knots_per_slot = 150;
  m.pitch_m = 1.0 / 300.0;
  m.last_row = last_row;
  m.design_rows = 540;
  return m;
}

class SimStateCarpet : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = (std::filesystem::temp_directory_path() /
             ("loom_carpet_" + std::to_string(::getpid()) + "_" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".bin"))
                .string();
    std::filesystem::remove(path_);
  }
  void TearDown() override { std::filesystem::remove(path_); }
  std::string path_;
};

TEST_F(SimStateCarpet, HoldsTheWholeCarpetAndGrowsWithTheNextRun) {
  std::uintmax_t first_size = 0;
  {
    SimStateFile file(path_);
    SimKnotter k(heads(360, 540), Knotter{}, 0.002);
    k.persist_in(*file.carpet(), 0);
    store_machine(file);
    EXPECT_EQ(k.capacity_rows(), 540);  // 360 x 540 = 194,400 knots, no cap
    EXPECT_GE(file.room(), 194'400u);
    EXPECT_EQ(k.first_row(), 0u);
    first_size = std::filesystem::file_size(path_);
    EXPECT_GE(first_size, 194'400u);
  }
  {
    // The next run (after a cut, its counters at row 12) weaves on to row 1000: the carpet is adopted (it
    // still begins at production row 0) and its record grows; nothing is cut short.
    SimStateFile file(path_);
    SimKnotter k(heads(360, 1000), Knotter{}, 0.002);
    k.persist_in(*file.carpet(), 12);
    EXPECT_EQ(k.first_row(), 0u);
    EXPECT_EQ(k.capacity_rows(), 1000);
    EXPECT_EQ(std::filesystem::file_size(path_), first_size + 460u * 360u);
  }
  {
    // Another loom's width: a fresh carpet from the counters' row, in the room the file has.
    SimStateFile file(path_);
    SimKnotter k(heads(90, 20), Knotter{}, 0.002);
    k.persist_in(*file.carpet(), 7);
    EXPECT_EQ(k.first_row(), 7u);
    EXPECT_EQ(k.capacity_rows(), 13);
    EXPECT_EQ(k.rows(), 0);
  }
}

TEST_F(SimStateCarpet, SceneOverrideAndRunWithoutEnd) {
  SimStateFile file(path_);
  Knotter short_record;
  short_record.carpet_rows = 5;
  SimKnotter k(heads(360, 540), short_record, 0.002);
  k.persist_in(*file.carpet(), 0);
  EXPECT_EQ(k.capacity_rows(), 5);
  SimKnotter endless(heads(360, 0), Knotter{}, 0.002);  // serve without --rows: a pass of the design
  endless.start_at_row(3);
  EXPECT_EQ(endless.capacity_rows(), 540);
  EXPECT_EQ(endless.first_row(), 3u);
}

TEST_F(SimStateCarpet, NoRoomOnTheDiskIsARefusalAndTheFileIsKept) {
  {
    SimStateFile file(path_);
    store_machine(file);
  }  // a machine without heads: the file ends after the carpet's header
  const std::uintmax_t before = std::filesystem::file_size(path_);
  // The disk's limit as a file-size limit (SIGXFSZ ignored: the call fails with EFBIG instead).
  struct sigaction ignore {
  }, old{};
  ignore.sa_handler = SIG_IGN;
  ::sigaction(SIGXFSZ, &ignore, &old);
  rlimit was{};
  ::getrlimit(RLIMIT_FSIZE, &was);
  rlimit small = was;
  small.rlim_cur = 64 * 1024;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string what;
  {
    SimStateFile file(path_);
    SimKnotter k(heads(360, 540), Knotter{}, 0.002);
    try {
      k.persist_in(*file.carpet(), 0);
    } catch (const std::runtime_error& e) {
      what = e.what();
    }
  }
  ::setrlimit(RLIMIT_FSIZE, &was);
  ::sigaction(SIGXFSZ, &old, nullptr);
  EXPECT_NE(what.find("cannot allocate sim state file " + path_ + " for a carpet of 194400 knots"),
            std::string::npos)
      << what;
  EXPECT_EQ(std::filesystem::file_size(path_), before);
  EXPECT_NO_THROW(SimStateFile again(path_));  // still a sim-state file
}

TEST_F(SimStateCarpet, AFileNotOursIsRefusedUntouched) {
  {
    std::ofstream f(path_, std::ios::binary);
    f << std::string(100, 'x');
  }
  EXPECT_THROW(SimStateFile file(path_), std::invalid_argument);
  EXPECT_EQ(std::filesystem::file_size(path_), 100u);
}

}  // namespace

// A power cut at every tick of a pick, restarted from the machine's persisted state (sim-state file)
// and the counters the disk holds: the cut pick is finished, never repeated and never mistaken for a
// slipped shuttle (the docs promise "a cut pick is finished on restart"). The issue found 23 of 3,482
// swept ticks — the first and last few of a pick — restarting into a false shuttle_slipped.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/firmware/machine.hpp"

using namespace loom;
using sequencer::Fault;
using sequencer::State;

namespace {

std::string state_file() {
  const auto p = std::filesystem::temp_directory_path() / ("loom-pick-cut-" + std::to_string(::getpid()));
  std::filesystem::remove(p);
  return p.string();
}

struct Cut {
  sequencer::Counters counters{};
  Fault fault = Fault::kNone;
};

// Weaves from `resume` on the machine in `path` until `rows` rows are done or `cut_at` ticks have run
// (the cut: the process is gone, the machine stays where it physically was).
Cut weave(const firmware::LoomConfig& cfg, const firmware::Scene& scene, const std::string& path,
          sequencer::Counters resume, std::uint32_t rows, hal::Tick cut_at,
          std::vector<hal::Tick>* pick_ticks) {
  firmware::MachineOptions opt;
  opt.telemetry = false;
  opt.rows = rows;
  opt.sim_state_path = path;
  firmware::Machine m(cfg, scene, opt, resume);
  m.sequencer().request_start();
  for (hal::Tick t = 0; t < 200000 && !m.sequencer().finished() && t != cut_at; ++t) {
    m.loop().cycle(t);
    if (pick_ticks != nullptr && m.sequencer().state() == State::kPick) pick_ticks->push_back(t + 1);
  }
  return {m.sequencer().counters(), m.sequencer().first_fault()};
}

}  // namespace

TEST(PickPowerCut, EveryTickOfAPickRestartsIntoTheSamePickFinished) {
  const auto cfg = firmware::default_loom_config();
  const firmware::Scene scene = firmware::default_scene();
  const std::string path = state_file();
  constexpr std::uint32_t kRows = 2;  // two picks: one each way
  std::vector<hal::Tick> pick_ticks;
  const Cut whole = weave(cfg, scene, path, {}, kRows, -1, &pick_ticks);
  ASSERT_EQ(whole.fault, Fault::kNone) << sequencer::fault_name(whole.fault);
  ASSERT_EQ(whole.counters.rows, kRows);
  const std::uint32_t picks = whole.counters.picks;
  ASSERT_GT(pick_ticks.size(), 20u);
  // Cut one tick before the first pick tick through one after the last of each pick.
  std::vector<hal::Tick> cuts;
  for (std::size_t i = 0; i < pick_ticks.size(); ++i) {
    if (i == 0 || pick_ticks[i - 1] != pick_ticks[i] - 1) cuts.push_back(pick_ticks[i] - 1);
    cuts.push_back(pick_ticks[i]);
    if (i + 1 == pick_ticks.size() || pick_ticks[i + 1] != pick_ticks[i] + 1)
      cuts.push_back(pick_ticks[i] + 1);
  }
  int false_faults = 0;
  for (const hal::Tick cut_at : cuts) {
    std::filesystem::remove(path);
    const Cut cut = weave(cfg, scene, path, {}, kRows, cut_at, nullptr);
    ASSERT_EQ(cut.fault, Fault::kNone) << "tick " << cut_at;
    // The disk holds what the reporter saved: every finished pick and row (the lost-count case, a count
    // that never reached the disk, is APickWhoseCountWasLostIsRecognisedFromTheMachine).
    const Cut after = weave(cfg, scene, path, cut.counters, kRows, -1, nullptr);
    if (after.fault != Fault::kNone || after.counters.rows != kRows || after.counters.picks != picks) {
      ++false_faults;
      ADD_FAILURE() << "power cut at tick " << cut_at << " (counters rows " << cut.counters.rows << ", picks "
                    << cut.counters.picks << "): restart ended with " << sequencer::fault_name(after.fault)
                    << ", rows " << after.counters.rows << ", picks " << after.counters.picks;
    }
  }
  std::printf("power cuts at %zu ticks in and around %u picks: %d restarts wrong\n", cuts.size(), picks,
              false_faults);
  std::filesystem::remove(path);
}

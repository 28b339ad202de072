// The safety property campaign behind loom-safety: random scenes (effects, parameters, seeds) with
// random faults — every kind a scene can inject, alone and in the combinations that have hurt before
// (shuttle slip with a stuck arrival sensor, stuck end sensors) — each woven on the firmware's own
// machine assembly while the simulated machine's TRUE state (not what the controller believes) is
// checked every tick:
//   - the carriage never moves while the beater is in the warp;
//   - the helix shaft (a pick) never moves unless the shed is truly open (both frames at their ends);
//   - no heald frame moves while the shuttle is in the shed;
//   - once a fault is latched no axis moves any more;
// and on a loom with knotting heads (the scene then simulates them: misses, jammed selectors, empty slots,
// a weaver who answers):
//   - the carriage, the beater's crank and the heald frames never move while a gripper is in the warp;
//   - no knotting servo leaves its rest while the beater is in the warp;
//   - no selector turns while its gripper holds yarn;
//   - no knot is tied twice, and every row the counters call woven has every knot tied (none skipped);
// and, with stopping commands drawn at random ticks (stop, pause, exit, stop now — as the service and weave
// apply them, through the operator policy):
//   - once the loom stands after one (paused, done, faulted, idle, waiting for the weaver), nothing it
//     commands starts moving until a starting command (the weaver's pedal) comes (hal/motion_outputs.hpp).
// "Moves" means more than 1 µm (or µrad) in a tick: a servo's settling tail is not motion that can
// catch a warp thread. Each run is deterministic for (campaign seed, run index), whatever the threads.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "loom/config/config.hpp"

namespace loom::safety {

struct RunOutcome {
  bool violated = false;
  std::string what;  // the violation, with its tick
  bool faulted = false;
  bool completed = false;
  bool power_cut = false;
  std::string first_fault;
  std::string fault_sensor;  // the safety sensor the first fault names (sensor_discrepancy), or ""
};

// The scene of run `run` of the campaign seeded `seed`, and a one-line description of it. Faults go
// into every switch the machine has: the six safety sensors' first channels, and their second channels
// where `second_channel` says the machine has one.
// `heads` and `slots`: the loom's knotting heads and their magazine slots (0 without heads): the scene then
// simulates them and draws their faults too. `axis_jams`: a jammed core axis (a seized gearbox, a blocked
// rail: its drive stops following without reporting it) is one more fault kind drawn; without it the draws
// are those the campaign had before that kind existed.
sim_hal::SceneSpec random_scene(std::uint64_t seed, std::uint64_t run,
                                const std::array<bool, hal::kSafetySensorCount>& second_channel, int heads,
                                int slots, std::string& description, bool axis_jams = false);

// A stopping command an operator gives at a tick: stop (weave's SIGTERM or the service's ctl/panel stop),
// pause, exit (the service's SIGTERM), or stop now (a second SIGTERM).
struct StoppingAct {
  enum class Kind : std::uint8_t { kStop, kPause, kExit, kStopNow };
  hal::Tick at = 0;
  Kind kind = Kind::kStop;
  bool held_session = false;  // as the service gives it (else as weave does)
};
const char* stopping_act_name(StoppingAct::Kind k);

// The stopping commands of run `run` (none, one or two, at random ticks within the run's usual length),
// appended to `description`.
std::vector<StoppingAct> random_stopping_acts(std::uint64_t seed, std::uint64_t run, int heads,
                                              std::string& description);

// Weave `rows` rows of `scene` on `cfg`, giving `acts` at their ticks, and check the true state every tick.
RunOutcome run_one(const firmware::LoomConfig& cfg, const sim_hal::SceneSpec& scene, std::uint32_t rows,
                   const std::vector<StoppingAct>& acts = {});

struct Violation {
  std::uint64_t run = 0;
  std::string description, what, scene_toml;
};

struct CampaignOptions {
  std::uint64_t runs = 2000;
  std::uint64_t seed = 1;
  int threads = 1;
  std::uint32_t rows = 2;
  std::string config_path;  // the loom description the runs weave on ("" = the embedded default loom)
  bool axis_jams = false;   // draw jammed core axes too (random_scene)
  const std::atomic<bool>* stop = nullptr;  // set asynchronously: finish the runs in progress and return
  // Called (serialised) after each run with the totals so far and the run's violation, if any.
  std::function<void(const struct CampaignResult&, const struct Violation*)> on_run;
};

struct CampaignResult {
  std::uint64_t runs = 0, faulted = 0, completed = 0, power_cuts = 0;
  std::vector<Violation> violations;  // in run order
};

CampaignResult run_campaign(const CampaignOptions& opt);

}  // namespace loom::safety

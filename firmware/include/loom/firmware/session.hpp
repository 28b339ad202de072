// One session of the loom — build, arm, run, report — as every command that runs the machine runs it.
// `loomctl weave`, `loomctl serve` and `loomctl commission` differ in policy only (where messages go,
// whether counters are kept, what ends a run, whether anything may move); the steps, their checks and
// the exit codes their failures map to live here, once:
//   build   the machine (Machine) from a resolved config and scene: bad input is kExitBadInput, hardware
//           that cannot be brought up kExitNotArmed; the simulated-I/O banner is said on every build;
//   arm     the process made ready for real time when the HAL is real (prepare_realtime); the production
//           record — counters and design book — read, checked against the recipe, proven writable;
//   run     the fixed-rate loop with the options every command shares, derived from the config and the
//           HAL (run_options, run); or, while nothing may move, ticks on the caller's thread (tick);
//   report  the run's line said; the latched fault as one FaultReport for the log, the run report and
//           the fault history.
// Everything here is configure-time or the reporter's thread: the loop itself is the runner's.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "loom/config/config.hpp"
#include "loom/firmware/carpet_job.hpp"
#include "loom/firmware/machine.hpp"
#include "loom/firmware/runner.hpp"
#include "loom/firmware/severity.hpp"
#include "loom/state/counter_store.hpp"
#include "loom/state/design_book.hpp"

namespace loom::firmware {

// loomctl's exit codes, the same for every command.
inline constexpr int kExitOk = 0;        // done (rows woven, calibration written, service stopped)
inline constexpr int kExitBadInput = 2;  // config, scene, state file or command line refused; nothing started
inline constexpr int kExitFault = 3;     // the run ended in a fault (counters kept)
inline constexpr int kExitNotArmed = 4;  // the hardware or the real-time setup could not be armed

// A session step refused: the exit code its cause maps to, and why (input errors name file:line, field
// and value, as the config reader wrote them).
class SessionError : public std::runtime_error {
 public:
  SessionError(int exit_code, const std::string& why) : std::runtime_error(why), exit_code_(exit_code) {}
  int exit_code() const { return exit_code_; }

 private:
  int exit_code_;
};

// Where a session's messages go: one line per call, never from the loop's thread.
using Say = std::function<void(Severity, const std::string&)>;
// A console command's voice: errors to stderr as "WHO: text", warnings as "WHO: WARNING: text", the
// rest to stdout as it is.
Say console_say(std::string who);

// Runs a command: a SessionError or ConfigError out of `body` is said (an error) and becomes the
// command's exit code; otherwise `body`'s own exit code.
template <class Body>
int exit_code_of(const Say& say, Body&& body) {
  try {
    return body();
  } catch (const SessionError& e) {
    say(Severity::kErr, e.what());
    return e.exit_code();
  } catch (const ConfigError& e) {
    say(Severity::kErr, e.what());
    return kExitBadInput;
  }
}

// What the command line chose of the hardware and the timing.
struct SessionOptions {
  HalKind hal = HalKind::kSim;
  std::string iface;            // SocketCAN interface(s), "can0" or "can0,can1": kSocketCan only
  std::optional<IoKind> io;     // --io: overrides the config's io.kind
  bool realtime = false;        // pace at the tick rate (always on hardware)
  double pace = 1.0;            // simulation in real time: this many times faster (1 on hardware)
  int rt_priority = 80;         // SCHED_FIFO priority of the loop thread
  int cpu = -1;                 // pin the loop thread to this CPU; -1 = any
  bool allow_degraded = false;  // hardware without mlockall/SCHED_FIFO: said, never silent
  std::optional<std::uint32_t> overrun_stop;  // unset: timing.overrun_stop_after on hardware, never in sim

  bool hardware() const { return hal == HalKind::kSocketCan; }
  bool paced() const { return hardware() || realtime; }
  // The command line's words. ConfigError when they contradict each other: an interface without the
  // SocketCAN HAL (the simulated loom would run), the SocketCAN HAL without an interface, a pace on
  // hardware, an unknown HAL or I/O kind.
  static SessionOptions from_command_line(const std::string& hal, const std::string& iface,
                                          const std::string& io, double pace = 1.0);
};

// Process-wide, before the first session on hardware (nothing to do in simulation): memory locked and
// SCHED_FIFO probed for the loop thread, which alone runs at real-time priority. SessionError
// (kExitNotArmed) when that fails, unless allow_degraded — then a warning says timing is not guaranteed.
void prepare_realtime(const SessionOptions& opt, const Say& say);

// The production record a session keeps: the counters file and, when the recipe names a design, the
// design book beside it (designs.json); and the loop's side of the row-boundary handshake, so no row
// starts before the one before it is on disk. Non-RT: arming and the reporter's thread.
class ProductionRecord {
 public:
  // `counters_path` "": nothing is kept (a weave without --counters).
  ProductionRecord(std::string counters_path, const LoomConfig& cfg);

  bool kept() const { return store_ != nullptr; }
  const std::string& counters_path() const { return path_; }
  // The counters to resume from: zero without a file, or with one that does not exist yet. ConfigError
  // for a file that cannot be read or is not this loom's (picks_in_row beyond the recipe's picks).
  sequencer::Counters load() const;
  // Arming a loom that must count: the counters written once before anything moves. ConfigError when
  // the file cannot be written ("refusing to arm").
  void prove_writable(const sequencer::Counters& c) const;
  // The carpet job queue of a state directory: while it has a job to weave, the job's progress replaces
  // the design book's (the design is the job's) and every row saved is credited to the job.
  void weave_jobs(std::unique_ptr<CarpetJob> jobs) { jobs_ = std::move(jobs); }
  CarpetJob* jobs() const { return jobs_ && jobs_->in_use() ? jobs_.get() : nullptr; }
  CarpetJob* job_queue() const { return jobs_.get(); }  // also when it has nothing to weave
  // The carpet's last row was saved (the job is carpet_done): true once, then false.
  bool take_carpet_done() { return std::exchange(carpet_done_, false); }
  // The magazines' levels (magazines.txt beside the counters, loom::job::YarnStock), for a loom with
  // knotting heads that keeps its counters: read at arming, written at every row's end, so a restart starts
  // from the levels before it instead of full magazines.
  void keep_magazines(const LoomConfig& cfg);
  // The levels to arm with; nullopt (start full) when there is no file yet or it is for other magazines,
  // said through `say`. ConfigError on a file that is not a magazines file.
  std::optional<sequencer::MagazineLevels> load_magazines(const Say& say) const;
  // A row's end or a reload (kRowDone, kReloaded with stock_known): the levels written durably. Throws as
  // the counters' save does.
  void save_magazines(const RunEvent& e) const;
  // Arming: which slots run out in the `rows` rows from production row `next_row` (0-based) at the levels
  // the loom arms with (`levels`; nullopt: full magazines), one line each through `say` — the loom asks
  // for each reload before the row that needs it. Nothing said without kept magazines or without heads.
  void say_yarn_forecast(const sequencer::KnotProgram* program,
                         const std::optional<sequencer::MagazineLevels>& levels, std::uint32_t next_row,
                         std::uint64_t rows, const Say& say) const;
  // Arming: the recipe's design made the active one at `counter_rows`; returns the rows of it woven
  // before (0 without a design or without a record). With a job: the job's rows woven. ConfigError when
  // the book cannot be read or written.
  std::uint64_t activate_design(std::uint32_t counter_rows);
  // A new session's handshake: the loop is told that `c` is on disk (a fresh RowSaves).
  void begin_session(const sequencer::Counters& c);
  // After a row, pick or knot: the counters, then the design book (a cut between the two lags, never
  // leads), then the loop. On failure the loop is told (it stops at the row boundary with
  // counters_not_saved) and the exception propagates for the caller to word.
  void save(const sequencer::Counters& c);
  RowSaves* row_saves() { return kept() ? row_saves_.get() : nullptr; }

 private:
  std::string path_;
  std::uint32_t picks_per_row_;
  std::string design_name_;  // "" without a design
  std::unique_ptr<state::CounterStore> store_;
  std::unique_ptr<state::DesignBook> book_;
  std::unique_ptr<RowSaves> row_saves_;
  std::unique_ptr<CarpetJob> jobs_;
  bool carpet_done_ = false;
  std::string magazines_path_;  // "" when not kept
  int heads_ = 0, slots_ = 0;
  std::int32_t knots_per_slot_ = 0;
};

// Where the design stands, in words: "design NAME (W x H knots): row R to knot next[, repeat N]".
std::string design_position(const design::Design& d, std::uint64_t rows_done);

// A latched fault as every report names it: the FAULT line, the run report's summary, the fault history.
struct FaultReport {
  sequencer::Fault fault = sequencer::Fault::kNone;
  sequencer::Fault stopped_by = sequencer::Fault::kNone;  // the symptom motion stopped on
  std::string axis;                                       // "" when the fault is not one axis'
  std::uint16_t device_code = 0;                          // what the drive or the link reported (0: nothing)
  int sensor = -1;                                        // hal::SafetySensor the fault names, or -1
  sequencer::CarriageMiss carriage_miss{};                // carriage_not_at_knot: where (cycle -1: none)
  hal::Tick tick = 0;

  // The sequencer's first fault (at the end of a run), or the one a run event latched.
  static FaultReport of(const sequencer::Sequencer& seq);
  static FaultReport of(const RunEvent& e, const hal::AxisLayout& axes);
  const char* name() const { return sequencer::fault_name(fault); }
  std::uint16_t code() const { return sequencer::fault_code(fault); }
  const char* sensor_name() const;  // "" when the fault names no sensor
  // "(motion stopped on X)" when diagnosis refined the symptom motion stopped on, else "".
  std::string stopped_note() const;
  // "the carriage measured 20.0 mm left of the knot of knot cycle 5 (...), tolerance 2.5 mm" for
  // carriage_not_at_knot, else "".
  std::string where() const;
  // The fault's text with the sensor it names, where it struck and what motion stopped on.
  std::string text() const;
};

class Session {
 public:
  Session(SessionOptions opt, Say say);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  const SessionOptions& options() const { return opt_; }
  // build: the machine for `cfg` and `scene`, resuming at `resume`. The HAL fields of `mo` come from the
  // options; telemetry never waits in real time. SessionError: kExitBadInput for input,
  // kExitNotArmed when the hardware cannot be brought up (the message names interface, node and step).
  Machine& build(const LoomConfig& cfg, const Scene& scene, MachineOptions mo,
                 const sequencer::Counters& resume);
  Machine& machine() { return *machine_; }

  // The run's options every command shares: the period, pacing (real time on hardware), the loop
  // thread's priority and CPU, the overrun policy, and the production record's handshake when it keeps
  // one. The command adds its own (stop flags, the operator link, ...).
  RunOptions run_options(ProductionRecord* record) const;
  // run: the loop until it ends, then the telemetry publisher drained and stopped and the run's line said
  // (its warnings as warnings). SessionError(kExitNotArmed) when the loop thread could not start.
  RunResult run(const RunOptions& ro, const EventHandler& on_event);
  // While nothing may move (commission): `n` more ticks on the caller's thread, at the period when paced
  // (absolute deadlines), as fast as possible otherwise. SYNC and heartbeats keep the nodes supervised.
  void tick(hal::Tick n);

  // report: the latched fault at the end of the run, if any.
  std::optional<FaultReport> fault() const;

 private:
  SessionOptions opt_;
  Say say_;
  std::unique_ptr<Machine> machine_;
  MonotonicClock clock_;
  hal::Tick next_tick_ = 0;
  std::int64_t next_deadline_ns_ = 0;
};

}  // namespace loom::firmware

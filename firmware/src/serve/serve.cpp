// `loomctl serve`: the service a board runs. Configures the loom, arms it (drives stay disabled, valves
// hold), and waits: weaving starts, pauses, resumes, stops at row end and faults are acknowledged only on
// an operator command (control socket or the I/O node's buttons). Counters, the simulated machine's
// state and the fault history live in the state directory, so a board that reboots after a power cut
// comes up resumable — armed at the same row and pick — and not moving.
//
// Sessions: the service runs one firmware::Session after another (build, arm, run, report — the steps
// weave and commission run too). A session ends when the service stops, when `start` comes after the
// rows were woven (a new session starts weaving at once), or when a fault is acknowledged (a new
// session re-arms from the measured positions and waits). What is the service's own is here: the state
// directory, the operator's desk and socket, the audit, the latched fault across restarts, systemd.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "loom/config/config.hpp"
#include "loom/firmware/job_feed.hpp"
#include "loom/firmware/job_recorder.hpp"
#include "loom/firmware/serve/commands.hpp"
#include "loom/firmware/serve/control_socket.hpp"
#include "loom/firmware/serve/fault_history.hpp"
#include "loom/firmware/serve/job_verbs.hpp"
#include "loom/firmware/serve/journal.hpp"
#include "loom/firmware/serve/latched_fault.hpp"
#include "loom/firmware/serve/operator_desk.hpp"
#include "loom/firmware/serve/pairings.hpp"
#include "loom/firmware/serve/sd_notify.hpp"
#include "loom/firmware/serve/state_lock.hpp"
#include "loom/firmware/session.hpp"
#include "loom/telemetry/command_events.hpp"
#include "loom/telemetry/identity.hpp"

namespace loom::firmware::serve {
namespace {

constexpr const char* kEtcConfig = "/etc/loomctl/loom.toml";
// The id every board's embedded default loom has: two boards left on it are one loom on the LCM group.
constexpr const char* kDefaultLoomId = "loom1";
constexpr std::int64_t kSaveRetryNs = 1'000'000'000;  // a failed counters save is retried once a second
// How long a loom listens for another publisher of its id before arming: IDENTITY comes once a second,
// so two and a half periods let one late message (a loaded host) go by without letting a twin through.
constexpr std::chrono::milliseconds kIdentityListen{2500};

OperatorLink* g_link = nullptr;
extern "C" void on_terminate(int) {
  if (g_link != nullptr) g_link->post(Command::kExit);  // lock-free fetch_or: async-signal-safe
}

// Where the session's design stands: rows of it woven when the session was armed, against the
// production rows then (the control thread reads it while the loop weaves).
struct DesignProgress {
  std::atomic<std::uint64_t> rows_at_arm{0};
  std::atomic<std::uint32_t> counter_rows_at_arm{0};
};

std::string status_text(const OperatorLink& l, const std::string& loom_id, const design::Design* d,
                        const DesignProgress& p) {
  constexpr auto r = std::memory_order_relaxed;
  const auto f = static_cast<sequencer::Fault>(l.first_fault.load(r));
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "loom=%s state=%s rows=%u picks=%u beats=%u fault=%s overruns=%u max_wake_latency_ns=%lld tick=%lld",
      loom_id.c_str(), sequencer::state_name(static_cast<sequencer::State>(l.state.load(r))), l.rows.load(r),
      l.picks.load(r), l.beats.load(r), f == sequencer::Fault::kNone ? "none" : sequencer::fault_name(f),
      l.overruns.load(r), static_cast<long long>(l.max_wake_latency_ns.load(r)),
      static_cast<long long>(l.tick.load(r)));
  std::string out = buf;
  const auto rec = static_cast<hal::LinkRecovery>(l.link_recovery.load(r));
  if (rec != hal::LinkRecovery::kHealthy) {
    out += std::string(" link=") + hal::link_recovery_name(rec);
    if (rec == hal::LinkRecovery::kNodeSilent) out += " silent_node=" + std::to_string(l.silent_node.load(r));
  }
  if (d != nullptr) {
    const auto pos = design::position_after(
        *d, design::rows_woven(p.rows_at_arm.load(r), p.counter_rows_at_arm.load(r), l.rows.load(r)));
    std::snprintf(buf, sizeof buf, " design=%s design_row=%d/%d repeat=%d", d->name().c_str(), pos.row + 1,
                  d->height(), pos.repeat);
    out += buf;
  }
  return out + "\n";
}

// The audit of one command: a journal line naming who gave it and the verdict; accepted ones also go
// to the fault history (`ctl faults`). Refused ones stay in the journal only, so a flood of refusals
// cannot rotate the faults out of the history.
// The COMMAND event (when telemetry is on) carries the same: word, station, who, verdict, state.
// The counters in the history's record are the loom's when the command was decided.
void audit(FaultHistory& history, const std::string& loom_id, const std::string& line, const Decision& d,
           telemetry::CommandEvents* events, sequencer::State state, const OperatorLink& link) {
  std::string verdict = d.reply;
  if (!verdict.empty() && verdict.back() == '\n') verdict.pop_back();
  // Tokens and pairing codes never reach a log.
  for (const char* secret : {" token=", " code="}) {
    const auto at = verdict.find(secret);
    if (at != std::string::npos) verdict.erase(at, verdict.find(' ', at + 1) - at);
  }
  std::string word = line.substr(0, line.find(' '));
  if (d.request && d.request->word == "job") word += " " + d.request->arg;  // "job add", "job remove"
  log(d.accepted() ? Severity::kNotice : Severity::kWarning, "operator: %s by %s: %s", word.c_str(),
      d.who.c_str(), verdict.c_str());
  if (events != nullptr) {
    events->publish({word, d.station, d.who, d.accepted(), verdict, sequencer::state_name(state)});
  }
  if (!d.accepted()) return;
  FaultRecord r;
  r.loom_id = loom_id;
  r.kind = "command";
  r.name = word;
  r.rows = link.rows.load(std::memory_order_relaxed);
  r.picks = link.picks.load(std::memory_order_relaxed);
  r.beats = link.beats.load(std::memory_order_relaxed);
  r.text = "by " + d.who + ": " + verdict;
  try {
    history.append(r);
  } catch (const std::exception& ex) {
    log(Severity::kErr, "%s", ex.what());
  }
}

// The service's voice: journal lines, errors named as the service's.
void say_in_journal(Severity s, const std::string& text) {
  if (s == Severity::kErr) {
    log(s, "loomctl serve: %s", text.c_str());
  } else {
    log(s, "%s", text.c_str());
  }
}

// The configuration the service runs with, resolved once: every input error is reported before anything
// is armed.
struct ServeInputs {
  LoomConfig cfg;
  Scene scene;
  SessionOptions session;
};

ServeInputs resolve_inputs(const ServeArgs& a) {
  ServeInputs in;
  std::string config_path = a.config;
  if (config_path.empty() && std::filesystem::exists(kEtcConfig)) config_path = kEtcConfig;
  in.session = SessionOptions::from_command_line(a.hal, a.iface, "", a.pace);
  in.session.realtime = true;  // a service always runs at the machine's pace, simulated or not
  in.session.rt_priority = a.rt_priority;
  in.session.cpu = a.cpu;
  in.session.allow_degraded = a.allow_degraded;
  in.session.overrun_stop = a.overrun_stop;
  in.cfg = config_path.empty() ? default_loom_config() : load_loom_config(config_path);
  in.scene = a.scene.empty() ? default_scene() : load_scene(a.scene);
  if (!a.loom_id.empty()) in.cfg.loom_id = a.loom_id;
  if (!a.lcm_url.empty()) in.cfg.telemetry.lcm_url = a.lcm_url;
  if (in.session.hardware() && in.cfg.loom_id == kDefaultLoomId) {
    throw ConfigError(std::string("loom id '") + kDefaultLoomId +
                      "' is the default every installed board has: give "
                      "this loom its own (LOOMCTL_LOOM_ID in /etc/loomctl/loom-id, loom.id in the config, or "
                      "--loom-id)");
  }
  return in;
}

std::string make_state_dir(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    throw SessionError(kExitBadInput, "state directory " + dir + " cannot be created: " +
                                          (ec ? ec.message() : std::string("not a directory")));
  }
  return std::filesystem::path(dir).string();
}

class Service {
 public:
  Service(const ServeArgs& a, ServeInputs in)
      : a_(a),
        cfg_(std::move(in.cfg)),
        scene_(std::move(in.scene)),
        so_(std::move(in.session)),
        state_(make_state_dir(a.state_dir)),
        socket_path_(a.socket.empty() ? "/run/loomctl/" + cfg_.loom_id + ".sock" : a.socket),
        // One serve per state directory (the socket alone does not say so: another --socket would share
        // these counters). Held until this process ends.
        state_lock_(lock_state_dir(state_, cfg_.loom_id, socket_path_)),
        record_(state_ + "/counters.json", cfg_),
        history_(state_ + "/faults.log"),
        latched_(state_ + "/latched-fault", state_ + "/reserve"),
        watchdog_(systemd_),
        desk_(pairings_, a.iface) {
    // The fault latched when the service last stopped (power cut, restart, watchdog): latched again when
    // the first session arms, until an acknowledgement clears it (a restart is no reset).
    relatch_ = latched_.load();
    // Real time: memory locked and SCHED_FIFO probed for the loop thread only (this thread, the control
    // thread and the telemetry publisher stay SCHED_OTHER).
    prepare_realtime(so_, say_in_journal);
    record_.weave_jobs(std::make_unique<CarpetJob>(state_));  // JobError: a bad jobs.txt refuses to start
    record_.keep_magazines(cfg_);
    // `ctl status` answers from the link, which the loop fills from its first tick on; until then (config,
    // the LCM identity check, arming) it shows the counters on disk, never zeros that look like a reset.
    try {
      show_counters(record_.load());
    } catch (const ConfigError&) {
      // Reported (and refused) when the first session loads them.
    }
    // The audit as LCM events (COMMAND), for the service's whole life: sessions' publishers come and go.
    if (!a.no_telemetry) {
      try {
        command_events_ = std::make_unique<telemetry::CommandEvents>(
            cfg_.telemetry.lcm_url, std::string(telemetry::kDefaultChannelPrefix), cfg_.loom_id);
        job_feed_ = std::make_unique<JobFeed>(state_, cfg_.telemetry.lcm_url, cfg_.loom_id);  // JOB, CARPET
      } catch (const std::exception& e) {
        throw ConfigError(cfg_.source + ": telemetry: " + e.what());
      }
    }
    try {
      server_ = std::make_unique<ControlServer>(socket_path_, a.group,
                                                [this](const ControlRequest& req) { return answer(req); });
    } catch (const std::exception& e) {
      throw ConfigError(e.what());
    }
    if (!server_->group_note().empty()) log(Severity::kWarning, "%s", server_->group_note().c_str());
    log(Severity::kNotice, "loomctl %s serve: loom '%s' (%s), HAL %s%s%s, state %s, control socket %s",
        version(), cfg_.loom_id.c_str(), cfg_.source.c_str(), a.hal.c_str(), so_.hardware() ? " " : "",
        so_.hardware() ? a.iface.c_str() : "", state_.c_str(), socket_path_.c_str());
    // Last, when nothing can throw any more (a constructor that throws runs no destructor to unset it).
    g_link = &link_;
    std::signal(SIGTERM, on_terminate);
    std::signal(SIGINT, on_terminate);
  }

  ~Service() {
    server_.reset();  // no request reaches the desk while the service is taken down
    g_link = nullptr;
  }

  // Sessions one after another until the service is told to stop.
  void run() {
    for (;;) {
      watchdog_.ping_outside_loop();  // re-arming: no loop runs, this thread is the proof of life
      Session session(so_, say_in_journal);
      if (!arm(session)) {
        if (!stand_until_the_queue_changes()) break;
        continue;
      }
      const RunResult res = run_session(session);
      if (!next_session(session, res)) break;
    }
    systemd_.notify("STOPPING=1");
  }

 private:
  static std::unique_ptr<StateDirLock> lock_state_dir(const std::string& state, const std::string& loom_id,
                                                      const std::string& socket) {
    try {
      return std::make_unique<StateDirLock>(state, loom_id, socket);
    } catch (const std::exception& e) {
      throw SessionError(kExitNotArmed, std::string("refusing to arm: ") + e.what());
    }
  }

  void show_counters(const sequencer::Counters& c) {
    link_.rows.store(c.rows, std::memory_order_relaxed);
    link_.picks.store(c.picks, std::memory_order_relaxed);
    link_.beats.store(c.beats, std::memory_order_relaxed);
  }

  // ---- the control socket's thread ----
  std::string answer(const ControlRequest& req) {
    LoomView view = view_of(link_, cfg_.sequencer.knotting);
    view.counters_unsaved = counters_unsaved_.load(std::memory_order_acquire);
    view.pause_pending = pause_pending_.load(std::memory_order_acquire);
    if (cfg_.knotting.mode == sequencer::KnottingMode::kHeads) {
      view.heads = cfg_.knotting.heads;
      view.slots = static_cast<int>(cfg_.knotting.slot_colours.size());
      view.knots_per_slot = cfg_.knotting.knots_per_slot;
    }
    Decision d = desk_.decide(req, view, static_cast<std::int64_t>(std::time(nullptr)));
    if (d.post == Command::kStart &&
        (view.state == sequencer::State::kIdle || view.state == sequencer::State::kDone)) {
      std::lock_guard<std::mutex> lock(job_mu_);
      // The loom stands (nothing to weave, or the job's design changed) — unless the queue changed since it
      // armed: then the re-arm decides, and the start goes with it (start and rearm in one tick re-arm,
      // then start; a start the new session takes is judged by it).
      if (!start_refusal_.empty() && queue_changes_ == queue_changes_armed_) {
        d.reply = "refused: start: " + start_refusal_ + "\n";
        d.post.reset();
      }
    }
    if (d.post == Command::kNext && view.state == sequencer::State::kKnotting) {
      std::lock_guard<std::mutex> lock(weaver_mu_);
      // Taken once: a `next` before the reporter has heard the request it answers says plain `ok next`,
      // and that request's words, when they come, are dropped: never named by a later `next`.
      if (!weaver_request_.empty()) d.reply = "ok next: answered " + weaver_request_ + "\n";
      weaver_answered_unheard_ = weaver_request_.empty();
      weaver_request_.clear();
    }
    if (d.read == Decision::Read::kStatus) {
      return job_status(status_text(link_, cfg_.loom_id, armed_design().get(), design_progress_), view) +
             open_requests(view);
    }
    if (d.read == Decision::Read::kJob) {
      {
        std::lock_guard<std::mutex> lock(job_mu_);  // against an arming reading the queue
        const JobVerbResult res =
            carry_out_job_verb(*d.request, *record_.job_queue(), cfg_, link_, view.state);
        d.reply = res.reply;
        if (res.rearm) ++queue_changes_;
      }
      if (d.audit) audit(history_, cfg_.loom_id, req.line, d, command_events_.get(), view.state, link_);
      return d.reply;
    }
    if (d.read == Decision::Read::kFaults) {
      std::string out;
      for (const std::string& line : history_.read_all()) out += line + "\n";
      return out.empty() ? "no faults recorded in " + history_.path() + "\n" : out;
    }
    if (d.post) {
      if (*d.post == Command::kAck) {
        std::lock_guard<std::mutex> lock(ack_mu_);
        ack_by_ = d.who;
        ack_at_ = std::chrono::steady_clock::now();
      }
      if (*d.post == Command::kStart) started_at_machine(d);
      if (*d.post == Command::kReload && d.reload) {
        link_.post_reload(d.reload->head, d.reload->slot, d.reload->knots);
        d.reply = "ok reload head " + std::to_string(d.reload->head + 1) + " slot " +
                  std::to_string(d.reload->slot) + ": " +
                  (d.reload->knots < 0 ? std::string("full") : std::to_string(d.reload->knots) + " knots") +
                  "\n";
      }
      if (*d.post == Command::kPause) pause_pending_.store(true, std::memory_order_release);
      if (*d.post == Command::kResume || *d.post == Command::kStop)
        pause_pending_.store(false, std::memory_order_release);
      if (*d.post != Command::kReload) link_.post(*d.post);
    }
    if (d.audit) audit(history_, cfg_.loom_id, req.line, d, command_events_.get(), view.state, link_);
    return d.reply;
  }

  // What the loom waits for, as lines after the status line: the weaver's open request (the row to knot,
  // or the heads' request in words) and a pause given but not reached yet.
  std::string open_requests(const LoomView& v) {
    std::string out;
    if (v.state == sequencer::State::kAwaitKnotting) {
      out += "open: weaver knot_row: knot row " +
             std::to_string(link_.rows.load(std::memory_order_relaxed) + 1) +
             " by hand, then answer (ctl next, the pedal or the panel)\n";
    } else if (v.state == sequencer::State::kKnotting && v.weaver_ask != sequencer::WeaverAsk::kNone) {
      std::string words;
      {
        std::lock_guard<std::mutex> lock(weaver_mu_);
        words = weaver_request_;
      }
      out += std::string("open: weaver ") + sequencer::weaver_ask_name(v.weaver_ask) + ": " +
             (words.empty() ? std::string("the knotting heads wait for the weaver") : words) +
             ", then answer (ctl next, the pedal or the panel)\n";
    }
    if (v.pause_pending && weaving(v.state)) {
      out += "open: pause: given, the loom holds at the next safe point (state " +
             std::string(sequencer::state_name(v.state)) + "); ctl resume withdraws it\n";
    }
    return out;
  }

  // A loom with knotting heads and no design to tie (none in the recipe, no carpet job): there is no
  // machine to build. The service stands without a session — `ctl status` answers (state idle), a start is
  // refused with the reason at the config's line — until the job queue changes (ctl job add) or it is told
  // to stop. False when told to stop.
  bool stand_until_the_queue_changes() {
    std::uint64_t seen = 0;
    {
      std::lock_guard<std::mutex> lock(job_mu_);
      seen = queue_changes_armed_ = queue_changes_;
    }
    if (!ready_sent_) {
      systemd_.notify("READY=1\nSTATUS=standing: no design to weave (loomctl ctl job add DESIGN)");
      ready_sent_ = true;
    }
    constexpr auto kLook = std::chrono::milliseconds(50);
    for (;;) {
      watchdog_.ping_outside_loop();
      if ((link_.pending.load(std::memory_order_acquire) & static_cast<std::uint32_t>(Command::kExit)) != 0) {
        log(Severity::kNotice, "loomctl serve: stopped (standing, no design to weave)");
        return false;
      }
      {
        std::lock_guard<std::mutex> lock(job_mu_);
        if (queue_changes_ != seen) return true;
      }
      std::this_thread::sleep_for(kLook);
    }
  }

  // ---- build and arm one session from what is on disk ----
  // False when there is nothing to build (knotting heads with no design and no job): the loom stands.
  bool arm(Session& session) {
    // Room for the latched-fault record on a full disk: a loom whose fault could not be kept would forget
    // it at the next restart. A disk too full to keep it refuses to arm, as unwritable counters do.
    try {
      latched_.keep_reserve();
    } catch (const std::exception& e) {
      throw SessionError(kExitNotArmed, std::string("refusing to arm: ") + e.what() +
                                            " (free space in the state directory; a fault latched on a full "
                                            "disk must still be kept)");
    }
    sequencer::Counters resume = record_.load();
    // Counters woven but not on disk when the last session ended: armed from these, never from the file's
    // older counts (which would weave those rows again).
    const std::optional<sequencer::Counters> arm_unsaved = unsaved_;
    if (unsaved_) resume = *std::exchange(unsaved_, std::nullopt);
    show_counters(resume);
    const ArmedJob armed = arm_job(resume);
    if (!armed.cfg.recipe.design && !armed.cfg.recipe.design_missing.empty()) {
      std::lock_guard<std::mutex> lock(job_mu_);
      start_refusal_ = armed.refusal.empty() ? armed.cfg.recipe.design_missing : armed.refusal;
      log(Severity::kWarning, "standing, no session armed: %s", start_refusal_.c_str());
      unsaved_ = arm_unsaved;  // counters held in memory stay for the arming that follows
      return false;
    }
    const std::uint64_t design_rows = armed.design_rows;
    if (const design::Design* d = armed.cfg.recipe.design.get()) {
      design_progress_.rows_at_arm.store(design_rows);
      design_progress_.counter_rows_at_arm.store(resume.rows);
      log(Severity::kNotice, "%s", design_position(*d, design_rows).c_str());
    }
    if (!a_.no_telemetry) refuse_a_twin();
    MachineOptions mo;
    mo.design_rows_done = design_rows;
    if (record_.jobs() != nullptr && armed.refusal.empty()) {
      mo.carpet_began = carpet_began(resume.rows, design_rows);
    }
    mo.telemetry = !a_.no_telemetry;
    mo.rows = a_.rows == 0 ? 0 : resume.rows + a_.rows;
    if (armed.rows_left > 0) {
      mo.rows = resume.rows + static_cast<std::uint32_t>(std::min<std::uint64_t>(
                                  armed.rows_left, a_.rows == 0 ? armed.rows_left : a_.rows));
    }
    mo.await_row_saved = true;  // the state dir always keeps the counters
    if (!so_.hardware()) mo.sim_state_path = state_ + "/sim-state.bin";
    Machine& machine = session.build(armed.cfg, scene_, mo, resume);
    sequencer::Sequencer& seq = machine.sequencer();
    const auto levels = record_.load_magazines(say_in_journal);
    if (levels) seq.restore_magazines(*levels);
    // The yarn for the job's rows left (or the run's rows; a loom weaving on without end: the next 100).
    constexpr std::uint64_t kForecastRowsUnbounded = 100;
    const std::uint64_t forecast_rows = mo.rows != 0 ? mo.rows - resume.rows : kForecastRowsUnbounded;
    record_.say_yarn_forecast(machine.knot_program(), levels, resume.rows, forecast_rows, say_in_journal);
    if (job_feed_) job_feed_->armed(machine);
    {
      std::lock_guard<std::mutex> lock(job_mu_);
      armed_design_ = armed.cfg.recipe.design;
      start_refusal_ = armed.refusal;
      queue_changes_armed_ = armed.queue_changes;
    }
    if (start_at_once_) {
      start_at_once_ = false;
      if (armed.refusal.empty() && !link_.take_start()) {
        log(Severity::kWarning, "start not taken: the job queue changed while the loom armed; start again");
      } else if (armed.refusal.empty()) {
        started_at_machine(std::nullopt);
        seq.request_start();
      } else {
        log(Severity::kWarning, "start not taken: %s", armed.refusal.c_str());
      }
    }
    // Latched at the session's first tick, before anything can start; its kFault event is not a new fault.
    relatch_pending_ = false;
    pause_pending_.store(false, std::memory_order_release);  // a new session holds no pause
    if (relatch_) {
      seq.request_safe_stop(relatch_->fault);
      relatch_pending_ = true;
      const FaultRecord& r = relatch_->record;
      log(Severity::kErr,
          "FAULT %s (0x%04X)%s%s latched before the restart, at %s (rows %u, picks %u): %s — latched "
          "again; a restart is no reset: acknowledge it with ctl ack or the ack button",
          r.name.c_str(), r.code, r.axis.empty() ? "" : " axis ", r.axis.c_str(),
          LatchedFaultStore::utc(relatch_->latched_at_s).c_str(), r.rows, r.picks, r.text.c_str());
      relatch_.reset();
    }
    log(Severity::kNotice, "armed, %s: rows %u, picks %u (%u in the row in progress), beats %u",
        seq.state() == sequencer::State::kIdle ? "waiting for the operator (ctl start or the start button)"
                                               : "weaving",
        resume.rows, resume.picks, resume.picks_in_row, resume.beats);
    if (!ready_sent_) {
      systemd_.notify("READY=1\nSTATUS=armed, waiting for the operator");
      ready_sent_ = true;
    }
    record_.begin_session(resume);
    failed_save_.reset();
    last_retry_ns_ = 0;
    if (arm_unsaved) save_failed(*arm_unsaved);  // armed from memory: the disk lags until a retry succeeds
    return true;
  }

  // ---- the carpet job ----
  struct ArmedJob {
    LoomConfig cfg;                   // the loom with the job's design (or the recipe's, without a job)
    std::uint64_t design_rows = 0;    // rows of the design (or the job's carpet) woven
    std::uint64_t rows_left = 0;      // of the job's carpet (0: no job, no limit from it)
    std::string refusal;              // why a start is refused ("" when the loom may weave)
    std::uint64_t queue_changes = 0;  // the control socket's queue changes this arming has seen
  };

  // The job queue read again (only this service changes it while it runs), the rows a power cut kept
  // from it credited, and the loom described with the job's design. A queue with nothing to weave, or a
  // job whose design file changed, arms the loom standing: every start refused with the reason.
  ArmedJob arm_job(const sequencer::Counters& resume) {
    ArmedJob a{cfg_, 0, 0, "", 0};
    job_record_refused_ = false;  // each session tries the record again
    CarpetJob& q = *record_.job_queue();
    {
      // The control socket's job verbs wait while the session's job is chosen; the gate opens for it.
      std::lock_guard<std::mutex> lock(job_mu_);
      q.reload();
      a.design_rows = record_.activate_design(resume.rows);
      link_.queue_gate.store(OperatorLink::kGateOpen, std::memory_order_release);
      // The queue is read now: a rearm asked before this has what it asked for (a later one stays).
      link_.pending.fetch_and(~static_cast<std::uint32_t>(Command::kRearm), std::memory_order_acq_rel);
      a.queue_changes = queue_changes_;
    }
    if (CarpetJob* job = record_.jobs()) {
      try {
        a.cfg = job->config_for(cfg_);
        a.rows_left = job->rows_left();
        log(Severity::kNotice, "%s", job->describe().c_str());
      } catch (const job::JobError& e) {
        a.refusal =
            std::string(e.what()) + " (the loom stands: loomctl ctl job start-over N, or job remove N)";
        a.design_rows = 0;
      }
    } else if (const std::uint32_t done = q.carpet_done_id(); done != 0) {
      a.refusal = "no carpet job to weave: job " + std::to_string(done) +
                  " is carpet_done and none is queued (add the next: loomctl ctl job add DESIGN)";
    }
    if (!a.refusal.empty()) log(Severity::kWarning, "%s", a.refusal.c_str());
    return a;
  }

  // An accepted start at the machine (the control socket, a paired panel, a re-arm's start): a queued job
  // becomes current, audited in the journal. A press of the start button is heard after the loop acted:
  // its first row's save starts the job then (CarpetJob::row_saved).
  void started_at_machine(const std::optional<Decision>& by) {
    {
      std::lock_guard<std::mutex> lock(job_mu_);
      carpet_done_job_ = 0;
    }
    CarpetJob* job = record_.jobs();
    if (job == nullptr) return;
    try {
      if (job->start(link_.rows.load(std::memory_order_relaxed))) {
        log(Severity::kNotice, "%s: started at the machine%s%s", job->describe().c_str(), by ? " by " : "",
            by ? by->who.c_str() : "");
      }
    } catch (const std::exception& e) {
      log(Severity::kErr,
          "the job queue was not written at the start (%s): the first row's save starts the job", e.what());
    }
  }

  // The carpet's last row is on disk: the loom holds (done) for the cut-off; status says carpet_done until
  // the next start.
  void carpet_done(const sequencer::Counters& c) {
    std::uint32_t id = 0;
    if (const CarpetJob* q = record_.job_queue()) id = q->carpet_done_id();
    const bool next_queued = record_.jobs() != nullptr;
    {
      std::lock_guard<std::mutex> lock(job_mu_);
      carpet_done_job_ = id;
      if (!next_queued) {
        start_refusal_ = "no carpet job to weave: job " + std::to_string(id) +
                         " is carpet_done and none is queued (add the next: loomctl ctl job add DESIGN)";
      }
    }
    carpet_finished_ = true;  // the record ends the job with the row's event
    log(Severity::kNotice,
        "carpet done: job %u, its last row woven (rows %u): cut the carpet off and tie the fringe warp; the "
        "next "
        "queued job starts at the machine (ctl start)",
        id, c.rows);
  }

  std::shared_ptr<const design::Design> armed_design() {
    std::lock_guard<std::mutex> lock(job_mu_);
    return armed_design_ ? armed_design_ : cfg_.recipe.design;
  }

  // The status line with the job: " job=N job_row=R/L", and state=carpet_done while the loom waits for
  // the cut-off (or stands with nothing to weave).
  std::string job_status(std::string line, const LoomView& v) {
    std::uint32_t done_id = 0;
    bool nothing = false;
    {
      std::lock_guard<std::mutex> lock(job_mu_);
      done_id = carpet_done_job_;
      nothing = !start_refusal_.empty();
    }
    if (const CarpetJob* q = record_.job_queue()) {
      if (done_id == 0 && nothing) done_id = q->carpet_done_id();
      if (!line.empty() && line.back() == '\n') line.pop_back();
      if (done_id != 0 && (v.state == sequencer::State::kDone || v.state == sequencer::State::kIdle)) {
        const std::string from = std::string("state=") + sequencer::state_name(v.state) + " ";
        if (const auto at = line.find(from); at != std::string::npos)
          line.replace(at, from.size(), "state=carpet_done ");
        line += " carpet_done_job=" + std::to_string(done_id);
      } else {
        line += q->status_fields();
      }
      line += "\n";
    }
    return line;
  }

  // One loom id, one publisher: another loom (or a recording replayed onto the live group) with this id
  // would mix with ours on every subscriber.
  void refuse_a_twin() const {
    std::string other;
    try {
      other =
          telemetry::other_publisher(cfg_.telemetry.lcm_url, std::string(telemetry::kDefaultChannelPrefix),
                                     cfg_.loom_id, kIdentityListen);
    } catch (const std::exception& e) {
      throw ConfigError(cfg_.source + ": telemetry: " + e.what());
    }
    if (other.empty()) return;
    throw SessionError(
        kExitNotArmed,
        "refusing to arm: loom id '" + cfg_.loom_id + "' is already published on the LCM group (" +
            (cfg_.telemetry.lcm_url.empty() ? std::string("LCM's default URL") : cfg_.telemetry.lcm_url) +
            ") by " + other +
            "; two looms with one id mix on every monitor and panel: give this loom "
            "its own id, or replay recordings onto another group");
  }

  // ---- run: the loop, with the reporter on this thread ----
  RunResult run_session(Session& session) {
    Machine& machine = session.machine();
    RunOptions ro = session.run_options(&record_);
    ro.link = &link_;
    ro.audit_buttons = true;
    ro.hold_when_finished = true;
    {
      std::lock_guard<std::mutex> lock(job_mu_);
      ro.nothing_to_weave = !start_refusal_.empty();
    }
    // The reporter thread's poll: the watchdog is fed only while the loop's tick moves, and a failed save
    // is retried, so freeing the disk lets the acknowledgement through.
    ro.reporter_poll = [this] { poll(); };
    const RunResult res = session.run(ro, [this, &machine](const RunEvent& e) { on_event(e, machine); });
    if (job_record_) {
      try {
        job_record_->finish(res.ticks, false);
      } catch (const std::exception& ex) {
        log(Severity::kWarning, "the production record's last commit failed: %s", ex.what());
      }
      job_record_.reset();
    }
    return res;
  }

  // The carpet job's production record (production.sqlite), kept from the job's start at the machine: a
  // record that cannot be written is said once and the loom weaves on (the counters are the authority).
  void record_job_event(const RunEvent& e, const Machine& machine) {
    if (!job_record_) {
      CarpetJob* job = record_.jobs();
      if (job == nullptr || !job->started() || job_record_refused_) return;
      try {
        const job::Job j = job->job();
        job_record_ =
            std::make_unique<JobRecorder>(state_, j, j.progress.at_counter_rows, cfg_.sequencer.period_s,
                                          !so_.hardware() && so_.pace != 1.0);
      } catch (const std::exception& ex) {
        job_record_refused_ = true;
        log(Severity::kWarning, "no production record for this job: %s", ex.what());
        return;
      }
    }
    try {
      job_record_->on_event(e, machine.knot_program(), machine.config().recipe.design.get());
      if (carpet_finished_) {
        job_record_->finish(e.tick, true);
        job_record_.reset();
        carpet_finished_ = false;
      }
    } catch (const std::exception& ex) {
      log(Severity::kWarning, "the production record stops here: %s", ex.what());
      job_record_.reset();
      job_record_refused_ = true;
    }
  }

  void save_counters(const sequencer::Counters& c) {
    record_.save(c);
    if (record_.take_carpet_done()) carpet_done(c);
    failed_save_.reset();
    counters_unsaved_.store(false, std::memory_order_release);
  }

  // Every failed save comes here: the loop (the record's handshake) and the desk (counters_unsaved) learn it.
  void save_failed(const sequencer::Counters& c) {
    failed_save_ = c;
    record_.row_saves()->failed();
    counters_unsaved_.store(true, std::memory_order_release);
  }

  void poll() {
    if (job_feed_) job_feed_->poll();
    const std::int64_t now = MonotonicClock{}.now_ns();
    const std::int64_t control_idle = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                          std::chrono::steady_clock::now().time_since_epoch())
                                          .count() -
                                      server_->alive_ns();
    watchdog_.poll(link_.tick.load(std::memory_order_acquire), now, control_idle);
    if (watchdog_.control_hung(control_idle) != control_hung_) {
      control_hung_ = !control_hung_;
      if (control_hung_) {
        log(Severity::kErr,
            "the control socket's thread has not come round for %.1f s (operators get no answer): "
            "the watchdog is no longer fed, systemd restarts the service",
            static_cast<double>(control_idle) * 1e-9);
      }
    }
    if (!failed_save_ || now - last_retry_ns_ < kSaveRetryNs) return;
    last_retry_ns_ = now;
    try {
      save_counters(*failed_save_);
      log(Severity::kNotice, "counters saved again (rows %u, picks %u): the fault can be acknowledged",
          record_.row_saves()->rows_on_disk.load(), link_.picks.load());
    } catch (const std::exception&) {
      // Still failing: the fault stays and the ack is refused; the first failure was logged.
    }
  }

  void on_event(const RunEvent& e, Machine& machine) {
    machine.collect_retired_recipes();
    switch (e.kind) {
      case RunEvent::Kind::kRowDone:
        log_row(e);
        // The magazines before the counters: a cut between the two leaves the levels low, never high.
        try {
          record_.save_magazines(e);
        } catch (const std::exception& ex) {
          log(Severity::kWarning, "the magazines' levels were not saved: %s", ex.what());
        }
        break;
      case RunEvent::Kind::kPaused:
      case RunEvent::Kind::kResumed:
        pause_pending_.store(false, std::memory_order_release);
        log(Severity::kNotice, "%s after row %u, pick %u",
            e.kind == RunEvent::Kind::kPaused ? "paused" : "resumed", e.counters.rows, e.counters.picks);
        break;
      case RunEvent::Kind::kFault:
      case RunEvent::Kind::kOverrunStop:
        pause_pending_.store(false, std::memory_order_release);
        record_fault(e);
        break;
      case RunEvent::Kind::kButton:
        audit_button(e);
        return;  // a press changes no counters: nothing to save
      case RunEvent::Kind::kWeaverRequest:
        heard_weaver_request(e, machine);
        record_job_event(e, machine);
        return;  // nothing changed in the counters
      case RunEvent::Kind::kReloaded:
        // Kept at once: a power cut after a reload must not ask for it again.
        try {
          record_.save_magazines(e);
        } catch (const std::exception& ex) {
          log(Severity::kWarning, "the magazines' levels after a reload were not saved: %s", ex.what());
        }
        return;  // the counters did not change
      case RunEvent::Kind::kPickDone:
      case RunEvent::Kind::kKnotProgress:
      case RunEvent::Kind::kFinished:
        break;
    }
    try {
      save_counters(e.counters);
    } catch (const std::exception& ex) {
      // The sequencer stops at the row boundary with counters_not_saved (a fault like any other); an
      // acknowledgement is refused until a retry (poll) has saved these counts.
      log(Severity::kErr, "counters not saved: %s", ex.what());
      save_failed(e.counters);
    }
    record_job_event(e, machine);
    if (job_feed_) job_feed_->on_event(e);  // after the save: the rows credited to the job are on disk
  }

  void log_row(const RunEvent& e) const {
    const double period = cfg_.sequencer.period_s;
    char knotting[64] = "";
    if (e.row.knotting_ticks > 0) {
      std::snprintf(knotting, sizeof knotting, ", knotted in %.2f s before it",
                    static_cast<double>(e.row.knotting_ticks) * period);
    }
    log(Severity::kInfo, "row %u done: %.2f s, %d beats, %d carriage steps (picks %u, beats %u)%s", e.row.row,
        static_cast<double>(e.row.total_ticks) * period, e.row.beats, e.row.carriage_steps, e.counters.picks,
        e.counters.beats, knotting);
  }

  // A fault history record of `kind` naming `f`, with the counters it happened at.
  FaultRecord record_of(const char* kind, sequencer::Fault f, const sequencer::Counters& c) const {
    FaultRecord r;
    r.loom_id = cfg_.loom_id;
    r.kind = kind;
    r.name = sequencer::fault_name(f);
    r.code = sequencer::fault_code(f);
    r.rows = c.rows;
    r.picks = c.picks;
    r.beats = c.beats;
    return r;
  }

  // A fault latched (or the overrun policy stopped the loop): kept on disk so a restart latches it again,
  // logged, and added to the history.
  void record_fault(const RunEvent& e) {
    const bool overrun = e.kind == RunEvent::Kind::kOverrunStop;
    FaultReport f;
    if (overrun) {
      f.fault = sequencer::Fault::kLoopOverrun;
    } else {
      f = FaultReport::of(e, cfg_.sequencer.axes);
    }
    FaultRecord r = record_of(overrun ? "overrun_stop" : "fault", f.fault, e.counters);
    r.axis = f.axis;
    r.device_code = f.device_code;
    r.text = f.text();
    if (relatch_pending_ &&
        f.fault == e.fault) {  // the fault from before the restart: logged and on disk already
      relatch_pending_ = false;
      return;
    }
    relatch_pending_ = false;
    try {
      latched_.save({f.fault, r, static_cast<std::int64_t>(std::time(nullptr))});
    } catch (const std::exception& ex) {
      log(Severity::kErr, "latched fault not kept on disk (a restart would not latch it again): %s",
          ex.what());
    }
    log(Severity::kErr,
        "FAULT %s (0x%04X)%s%s: %s; rows %u, picks %u — acknowledge with ctl ack or the ack "
        "button",
        r.name.c_str(), r.code, r.axis.empty() ? "" : " axis ", r.axis.c_str(), r.text.c_str(), r.rows,
        r.picks);
    try {
      history_.append(r);
    } catch (const std::exception& ex) {
      log(Severity::kErr, "%s", ex.what());
    }
  }

  // The I/O module's buttons and the weaver's pedal, audited like any command: who, and the verdict in the
  // state the press was seen in — what the same command would have answered then.
  void audit_button(const RunEvent& e) {
    struct Press {
      const char* word;
      const char* who;
    };
    const Press p = e.button == Command::kStart   ? Press{"start", "the I/O module's start button"}
                    : e.button == Command::kPause ? Press{"pause", "the I/O module's pause button"}
                    : e.button == Command::kAck   ? Press{"ack", "the I/O module's reset/acknowledge button"}
                                                  : Press{"next", "the weaver's row-knotted pedal"};
    LoomView v = view_of(link_, cfg_.sequencer.knotting);
    v.state = e.state;
    v.weaver_ask = e.request.ask;  // judged against the request open at the press, not the one open now
    v.counters_unsaved = counters_unsaved_.load(std::memory_order_acquire);
    // One start button and no resume button: a start press while paused resumes, and is judged as resume.
    const bool resumes = e.button == Command::kStart && e.state == sequencer::State::kPaused;
    const std::string verdict = desk_.answer_in_state(resumes ? "resume" : p.word, v);
    log(Severity::kNotice, "operator: %s by %s (state %s): %s", p.word, p.who, sequencer::state_name(e.state),
        verdict.c_str());
    if (e.button == Command::kPause && verdict.rfind("ok", 0) == 0)
      pause_pending_.store(true, std::memory_order_release);
    if (command_events_) {
      command_events_->publish(
          {p.word, "button", p.who, verdict.rfind("ok", 0) == 0, verdict, sequencer::state_name(e.state)});
    }
  }

  // The loom waits for the weaver (lamp amber, buzzer): logged for the shift's record; the panel and
  // `ctl status` show it, and the `next` that answers it names it.
  void heard_weaver_request(const RunEvent& e, const Machine& machine) {
    const sequencer::KnotProgram* p = machine.knot_program();
    if (p == nullptr) return;
    const std::string asked = sequencer::describe(e.request, *p);
    log(Severity::kNotice, "weaver asked: %s", asked.c_str());
    std::lock_guard<std::mutex> lock(weaver_mu_);
    if (weaver_answered_unheard_) {
      weaver_answered_unheard_ = false;  // already answered
    } else {
      weaver_request_ = asked;
    }
  }

  // ---- report: what ended the session, and whether another one follows ----
  bool next_session(Session& session, const RunResult& res) {
    const sequencer::Sequencer& seq = session.machine().sequencer();
    switch (res.end) {
      case RunResult::End::kStartRequested:
        log(Severity::kNotice, "start after the woven rows: re-arming for the next rows");
        start_at_once_ = true;
        return true;
      case RunResult::End::kAckRequested:
        acknowledged(seq);
        return true;
      case RunResult::End::kRearmRequested:
        log(Severity::kNotice, "the job queue changed while the loom stood: arming again from it");
        return true;
      case RunResult::End::kError:  // Session::run threw already
      case RunResult::End::kExitRequested:
      case RunResult::End::kFinished:
      case RunResult::End::kMaxTicks:
        break;
    }
    if (failed_save_) {
      try {
        save_counters(seq.counters());
      } catch (const std::exception& ex) {
        log(Severity::kErr, "counters not saved at exit (%s): %s lags rows %u, picks %u", ex.what(),
            record_.counters_path().c_str(), seq.counters().rows, seq.counters().picks);
      }
    }
    log(Severity::kNotice, "loomctl serve: stopped (rows %u, picks %u, beats %u kept in %s)",
        seq.counters().rows, seq.counters().picks, seq.counters().beats, record_.counters_path().c_str());
    return false;
  }

  void acknowledged(const sequencer::Sequencer& seq) {
    FaultRecord r = record_of("ack", seq.first_fault(), seq.counters());
    {
      std::lock_guard<std::mutex> lock(ack_mu_);
      // The loop reports the acknowledgement itself; none from the desk in the last second: the button.
      const bool by_command =
          !ack_by_.empty() && std::chrono::steady_clock::now() - ack_at_ < std::chrono::seconds(1);
      r.text = "acknowledged by " + (by_command ? ack_by_ : std::string("the I/O module's ack button")) +
               "; re-arming from the measured positions";
      ack_by_.clear();
    }
    try {
      history_.append(r);
    } catch (const std::exception& ex) {
      log(Severity::kErr, "%s", ex.what());
    }
    log(Severity::kNotice, "fault %s %s", r.name.c_str(), r.text.c_str());
    try {
      latched_.clear();
    } catch (const std::exception& ex) {
      log(Severity::kErr, "acknowledged fault still on disk (a restart would latch it again): %s", ex.what());
    }
    // The counters in memory are the truth (a fault keeps them; counters_not_saved means the disk lags
    // them): write them before re-arming, which reads them back.
    try {
      save_counters(seq.counters());
    } catch (const std::exception& ex) {
      // Never re-arm from the file's older counts: the next session starts from what was woven, and its
      // first row end stops again with counters_not_saved while the disk still refuses.
      log(Severity::kErr,
          "counters still not saved (%s): re-arming from the counts in memory (rows %u, picks %u)", ex.what(),
          seq.counters().rows, seq.counters().picks);
      unsaved_ = seq.counters();
    }
  }

  const ServeArgs& a_;
  const LoomConfig cfg_;
  const Scene scene_;
  const SessionOptions so_;
  const std::string state_;
  const std::string socket_path_;
  std::unique_ptr<StateDirLock> state_lock_;
  ProductionRecord record_;
  FaultHistory history_;
  const LatchedFaultStore latched_;
  std::optional<LatchedFault>
      relatch_;                   // the fault from before a restart, until the first session latches it
  bool relatch_pending_ = false;  // the session's first fault event is that one (not a new fault)
  DesignProgress design_progress_;
  // The carpet job (arming and the reporter write, the control thread reads).
  std::mutex job_mu_;
  std::shared_ptr<const design::Design> armed_design_;  // the design the armed loom ties
  std::string start_refusal_;          // why a start is refused now ("" when the loom may weave)
  std::uint32_t carpet_done_job_ = 0;  // the job whose carpet was finished in this service, until a start
  // Queue changes that asked for a re-arm (the control socket's job verbs), and how many the armed session
  // has seen: while they differ, a standing loom is about to arm again and a start is not refused here.
  std::uint64_t queue_changes_ = 0, queue_changes_armed_ = 0;
  // The production record of the job being woven (reporter thread only).
  std::unique_ptr<JobRecorder> job_record_;
  bool job_record_refused_ = false;
  bool carpet_finished_ = false;
  const SystemdNotifier systemd_;
  LoopWatchdog watchdog_;
  OperatorLink link_;
  // Who gave the latest accepted `ack`, and when (control thread → reporter).
  std::mutex ack_mu_;
  std::string ack_by_;
  std::chrono::steady_clock::time_point ack_at_{};
  // Whether the counters on disk lag what was woven (the last save failed; the loop refuses an ack until a
  // retried save succeeds): the desk refuses `ctl ack` with the reason instead of answering `ok`.
  std::atomic<bool> counters_unsaved_{false};
  std::atomic<bool> pause_pending_{false};          // LoomView::pause_pending (control thread and reporter)
  std::optional<sequencer::Counters> failed_save_;  // the latest counters a save failed for (reporter thread)
  std::int64_t last_retry_ns_ = 0;
  std::optional<sequencer::Counters> unsaved_;  // woven but not on disk when a session ended
  // The knotting heads' open request of the weaver, in words (the reporter sets it when the loop reports
  // it): the `next` that answers it says which, in its reply and its audit (journal, faults.log, COMMAND).
  std::mutex weaver_mu_;
  std::string weaver_request_;
  bool weaver_answered_unheard_ = false;  // a `next` answered a request whose words had not come yet
  Pairings pairings_;
  OperatorDesk desk_;
  std::unique_ptr<telemetry::CommandEvents> command_events_;
  std::unique_ptr<JobFeed> job_feed_;
  std::unique_ptr<ControlServer> server_;  // last: its thread calls answer(), which uses all of the above
  bool start_at_once_ = false, ready_sent_ = false;
  bool control_hung_ = false;  // the control socket's thread was last seen hung (reporter thread)
};

}  // namespace

int serve_main(const ServeArgs& a) {
  return exit_code_of(say_in_journal, [&] {
    Service service(a, resolve_inputs(a));
    service.run();
    return kExitOk;
  });
}

}  // namespace loom::firmware::serve

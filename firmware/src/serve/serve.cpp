// `loomctl serve`: the service a board runs. Configures the loom, arms it (drives stay disabled, valves
// hold), and waits: weaving starts, pauses, resumes, stops at row end and faults are acknowledged only on
// an operator command (control socket or the I/O node's buttons). Counters, the simulated machine's
// state and the fault history live in the state directory, so a board that reboots after a power cut
// comes up resumable — armed at the same row and pick — and not moving.
//
// Sessions: one Machine per session. A session ends when the service stops, when `start` comes after the
// rows were woven (a new session starts weaving at once), or when a fault is acknowledged (a new
// session re-arms from the measured positions and waits).
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <ctime>
#include <memory>
#include <optional>
#include <mutex>

#include "loom/firmware/config.hpp"
#include "loom/firmware/counter_store.hpp"
#include "loom/firmware/design_book.hpp"
#include "loom/firmware/machine.hpp"
#include "loom/firmware/runner.hpp"
#include "loom/firmware/serve/commands.hpp"
#include "loom/firmware/serve/control_socket.hpp"
#include "loom/firmware/serve/fault_history.hpp"
#include "loom/firmware/serve/journal.hpp"
#include "loom/firmware/serve/latched_fault.hpp"
#include "loom/firmware/serve/sd_notify.hpp"
#include "loom/firmware/serve/state_lock.hpp"
#include "loom/telemetry/command_events.hpp"
#include "loom/telemetry/identity.hpp"
#include "loom/firmware/serve/operator_desk.hpp"
#include "loom/firmware/serve/pairings.hpp"

namespace loom::firmware::serve {
namespace {

constexpr int kExitOk = 0, kExitBadInput = 2, kExitNotArmed = 4;
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

std::string axis_label(const hal::AxisLayout& axes, int axis) {
  return axis >= 0 ? axes.name(static_cast<std::size_t>(axis)) : "";
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
  std::snprintf(buf, sizeof buf,
                "loom=%s state=%s rows=%u picks=%u beats=%u fault=%s overruns=%u max_wake_latency_ns=%lld tick=%lld",
                loom_id.c_str(), sequencer::state_name(static_cast<sequencer::State>(l.state.load(r))),
                l.rows.load(r), l.picks.load(r), l.beats.load(r),
                f == sequencer::Fault::kNone ? "none" : sequencer::fault_name(f), l.overruns.load(r),
                static_cast<long long>(l.max_wake_latency_ns.load(r)), static_cast<long long>(l.tick.load(r)));
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
void audit(FaultHistory& history, const std::string& loom_id, const std::string& line, const Decision& d,
           telemetry::CommandEvents* events, sequencer::State state) {
  std::string verdict = d.reply;
  if (!verdict.empty() && verdict.back() == '\n') verdict.pop_back();
  // Tokens and pairing codes never reach a log.
  for (const char* secret : {" token=", " code="}) {
    const auto at = verdict.find(secret);
    if (at != std::string::npos) verdict.erase(at, verdict.find(' ', at + 1) - at);
  }
  std::string word = line.substr(0, line.find(' '));
  log(d.accepted() ? Severity::kNotice : Severity::kWarning, "operator: %s by %s: %s", word.c_str(), d.who.c_str(),
      verdict.c_str());
  if (events != nullptr) {
    events->publish({word, d.station, d.who, d.accepted(), verdict, sequencer::state_name(state)});
  }
  if (!d.accepted()) return;
  FaultRecord r;
  r.loom_id = loom_id;
  r.kind = "command";
  r.name = word;
  r.text = "by " + d.who + ": " + verdict;
  try {
    history.append(r);
  } catch (const std::exception& ex) {
    log(Severity::kErr, "%s", ex.what());
  }
}

}  // namespace

int serve_main(const ServeArgs& a) {
  // ---- configure: every input error is reported here, before anything is armed ----
  LoomConfig cfg;
  Scene scene;
  std::string config_path = a.config;
  if (config_path.empty() && std::filesystem::exists(kEtcConfig)) config_path = kEtcConfig;
  const bool hardware = a.hal == "socketcan";
  try {
    cfg = config_path.empty() ? default_loom_config() : load_loom_config(config_path);
    if (!a.scene.empty()) scene = load_scene(a.scene);
    else scene = default_scene();
    if (!a.loom_id.empty()) cfg.loom_id = a.loom_id;
    if (!a.lcm_url.empty()) cfg.telemetry.lcm_url = a.lcm_url;
    if (hardware && a.pace != 1.0) throw ConfigError("--pace = " + std::to_string(a.pace) + ": simulation only");
    if (hardware && a.iface.empty()) throw ConfigError("--hal socketcan needs --iface NAME");
    if (hardware && cfg.loom_id == kDefaultLoomId) {
      throw ConfigError(std::string("loom id '") + kDefaultLoomId + "' is the default every installed board has: give this "
                        "loom its own (LOOMCTL_LOOM_ID in /etc/loomctl/loom-id, loom.id in the config, or --loom-id)");
    }
    if (!hardware && !a.iface.empty()) {
      throw ConfigError("--iface " + a.iface + " needs --hal socketcan (without it the simulated loom would run)");
    }
  } catch (const ConfigError& e) {
    log(Severity::kErr, "loomctl serve: %s", e.what());
    return kExitBadInput;
  }
  std::error_code ec;
  std::filesystem::create_directories(a.state_dir, ec);
  if (ec || !std::filesystem::is_directory(a.state_dir)) {
    log(Severity::kErr, "loomctl serve: state directory %s cannot be created: %s", a.state_dir.c_str(),
        ec ? ec.message().c_str() : "not a directory");
    return kExitBadInput;
  }
  const std::string state = std::filesystem::path(a.state_dir).string();
  const std::string socket_path = a.socket.empty() ? "/run/loomctl/" + cfg.loom_id + ".sock" : a.socket;
  // One serve per state directory (the socket alone does not say so: another --socket would share
  // these counters). Held until this process ends.
  std::unique_ptr<StateDirLock> state_lock;
  try {
    state_lock = std::make_unique<StateDirLock>(state, cfg.loom_id, socket_path);
  } catch (const std::exception& e) {
    log(Severity::kErr, "loomctl serve: refusing to arm: %s", e.what());
    return kExitNotArmed;
  }
  CounterStore store(state + "/counters.json");
  FaultHistory history(state + "/faults.log");
  // The fault latched when the service last stopped (power cut, restart, watchdog): latched again when
  // the first session arms, until an acknowledgement clears it (a restart is no reset).
  const LatchedFaultStore latched(state + "/latched-fault");
  std::optional<LatchedFault> relatch;
  try {
    relatch = latched.load();
  } catch (const ConfigError& e) {
    log(Severity::kErr, "loomctl serve: %s", e.what());
    return kExitBadInput;
  }
  // The row each design has reached, beside the counters (only when the recipe names a design).
  std::unique_ptr<DesignBook> book;
  if (cfg.recipe.design) book = std::make_unique<DesignBook>(state + "/designs.json");
  DesignProgress design_progress;
  const SystemdNotifier systemd;
  LoopWatchdog watchdog(systemd);

  // Real time: memory locked and SCHED_FIFO probed for the loop thread only (this thread, the control
  // thread and the telemetry publisher stay SCHED_OTHER).
  if (hardware) {
    const RtSetup rt = setup_realtime(a.rt_priority);
    if (!rt.ok()) {
      if (!a.allow_degraded) {
        log(Severity::kErr, "loomctl serve: refusing to arm: real-time setup failed (%s) — check LimitRTPRIO/"
            "LimitMEMLOCK or pass --allow-degraded", rt.problems.c_str());
        return kExitNotArmed;
      }
      log(Severity::kWarning, "RUNNING DEGRADED: %s timing is not guaranteed", rt.problems.c_str());
    }
  }

  OperatorLink link;
  g_link = &link;
  // `ctl status` answers from the link, which the loop fills from its first tick on; until then (config,
  // the LCM identity check, arming) it shows the counters on disk, never zeros that look like a reset.
  const auto show_counters = [&link](const sequencer::Counters& c) {
    link.rows.store(c.rows, std::memory_order_relaxed);
    link.picks.store(c.picks, std::memory_order_relaxed);
    link.beats.store(c.beats, std::memory_order_relaxed);
  };
  try {
    if (auto c = store.load()) show_counters(*c);
  } catch (const ConfigError&) {
    // Reported (and refused) when the first session loads them.
  }
  std::signal(SIGTERM, on_terminate);
  std::signal(SIGINT, on_terminate);

  // Who gave the latest accepted `ack`, and when (the loop reports the acknowledgement itself; none in
  // the last second → the I/O module's button).
  std::mutex ack_mu;
  std::string ack_by;
  std::chrono::steady_clock::time_point ack_at{};
  // Whether the counters on disk lag what was woven (the last save failed; the loop refuses an ack until a
  // retried save succeeds): the desk refuses `ctl ack` with the reason instead of answering `ok`.
  std::atomic<bool> counters_unsaved{false};
  // The knotting heads' open request of the weaver, in words (the reporter sets it when the loop reports
  // it): the `next` that answers it says which, in its reply and its audit (journal, faults.log, COMMAND).
  std::mutex weaver_mu;
  std::string weaver_request;
  bool weaver_answered_unheard = false;  // a `next` answered a request whose words had not come yet
  Pairings pairings;
  OperatorDesk desk(pairings, a.iface);
  // The audit as LCM events (COMMAND), for the service's whole life: sessions' publishers come and go.
  std::unique_ptr<telemetry::CommandEvents> command_events;
  if (!a.no_telemetry) {
    try {
      command_events = std::make_unique<telemetry::CommandEvents>(
          cfg.telemetry.lcm_url, std::string(telemetry::kDefaultChannelPrefix), cfg.loom_id);
    } catch (const std::exception& e) {
      log(Severity::kErr, "loomctl serve: %s: telemetry: %s", cfg.source.c_str(), e.what());
      return kExitBadInput;
    }
  }
  std::unique_ptr<ControlServer> server;
  try {
    server = std::make_unique<ControlServer>(socket_path, a.group, [&](const ControlRequest& req) -> std::string {
      LoomView view = view_of(link, cfg.sequencer.knotting);
      view.counters_unsaved = counters_unsaved.load(std::memory_order_acquire);
      Decision d = desk.decide(req, view, static_cast<std::int64_t>(std::time(nullptr)));
      if (d.post == Command::kNext && view.state == sequencer::State::kKnotting) {
        std::lock_guard<std::mutex> lock(weaver_mu);
        // Taken once: a `next` before the reporter has heard the request it answers says plain `ok next`,
        // and that request's words, when they come, are dropped: never named by a later `next`.
        if (!weaver_request.empty()) d.reply = "ok next: answered " + weaver_request + "\n";
        weaver_answered_unheard = weaver_request.empty();
        weaver_request.clear();
      }
      if (d.read == Decision::Read::kStatus) return status_text(link, cfg.loom_id, cfg.recipe.design.get(), design_progress);
      if (d.read == Decision::Read::kFaults) {
        std::string out;
        for (const std::string& line : history.read_all()) out += line + "\n";
        return out.empty() ? "no faults recorded in " + history.path() + "\n" : out;
      }
      if (d.post) {
        if (*d.post == Command::kAck) {
          std::lock_guard<std::mutex> lock(ack_mu);
          ack_by = d.who;
          ack_at = std::chrono::steady_clock::now();
        }
        link.post(*d.post);
      }
      if (d.audit) audit(history, cfg.loom_id, req.line, d, command_events.get(), view.state);
      return d.reply;
    });
  } catch (const std::exception& e) {
    log(Severity::kErr, "loomctl serve: %s", e.what());
    return kExitBadInput;
  }
  if (!server->group_note().empty()) log(Severity::kWarning, "%s", server->group_note().c_str());
  log(Severity::kNotice, "loomctl %s serve: loom '%s' (%s), HAL %s%s%s, state %s, control socket %s", version(),
      cfg.loom_id.c_str(), cfg.source.c_str(), a.hal.c_str(), hardware ? " " : "", hardware ? a.iface.c_str() : "",
      state.c_str(), socket_path.c_str());

  bool start_at_once = false, ready_sent = false;
  // Counters woven but not on disk when a session ended: the next session arms from these, never from
  // the file's older counts (which would weave those rows again).
  std::optional<sequencer::Counters> unsaved;
  for (;;) {
    watchdog.ping_outside_loop();  // re-arming: no loop runs, this thread is the proof of life
    // ---- arm one session from what is on disk ----
    sequencer::Counters resume{};
    try {
      if (auto c = store.load()) resume = *c;
    } catch (const ConfigError& e) {
      log(Severity::kErr, "loomctl serve: %s", e.what());
      return kExitBadInput;
    }
    const std::optional<sequencer::Counters> arm_unsaved = unsaved;
    if (unsaved) {
      resume = *unsaved;
      unsaved.reset();
    }
    show_counters(resume);
    std::uint64_t design_rows = 0;
    if (book) {
      try {
        design_rows = book->activate(cfg.recipe.design->name(), resume.rows);
      } catch (const ConfigError& e) {
        log(Severity::kErr, "loomctl serve: %s", e.what());
        return kExitBadInput;
      } catch (const std::exception& e) {
        log(Severity::kErr, "loomctl serve: design book cannot be written, refusing to arm: %s", e.what());
        return kExitBadInput;
      }
      design_progress.rows_at_arm.store(design_rows);
      design_progress.counter_rows_at_arm.store(resume.rows);
      const auto pos = design::position_after(*cfg.recipe.design, design_rows);
      log(Severity::kNotice, "design %s (%d x %d knots): row %d to knot next%s", cfg.recipe.design->name().c_str(),
          cfg.recipe.design->width(), cfg.recipe.design->height(), pos.row + 1,
          pos.repeat > 1 ? (", repeat " + std::to_string(pos.repeat)).c_str() : "");
    }
    if (!a.no_telemetry) {
      // One loom id, one publisher: another loom (or a recording replayed onto the live group) with this
      // id would mix with ours on every subscriber.
      std::string other;
      try {
        other = telemetry::other_publisher(cfg.telemetry.lcm_url, std::string(telemetry::kDefaultChannelPrefix),
                                           cfg.loom_id, kIdentityListen);
      } catch (const std::exception& e) {
        log(Severity::kErr, "loomctl serve: %s: telemetry: %s", cfg.source.c_str(), e.what());
        return kExitBadInput;
      }
      if (!other.empty()) {
        log(Severity::kErr, "loomctl serve: refusing to arm: loom id '%s' is already published on the LCM group "
            "(%s) by %s; two looms with one id mix on every monitor and panel: give this loom its own id, or "
            "replay recordings onto another group", cfg.loom_id.c_str(),
            cfg.telemetry.lcm_url.empty() ? "LCM's default URL" : cfg.telemetry.lcm_url.c_str(), other.c_str());
        return kExitNotArmed;
      }
    }
    MachineOptions mo;
    mo.design_rows_done = design_rows;
    mo.hal = hardware ? HalKind::kSocketCan : HalKind::kSim;
    mo.iface = a.iface;
    mo.telemetry = !a.no_telemetry;
    mo.lossless_telemetry = false;  // real time: a slow subscriber loses snapshots, never delays a tick
    mo.rows = a.rows == 0 ? 0 : resume.rows + a.rows;
    mo.await_row_saved = true;  // the state dir always keeps the counters
    if (!hardware) mo.sim_state_path = state + "/sim-state.bin";
    std::unique_ptr<Machine> machine;
    try {
      machine = std::make_unique<Machine>(cfg, scene, mo, resume);
    } catch (const ConfigError& e) {
      log(Severity::kErr, "loomctl serve: %s", e.what());
      return kExitBadInput;
    } catch (const std::exception& e) {
      log(Severity::kErr, "loomctl serve: cannot arm: %s", e.what());
      return kExitNotArmed;
    }
    auto& seq = machine->sequencer();
    if (start_at_once) {
      seq.request_start();
      start_at_once = false;
    }
    // Latched at the session's first tick, before anything can start; its kFault event is not a new fault.
    bool relatch_pending = false;
    if (relatch) {
      seq.request_safe_stop(relatch->fault);
      relatch_pending = true;
      const FaultRecord& r = relatch->record;
      log(Severity::kErr, "FAULT %s (0x%04X)%s%s latched before the restart, at %s (rows %u, picks %u): %s — latched "
          "again; a restart is no reset: acknowledge it with ctl ack or the ack button", r.name.c_str(), r.code,
          r.axis.empty() ? "" : " axis ", r.axis.c_str(), LatchedFaultStore::utc(relatch->latched_at_s).c_str(),
          r.rows, r.picks, r.text.c_str());
      relatch.reset();
    }
    log(Severity::kNotice, "armed, %s: rows %u, picks %u (%u in the row in progress), beats %u",
        seq.state() == sequencer::State::kIdle ? "waiting for the operator (ctl start or the start button)"
                                               : "weaving",
        resume.rows, resume.picks, resume.picks_in_row, resume.beats);

    if (!ready_sent) {
      systemd.notify("READY=1\nSTATUS=armed, waiting for the operator");
      ready_sent = true;
    }
    const double period = cfg.sequencer.period_s;
    RowSaves row_saves;
    row_saves.saved(resume.rows);
    std::optional<sequencer::Counters> failed_save;  // the latest counters a save failed for (reporter thread)
    std::int64_t last_retry_ns = 0;
    const auto save_counters = [&](const sequencer::Counters& c) {
      store.save(c);
      if (book) book->record(c.rows);  // after the counters: a cut between lags, never leads
      row_saves.saved(c.rows);
      row_saves.saved_knots(c.rows, c.knot.cycles_started);
      failed_save.reset();
      counters_unsaved.store(false, std::memory_order_release);
    };
    // Every failed save goes through here: the loop (row_saves) and the desk (counters_unsaved) both learn it.
    const auto save_failed = [&](const sequencer::Counters& c) {
      failed_save = c;
      row_saves.failed();
      counters_unsaved.store(true, std::memory_order_release);
    };
    if (arm_unsaved) save_failed(*arm_unsaved);  // armed from memory: the disk still lags until a retry succeeds
    const auto on_event = [&](const RunEvent& e) {
      machine->collect_retired_recipes();
      switch (e.kind) {
        case RunEvent::Kind::kRowDone:
        {
          char knotting[64] = "";
          if (e.row.knotting_ticks > 0) {
            std::snprintf(knotting, sizeof knotting, ", knotted in %.2f s before it",
                          static_cast<double>(e.row.knotting_ticks) * period);
          }
          log(Severity::kInfo, "row %u done: %.2f s, %d beats, %d carriage steps (picks %u, beats %u)%s", e.row.row,
              static_cast<double>(e.row.total_ticks) * period, e.row.beats, e.row.carriage_steps, e.counters.picks,
              e.counters.beats, knotting);
        }
          break;
        case RunEvent::Kind::kPaused:
        case RunEvent::Kind::kResumed:
          log(Severity::kNotice, "%s after row %u, pick %u", e.kind == RunEvent::Kind::kPaused ? "paused" : "resumed",
              e.counters.rows, e.counters.picks);
          break;
        case RunEvent::Kind::kFault:
        case RunEvent::Kind::kOverrunStop: {
          const bool overrun = e.kind == RunEvent::Kind::kOverrunStop;
          const sequencer::Fault f = overrun ? sequencer::Fault::kLoopOverrun : e.fault;
          FaultRecord r;
          r.loom_id = cfg.loom_id;
          r.kind = overrun ? "overrun_stop" : "fault";
          r.name = sequencer::fault_name(f);
          r.code = sequencer::fault_code(f);
          r.axis = overrun ? "" : axis_label(cfg.sequencer.axes, e.fault_axis);
          r.device_code = overrun ? 0 : e.fault_detail;
          r.rows = e.counters.rows;
          r.picks = e.counters.picks;
          r.beats = e.counters.beats;
          r.text = sequencer::fault_text(f);
          if (!overrun && e.fault_sensor >= 0) {
            r.text += std::string(": ") + hal::safety_sensor_name(static_cast<hal::SafetySensor>(e.fault_sensor));
          }
          if (!overrun && e.stopped_by != e.fault) r.text += std::string(" (motion stopped on ") +
                                                            sequencer::fault_name(e.stopped_by) + ")";
          if (relatch_pending && f == e.fault) {  // the fault from before the restart: logged and on disk already
            relatch_pending = false;
            break;
          }
          relatch_pending = false;
          try {
            latched.save({f, r, static_cast<std::int64_t>(std::time(nullptr))});
          } catch (const std::exception& ex) {
            log(Severity::kErr, "latched fault not kept on disk (a restart would not latch it again): %s", ex.what());
          }
          log(Severity::kErr, "FAULT %s (0x%04X)%s%s: %s; rows %u, picks %u — acknowledge with ctl ack or the ack "
              "button", r.name.c_str(), r.code, r.axis.empty() ? "" : " axis ", r.axis.c_str(), r.text.c_str(),
              r.rows, r.picks);
          try {
            history.append(r);
          } catch (const std::exception& ex) {
            log(Severity::kErr, "%s", ex.what());
          }
          break;
        }
        case RunEvent::Kind::kButton:
          // Audit only: a press changes no counters, so nothing is saved for it.
        {
          const char* word = e.button == Command::kStart ? "start" : e.button == Command::kPause ? "pause" : "ack";
          const std::string who = std::string("the I/O module's ") +
                                  (e.button == Command::kStart   ? "start"
                                   : e.button == Command::kPause ? "pause"
                                                                 : "reset/acknowledge") +
                                  " button";
          log(Severity::kNotice, "operator: %s by %s (state %s)", word, who.c_str(), sequencer::state_name(e.state));
          if (command_events) {
            // The loop takes the press itself; the event says what the same command would have answered.
            LoomView v = view_of(link, cfg.sequencer.knotting);
            v.state = e.state;
            v.counters_unsaved = counters_unsaved.load(std::memory_order_acquire);
            const std::string verdict = desk.answer_in_state(word, v);
            command_events->publish({word, "button", who, verdict.rfind("ok", 0) == 0, verdict,
                                     sequencer::state_name(e.state)});
          }
          return;
        }
        case RunEvent::Kind::kWeaverRequest:
          // The loom waits for the weaver (lamp amber, buzzer): logged for the shift's record; the panel and
          // `ctl status` show it. Nothing changed in the counters.
          if (const sequencer::KnotProgram* p = machine->knot_program()) {
            const std::string asked = sequencer::describe(e.request, *p);
            log(Severity::kNotice, "weaver asked: %s", asked.c_str());
            std::lock_guard<std::mutex> lock(weaver_mu);
            if (weaver_answered_unheard) weaver_answered_unheard = false;  // already answered
            else weaver_request = asked;
          }
          return;
        case RunEvent::Kind::kPickDone:
        case RunEvent::Kind::kKnotProgress:
        case RunEvent::Kind::kFinished:
          break;
      }
      try {
        save_counters(e.counters);
      } catch (const std::exception& ex) {
        // The sequencer stops at the row boundary with counters_not_saved (a fault like any other); an
        // acknowledgement is refused until a retry (below) has saved these counts.
        log(Severity::kErr, "counters not saved: %s", ex.what());
        save_failed(e.counters);
      }
    };
    // The reporter thread's poll: the watchdog is fed only while the loop's tick moves, and a failed
    // save is retried, so freeing the disk lets the acknowledgement through.
    const auto reporter_poll = [&] {
      const std::int64_t now = MonotonicClock{}.now_ns();
      watchdog.poll(link.tick.load(std::memory_order_acquire), now);
      if (failed_save && now - last_retry_ns >= kSaveRetryNs) {
        last_retry_ns = now;
        try {
          save_counters(*failed_save);
          log(Severity::kNotice, "counters saved again (rows %u, picks %u): the fault can be acknowledged",
              row_saves.rows_on_disk.load(), link.picks.load());
        } catch (const std::exception&) {
          // Still failing: the fault stays and the ack is refused; the first failure was logged.
        }
      }
    };

    RunOptions ro;
    ro.period_s = period;
    ro.realtime = true;
    ro.pace = hardware ? 1.0 : a.pace;
    ro.fifo_priority = a.rt_priority;
    ro.require_fifo = hardware && !a.allow_degraded;
    ro.cpu = a.cpu;
    ro.overrun_stop_after = a.overrun_stop.value_or(hardware ? cfg.run.overrun_stop_after : 0);
    ro.row_saves = &row_saves;
    ro.link = &link;
    ro.operator_buttons = true;
    ro.hold_when_finished = true;
    ro.reporter_poll = reporter_poll;
    const RunResult res = run_loop(machine->loop(), seq, ro, on_event);
    if (auto* tm = machine->telemetry()) tm->stop();
    const std::string summary = describe_run(res, ro);
    log(res.fell_behind || res.overrun_stop ? Severity::kWarning : Severity::kInfo, "%s", summary.c_str());

    switch (res.end) {
      case RunResult::End::kError:
        log(Severity::kErr, "loomctl serve: %s", res.error.c_str());
        return kExitNotArmed;
      case RunResult::End::kStartRequested:
        log(Severity::kNotice, "start after the woven rows: re-arming for the next rows");
        start_at_once = true;
        continue;
      case RunResult::End::kAckRequested: {
        FaultRecord r;
        r.loom_id = cfg.loom_id;
        r.kind = "ack";
        const sequencer::Fault f = seq.first_fault();
        r.name = sequencer::fault_name(f);
        r.code = sequencer::fault_code(f);
        r.rows = seq.counters().rows;
        r.picks = seq.counters().picks;
        r.beats = seq.counters().beats;
        {
          std::lock_guard<std::mutex> lock(ack_mu);
          const bool by_command = !ack_by.empty() && std::chrono::steady_clock::now() - ack_at < std::chrono::seconds(1);
          r.text = "acknowledged by " + (by_command ? ack_by : std::string("the I/O module's ack button")) +
                   "; re-arming from the measured positions";
          ack_by.clear();
        }
        try {
          history.append(r);
        } catch (const std::exception& ex) {
          log(Severity::kErr, "%s", ex.what());
        }
        log(Severity::kNotice, "fault %s %s", r.name.c_str(), r.text.c_str());
        try {
          latched.clear();
        } catch (const std::exception& ex) {
          log(Severity::kErr, "acknowledged fault still on disk (a restart would latch it again): %s", ex.what());
        }
        // The counters in memory are the truth (a fault keeps them; counters_not_saved means the disk
        // lags them): write them before re-arming, which reads them back.
        try {
          save_counters(seq.counters());
        } catch (const std::exception& ex) {
          // Never re-arm from the file's older counts: the next session starts from what was woven, and
          // its first row end stops again with counters_not_saved while the disk still refuses.
          log(Severity::kErr, "counters still not saved (%s): re-arming from the counts in memory (rows %u, picks %u)",
              ex.what(), seq.counters().rows, seq.counters().picks);
          unsaved = seq.counters();
        }
        continue;
      }
      case RunResult::End::kExitRequested:
      case RunResult::End::kFinished:
      case RunResult::End::kMaxTicks:
        break;
    }
    if (failed_save) {
      try {
        save_counters(seq.counters());
      } catch (const std::exception& ex) {
        log(Severity::kErr, "counters not saved at exit (%s): %s lags rows %u, picks %u", ex.what(),
            store.path().c_str(), seq.counters().rows, seq.counters().picks);
      }
    }
    log(Severity::kNotice, "loomctl serve: stopped (rows %u, picks %u, beats %u kept in %s)", seq.counters().rows,
        seq.counters().picks, seq.counters().beats, store.path().c_str());
    break;
  }
  systemd.notify("STOPPING=1");
  g_link = nullptr;
  return kExitOk;
}

}  // namespace loom::firmware::serve

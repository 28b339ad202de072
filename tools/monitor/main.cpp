// loom-monitor: a technician's terminal view of a loom's LCM telemetry, live, from lcm-logplayer, or
// straight from a log (file://…?mode=r).
//   default             one line per event (state change, beat, row done with its force summary,
//                       fault with axis, hex codes and text) and a compact status at most once per
//                       second of loop time, a line per weaver request (knotting heads)
//   --channel KIND,...  one key=value line per message of those channels (status axes rt beat fault row
//                       design weaver knots)
// Replayed data is marked, never mixed with a live loom's: a message stamped (utime, the publisher's wall
// clock) more than --replay-after-s before now was recorded earlier and is being replayed (lcm-logplayer
// onto this group, or a log read through file://). Its lines say so ("REPLAY recorded N s ago" in the event
// view, " replayed=1 recorded_s_ago=N" at the end of key=value lines) and the event view keeps a separate
// state per loom for replayed messages, so a recording never invents state changes of the live loom.
// Exit 0 after --count lines (or, without --count, on Ctrl-C / end of log once something was printed),
// 1 when the timeout or the log ends without them, 2 on bad arguments.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <set>
#include <string>
#include <vector>

#include "lines.hpp"
#include "loom/telemetry/channels.hpp"

namespace {

volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_signal(int) {
  g_interrupted = 1;
}

constexpr double kMaxTimeoutS = 1e7;  // ~4 months: beyond that a timeout is a typo

struct Options {
  std::string lcm_url;
  std::string loom_id;
  std::string channel_prefix = std::string(loom::telemetry::kDefaultChannelPrefix);
  std::vector<std::string> channels;  // empty: the event view
  std::int64_t count = 0;
  double timeout_s = 0.0;
  double status_every_s = 1.0;
  bool no_beats = false;
  double replay_after_s = 10.0;
};

std::int64_t wall_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Handlers are static functions with a context pointer (subscribeFunction) rather than member
// functions: LCM 1.3.1's member-function subscribe() crashes when built with -fsanitize=undefined.
class Printer {
  using View = loom::monitor::EventView;

 public:
  Printer(bool event_view, std::set<std::string> raw, double status_every_s, bool show_beats,
          double replay_after_s)
      : event_view_(event_view),
        raw_(std::move(raw)),
        view_(status_every_s, show_beats),
        replay_view_(status_every_s, show_beats),
        replay_after_us_(static_cast<std::int64_t>(replay_after_s * 1e6)) {}

  template <typename Msg>
  static void on(const lcm::ReceiveBuffer*, const std::string&, const Msg* m, Printer* self) {
    self->handle(*m);
  }
  std::int64_t printed = 0;

 private:
  void handle(const loomlcm::status_t& m) {
    dispatch("status", m, &loom::monitor::status_line, &View::on_status);
  }
  void handle(const loomlcm::axes_t& m) {
    dispatch("axes", m, &loom::monitor::axes_line,
             static_cast<std::vector<std::string> (View::*)(const loomlcm::axes_t&)>(nullptr));
  }
  void handle(const loomlcm::rt_stats_t& m) { dispatch("rt", m, &loom::monitor::rt_line, &View::on_rt); }
  void handle(const loomlcm::beat_t& m) { dispatch("beat", m, &loom::monitor::beat_line, &View::on_beat); }
  void handle(const loomlcm::fault_t& m) {
    dispatch("fault", m, &loom::monitor::fault_line, &View::on_fault);
  }
  void handle(const loomlcm::row_t& m) { dispatch("row", m, &loom::monitor::row_line, &View::on_row); }
  void handle(const loomlcm::design_t& m) {
    dispatch("design", m, &loom::monitor::design_line, &View::on_design);
  }
  void handle(const loomlcm::weaver_request_t& m) {
    dispatch("weaver", m, &loom::monitor::weaver_line, &View::on_weaver);
  }
  void handle(const loomlcm::knots_t& m) {
    dispatch("knots", m, &loom::monitor::knots_line,
             static_cast<std::vector<std::string> (View::*)(const loomlcm::knots_t&)>(nullptr));
  }

  template <typename Msg>
  void dispatch(const char* kind, const Msg& m, std::string (*raw_line)(const Msg&),
                std::vector<std::string> (View::*view_lines)(const Msg&)) {
    const std::int64_t age_us = wall_utime() - m.utime;
    const bool replayed = age_us > replay_after_us_;
    const std::string ago = std::to_string(age_us / 1'000'000);
    if (replayed) note_replay(m.loom_id, ago);
    if (event_view_) {
      if (view_lines != nullptr) {
        View& v = replayed ? replay_view_ : view_;
        for (const auto& line : (v.*view_lines)(m))
          print(replayed ? "REPLAY recorded " + ago + " s ago: " + line : line);
      }
    } else if (raw_.count(kind) != 0) {
      print(replayed ? raw_line(m) + " replayed=1 recorded_s_ago=" + ago : raw_line(m));
    }
  }
  // Once per loom: say on stderr that replayed messages are arriving (on a live group they would
  // otherwise look like the loom itself).
  void note_replay(const std::string& loom_id, const std::string& ago) {
    if (!replay_noted_.insert(loom_id).second) return;
    std::fprintf(
        stderr,
        "loom-monitor: %s: replayed messages (recorded %s s ago) on this group; marked REPLAY and kept "
        "apart from the live loom (replay recordings onto their own group: tools/README.md)\n",
        loom::monitor::printable_field(loom_id).c_str(), ago.c_str());
  }
  // Flushed per line so `loom-monitor | grep` and scripts see each message as it arrives.
  void print(const std::string& line) {
    std::fputs(line.c_str(), stdout);
    std::fputc('\n', stdout);
    std::fflush(stdout);
    ++printed;
  }

  bool event_view_;
  std::set<std::string> raw_;
  View view_;         // live messages
  View replay_view_;  // replayed ones: their own per-loom state
  std::int64_t replay_after_us_;
  std::set<std::string> replay_noted_;
};

int usage_error(const std::string& msg) {
  std::fprintf(stderr, "loom-monitor: %s\n", msg.c_str());
  return 2;
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{
      "Print a loom's LCM telemetry: by default one line per event (state change, beat, row done, fault) and "
      "a "
      "compact status once per second; with --channel one key=value line per message."};
  app.add_option("--lcm-url", o.lcm_url,
                 "LCM URL, e.g. udpm://239.255.76.67:7667?ttl=0 or file:///x.lcmlog?mode=r (default: "
                 "$LCM_DEFAULT_URL or LCM's own default)");
  app.add_option("--loom-id", o.loom_id, "Only this loom (default: every loom on the URL)");
  app.add_option(
         "--channel", o.channels,
         "Print every message of these channels as key=value lines: status, axes, rt, beat, fault, row, "
         "design, weaver, knots (repeat or comma-separate)")
      ->delimiter(',');
  app.add_option("--count", o.count, "Exit 0 after printing this many lines (0: no limit)");
  app.add_option("--timeout-s", o.timeout_s,
                 "Give up after this many seconds, exit 1 if --count was not reached or nothing "
                 "was printed (0: wait forever)");
  app.add_option("--status-every-s", o.status_every_s,
                 "Event view: a compact status line at most this often, in seconds of loop time")
      ->capture_default_str();
  app.add_flag("--no-beats", o.no_beats, "Event view: leave out the per-beat lines");
  app.add_option(
         "--replay-after-s", o.replay_after_s,
         "Messages stamped more than this many seconds ago are replayed recordings: marked REPLAY and "
         "kept apart from the live loom")
      ->capture_default_str();
  app.add_option("--channel-prefix", o.channel_prefix, "First field of the channel names")
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  if (o.count < 0) return usage_error("--count " + std::to_string(o.count) + " must be >= 0");
  if (!std::isfinite(o.timeout_s) || o.timeout_s < 0.0 || o.timeout_s > kMaxTimeoutS) {
    return usage_error("--timeout-s " + std::to_string(o.timeout_s) +
                       " must be a number of seconds in [0, 1e7]");
  }
  if (!std::isfinite(o.status_every_s) || o.status_every_s < 0.0 || o.status_every_s > kMaxTimeoutS) {
    return usage_error("--status-every-s " + std::to_string(o.status_every_s) +
                       " must be a number of seconds >= 0");
  }
  if (!std::isfinite(o.replay_after_s) || o.replay_after_s < 0.0 || o.replay_after_s > kMaxTimeoutS) {
    return usage_error("--replay-after-s " + std::to_string(o.replay_after_s) +
                       " must be a number of seconds >= 0");
  }
  if (!o.loom_id.empty()) {
    if (auto e = loom::telemetry::loom_id_error(o.loom_id); !e.empty()) return usage_error("--loom-id: " + e);
  }
  if (auto e = loom::telemetry::channel_prefix_error(o.channel_prefix); !e.empty()) {
    return usage_error("--channel-prefix: " + e);
  }
  std::set<std::string> raw;
  for (const auto& c : o.channels) {
    static const std::set<std::string> kKnown = {"status", "axes",   "rt",     "beat", "fault",
                                                 "row",    "design", "weaver", "knots"};
    if (kKnown.count(c) == 0) {
      return usage_error("--channel '" + c +
                         "' is not one of status, axes, rt, beat, fault, row, design, weaver, knots");
    }
    raw.insert(c);
  }
  const bool event_view = raw.empty();

  lcm::LCM lcm(o.lcm_url);
  if (!lcm.good()) {
    return usage_error("--lcm-url '" + o.lcm_url + "' could not be opened by LCM");
  }

  Printer printer(event_view, raw, o.status_every_s, !o.no_beats, o.replay_after_s);
  // LCM keeps 30 unhandled messages per subscription by default; a log replayed fast or a burst of
  // row-end changes can exceed that, so allow a generous queue.
  constexpr int kQueue = 10000;
  const auto re = [&](const char* kind) {
    return loom::telemetry::channel_regex(o.channel_prefix, o.loom_id, kind);
  };
  const auto wanted = [&](const char* kind, bool in_view) {
    return event_view ? in_view : raw.count(kind) != 0;
  };
  std::string listening;
  const auto sub = [&](const char* kind, auto handler) {
    lcm.subscribeFunction(re(upper(kind).c_str()), handler, &printer)->setQueueCapacity(kQueue);
    listening += (listening.empty() ? "" : " ") + re(upper(kind).c_str());
  };
  if (wanted("status", true)) sub("status", &Printer::on<loomlcm::status_t>);
  if (wanted("axes", false)) sub("axes", &Printer::on<loomlcm::axes_t>);
  if (wanted("rt", true)) sub("rt", &Printer::on<loomlcm::rt_stats_t>);
  if (wanted("beat", !o.no_beats)) sub("beat", &Printer::on<loomlcm::beat_t>);
  if (wanted("fault", true)) sub("fault", &Printer::on<loomlcm::fault_t>);
  if (wanted("row", true)) sub("row", &Printer::on<loomlcm::row_t>);
  if (wanted("design", true)) sub("design", &Printer::on<loomlcm::design_t>);
  if (wanted("weaver", true)) sub("weaver", &Printer::on<loomlcm::weaver_request_t>);
  if (wanted("knots", false)) sub("knots", &Printer::on<loomlcm::knots_t>);

  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  // Scripts wait for this line before they start publishing or replaying.
  std::fprintf(stderr, "loom-monitor: listening on %s for %s\n",
               o.lcm_url.empty() ? "LCM's default URL" : o.lcm_url.c_str(), listening.c_str());

  using Clock = std::chrono::steady_clock;
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.timeout_s));
  constexpr int kSliceMs = 100;  // how often Ctrl-C and the deadline are noticed
  // A file:// URL in read mode replays a log; LCM reports its end as a failed handle().
  const bool reading_log = o.lcm_url.rfind("file://", 0) == 0;
  const char* why = "interrupted";
  while (true) {
    if (o.count > 0 && printer.printed >= o.count) return 0;
    if (g_interrupted) break;
    int slice_ms = kSliceMs;
    if (o.timeout_s > 0.0) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0) {
        why = "timed out";
        break;
      }
      slice_ms = static_cast<int>(std::min<std::int64_t>(left, kSliceMs));
    }
    if (lcm.handleTimeout(slice_ms) < 0 && !g_interrupted) {
      if (reading_log) {
        why = "end of log";
        break;
      }
      std::fprintf(stderr, "loom-monitor: LCM stopped delivering messages on %s\n", o.lcm_url.c_str());
      return 1;
    }
  }

  if (o.count > 0) {
    std::fprintf(stderr, "loom-monitor: %s with %lld of %lld lines on %s\n", why,
                 static_cast<long long>(printer.printed), static_cast<long long>(o.count), listening.c_str());
    return 1;
  }
  if (printer.printed == 0) {
    std::fprintf(stderr, "loom-monitor: %s with no message on %s\n", why, listening.c_str());
    return 1;
  }
  return 0;
}

// loom-monitor: a technician's terminal view of a loom's LCM telemetry — one line per STATUS message
// (optionally AXES and RT), live, from lcm-logplayer, or straight from a log (file://…?mode=r). Exit 0
// after --count messages (or, without --count, on Ctrl-C / end of log once something arrived), 1 when
// the timeout or the log ends without them, 2 on bad arguments.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <string>

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
  std::int64_t count = 0;
  double timeout_s = 0.0;
  bool axes = false;
  bool rt = false;
};

// Prints each message as it is handled; counts STATUS, the only kind --count refers to.
// Handlers are static functions with a context pointer (subscribeFunction) rather than member
// functions: LCM 1.3.1's member-function subscribe() crashes when built with -fsanitize=undefined.
class Printer {
 public:
  static void on_status(const lcm::ReceiveBuffer*, const std::string&, const loomlcm::status_t* m,
                        Printer* self) {
    print(loom::monitor::status_line(*m));
    ++self->status_seen;
  }
  static void on_axes(const lcm::ReceiveBuffer*, const std::string&, const loomlcm::axes_t* m, Printer*) {
    print(loom::monitor::axes_line(*m));
  }
  static void on_rt(const lcm::ReceiveBuffer*, const std::string&, const loomlcm::rt_stats_t* m, Printer*) {
    print(loom::monitor::rt_line(*m));
  }
  std::int64_t status_seen = 0;

 private:
  // Flushed per line so `loom-monitor | grep` and scripts see each message as it arrives.
  static void print(const std::string& line) {
    std::fputs(line.c_str(), stdout);
    std::fputc('\n', stdout);
    std::fflush(stdout);
  }
};

int usage_error(const std::string& msg) {
  std::fprintf(stderr, "loom-monitor: %s\n", msg.c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"Print a loom's LCM telemetry: one line per STATUS message, optionally AXES and RT."};
  app.add_option("--lcm-url", o.lcm_url,
                 "LCM URL, e.g. udpm://239.255.76.67:7667?ttl=0 (default: $LCM_DEFAULT_URL or LCM's "
                 "own default)");
  app.add_option("--loom-id", o.loom_id, "Only this loom (default: every loom on the URL)");
  app.add_option("--count", o.count, "Exit 0 after this many STATUS messages (0: no limit)");
  app.add_option("--timeout-s", o.timeout_s,
                 "Give up after this many seconds, exit 1 if --count was not reached or nothing "
                 "arrived (0: wait forever)");
  app.add_option("--channel-prefix", o.channel_prefix, "First field of the channel names")
      ->capture_default_str();
  app.add_flag("--axes", o.axes, "Also print AXES messages");
  app.add_flag("--rt", o.rt, "Also print RT (loop health) messages");
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
  if (!o.loom_id.empty()) {
    if (auto e = loom::telemetry::loom_id_error(o.loom_id); !e.empty()) return usage_error("--loom-id: " + e);
  }
  if (auto e = loom::telemetry::channel_prefix_error(o.channel_prefix); !e.empty()) {
    return usage_error("--channel-prefix: " + e);
  }

  lcm::LCM lcm(o.lcm_url);
  if (!lcm.good()) {
    return usage_error("--lcm-url '" + o.lcm_url + "' could not be opened by LCM");
  }

  Printer printer;
  const std::string status_re = loom::telemetry::channel_regex(o.channel_prefix, o.loom_id, "STATUS");
  // LCM keeps 30 unhandled messages per subscription by default; a log replayed fast or a burst of
  // row-end changes can exceed that, so allow a generous queue.
  constexpr int kQueue = 10000;
  lcm.subscribeFunction(status_re, &Printer::on_status, &printer)->setQueueCapacity(kQueue);
  if (o.axes) {
    lcm.subscribeFunction(loom::telemetry::channel_regex(o.channel_prefix, o.loom_id, "AXES"),
                          &Printer::on_axes, &printer)
        ->setQueueCapacity(kQueue);
  }
  if (o.rt) {
    lcm.subscribeFunction(loom::telemetry::channel_regex(o.channel_prefix, o.loom_id, "RT"), &Printer::on_rt,
                          &printer)
        ->setQueueCapacity(kQueue);
  }

  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  // Scripts wait for this line before they start publishing or replaying.
  std::fprintf(stderr, "loom-monitor: listening on %s for %s\n",
               o.lcm_url.empty() ? "LCM's default URL" : o.lcm_url.c_str(), status_re.c_str());

  using Clock = std::chrono::steady_clock;
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.timeout_s));
  constexpr int kSliceMs = 100;  // how often Ctrl-C and the deadline are noticed
  // A file:// URL in read mode replays a log; LCM reports its end as a failed handle().
  const bool reading_log = o.lcm_url.rfind("file://", 0) == 0;
  const char* why = "interrupted";
  while (true) {
    if (o.count > 0 && printer.status_seen >= o.count) return 0;
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
    std::fprintf(stderr, "loom-monitor: %s with %lld of %lld STATUS messages on %s\n", why,
                 static_cast<long long>(printer.status_seen), static_cast<long long>(o.count),
                 status_re.c_str());
    return 1;
  }
  if (printer.status_seen == 0) {
    std::fprintf(stderr, "loom-monitor: %s with no STATUS message on %s\n", why, status_re.c_str());
    return 1;
  }
  return 0;
}

// loom-panel — a live page per loom and a hall page, for a phone, a tablet or a hall PC. A separate,
// non-real-time process: it subscribes to the looms' LCM telemetry (every loom id it hears), keeps a
// bounded picture of each (hall.hpp) and serves it over HTTP with live updates as server-sent events.
//   loom-panel [--port 8080] [--bind 127.0.0.1] [--lcm-url URL]
//   GET /                 the hall: every loom heard          GET /loom/<id>      one loom
//   GET /api/hall         the hall as JSON                    GET /api/loom/<id>  one loom as JSON
//   GET /events[?loom=ID] server-sent events: the same JSON, pushed on change (at most 4 per second)
// Read-only: nothing it receives over HTTP reaches the loom. Binds to 127.0.0.1 unless --bind says
// otherwise (a hall network). Exit 2 on bad arguments, 1 when it cannot listen or open LCM.
#include <httplib.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <thread>

#include "hall.hpp"
#include "loom/telemetry/channels.hpp"

namespace loom::panel {
extern const char* const kPanelHtml;
}

namespace {

using loom::panel::Hall;

std::atomic<bool> g_stop{false};
httplib::Server* g_server = nullptr;
extern "C" void on_signal(int) {
  g_stop.store(true);
}

struct PanelOptions {
  int port = 8080;
  std::string bind = "127.0.0.1";
  std::string lcm_url;
  std::string channel_prefix = std::string(loom::telemetry::kDefaultChannelPrefix);
  double min_push_interval_s = 0.25;  // live updates are coalesced to at most this often per client
  int http_threads = 32;              // each open page holds one for its event stream
  // Operator buttons (pause / resume / stop at row end / acknowledge) will act through the board's
  // local control socket, never over LCM. Empty = read-only, and no option sets it yet: the socket
  // is the board's to provide. The page shows buttons only when the JSON says "controls": true.
  std::string control_socket;
};

template <typename Msg>
void handler(const lcm::ReceiveBuffer*, const std::string&, const Msg* m, Hall* hall);
template <>
void handler(const lcm::ReceiveBuffer*, const std::string&, const loomlcm::status_t* m, Hall* h) { h->on_status(*m); }
template <>
void handler(const lcm::ReceiveBuffer*, const std::string&, const loomlcm::axes_t* m, Hall* h) { h->on_axes(*m); }
template <>
void handler(const lcm::ReceiveBuffer*, const std::string&, const loomlcm::rt_stats_t* m, Hall* h) { h->on_rt(*m); }
template <>
void handler(const lcm::ReceiveBuffer*, const std::string&, const loomlcm::beat_t* m, Hall* h) { h->on_beat(*m); }
template <>
void handler(const lcm::ReceiveBuffer*, const std::string&, const loomlcm::fault_t* m, Hall* h) { h->on_fault(*m); }
template <>
void handler(const lcm::ReceiveBuffer*, const std::string&, const loomlcm::row_t* m, Hall* h) { h->on_row(*m); }

std::string json_for(const Hall& hall, const std::string& loom) {
  if (loom.empty()) return hall.hall_json().dump();
  const auto j = hall.loom_json(loom);
  return j ? j->dump() : nlohmann::json{{"id", loom}, {"heard", false}}.dump();
}

}  // namespace

int main(int argc, char** argv) {
  PanelOptions o;
  CLI::App app{"loom-panel — live web page of every loom's LCM telemetry (read-only)"};
  app.add_option("--port", o.port, "TCP port (0: any free port, printed on start)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  app.add_option("--bind", o.bind, "address to listen on (0.0.0.0 for a hall network)")->capture_default_str();
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or udpm://239.255.76.67:7667?ttl=0)");
  app.add_option("--channel-prefix", o.channel_prefix, "first field of the channel names")->capture_default_str();
  app.add_option("--min-push-interval-s", o.min_push_interval_s, "shortest gap between two live updates of a page")
      ->check(CLI::Range(0.01, 60.0))
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "loom-panel: %s\n", e.what());
    return 2;
  }
  if (auto e = loom::telemetry::channel_prefix_error(o.channel_prefix); !e.empty()) {
    std::fprintf(stderr, "loom-panel: --channel-prefix: %s\n", e.c_str());
    return 2;
  }

  Hall hall;
  lcm::LCM lcm(o.lcm_url);
  if (!lcm.good()) {
    std::fprintf(stderr, "loom-panel: --lcm-url '%s' could not be opened by LCM\n", o.lcm_url.c_str());
    return 1;
  }
  const auto re = [&](const char* kind) { return loom::telemetry::channel_regex(o.channel_prefix, "", kind); };
  constexpr int kQueue = 10000;  // 20 looms at full rate between two handle() calls fit easily
  lcm.subscribeFunction(re("STATUS"), &handler<loomlcm::status_t>, &hall)->setQueueCapacity(kQueue);
  lcm.subscribeFunction(re("AXES"), &handler<loomlcm::axes_t>, &hall)->setQueueCapacity(kQueue);
  lcm.subscribeFunction(re("RT"), &handler<loomlcm::rt_stats_t>, &hall)->setQueueCapacity(kQueue);
  lcm.subscribeFunction(re("BEAT"), &handler<loomlcm::beat_t>, &hall)->setQueueCapacity(kQueue);
  lcm.subscribeFunction(re("FAULT"), &handler<loomlcm::fault_t>, &hall)->setQueueCapacity(kQueue);
  lcm.subscribeFunction(re("ROW"), &handler<loomlcm::row_t>, &hall)->setQueueCapacity(kQueue);

  httplib::Server svr;
  svr.new_task_queue = [&] { return new httplib::ThreadPool(static_cast<std::size_t>(o.http_threads)); };
  const auto page = [](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(loom::panel::kPanelHtml, "text/html; charset=utf-8");
  };
  svr.Get("/", page);
  svr.Get(R"(/loom/([A-Za-z0-9_-]{1,32}))", page);
  svr.Get("/api/hall", [&](const httplib::Request&, httplib::Response& res) {
    res.set_content(hall.hall_json().dump(), "application/json");
  });
  svr.Get(R"(/api/loom/([A-Za-z0-9_-]{1,32}))", [&](const httplib::Request& req, httplib::Response& res) {
    const auto j = hall.loom_json(req.matches[1]);
    if (!j) {
      res.status = 404;
      res.set_content(nlohmann::json{{"error", "loom not heard"}, {"id", std::string(req.matches[1])}}.dump(),
                      "application/json");
      return;
    }
    res.set_content(j->dump(), "application/json");
  });
  svr.Get("/events", [&](const httplib::Request& req, httplib::Response& res) {
    const std::string loom = req.has_param("loom") ? req.get_param_value("loom") : std::string();
    if (!loom.empty() && !loom::telemetry::loom_id_error(loom).empty()) {
      res.status = 400;
      res.set_content("bad loom id\n", "text/plain");
      return;
    }
    res.set_header("Cache-Control", "no-store");
    const auto gap = std::chrono::duration_cast<std::chrono::milliseconds>(
        std::chrono::duration<double>(o.min_push_interval_s));
    // Each call of the provider sends one event: the current JSON, once it differs from the last sent.
    auto seen = std::make_shared<std::uint64_t>(~std::uint64_t{0});
    res.set_chunked_content_provider("text/event-stream", [&hall, loom, gap, seen](std::size_t, httplib::DataSink& sink) {
      const auto t0 = std::chrono::steady_clock::now();
      // Wake every second to notice a closed page or a stopping server; a comment keeps proxies awake.
      for (;;) {
        if (g_stop.load() || !sink.is_writable()) return false;
        const std::uint64_t v = hall.wait_for_change(*seen, std::chrono::milliseconds(1000));
        if (v != *seen) break;
        if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(15)) {
          static const char kKeepAlive[] = ": keep-alive\n\n";
          return sink.write(kKeepAlive, sizeof kKeepAlive - 1);
        }
      }
      *seen = hall.version();
      const std::string msg = "data: " + json_for(hall, loom) + "\n\n";
      if (!sink.write(msg.data(), msg.size())) return false;
      std::this_thread::sleep_for(gap);  // coalesce: a busy loom costs at most one update per gap
      return true;
    });
  });

  int port = o.port;
  if (port == 0) {
    port = svr.bind_to_any_port(o.bind);
  } else if (!svr.bind_to_port(o.bind, port)) {
    port = -1;
  }
  if (port < 0) {
    std::fprintf(stderr, "loom-panel: cannot listen on %s:%d\n", o.bind.c_str(), o.port);
    return 1;
  }
  g_server = &svr;
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  std::thread http([&] { svr.listen_after_bind(); });
  std::fprintf(stderr, "loom-panel: serving http://%s:%d/ (read-only), LCM %s\n", o.bind.c_str(), port,
               o.lcm_url.empty() ? "default URL" : o.lcm_url.c_str());
  while (!g_stop.load()) {
    if (lcm.handleTimeout(200) < 0) {
      std::fprintf(stderr, "loom-panel: LCM stopped delivering messages\n");
      break;
    }
  }
  svr.stop();
  http.join();
  return g_stop.load() ? 0 : 1;
}

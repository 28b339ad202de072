// loom-panel — a live page per loom and a hall page, for a phone, a tablet or a hall PC. A separate,
// non-real-time process: it subscribes to the looms' LCM telemetry (every loom id it hears), keeps a
// bounded picture of each (hall.hpp) and serves it over HTTP with live updates as server-sent events.
//   loom-panel [--port 8080] [--bind 127.0.0.1] [--lcm-url URL] [--tls-cert FILE --tls-key FILE]
//   GET /                 the hall: every loom heard          GET /loom/<id>      one loom
//   GET /api/hall         the hall as JSON                    GET /api/loom/<id>  one loom as JSON
//   GET /events[?loom=ID] server-sent events: the same JSON, pushed on change (at most 4 per second)
//   POST /api/loom/<id>/ctl/<pause|resume|stop|ack|next>   operator buttons, only with --control-dir
//   POST /api/loom/<id>/pair  (body: the code from `loomctl ctl pair NAME`)  pair this client
//   GET  /api/loom/<id>/authority   whether this client is paired (may give starting commands)
//   GET  /api/loom/<id>/history     the loom's persisted fault history (faults.log), with --control-dir
//   GET  /api/loom/<id>/faults.log  all of it, as a file to download
//   GET  /api/loom/<id>/rows.csv    the row report: every row the panel kept (newest 500), as CSV
//   GET  /api/loom/<id>/last.lcmlog every message of that loom heard in the last 5 minutes (--lcmlog-minutes)
//   GET  /api/loom/<id>/carpet      the current carpet job's knot map (JOB/CARPET), for the carpet view
//   POST /api/loom/<id>/ctl/reload?head=H&slot=S[&knots=K]   "slot reloaded" (paired clients only)
//   GET  /api/loom/<id>/jobs[?id=N]   the loom's job queue (`job list`, as rows) or one job (`job show`)
//   POST /api/loom/<id>/job/<add|remove|start-over>   change the job queue (paired clients only):
//        add: design=/PATH on the loom's board [rows=R|metres=M|repeat=K]; remove, start-over: id=N
//   GET  /api/loom/<id>/scope?axis=NAME   the last 30 s of one axis' position, velocity, following error
// Read-only by default: nothing it receives over HTTP reaches the loom. With --control-dir DIR the
// page offers pause / stop at row end to every client, and resume / acknowledge / "row knotted" only to
// a client paired with that loom (request_gate.hpp), each sent to that loom's local control socket
// DIR/<id>.sock (loomctl serve's) tagged with the client's address, the page's device secret and its
// token, so the loom decides and audits who pressed; never published on LCM. With --tls-cert it serves
// HTTPS only and the pairing cookie is Secure (README.md: the hall's threat model). Host and Origin are
// checked, bodies, connections and event streams bounded (README.md). Binds to 127.0.0.1 unless --bind says
// otherwise (a hall network). A recording replayed onto the group (stamped older than --replay-after-s) is
// shown apart as <id>~replay, marked, without buttons; it never mixes into the live loom of that id. Exit 2
// on bad arguments, 1 when it cannot listen or open LCM.
#include <httplib.h>
#include <sys/stat.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "fault_history.hpp"
#include "hall.hpp"
#include "job_request.hpp"
#include "loom/firmware/serve/control_socket.hpp"
#include "loom/telemetry/channels.hpp"
#include "recorder.hpp"
#include "request_gate.hpp"
#include "udpm_receiver.hpp"

namespace loom::panel {
extern const char* const kPanelHtml;
}

namespace {

using loom::panel::Hall;

// Lines of the persisted fault history a page shows (the newest; serve keeps 256-512 KiB of them).
constexpr std::size_t kHistoryShown = 50;

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
  int http_threads = 64;              // each open page holds one for its event stream
  int max_streams = 16;               // event streams at once (each holds a thread); more get 503
  int max_streams_per_client = 4;     // per client address
  double replay_after_s = 10.0;       // older stamps are a replayed recording: shown apart, marked (hall.hpp)
  double lcmlog_minutes = 5.0;        // the flight recorder's window (0: off)
  double lcmlog_mib = 64.0;           // its memory for all looms together
  std::vector<std::string> hosts;     // --host: names the hall uses for this panel (Host header check)
  // Operator buttons act through the board's local control sockets, <control_dir>/<loom id>.sock,
  // never over LCM. Empty = read-only. The page shows buttons only when the JSON says "controls": true
  // (the option is set and that loom's socket exists).
  std::string control_dir;
  // TLS: the certificate (PEM, chain first) and its key; both or neither. With them the panel serves
  // HTTPS only and its pairing cookies are Secure.
  std::string tls_cert, tls_key;
  bool tls() const { return !tls_cert.empty(); }
};

// The client's pairing token for `loom`, from its cookie loom_token_<id> ("" when none or malformed).
std::string token_of(const httplib::Request& req, const std::string& loom) {
  const std::string cookies = req.get_header_value("Cookie");
  const std::string key = "loom_token_" + loom + "=";
  std::size_t at = 0;
  while ((at = cookies.find(key, at)) != std::string::npos) {
    if (at == 0 || cookies[at - 1] == ' ' || cookies[at - 1] == ';') {
      const std::size_t v = at + key.size();
      const std::string tok = cookies.substr(v, cookies.find(';', v) - v);
      return loom::panel::token_shape(tok) ? tok : std::string();
    }
    at += key.size();
  }
  return "";
}

// The page's per-device secret (X-Loom-Device, kept in the browser's storage), "" when none or malformed.
std::string device_of(const httplib::Request& req) {
  const std::string d = req.get_header_value("X-Loom-Device");
  return loom::panel::device_shape(d) ? d : std::string();
}

// A request line for the loom's control socket on behalf of this HTTP client: its address, the page's
// device secret and its token (the loom counts a token only from the address and secret it was
// redeemed with).
std::string on_behalf(const std::string& word, const httplib::Request& req, const std::string& token) {
  std::string client;
  for (char c : req.remote_addr) client += (c > ' ' && c < 0x7F) ? c : '?';
  const std::string device = device_of(req);
  return word + " via=panel client=" + (client.empty() ? "unknown" : client) +
         (device.empty() ? "" : " device=" + device) + (token.empty() ? "" : " token=" + token);
}

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

// The words of a reply line "ok redeem NAME token=T expires=E": the value of `key`, or "".
std::string reply_field(const std::string& reply, const std::string& key) {
  const auto at = reply.find(" " + key + "=");
  if (at == std::string::npos) return "";
  const auto v = at + key.size() + 2;
  return reply.substr(v, reply.find_first_of(" \n", v) - v);
}

// Counts the event streams open, in all and per client; a stream is admitted only under both limits.
class StreamSlots {
 public:
  StreamSlots(int total, int per_client) : total_(total), per_client_(per_client) {}
  bool take(const std::string& client) {
    std::lock_guard<std::mutex> lock(mu_);
    if (open_ >= total_ || by_client_[client] >= per_client_) return false;
    ++open_;
    ++by_client_[client];
    return true;
  }
  void give(const std::string& client) {
    std::lock_guard<std::mutex> lock(mu_);
    --open_;
    if (--by_client_[client] <= 0) by_client_.erase(client);
  }

 private:
  std::mutex mu_;
  int total_, per_client_, open_ = 0;
  std::map<std::string, int> by_client_;
};

std::string control_socket_of(const PanelOptions& o, const std::string& loom) {
  return o.control_dir + "/" + loom + ".sock";
}

bool controls_for(const PanelOptions& o, const std::string& loom) {
  // A replayed recording has no loom behind it to command.
  if (loom.find('~') != std::string::npos) return false;
  struct stat st {};
  return !o.control_dir.empty() && ::stat(control_socket_of(o, loom).c_str(), &st) == 0 &&
         S_ISSOCK(st.st_mode);
}

// Routes one received message by its channel, <prefix>.<loom id>.<KIND>, to the hall. AXES comes at
// up to 50 Hz per loom; a page needs a few per second, so each loom's AXES is decoded at most every
// 100 ms and the rest are skipped before decoding.
class Router {
 public:
  Router(Hall& hall, loom::panel::Recorder& recorder, std::string prefix)
      : hall_(hall), recorder_(recorder), prefix_(std::move(prefix) + ".") {}
  // Live traffic only: a log replayed at full speed would otherwise keep just its first AXES.
  void throttle_axes(bool on) { throttle_axes_ = on; }

  void route(std::string_view channel, const void* data, std::size_t size) {
    if (channel.substr(0, prefix_.size()) != prefix_) return;
    const std::string_view rest = channel.substr(prefix_.size());
    const auto dot = rest.rfind('.');
    if (dot == std::string_view::npos) return;
    const std::string_view id = rest.substr(0, dot), kind = rest.substr(dot + 1);
    if (!loom::telemetry::loom_id_error(id).empty()) return;
    // Every message as received (before throttling) into the flight recorder: the lcmlog download.
    if (recorder_.enabled()) {
      recorder_.add(id, channel, data, size,
                    std::chrono::duration_cast<std::chrono::microseconds>(
                        std::chrono::system_clock::now().time_since_epoch())
                        .count());
    }
    const int len = static_cast<int>(size);
    if (kind == "STATUS") {
      decode<loomlcm::status_t>(data, len, [&](const auto& m) { hall_.on_status(m); });
    } else if (kind == "AXES") {
      const auto now =
          throttle_axes_ ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
      auto it = last_axes_.find(id);
      if (it == last_axes_.end())
        it = last_axes_.emplace(std::string(id), now - std::chrono::seconds(1)).first;
      if (throttle_axes_ && now - it->second < std::chrono::milliseconds(100)) return;
      it->second = now;
      decode<loomlcm::axes_t>(data, len, [&](const auto& m) { hall_.on_axes(m); });
    } else if (kind == "RT") {
      decode<loomlcm::rt_stats_t>(data, len, [&](const auto& m) { hall_.on_rt(m); });
    } else if (kind == "BEAT") {
      decode<loomlcm::beat_t>(data, len, [&](const auto& m) { hall_.on_beat(m); });
    } else if (kind == "FAULT") {
      decode<loomlcm::fault_t>(data, len, [&](const auto& m) { hall_.on_fault(m); });
    } else if (kind == "ROW") {
      decode<loomlcm::row_t>(data, len, [&](const auto& m) { hall_.on_row(m); });
    } else if (kind == "DESIGN") {
      decode<loomlcm::design_t>(data, len, [&](const auto& m) { hall_.on_design(m); });
    } else if (kind == "KNOTS") {
      decode<loomlcm::knots_t>(data, len, [&](const auto& m) { hall_.on_knots(m); });
    } else if (kind == "WEAVER") {
      decode<loomlcm::weaver_request_t>(data, len, [&](const auto& m) { hall_.on_weaver(m); });
    } else if (kind == "JOB") {
      decode<loomlcm::job_t>(data, len, [&](const auto& m) { hall_.on_job(m); });
    } else if (kind == "CARPET") {
      decode<loomlcm::carpet_t>(data, len, [&](const auto& m) { hall_.on_carpet(m); });
    }
  }
  std::uint64_t decode_errors() const { return decode_errors_; }

  // For LCM's own receive path (file://, memq://, or a udpm the lean receiver cannot open).
  static void on_lcm(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Router* self) {
    self->route(channel, rbuf->data, rbuf->data_size);
  }

 private:
  template <typename Msg, typename F>
  void decode(const void* data, int len, F&& use) {
    Msg m;
    // decode() checks the type's fingerprint first: another type on the channel is an error, not garbage.
    if (m.decode(data, 0, len) < 0) {
      ++decode_errors_;
      return;
    }
    use(m);
  }
  Hall& hall_;
  loom::panel::Recorder& recorder_;
  std::string prefix_;
  std::map<std::string, std::chrono::steady_clock::time_point, std::less<>> last_axes_;
  std::uint64_t decode_errors_ = 0;
  bool throttle_axes_ = true;
};

std::optional<nlohmann::json> loom_json(const Hall& hall, const PanelOptions& o, const std::string& loom) {
  auto j = hall.loom_json(loom);
  if (j) (*j)["controls"] = controls_for(o, loom);
  return j;
}

std::string json_for(const Hall& hall, const PanelOptions& o, const std::string& loom) {
  if (loom.empty()) return loom::panel::json_text(hall.hall_json());
  const auto j = loom_json(hall, o, loom);
  return loom::panel::json_text(j ? *j : nlohmann::json{{"id", loom}, {"heard", false}});
}

}  // namespace

int main(int argc, char** argv) {
  PanelOptions o;
  CLI::App app{"loom-panel — live web page of every loom's LCM telemetry (read-only)"};
  app.add_option("--port", o.port, "TCP port (0: any free port, printed on start)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  app.add_option("--bind", o.bind, "address to listen on (0.0.0.0 for a hall network)")
      ->capture_default_str();
  app.add_option("--lcm-url", o.lcm_url,
                 "LCM URL (default: $LCM_DEFAULT_URL or udpm://239.255.76.67:7667?ttl=0)");
  app.add_option("--channel-prefix", o.channel_prefix, "first field of the channel names")
      ->capture_default_str();
  app.add_option(
      "--control-dir", o.control_dir,
      "operator buttons: send them to the looms' control sockets DIR/<loom id>.sock (loomctl serve; "
      "on a board /run/loomctl). Without it the panel is read-only");
  app.add_option(
         "--host", o.hosts,
         "a name the hall uses for this panel (repeatable); requests naming any other host are refused")
      ->check([](const std::string& h) {
        return h.empty() || h.size() > 253 ? std::string("bad host name") : std::string();
      });
  app.add_option("--max-streams", o.max_streams, "live pages (event streams) served at once")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--min-push-interval-s", o.min_push_interval_s,
                 "shortest gap between two live updates of a page")
      ->check(CLI::Range(0.01, 60.0))
      ->capture_default_str();
  app.add_option(
         "--lcmlog-minutes", o.lcmlog_minutes,
         "keep every message of the last this many minutes per loom, downloadable as an lcmlog (0: off)")
      ->check(CLI::Range(0.0, 60.0))
      ->capture_default_str();
  app.add_option("--lcmlog-mib", o.lcmlog_mib, "memory for those messages, all looms together (MiB)")
      ->check(CLI::Range(1.0, 4096.0))
      ->capture_default_str();
  auto* cert =
      app.add_option("--tls-cert", o.tls_cert,
                     "serve HTTPS with this certificate (PEM; a board's is /etc/loomctl/panel.crt, made at "
                     "install when the builder gave none); pairing cookies become Secure")
          ->check(CLI::ExistingFile);
  auto* key =
      app.add_option("--tls-key", o.tls_key, "the private key of --tls-cert (PEM)")->check(CLI::ExistingFile);
  cert->needs(key);
  key->needs(cert);
  app.add_option(
         "--replay-after-s", o.replay_after_s,
         "a message stamped longer ago than this is a replayed recording: shown apart as <id>~replay and "
         "marked REPLAY (0: every message is live)")
      ->check(CLI::Range(0.0, 1e6))
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

  loom::panel::HallLimits limits;
  limits.replay_after_s = o.replay_after_s;
  Hall hall(limits);
  loom::panel::Recorder recorder(o.lcmlog_minutes * 60.0,
                                 static_cast<std::size_t>(o.lcmlog_mib * 1024 * 1024));
  Router router(hall, recorder, o.channel_prefix);
  // udpm (the normal case): the lean batched receiver. Anything else: LCM's own provider.
  std::unique_ptr<loom::panel::UdpmReceiver> udpm;
  std::unique_ptr<lcm::LCM> lcm;
  if (const auto addr = loom::panel::parse_udpm_url(o.lcm_url)) {
    try {
      udpm = std::make_unique<loom::panel::UdpmReceiver>(*addr);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "loom-panel: --lcm-url '%s': %s\n", o.lcm_url.c_str(), e.what());
      return 1;
    }
  } else {
    router.throttle_axes(false);
    lcm = std::make_unique<lcm::LCM>(o.lcm_url);
    if (!lcm->good()) {
      std::fprintf(stderr, "loom-panel: --lcm-url '%s' could not be opened by LCM\n", o.lcm_url.c_str());
      return 1;
    }
    std::string re;
    for (char c : o.channel_prefix) re += c == '.' ? std::string("\\.") : std::string(1, c);
    lcm->subscribeFunction(re + "\\..*", &Router::on_lcm, &router)->setQueueCapacity(10000);
  }

  std::unique_ptr<httplib::Server> server;
  if (o.tls()) {
    auto ssl = std::make_unique<httplib::SSLServer>(o.tls_cert.c_str(), o.tls_key.c_str());
    if (!ssl->is_valid()) {
      std::fprintf(stderr,
                   "loom-panel: --tls-cert %s / --tls-key %s: not a usable certificate and key (PEM)\n",
                   o.tls_cert.c_str(), o.tls_key.c_str());
      return 2;
    }
    server = std::move(ssl);
  } else {
    server = std::make_unique<httplib::Server>();
  }
  httplib::Server& svr = *server;
  svr.new_task_queue = [&] { return new httplib::ThreadPool(static_cast<std::size_t>(o.http_threads)); };
  // Bounded: bodies (a pairing code is a few bytes), idle and slow connections, keep-alive reuse.
  svr.set_payload_max_length(4096);
  svr.set_read_timeout(5, 0);
  svr.set_write_timeout(5, 0);
  svr.set_keep_alive_timeout(5);
  svr.set_keep_alive_max_count(100);
  for (std::string& h : o.hosts) {
    std::transform(h.begin(), h.end(), h.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  }
  loom::panel::GateConfig gate{o.bind, o.port, o.hosts};
  // Every request: its Host must name this panel (DNS rebinding); a POST must come from this panel's own
  // page (Origin) and carry X-Loom-Panel (a cross-site form cannot).
  svr.set_pre_routing_handler([&](const httplib::Request& req, httplib::Response& res) {
    const auto refuse = [&](int status, const std::string& why) {
      res.status = status;
      res.set_content(loom::panel::json_text({{"error", why}}), "application/json");
      std::fprintf(stderr, "loom-panel: refused %s %s from %s: %s\n", req.method.c_str(),
                   req.path.substr(0, 80).c_str(), req.remote_addr.c_str(), why.c_str());
      return httplib::Server::HandlerResponse::Handled;
    };
    if (auto why = loom::panel::host_refusal(gate, req.get_header_value("Host")); !why.empty())
      return refuse(421, why);
    if (req.method != "GET" && req.method != "HEAD") {
      if (auto why =
              loom::panel::origin_refusal(req.get_header_value("Origin"), req.get_header_value("Host"));
          !why.empty()) {
        return refuse(403, why);
      }
      if (req.get_header_value("X-Loom-Panel") != "1") return refuse(403, "missing X-Loom-Panel header");
      // A body without a length is read until the connection's timeout: the command would be carried out
      // after the client gave up. Refused instead.
      if (!req.has_header("Content-Length")) return refuse(411, "a POST needs Content-Length");
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  const auto page = [](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(loom::panel::kPanelHtml, "text/html; charset=utf-8");
  };
  svr.Get("/", page);
  // A loom's page and JSON also for a replayed recording (<id>~replay); commands never (POST routes below).
  svr.Get(R"(/loom/([A-Za-z0-9_-]{1,32}(?:~replay)?))", page);
  svr.Get("/api/hall", [&](const httplib::Request&, httplib::Response& res) {
    res.set_content(loom::panel::json_text(hall.hall_json()), "application/json");
  });
  svr.Get(R"(/api/loom/([A-Za-z0-9_-]{1,32}(?:~replay)?))",
          [&](const httplib::Request& req, httplib::Response& res) {
            const auto j = loom_json(hall, o, req.matches[1]);
            if (!j) {
              res.status = 404;
              res.set_content(
                  loom::panel::json_text({{"error", "loom not heard"}, {"id", std::string(req.matches[1])}}),
                  "application/json");
              return;
            }
            res.set_content(loom::panel::json_text(*j), "application/json");
          });
  // The scope strip of one axis (?axis=NAME; the first axis when none): the last seconds of its position,
  // velocity and following error. The page polls it once a second for the axis the technician picked.
  svr.Get(R"(/api/loom/([A-Za-z0-9_-]{1,32}(?:~replay)?)/scope)",
          [&](const httplib::Request& req, httplib::Response& res) {
            const std::string loom = req.matches[1];
            res.set_header("Cache-Control", "no-store");
            std::string axis = req.has_param("axis") ? req.get_param_value("axis") : std::string();
            if (axis.size() > 64) axis.clear();
            auto j = hall.scope_json(loom, axis);
            if (j && axis.empty() && !(*j)["axes"].empty())
              j = hall.scope_json(loom, (*j)["axes"][0].get<std::string>());
            if (!j) {
              res.status = 404;
              res.set_content(loom::panel::json_text({{"error", "loom not heard"}, {"id", loom}}),
                              "application/json");
              return;
            }
            res.set_content(loom::panel::json_text(*j), "application/json");
          });
  // The current carpet job's knot map (CARPET), fetched by the page when the loom's JSON says it changed.
  svr.Get(R"(/api/loom/([A-Za-z0-9_-]{1,32}(?:~replay)?)/carpet)",
          [&](const httplib::Request& req, httplib::Response& res) {
            res.set_header("Cache-Control", "no-store");
            const auto j = hall.carpet_json(req.matches[1]);
            if (!j) {
              res.status = 404;
              res.set_content(loom::panel::json_text({{"error", "no knot map heard"}}), "application/json");
              return;
            }
            res.set_content(loom::panel::json_text(*j), "application/json");
          });
  // An operator button, forwarded to the loom on behalf of this client (its address and pairing token):
  // the loom decides and audits. A starting command without a token is refused here and never forwarded.
  svr.Post(R"(/api/loom/([A-Za-z0-9_-]{1,32})/ctl/([a-z]{1,16}))", [&](const httplib::Request& req,
                                                                       httplib::Response& res) {
    const std::string loom = req.matches[1], cmd = req.matches[2];
    const auto reply = [&](int status, const std::string& text) {
      res.status = status;
      res.set_content(loom::panel::json_text({{"loom", loom}, {"command", cmd}, {"reply", text}}),
                      "application/json");
      std::fprintf(stderr, "loom-panel: %s %s by %s%s -> %s\n", loom.c_str(), cmd.c_str(),
                   req.remote_addr.c_str(), token_of(req, loom).empty() ? " (not paired)" : " (token)",
                   text.c_str());
    };
    if (o.control_dir.empty())
      return reply(403, "read-only panel (start it with --control-dir to offer buttons)");
    const auto cls = loom::panel::panel_command(cmd);
    if (cls == loom::panel::PanelCommand::kUnknown)
      return reply(400, "unknown command (pause, stop, resume, ack, next, reload)");
    // "Slot reloaded": which head and slot (1-based, as the weaver counts them) and, optionally, the knots
    // of yarn put in (a partly filled slot); only digits reach the loom's socket.
    std::string line = cmd;
    if (cmd == "reload") {
      const auto digits = [&](const char* name, std::size_t max_len, bool required) {
        const std::string v = req.has_param(name) ? req.get_param_value(name) : std::string();
        if (v.empty()) return required ? std::string("?") : std::string();
        if (v.size() > max_len || v.find_first_not_of("0123456789") != std::string::npos)
          return std::string("?");
        return v;
      };
      const std::string head = digits("head", 2, true), slot = digits("slot", 2, true),
                        knots = digits("knots", 7, false);
      if (head == "?" || slot == "?" || knots == "?") {
        return reply(400, "reload needs head=H and slot=S (numbers, 1-based) and optionally knots=K");
      }
      line += " head=" + head + " slot=" + slot + (knots.empty() ? "" : " knots=" + knots);
    }
    const std::string token = token_of(req, loom);
    if (cls == loom::panel::PanelCommand::kStarting && token.empty()) {
      return reply(
          403,
          "refused: " + cmd + ": this device is not paired with loom " + loom +
              " (a command that starts motion or resets a fault needs pairing: ctl pair NAME at the loom)");
    }
    std::string text;
    try {
      text = trimmed(loom::firmware::serve::control_request(control_socket_of(o, loom),
                                                            on_behalf(line, req, token), 3000));
    } catch (const std::exception& e) {
      return reply(503, e.what());
    }
    reply(text.rfind("ok", 0) == 0 ? 200 : text.rfind("refused:", 0) == 0 ? 403 : 409, text);
  });
  // The job queue (issue 29), through the loom's socket as `ctl job` at the loom. Reading is for anyone:
  // the queue as rows (the loom's `job list`), or one job's `job show` text with ?id=N.
  svr.Get(R"(/api/loom/([A-Za-z0-9_-]{1,32})/jobs)", [&](const httplib::Request& req,
                                                         httplib::Response& res) {
    const std::string loom = req.matches[1];
    res.set_header("Cache-Control", "no-store");
    const auto error = [&](int status, const std::string& why) {
      res.status = status;
      res.set_content(loom::panel::json_text({{"loom", loom}, {"error", why}}), "application/json");
    };
    if (o.control_dir.empty()) {
      return error(
          404, "read-only panel: the loom's job queue is read through its control socket (--control-dir)");
    }
    std::string line = "job list";
    if (req.has_param("id")) {
      const std::string id = req.get_param_value("id");
      if (id.empty() || id.size() > 10 || id.find_first_not_of("0123456789") != std::string::npos)
        return error(400, "id: a job number (1, 2, ...)");
      line = "job show id=" + id;
    }
    std::string text;
    try {
      text =
          loom::firmware::serve::control_request(control_socket_of(o, loom), on_behalf(line, req, ""), 3000);
    } catch (const std::exception& e) {
      return error(503, e.what());
    }
    if (text.rfind("error:", 0) == 0 || text.rfind("refused:", 0) == 0) return error(502, trimmed(text));
    auto j = req.has_param("id") ? nlohmann::json{{"text", text}} : loom::panel::job_list_json(text);
    j["loom"] = loom;
    res.set_content(loom::panel::json_text(j), "application/json");
  });
  // Changing the queue: add a job, remove one, start one over. Like a starting button, only for a paired
  // client: without a token the panel refuses it here and never forwards it; the loom decides and audits.
  // A job is never started from here (`start` stays at the machine).
  svr.Post(R"(/api/loom/([A-Za-z0-9_-]{1,32})/job/([a-z-]{1,16}))", [&](const httplib::Request& req,
                                                                        httplib::Response& res) {
    const std::string loom = req.matches[1], verb = req.matches[2];
    const auto reply = [&](int status, const std::string& text) {
      res.status = status;
      res.set_content(loom::panel::json_text({{"loom", loom}, {"command", "job " + verb}, {"reply", text}}),
                      "application/json");
      std::fprintf(stderr, "loom-panel: %s job %s by %s%s -> %s\n", loom.c_str(), verb.c_str(),
                   req.remote_addr.c_str(), token_of(req, loom).empty() ? " (not paired)" : " (token)",
                   text.c_str());
    };
    if (o.control_dir.empty())
      return reply(403, "read-only panel (start it with --control-dir to offer buttons)");
    const auto v = loom::panel::job_verb(verb);
    if (v == loom::panel::JobVerb::kUnknown) return reply(400, "unknown job verb (add, remove, start-over)");
    std::string why;
    const std::string line = loom::panel::job_line(
        v,
        [&](const char* name) -> std::optional<std::string> {
          if (!req.has_param(name) || req.get_param_value(name).empty()) return std::nullopt;
          return req.get_param_value(name);
        },
        why);
    if (line.empty()) return reply(400, "refused: job " + verb + ": " + why);
    const std::string token = token_of(req, loom);
    if (token.empty()) {
      return reply(403,
                   "refused: job " + verb + ": this device is not paired with loom " + loom +
                       " (changing the job queue needs pairing, as a start does: ctl pair NAME at the loom)");
    }
    std::string text;
    try {
      text = trimmed(loom::firmware::serve::control_request(control_socket_of(o, loom),
                                                            on_behalf(line, req, token), 3000));
    } catch (const std::exception& e) {
      return reply(503, e.what());
    }
    reply(text.rfind("ok", 0) == 0 ? 200 : text.rfind("refused:", 0) == 0 ? 403 : 409, text);
  });
  // Pairing: the code shown at the loom (`loomctl ctl pair NAME`) becomes this client's token, kept in an
  // HttpOnly, SameSite=Strict cookie for that loom only.
  svr.Post(
      R"(/api/loom/([A-Za-z0-9_-]{1,32})/pair)", [&](const httplib::Request& req, httplib::Response& res) {
        const std::string loom = req.matches[1];
        std::string code = req.has_param("code") ? req.get_param_value("code") : req.body;
        code = trimmed(code);
        const auto reply = [&](int status, const std::string& text) {
          res.status = status;
          res.set_content(loom::panel::json_text({{"loom", loom}, {"reply", text}}), "application/json");
          std::fprintf(stderr, "loom-panel: %s pair by %s -> %s\n", loom.c_str(), req.remote_addr.c_str(),
                       text.c_str());
        };
        if (o.control_dir.empty()) return reply(403, "read-only panel");
        if (code.empty() || code.size() > 8 || code.find_first_not_of("0123456789") != std::string::npos) {
          return reply(400, "a pairing code is the digits `loomctl ctl pair NAME` printed at the loom");
        }
        std::string text;
        try {
          text = trimmed(loom::firmware::serve::control_request(
              control_socket_of(o, loom), on_behalf("redeem", req, "") + " code=" + code, 3000));
        } catch (const std::exception& e) {
          return reply(503, e.what());
        }
        if (text.rfind("ok redeem ", 0) != 0) return reply(403, text);
        const std::string token = reply_field(text, "token");
        if (!loom::panel::token_shape(token)) return reply(502, "the loom's reply carried no token");
        // The cookie lasts as long as the pairing (the loom's valid_s), not a fixed week.
        const std::string valid = reply_field(text, "valid_s");
        if (valid.empty() || valid.size() > 9 || valid.find_first_not_of("0123456789") != std::string::npos) {
          return reply(502, "the loom's reply carried no validity");
        }
        res.set_header("Set-Cookie", loom::panel::token_cookie(loom, token, std::stoll(valid), o.tls()));
        const std::string name = text.substr(10, text.find(' ', 10) - 10);
        reply(200, "paired as " + name + " until " + reply_field(text, "expires"));
      });
  svr.Get(R"(/api/loom/([A-Za-z0-9_-]{1,32})/authority)",
          [&](const httplib::Request& req, httplib::Response& res) {
            const std::string loom = req.matches[1];
            res.set_header("Cache-Control", "no-store");
            const std::string token = token_of(req, loom);
            std::string text = "not paired";
            bool may_start = false;
            if (!o.control_dir.empty() && !token.empty()) {
              try {
                text = trimmed(loom::firmware::serve::control_request(control_socket_of(o, loom),
                                                                      on_behalf("whoami", req, token), 3000));
                may_start = text.rfind("ok whoami paired ", 0) == 0;
              } catch (const std::exception& e) {
                text = e.what();
              }
            }
            res.set_content(
                loom::panel::json_text(
                    {{"loom", loom}, {"may_start", may_start}, {"client", req.remote_addr}, {"reply", text}}),
                "application/json");
          });
  // The flight recorder's last minutes of one loom, as an lcmlog to replay (loom-replay) or open in lcm-spy.
  svr.Get(R"(/api/loom/([A-Za-z0-9_-]{1,32})/last\.lcmlog)",
          [&](const httplib::Request& req, httplib::Response& res) {
            const std::string loom = req.matches[1];
            res.set_header("Cache-Control", "no-store");
            const auto log = recorder.lcmlog(loom, std::chrono::duration_cast<std::chrono::microseconds>(
                                                       std::chrono::system_clock::now().time_since_epoch())
                                                       .count());
            if (!log) {
              res.status = 404;
              res.set_content(recorder.enabled() ? "nothing of loom " + loom + " heard in the last minutes\n"
                                                 : std::string("the recorder is off (--lcmlog-minutes 0)\n"),
                              "text/plain; charset=utf-8");
              return;
            }
            res.set_header("Content-Disposition", "attachment; filename=\"" + loom + "-last.lcmlog\"");
            res.set_content(*log, "application/octet-stream");
          });
  // The row report: every row summary the panel kept for this loom (the newest 500) as CSV to download.
  svr.Get(R"(/api/loom/([A-Za-z0-9_-]{1,32}(?:~replay)?)/rows\.csv)",
          [&](const httplib::Request& req, httplib::Response& res) {
            const std::string loom = req.matches[1];
            res.set_header("Cache-Control", "no-store");
            const auto csv = hall.rows_csv(loom);
            if (!csv) {
              res.status = 404;
              res.set_content("loom " + loom + " not heard\n", "text/plain; charset=utf-8");
              return;
            }
            res.set_header("Content-Disposition", "attachment; filename=\"" + loom + "-rows.csv\"");
            res.set_content(*csv, "text/csv; charset=utf-8");
          });
  // The loom's persisted fault history (faults.log, through serve's `faults` request): it survives a
  // restart of the panel, serve or the board, unlike what the panel heard on LCM. A GET: reading only.
  svr.Get(
      R"(/api/loom/([A-Za-z0-9_-]{1,32})/history)", [&](const httplib::Request& req, httplib::Response& res) {
        const std::string loom = req.matches[1];
        res.set_header("Cache-Control", "no-store");
        const auto error = [&](int status, const std::string& why) {
          res.status = status;
          res.set_content(loom::panel::json_text({{"loom", loom}, {"error", why}}), "application/json");
        };
        if (o.control_dir.empty()) {
          return error(
              404,
              "read-only panel: the loom's fault history is read through its control socket (--control-dir)");
        }
        std::string text;
        try {
          text = loom::firmware::serve::control_request(control_socket_of(o, loom),
                                                        on_behalf("faults", req, ""), 3000);
        } catch (const std::exception& e) {
          return error(503, e.what());
        }
        if (text.rfind("error:", 0) == 0 || text.rfind("refused:", 0) == 0) return error(502, trimmed(text));
        auto j = loom::panel::fault_history_json(text, kHistoryShown);
        j["loom"] = loom;
        res.set_content(loom::panel::json_text(j), "application/json");
      });
  // The whole faults.log as a file for the technician's report (the page offers the link): the same
  // text as `loomctl ctl faults`, through serve's socket.
  svr.Get(R"(/api/loom/([A-Za-z0-9_-]{1,32})/faults\.log)", [&](const httplib::Request& req,
                                                                httplib::Response& res) {
    const std::string loom = req.matches[1];
    res.set_header("Cache-Control", "no-store");
    if (o.control_dir.empty()) {
      res.status = 404;
      res.set_content(
          "read-only panel: the loom's faults.log is read through its control socket (--control-dir)\n",
          "text/plain; charset=utf-8");
      return;
    }
    std::string text;
    try {
      text = loom::firmware::serve::control_request(control_socket_of(o, loom), on_behalf("faults", req, ""),
                                                    3000);
    } catch (const std::exception& e) {
      res.status = 503;
      res.set_content(std::string(e.what()) + "\n", "text/plain; charset=utf-8");
      return;
    }
    if (text.rfind("error:", 0) == 0 || text.rfind("refused:", 0) == 0) {
      res.status = 502;
      res.set_content(text, "text/plain; charset=utf-8");
      return;
    }
    res.set_header("Content-Disposition", "attachment; filename=\"" + loom + "-faults.log\"");
    res.set_content(text, "text/plain; charset=utf-8");
  });
  StreamSlots slots(o.max_streams, o.max_streams_per_client);
  svr.Get("/events", [&](const httplib::Request& req, httplib::Response& res) {
    const std::string loom = req.has_param("loom") ? req.get_param_value("loom") : std::string();
    const std::string live_id =
        loom.size() > 7 && loom.compare(loom.size() - 7, 7, loom::panel::kReplaySuffix) == 0
            ? loom.substr(0, loom.size() - 7)
            : loom;
    if (!loom.empty() && !loom::telemetry::loom_id_error(live_id).empty()) {
      res.status = 400;
      res.set_content("bad loom id\n", "text/plain");
      return;
    }
    res.set_header("Cache-Control", "no-store");
    if (!slots.take(req.remote_addr)) {
      res.status = 503;
      res.set_header("Retry-After", "10");
      res.set_content("too many live pages open\n", "text/plain");
      return;
    }
    const auto gap = std::chrono::duration_cast<std::chrono::milliseconds>(
        std::chrono::duration<double>(o.min_push_interval_s));
    // Each call of the provider sends one event: the current JSON, once it differs from the last sent.
    auto seen = std::make_shared<std::uint64_t>(~std::uint64_t{0});
    const std::string client = req.remote_addr;
    res.set_chunked_content_provider(
        "text/event-stream",
        [&hall, &o, loom, gap, seen](std::size_t, httplib::DataSink& sink) {
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
          const std::string msg = "data: " + json_for(hall, o, loom) + "\n\n";
          if (!sink.write(msg.data(), msg.size())) return false;
          std::this_thread::sleep_for(gap);  // coalesce: a busy loom costs at most one update per gap
          return true;
        },
        [&slots, client](bool) { slots.give(client); });
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
  gate.port = port;  // the port actually listened on (--port 0 picks one)
  g_server = &svr;
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  std::thread http([&] { svr.listen_after_bind(); });
  std::fprintf(stderr, "loom-panel: serving %s://%s:%d/ (%s), LCM %s\n", o.tls() ? "https" : "http",
               o.bind.c_str(), port,
               o.control_dir.empty() ? "read-only" : ("operator buttons via " + o.control_dir).c_str(),
               o.lcm_url.empty() ? "default URL" : o.lcm_url.c_str());
  const auto on_packet = [&](const loom::panel::LcmPacket& p) { router.route(p.channel, p.data, p.size); };
  while (!g_stop.load()) {
    const int r = udpm ? udpm->poll(200, on_packet) : lcm->handleTimeout(200);
    if (r < 0) {
      if (o.lcm_url.rfind("file://", 0) == 0) {
        // A log read to its end: keep serving what it held until told to stop.
        std::fprintf(stderr, "loom-panel: end of log; still serving (Ctrl-C to stop)\n");
        while (!g_stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(200));
        break;
      }
      std::fprintf(stderr, "loom-panel: LCM stopped delivering messages\n");
      break;
    }
  }
  svr.stop();
  http.join();
  return g_stop.load() ? 0 : 1;
}

// See commission_cmd.hpp. A session that never starts: nothing moves, so the Session ticks the loop on
// the calling thread at normal priority (SYNC and the master heartbeat keep the drives and the I/O node
// supervised) and the loop's inputs are read between ticks, on the same thread.
#include "commission_cmd.hpp"

#include <poll.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/config/toml_edit.hpp"
#include "loom/config/toml_reader.hpp"
#include "loom/firmware/session.hpp"
#include "loom/state/durable_file.hpp"

namespace loom::firmware {
namespace {

// What each capture name measures, and the config key it writes.
struct Capture {
  const char* name;
  hal::CoreAxis axis;
  const char* section;
  const char* key;
  const char* pose;
};
constexpr Capture kCaptures[] = {
    {"park", hal::CoreAxis::kBeatCrank, "beatup", "crank_park_position_rad",
     "the crank at its park pose, beater clear of the warp"},
    {"home", hal::CoreAxis::kCarriage, "carriage", "home_position_m", "the carriage at the left selvedge"},
    {"left", hal::CoreAxis::kHelix, "helix", "left_position_rad", "the helix carrier at the left selvedge"},
};

// "" when the inputs agree with the pose `c` captures, else the contradiction. Only the helix carrier's
// pose has sensors that confirm it: at the left selvedge the shuttle rides it into the left sensor's reach
// and out of the right one's. (The crank's park and the carriage's home have no sensor on this loom.)
std::string pose_contradiction(const Capture& c, const hal::DigitalInputs& io) {
  if (c.axis != hal::CoreAxis::kHelix) return "";
  if (io.shuttle_at_right)
    return "shuttle_at_right=1: the shuttle (and its carrier) is at the right selvedge";
  if (!io.shuttle_at_left)
    return "shuttle_at_left=0: no shuttle seen at the left selvedge (is it on its carrier?)";
  return "";
}

const Capture* capture_named(const std::string& n) {
  for (const Capture& c : kCaptures) {
    if (n == c.name) return &c;
  }
  return nullptr;
}

std::string positions_line(const hal::HalInputs& in, const hal::AxisLayout& axes) {
  std::string s = "positions:";
  for (std::size_t i = 0; i < axes.count; ++i) {
    const hal::AxisFeedback& fb = in.axes[i];
    char buf[160];
    std::snprintf(buf, sizeof buf, " %s=%.9f %s (%s)", axes.name(i), fb.position,
                  hal::axis_unit(axes.role(i)), hal::drive_state_name(fb.state));
    s += buf;
  }
  return s;
}

// The I/O module's inputs as wired: name and value, the safety sensors' second switches where fitted.
std::vector<std::pair<std::string, bool>> named_inputs(
    const hal::DigitalInputs& io, const std::array<bool, hal::kSafetySensorCount>& second) {
  std::vector<std::pair<std::string, bool>> v{
      {"piston_a_extended", io.piston_a_extended}, {"piston_a_retracted", io.piston_a_retracted},
      {"piston_b_extended", io.piston_b_extended}, {"piston_b_retracted", io.piston_b_retracted},
      {"shuttle_at_left", io.shuttle_at_left},     {"shuttle_at_right", io.shuttle_at_right}};
  for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i) {
    if (second[i])
      v.emplace_back(std::string(hal::safety_sensor_name(static_cast<hal::SafetySensor>(i))) + "_2",
                     io.second_channel[i]);
  }
  v.insert(v.end(), {{"estop_ok", io.estop_ok},
                     {"button_start", io.button_start},
                     {"button_pause", io.button_pause},
                     {"button_ack", io.button_ack},
                     {"row_knotted", io.row_knotted}});
  return v;
}

std::string inputs_line(const hal::HalInputs& in, const std::array<bool, hal::kSafetySensorCount>& second) {
  std::string s = "inputs:";
  for (const auto& [name, on] : named_inputs(in.io, second)) s += " " + name + "=" + (on ? "1" : "0");
  return s +
         " load_cell=" + (in.analog.beat_force_valid ? std::to_string(in.analog.beat_force_n) + "N" : "-");
}

// Every input whose value changed since the last call, one line each: wiring is checked by working
// each sensor by hand and watching its line appear.
void print_input_changes(const hal::DigitalInputs& now, hal::DigitalInputs& last,
                         const std::array<bool, hal::kSafetySensorCount>& second) {
  const auto was = named_inputs(last, second), is = named_inputs(now, second);
  for (std::size_t i = 0; i < is.size(); ++i) {
    if (is[i].second != was[i].second) {
      std::printf("input %s %d -> %d\n", is[i].first.c_str(), was[i].second, is[i].second);
    }
  }
  last = now;
}

class Commissioning {
 public:
  Commissioning(const CommissionArgs& a, LoomConfig cfg, std::string text)
      : a_(a), cfg_(std::move(cfg)), text_(std::move(text)) {}

  int run(Session& session) {
    session_ = &session;
    loop_ = &session.machine().loop();
    seq_ = &session.machine().sequencer();
    tick(static_cast<hal::Tick>(std::ceil(a_.settle_s / cfg_.sequencer.period_s)));
    if (!all_disabled()) {
      std::fprintf(stderr, "loomctl commission: a drive is not disabled (%s); refusing to go on\n",
                   positions_line(loop_->inputs(), cfg_.sequencer.axes).c_str());
      return kExitNotArmed;
    }
    if (a_.io_once || !a_.capture.empty()) {
      std::printf("%s\n%s\n", positions_line(loop_->inputs(), cfg_.sequencer.axes).c_str(),
                  inputs_line(loop_->inputs(), cfg_.sequencer.second_channel).c_str());
      for (const std::string& c : a_.capture) {
        if (!take(*capture_named(c))) return kExitBadInput;  // nothing written
      }
      return a_.write ? write() : kExitOk;
    }
    return interactive();
  }

 private:
  // Drives are never asked to enable: the sequencer is idle and stays so.
  void tick(hal::Tick n) { session_->tick(n); }

  bool all_disabled() const {
    for (const hal::AxisFeedback& fb : loop_->inputs().axes) {
      if (fb.state == hal::DriveState::kOperationEnabled) return false;
    }
    return seq_->state() == sequencer::State::kIdle || seq_->state() == sequencer::State::kFault;
  }

  // Captures `c` unless the sensors contradict the pose; false (and why, on stderr) when refused.
  bool take(const Capture& c) {
    if (const std::string why = pose_contradiction(c, loop_->inputs().io); !why.empty()) {
      std::fprintf(stderr, "loomctl commission: %s refused: %s, but %s\n", c.name, c.pose, why.c_str());
      return false;
    }
    const double v = loop_->inputs().axes[hal::index(c.axis)].position;
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9f", v);
    captured_.push_back({c.section, c.key, buf});
    std::printf("captured %s: %s.%s = %s (%s)\n", c.name, c.section, c.key, buf, c.pose);
    return true;
  }

  int write() {
    if (captured_.empty()) {
      std::printf("nothing captured: %s unchanged\n", a_.config.c_str());
      return kExitOk;
    }
    std::vector<std::string> changes;
    std::string next;
    try {
      next = set_toml_values(text_, captured_, changes);
      parse_loom_config(next,
                        a_.config);  // the file must still be a valid loom before it replaces the old one
      state::write_file_durably(a_.config, next);
    } catch (const std::exception& e) {  // an invalid result (ConfigError) or a failed write
      std::fprintf(stderr, "loomctl commission: %s: not written: %s\n", a_.config.c_str(), e.what());
      return kExitBadInput;
    }
    for (const std::string& c : changes) std::printf("%s:%s\n", a_.config.c_str(), c.c_str());
    text_ = next;
    captured_.clear();
    return kExitOk;
  }

  int interactive() {
    std::printf("%s\n%s\n", positions_line(loop_->inputs(), cfg_.sequencer.axes).c_str(),
                inputs_line(loop_->inputs(), cfg_.sequencer.second_channel).c_str());
    std::printf(
        "drives disabled: move each axis by hand. Type park (crank at its park pose), home (carriage at the "
        "left selvedge), left (helix carrier at the left selvedge), write, positions, io, or quit.\n");
    hal::DigitalInputs last = loop_->inputs().io;
    const hal::Tick per_second = static_cast<hal::Tick>(std::llround(1.0 / cfg_.sequencer.period_s));
    std::string pending;
    for (hal::Tick t = 0;; ++t) {
      tick(per_second / 10);
      print_input_changes(loop_->inputs().io, last, cfg_.sequencer.second_channel);
      if (t % 10 == 9) std::printf("%s\n", positions_line(loop_->inputs(), cfg_.sequencer.axes).c_str());
      std::fflush(stdout);
      pollfd p{STDIN_FILENO, POLLIN, 0};
      if (::poll(&p, 1, 0) <= 0) continue;
      char buf[256];
      const ssize_t n = ::read(STDIN_FILENO, buf, sizeof buf);
      if (n <= 0) return captured_.empty() ? kExitOk : write();  // end of input: keep what was captured
      pending.append(buf, static_cast<std::size_t>(n));
      for (auto nl = pending.find('\n'); nl != std::string::npos; nl = pending.find('\n')) {
        std::string cmd = pending.substr(0, nl);
        pending.erase(0, nl + 1);
        while (!cmd.empty() && (cmd.back() == ' ' || cmd.back() == '\r')) cmd.pop_back();
        if (cmd == "quit")
          return captured_.empty() ? kExitOk : (std::printf("not written (quit)\n"), kExitOk);
        if (cmd == "write") {
          if (const int rc = write(); rc != kExitOk) return rc;
        } else if (cmd == "positions") {
          std::printf("%s\n", positions_line(loop_->inputs(), cfg_.sequencer.axes).c_str());
        } else if (cmd == "io") {
          std::printf("%s\n", inputs_line(loop_->inputs(), cfg_.sequencer.second_channel).c_str());
        } else if (const Capture* c = capture_named(cmd)) {
          (void)take(*c);  // a refusal says why; the operator moves the axis and tries again
        } else if (!cmd.empty()) {
          std::printf("unknown command '%s' (park, home, left, write, positions, io, quit)\n", cmd.c_str());
        }
      }
    }
  }

  const CommissionArgs& a_;
  LoomConfig cfg_;
  std::string text_;
  Session* session_ = nullptr;
  ControlLoop* loop_ = nullptr;
  sequencer::Sequencer* seq_ = nullptr;
  std::vector<TomlAssignment> captured_;
};

}  // namespace

int run_commission(const CommissionArgs& a) {
  for (const std::string& c : a.capture) {
    if (capture_named(c) == nullptr) {
      std::fprintf(stderr, "loomctl commission: --capture %s: want park, home or left\n", c.c_str());
      return kExitBadInput;
    }
  }
  if (a.write && a.capture.empty()) {
    std::fprintf(stderr, "loomctl commission: --write needs --capture (interactively, type write)\n");
    return kExitBadInput;
  }
  const Say say = console_say("loomctl commission");
  return exit_code_of(say, [&] {
    SessionOptions so = SessionOptions::from_command_line(a.hal, a.iface, a.io);
    // Interactive: the positions and inputs move at the machine's pace. Scripted: as fast as it can.
    so.realtime = a.capture.empty() && !a.io_once;
    const std::string text = read_config_file(a.config);
    const LoomConfig cfg = parse_loom_config(text, a.config);
    Session session(so, say);
    MachineOptions mo;
    mo.telemetry = false;
    mo.rows = 0;
    mo.sim_state_path = a.sim_state;
    session.build(cfg, default_scene(), mo, sequencer::Counters{});
    return Commissioning(a, cfg, text).run(session);
  });
}

}  // namespace loom::firmware

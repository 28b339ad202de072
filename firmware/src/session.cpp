// See session.hpp.
#include "loom/firmware/session.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <utility>

#include "loom/design/design.hpp"
#include "loom/firmware/run_summary.hpp"
#include "loom/job/yarn_stock.hpp"

namespace loom::firmware {

Say console_say(std::string who) {
  return [who = std::move(who)](Severity s, const std::string& text) {
    if (s == Severity::kErr) {
      std::fprintf(stderr, "%s: %s\n", who.c_str(), text.c_str());
    } else if (s == Severity::kWarning) {
      std::fprintf(stderr, "%s: WARNING: %s\n", who.c_str(), text.c_str());
    } else {
      std::printf("%s\n", text.c_str());
      std::fflush(stdout);
    }
  };
}

// ---------------------------------------------------------------------------------------------------
// Options
// ---------------------------------------------------------------------------------------------------
SessionOptions SessionOptions::from_command_line(const std::string& hal, const std::string& iface,
                                                 const std::string& io, double pace) {
  SessionOptions o;
  if (hal == "socketcan") {
    o.hal = HalKind::kSocketCan;
  } else if (hal != "sim") {
    throw ConfigError("--hal " + hal + ": want sim or socketcan");
  }
  if (o.hardware() && iface.empty()) throw ConfigError("--hal socketcan needs --iface NAME");
  if (!o.hardware() && !iface.empty()) {
    throw ConfigError("--iface " + iface +
                      " needs --hal socketcan (without it the simulated loom would run)");
  }
  if (o.hardware() && pace != 1.0) {
    char value[32];
    std::snprintf(value, sizeof value, "%g", pace);
    throw ConfigError(std::string("--pace = ") + value + ": simulation only (a loom runs at its own pace)");
  }
  if (io == "simulated") {
    o.io = IoKind::kSimulated;
  } else if (io == "can") {
    o.io = IoKind::kCan;
  } else if (!io.empty()) {
    throw ConfigError("--io " + io + ": want can or simulated");
  }
  o.iface = iface;
  o.pace = pace;
  return o;
}

void prepare_realtime(const SessionOptions& opt, const Say& say) {
  if (!opt.hardware()) return;  // a simulation paced in real time needs no guarantees: it asks, never refuses
  const RtSetup rt = setup_realtime(opt.rt_priority);
  if (rt.ok()) return;
  if (!opt.allow_degraded) {
    throw SessionError(kExitNotArmed, "refusing to arm: real-time setup failed (" + rt.problems +
                                          ") — grant real-time priority and locked memory (LimitRTPRIO/"
                                          "LimitMEMLOCK under systemd) or pass --allow-degraded to run "
                                          "without real-time guarantees");
  }
  say(Severity::kWarning, "RUNNING DEGRADED: " + rt.problems + " timing is not guaranteed");
}

// ---------------------------------------------------------------------------------------------------
// The production record
// ---------------------------------------------------------------------------------------------------
ProductionRecord::ProductionRecord(std::string counters_path, const LoomConfig& cfg)
    : path_(std::move(counters_path)),
      picks_per_row_(cfg.recipe.picks_per_row),
      design_name_(cfg.recipe.design ? cfg.recipe.design->name() : std::string()),
      row_saves_(std::make_unique<RowSaves>()) {
  if (path_.empty()) return;
  store_ = std::make_unique<state::CounterStore>(path_);
  if (!design_name_.empty()) {
    const auto dir = std::filesystem::path(path_).parent_path();
    book_ = std::make_unique<state::DesignBook>(dir.empty() ? std::string("designs.json")
                                                            : (dir / "designs.json").string());
  }
}

sequencer::Counters ProductionRecord::load() const {
  if (!store_) return {};
  const std::optional<sequencer::Counters> c = store_->load();
  if (!c) return {};
  if (c->picks_in_row > picks_per_row_) {
    throw ConfigError(path_ + ": picks_in_row = " + std::to_string(c->picks_in_row) + " but the recipe has " +
                      std::to_string(picks_per_row_) +
                      " pick(s) per row: these counters are not this loom's");
  }
  return *c;
}

void ProductionRecord::prove_writable(const sequencer::Counters& c) const {
  if (!store_) return;
  try {
    store_->save(c);
  } catch (const std::exception& ex) {
    throw ConfigError(std::string("counters file cannot be written, refusing to arm: ") + ex.what());
  }
}

std::uint64_t ProductionRecord::activate_design(std::uint32_t counter_rows) {
  if (CarpetJob* j = jobs()) {
    try {
      return j->arm(counter_rows);
    } catch (const ConfigError&) {
      throw;
    } catch (const std::exception& ex) {
      throw ConfigError(std::string("job queue cannot be written, refusing to arm: ") + ex.what());
    }
  }
  if (!book_) return 0;
  try {
    return book_->activate(design_name_, counter_rows);
  } catch (const ConfigError&) {
    throw;  // a book that is not this loom's, already worded with its file and field
  } catch (const std::exception& ex) {
    throw ConfigError(std::string("design book cannot be written, refusing to arm: ") + ex.what());
  }
}

void ProductionRecord::begin_session(const sequencer::Counters& c) {
  row_saves_ = std::make_unique<RowSaves>();
  row_saves_->saved(c.rows);
}

void ProductionRecord::save(const sequencer::Counters& c) {
  if (!store_) return;
  try {
    store_->save(c);
    // What the session was armed with is credited: its job, or the design book (a job added to the queue
    // while the loom weaves without one waits for the next arming).
    if (jobs_ && jobs_->armed_id() != 0) {
      if (jobs_->row_saved(c.rows)) carpet_done_ = true;
    } else if (book_) {
      book_->record(c.rows);
    }
  } catch (...) {
    // The loop must stop at the row boundary: weaving on without a durable count would lose work at the
    // next power cut.
    row_saves_->failed();
    throw;
  }
  row_saves_->saved(c.rows);
  row_saves_->saved_knots(c.rows, c.knot.cycles_started);
}

void ProductionRecord::keep_magazines(const LoomConfig& cfg) {
  if (!store_ || cfg.knotting.mode != sequencer::KnottingMode::kHeads) return;
  const auto dir = std::filesystem::path(path_).parent_path();
  magazines_path_ = job::YarnStock::path_in(dir.empty() ? std::string(".") : dir.string());
  heads_ = cfg.knotting.heads;
  slots_ = static_cast<int>(cfg.knotting.slot_colours.size());
  knots_per_slot_ = cfg.knotting.knots_per_slot;
}

std::optional<sequencer::MagazineLevels> ProductionRecord::load_magazines(const Say& say) const {
  if (magazines_path_.empty()) return std::nullopt;
  const std::optional<job::YarnStock> s = job::YarnStock::load(magazines_path_);
  if (!s) {
    say(Severity::kNotice, "magazines: no levels kept yet (" + magazines_path_ +
                               "): every slot is taken as full — load full magazines before the start");
    return std::nullopt;
  }
  if (const std::string why = s->mismatch(heads_, slots_, knots_per_slot_); !why.empty()) {
    say(Severity::kWarning, "magazines: the kept levels (" + magazines_path_ + ") are not this loom's (" +
                                why +
                                "): every slot is taken as full — load full magazines before the start");
    return std::nullopt;
  }
  sequencer::MagazineLevels levels{};
  for (int h = 0; h < heads_; ++h) {
    for (int sl = 0; sl < slots_; ++sl) {
      levels[static_cast<std::size_t>(h)][static_cast<std::size_t>(sl)] = s->knots(h, sl);
    }
  }
  return levels;
}

void ProductionRecord::save_magazines(const RunEvent& e) const {
  if (magazines_path_.empty() || !e.stock_known) return;
  job::YarnStock s(heads_, slots_, knots_per_slot_);
  for (int h = 0; h < heads_; ++h) {
    for (int sl = 0; sl < slots_; ++sl) {
      s.set(h, sl, std::max(0, e.stock[static_cast<std::size_t>(h)][static_cast<std::size_t>(sl)]));
    }
  }
  s.save(magazines_path_);
}

void ProductionRecord::say_yarn_forecast(const sequencer::KnotProgram* program,
                                         const std::optional<sequencer::MagazineLevels>& levels,
                                         std::uint32_t next_row, std::uint64_t rows, const Say& say) const {
  if (magazines_path_.empty() || program == nullptr || rows == 0) return;
  job::YarnStock stock(heads_, slots_, knots_per_slot_);
  for (int h = 0; levels && h < heads_; ++h) {
    for (int sl = 0; sl < slots_; ++sl) {
      stock.set(h, sl, std::max(0, (*levels)[static_cast<std::size_t>(h)][static_cast<std::size_t>(sl)]));
    }
  }
  const std::vector<job::SlotEmpty> empties = job::forecast_empty_slots(stock, *program, next_row, rows);
  if (empties.empty()) {
    say(Severity::kNotice, "yarn: every magazine slot lasts the " + std::to_string(rows) + " rows to weave");
    return;
  }
  constexpr std::size_t kShown = 8;  // the first ones; the loom forecasts again at every row
  for (std::size_t i = 0; i < empties.size() && i < kShown; ++i) {
    const job::SlotEmpty& e = empties[i];
    say(Severity::kNotice, "yarn: head " + std::to_string(e.head + 1) + " slot " + std::to_string(e.slot) +
                               " (colour " + e.colour + ", " + std::to_string(e.knots_left) +
                               " knots left) runs out in row " + std::to_string(e.counter_row + 1) + " (" +
                               (e.rows_from_now == 0 ? std::string("the next row")
                                                     : std::to_string(e.rows_from_now) + " rows from now") +
                               "): the loom asks for its reload before that row");
  }
  if (empties.size() > kShown) {
    say(Severity::kNotice, "yarn: and " + std::to_string(empties.size() - kShown) + " more slots in the " +
                               std::to_string(rows) + " rows to weave");
  }
}

std::string design_position(const design::Design& d, std::uint64_t rows_done) {
  const design::DesignPosition pos = design::position_after(d, rows_done);
  char buf[256];
  std::snprintf(buf, sizeof buf, "design %s (%d x %d knots): row %d to knot next", d.name().c_str(),
                d.width(), d.height(), pos.row + 1);
  std::string s = buf;
  if (pos.repeat > 1) s += ", repeat " + std::to_string(pos.repeat);
  return s;
}

// ---------------------------------------------------------------------------------------------------
// Faults
// ---------------------------------------------------------------------------------------------------
FaultReport FaultReport::of(const sequencer::Sequencer& seq) {
  FaultReport r;
  r.fault = seq.first_fault();
  r.stopped_by = seq.stopped_by();
  r.axis = seq.fault_axis() >= 0 ? seq.axes().name(static_cast<std::size_t>(seq.fault_axis())) : "";
  r.device_code = seq.fault_detail();
  r.sensor = seq.fault_sensor();
  r.carriage_miss = seq.knotter().carriage_miss();
  r.tick = seq.fault_tick();
  return r;
}

FaultReport FaultReport::of(const RunEvent& e, const hal::AxisLayout& axes) {
  FaultReport r;
  r.fault = e.fault;
  r.stopped_by = e.stopped_by;
  r.axis = e.fault_axis >= 0 ? axes.name(static_cast<std::size_t>(e.fault_axis)) : "";
  r.device_code = e.fault_detail;
  r.sensor = e.fault_sensor;
  r.carriage_miss = e.carriage_miss;
  r.tick = e.tick;
  return r;
}

const char* FaultReport::sensor_name() const {
  return sensor >= 0 ? hal::safety_sensor_name(static_cast<hal::SafetySensor>(sensor)) : "";
}

std::string FaultReport::stopped_note() const {
  if (stopped_by == fault || stopped_by == sequencer::Fault::kNone) return "";
  return std::string("(motion stopped on ") + sequencer::fault_name(stopped_by) + ")";
}

std::string FaultReport::where() const {
  return fault == sequencer::Fault::kCarriageNotAtKnot ? sequencer::describe(carriage_miss) : "";
}

std::string FaultReport::text() const {
  std::string t = sequencer::fault_text(fault);
  if (sensor >= 0) t += std::string(": ") + sensor_name();
  if (const std::string w = where(); !w.empty()) t += ": " + w;
  if (const std::string note = stopped_note(); !note.empty()) t += " " + note;
  return t;
}

// ---------------------------------------------------------------------------------------------------
// The session
// ---------------------------------------------------------------------------------------------------
Session::Session(SessionOptions opt, Say say) : opt_(std::move(opt)), say_(std::move(say)) {}

Session::~Session() = default;

Machine& Session::build(const LoomConfig& cfg, const Scene& scene, MachineOptions mo,
                        const sequencer::Counters& resume) {
  mo.hal = opt_.hal;
  mo.iface = opt_.iface;
  mo.io = opt_.io;
  if (opt_.paced()) mo.lossless_telemetry = false;  // real time never waits on telemetry: drop and count
  try {
    machine_ = std::make_unique<Machine>(cfg, scene, mo, resume);
  } catch (const ConfigError& e) {
    throw SessionError(kExitBadInput, e.what());
  } catch (const std::exception& e) {
    throw SessionError(kExitNotArmed, std::string("cannot arm: ") + e.what());
  }
  if (!machine_->banner().empty()) say_(Severity::kWarning, machine_->banner());
  return *machine_;
}

RunOptions Session::run_options(ProductionRecord* record) const {
  const LoomConfig& cfg = machine_->config();
  RunOptions ro;
  ro.period_s = cfg.sequencer.period_s;
  ro.realtime = opt_.paced();
  ro.pace = opt_.hardware() ? 1.0 : opt_.pace;
  ro.fifo_priority = opt_.rt_priority;
  ro.require_fifo = opt_.hardware() && !opt_.allow_degraded;
  ro.cpu = opt_.cpu;
  ro.overrun_stop_after = opt_.overrun_stop.value_or(opt_.hardware() ? cfg.run.overrun_stop_after : 0);
  ro.row_saves = record != nullptr ? record->row_saves() : nullptr;
  ro.sim_weaver = machine_->sim_weaver();  // simulation: the weaver answers the loom's requests
  return ro;
}

RunResult Session::run(const RunOptions& ro, const EventHandler& on_event) {
  const RunResult res = run_loop(machine_->loop(), machine_->sequencer(), ro, on_event);
  if (telemetry::Telemetry* tm = machine_->telemetry()) tm->stop();
  if (res.end == RunResult::End::kError) throw SessionError(kExitNotArmed, "refusing to run: " + res.error);
  // The run's line, then each of its warnings as a warning (a journal filters them by priority).
  const std::string text = describe_run(res, ro);
  std::size_t at = text.find('\n');
  say_(Severity::kInfo, text.substr(0, at));
  while (at != std::string::npos) {
    const std::size_t next = text.find('\n', at + 1);
    std::string line = text.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1);
    for (const char* prefix : {"loomctl: ", "WARNING: "}) {
      if (line.rfind(prefix, 0) == 0) line.erase(0, std::char_traits<char>::length(prefix));
    }
    say_(Severity::kWarning, line);
    at = next;
  }
  return res;
}

void Session::tick(hal::Tick n) {
  const std::int64_t period_ns = machine_->config().timing.period_ns;
  if (next_tick_ == 0) next_deadline_ns_ = clock_.now_ns();
  for (hal::Tick i = 0; i < n; ++i) {
    machine_->loop().cycle(next_tick_++);
    if (!opt_.paced()) continue;
    next_deadline_ns_ += period_ns;
    clock_.sleep_until(next_deadline_ns_);
  }
}

std::optional<FaultReport> Session::fault() const {
  const sequencer::Sequencer& seq = machine_->sequencer();
  if (seq.state() != sequencer::State::kFault) return std::nullopt;
  return FaultReport::of(seq);
}

}  // namespace loom::firmware

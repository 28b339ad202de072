// Machine assembly. The CAN path brings the drives up here (NMT, SDO) before the loop exists, so the
// loop never waits on the bus.
#include "loom/firmware/machine.hpp"

#include <cmath>
#include <stdexcept>

#include "loom/drivers/can_link_info.hpp"
#include "loom/drivers/configure_clock.hpp"
#include "loom/firmware/sim_weaver.hpp"
#include "loom/motion/errors.hpp"
#include "loom/sim_heads/sim_heads.hpp"

namespace loom::firmware {

Machine::Machine(const LoomConfig& cfg, const Scene& scene, const MachineOptions& opt,
                 sequencer::Counters resume)
    : cfg_(cfg) {
  const bool simulated_io = opt.hal == HalKind::kSim || opt.io.value_or(cfg_.io.kind) == IoKind::kSimulated;
  const Scene fitted = check_scene_fits(scene, cfg_, simulated_io);
  slot_ = std::make_unique<motion::ProfileSlot>(std::make_unique<const motion::ProfileSet>(cfg_.profile));
  sequencer::SequencerConfig scfg = cfg_.sequencer;
  if (cfg_.knotting.mode == sequencer::KnottingMode::kHeads) build_knotting(opt, resume.rows, scfg);
  scfg.rows_to_weave = opt.rows;
  scfg.await_row_saved = opt.await_row_saved;
  if (opt.hal == HalKind::kSocketCan) {
    // A dead drive first shows as stale PDOs (fast stop), then as a lost heartbeat (the root cause).
    scfg.diagnosis_window_s = cfg_.timing.can_diagnosis_window_s;
  }
  sequencer_ = std::make_unique<sequencer::Sequencer>(*slot_, scfg, resume);
  if (knot_program_) {
    // The simulated heads see the same machine: the knot geometry, the heads' axes and where the gripper
    // is in the warp (as the sequencer's interlock derives it from the knot cycle).
    cfg_.machine.knotting = sim_knotting(scfg);
  }
  sim_ = std::make_unique<sim_hal::SimWorld>(cfg_.machine, fitted.spec);
  if (!opt.sim_state_path.empty()) {
    try {
      sim_state_ = std::make_unique<sim_hal::SimStateFile>(opt.sim_state_path);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(std::string("--sim-state ") + e.what());
    }
    sim_->attach_state_file(*sim_state_);
  }
  sim_->persist_carpet(resume.rows, opt.carpet_began);

  if (opt.hal == HalKind::kSocketCan) {
    build_can_hal(opt);
  } else {
    hal_ = std::make_unique<hal::PortHal>(*sim_, *sim_);
    sim_weaver_ = std::make_unique<SimWeaver>(*sim_, cfg_.sequencer.period_s);
  }

  if (opt.telemetry) {
    telemetry::PublisherConfig pc;
    pc.lcm_url = cfg_.telemetry.lcm_url;
    pc.loom_id = cfg_.loom_id;
    pc.axes = axis_layout(cfg_);
    pc.decimation.status_every_n_ticks = cfg_.telemetry.status_every;
    pc.decimation.axes_every_n_ticks = cfg_.telemetry.axes_every;
    pc.decimation.rt_every_n_ticks = cfg_.telemetry.rt_every;
    pc.design = cfg_.recipe.design;
    pc.design_rows_at_start = opt.design_rows_done;
    pc.counter_rows_at_start = resume.rows;
    pc.knot_program = knot_program_.get();  // KNOTS and WEAVER (null without heads); outlives telemetry_
    try {
      telemetry_ = std::make_unique<telemetry::Telemetry>(pc);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(cfg_.source + ": telemetry: " + e.what());
    }
    telemetry_->start();
  }
  loop_ = std::make_unique<ControlLoop>(*hal_, *sequencer_, telemetry_.get(), cfg_.timing.period_ns,
                                        opt.lossless_telemetry && opt.hal == HalKind::kSim);
  TelemetryContext tc;
  tc.beat_force_min_n = cfg_.sequencer.beat_force_min_n;
  tc.beat_force_max_n = cfg_.sequencer.beat_force_max_n;
  tc.rows_target = opt.rows;
  tc.knot_program = knot_program_.get();  // the snapshot's knot progress (null without heads)
  loop_->set_telemetry_context(tc);
}

// The knotting heads: the knot cycle from the linkage and the design as magazine slots, both built once
// here (the design's progress says which row comes next) and read by the tick.
void Machine::build_knotting(const MachineOptions& opt, std::uint32_t counter_rows,
                             sequencer::SequencerConfig& scfg) {
  KnottingHeads heads = build_heads(cfg_, opt.design_rows_done, counter_rows);
  knot_cycle_ = std::move(heads.cycle);
  knot_program_ = std::move(heads.program);
  scfg.heads.program = knot_program_.get();
  scfg.heads.cycle = knot_cycle_.get();
}

void Machine::simulated_weaver_sink(void* machine, const sequencer::WeaverRequest& r) noexcept {
  static_cast<Machine*>(machine)->sim().ask_weaver(SimWeaver::task_for(r));
}

// The CAN HAL: the CiA 402 drives and the CiA 401 I/O modules on their buses (or, only when asked for on
// the command line, the drives beside the simulated I/O node). Every refusal that needs no bus comes
// before the bus is opened.
void Machine::build_can_hal(const MachineOptions& opt) {
  const IoKind io_kind = opt.io.value_or(cfg_.io.kind);
  if (io_kind == IoKind::kSimulated && opt.io != IoKind::kSimulated) {
    throw ConfigError(
        cfg_.source +
        ": io.kind = \"simulated\" with the CAN HAL: the servos would move while the e-stop chain, "
        "sensors and valves are imaginary; give --io simulated to do this on purpose");
  }
  // Derived from the machine description (and validated when it was read).
  const std::vector<drivers::CanIoConfig> io_configs = can_io_configs(cfg_);
  const std::vector<std::size_t> io_buses = can_io_buses(cfg_);
  LoomConfig with_can_io = cfg_;
  with_can_io.io.kind = io_kind;  // --io can over a simulated config puts the modules' frames on their buses
  const drivers::CanAxisPortConfig cc = can_axis_config(with_can_io);
  if (io_kind == IoKind::kCan && cfg_.io.kind != IoKind::kCan) {
    if (drivers::Status s = drivers::validate(io_configs.front()); !s)
      throw ConfigError(cfg_.source + ": " + s.message());
  }

  // One interface per bus, in bus order: "can0,can1" puts the axes with bus = 1 on can1.
  std::vector<std::string> ifaces;
  for (std::size_t at = 0;;) {
    const std::size_t comma = opt.iface.find(',', at);
    ifaces.push_back(opt.iface.substr(at, comma == std::string::npos ? std::string::npos : comma - at));
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  const std::size_t buses = drivers::bus_count(cc);
  for (std::size_t i = 0; i < ifaces.size(); ++i) {
    if (ifaces[i].empty())
      throw ConfigError("--iface \"" + opt.iface + "\": interface " + std::to_string(i) + " has no name");
    for (std::size_t j = 0; j < i; ++j) {
      if (ifaces[j] == ifaces[i]) {
        throw ConfigError("--iface \"" + opt.iface + "\": " + ifaces[i] +
                          " is named twice (one bus per interface)");
      }
    }
  }
  if (ifaces.size() != buses) {
    throw ConfigError("--iface \"" + opt.iface + "\" names " + std::to_string(ifaces.size()) +
                      " interface(s), but " + cfg_.source + " puts its axes and I/O modules on " +
                      std::to_string(buses) + " CAN bus(es) (axes.<name>.bus, io_modules.<name>.bus 0.." +
                      std::to_string(buses - 1) +
                      "): give one interface per bus, comma-separated, bus 0 first");
  }
  buses_.clear();
  std::vector<drivers::CanBus*> bus_ptrs;
  for (const std::string& iface : ifaces) {
    // The interface's real bitrate, from the kernel, before anything is sent.
    auto link = drivers::read_can_link_info(iface);
    if (!link) throw std::runtime_error(link.error());
    std::string note;
    if (drivers::Status s = drivers::check_can_bitrate(iface, link.value(), cfg_.can.bitrate, note); !s) {
      throw ConfigError(cfg_.source + ": can.bitrate: " + s.message());
    }
    if (!note.empty()) notes_.push_back(note);
    auto bus = drivers::SocketCanBus::open(iface);
    if (!bus) throw std::runtime_error(bus.error());
    buses_.push_back(std::move(bus.value()));
    bus_ptrs.push_back(buses_.back().get());
  }
  // The network of the buses; the axis port and each I/O module registered on it, brought up together
  // (each bus in its one NMT sequence) once the axis port's own checks pass.
  network_ = std::make_unique<drivers::CanNetwork>(drivers::can_master_config(cc), buses);
  can_port_ = std::make_unique<drivers::CanAxisPort>(*network_, cc);
  if (io_kind == IoKind::kCan) {
    io_port_ = std::make_unique<drivers::CanIoModules>();
    for (std::size_t k = 0; k < io_configs.size(); ++k) {
      io_modules_.push_back(std::make_unique<drivers::CanIoPort>(io_configs[k]));
      if (!network_->add(*io_modules_.back(), io_buses[k])) {
        throw ConfigError(cfg_.source + ": " + io_modules_.back()->label() + " cannot join CAN bus " +
                          std::to_string(io_buses[k]) +
                          ": its node id is taken there or the bus table is full");
      }
      io_port_->add(*io_modules_.back());
    }
  }
  drivers::MonotonicConfigureClock clock;
  if (const drivers::Status st = drivers::bring_up(*network_, *can_port_, bus_ptrs, clock); !st)
    throw std::runtime_error(st.message());
  for (std::size_t b = 0; b < buses; ++b) {
    notes_.push_back("CAN bus load (" + ifaces[b] +
                     "): " + drivers::describe_bus_load(can_port_->bus_load(b)));
  }
  for (const std::string& note : can_port_->notes()) notes_.push_back(note);
  if (io_port_) {  // each module brought up by its bus' master in the same NMT sequence as the drives
    for (const auto& m : io_modules_) notes_.insert(notes_.end(), m->notes().begin(), m->notes().end());
    hal_ = std::make_unique<drivers::CanHal>(*network_, *can_port_, *io_port_);
  } else {
    // Asked for explicitly: the simulated I/O node follows the real helix shaft for its shuttle sensors.
    banner_ = kSimulatedIoBanner;
    hal_ = std::make_unique<drivers::CanHal>(*network_, *can_port_, *sim_);
  }
}

void Machine::publish_recipe(const LoomConfig& next) {
  // What the running loop and its HAL were configured with cannot change between rows.
  // A reload may change the recipe only: the machine and the run settings are what the HAL, the
  // simulator and the loop were built from.
  if (const std::string changed = restart_only_changes(cfg_, next); !changed.empty()) {
    throw ConfigError(next.source +
                      ": only [recipe] and [profiles] may change while weaving; restart to change " +
                      changed);
  }
  // Recipe keys the sequencer holds (not the profiles) are fixed for the run: say so rather than
  // acknowledge a reload that would not change them.
  std::string fixed;
  const auto differs = [&](bool d, const char* key) {
    if (d) fixed += (fixed.empty() ? "" : ", ") + std::string(key);
  };
  differs(next.sequencer.picks_per_row != cfg_.sequencer.picks_per_row, "recipe.picks_per_row");
  // The design's remembered row and the panel's view are bound to the carpet on the loom.
  differs(next.recipe.design_file != cfg_.recipe.design_file, "recipe.design");
  differs(next.sequencer.beat_force_min_n != cfg_.sequencer.beat_force_min_n ||
              next.sequencer.beat_force_max_n != cfg_.sequencer.beat_force_max_n,
          "recipe.beat_force_min_n/max_n");
  if (!fixed.empty()) {
    throw ConfigError(next.source + ": " + fixed +
                      " change only with a restart (the sequencer or the design progress holds them)");
  }
  try {
    slot_->publish(std::make_unique<const motion::ProfileSet>(next.profile));
  } catch (const motion::MotionError& e) {
    throw ConfigError(next.source + ": motion profiles cannot be built: " + e.what());
  }
}

Machine::~Machine() {
  if (telemetry_) telemetry_->stop();
}

}  // namespace loom::firmware

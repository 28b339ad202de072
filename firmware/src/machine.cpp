// Machine assembly. The CAN path brings the drives up here (NMT, SDO) before the loop exists, so the
// loop never waits on the bus.
#include "loom/firmware/machine.hpp"

#include <cmath>
#include <stdexcept>

#include "loom/drivers/can_link_info.hpp"
#include "loom/drivers/configure_clock.hpp"
#include "loom/motion/errors.hpp"

namespace loom::firmware {

Machine::Machine(const LoomConfig& cfg, const Scene& scene, const MachineOptions& opt, sequencer::Counters resume)
    : cfg_(cfg) {
  slot_ = std::make_unique<motion::ProfileSlot>(std::make_unique<const motion::ProfileSet>(cfg_.profile));
  sequencer::SequencerConfig scfg = cfg_.sequencer;
  scfg.rows_to_weave = opt.rows;
  if (opt.hal == HalKind::kSocketCan) {
    // A dead drive first shows as stale PDOs (fast stop), then as a lost heartbeat (the root cause).
    scfg.diagnosis_window_s = cfg_.can.heartbeat_timeout_ms * 1e-3 + 10.0 * cfg_.sequencer.period_s;
  }
  sequencer_ = std::make_unique<sequencer::Sequencer>(*slot_, scfg, resume);
  sim_ = std::make_unique<sim_hal::SimWorld>(cfg_.machine, scene.spec);
  if (!opt.sim_state_path.empty()) {
    sim_state_ = std::make_unique<sim_hal::SimStateFile>(opt.sim_state_path);
    sim_->attach_state_file(*sim_state_);
  }

  if (opt.hal == HalKind::kSocketCan) {
    build_can_hal(opt);
  } else {
    hal_ = std::make_unique<hal::PortHal>(*sim_, *sim_);
  }

  if (opt.telemetry) {
    telemetry::PublisherConfig pc;
    pc.lcm_url = cfg_.telemetry.lcm_url;
    pc.loom_id = cfg_.loom_id;
    pc.decimation.status_every_n_ticks = cfg_.telemetry.status_every;
    pc.decimation.axes_every_n_ticks = cfg_.telemetry.axes_every;
    pc.decimation.rt_every_n_ticks = cfg_.telemetry.rt_every;
    try {
      telemetry_ = std::make_unique<telemetry::Telemetry>(pc);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(cfg_.source + ": telemetry: " + e.what());
    }
    telemetry_->start();
  }
  loop_ = std::make_unique<ControlLoop>(*hal_, *sequencer_, telemetry_.get(), cfg_.sequencer.period_s,
                                        opt.lossless_telemetry && opt.hal == HalKind::kSim);
}

// The CAN HAL: three CiA 402 drives and the CiA 401 I/O node on one bus (or, only when asked for on
// the command line, the drives beside the simulated I/O node). Every refusal that needs no bus comes
// before the bus is opened.
void Machine::build_can_hal(const MachineOptions& opt) {
  const IoKind io_kind = opt.io.value_or(cfg_.io.kind);
  if (io_kind == IoKind::kSimulated && opt.io != IoKind::kSimulated) {
    throw ConfigError(cfg_.source +
                      ": io.kind = \"simulated\" with the CAN HAL: the servos would move while the e-stop chain, "
                      "sensors and valves are imaginary; give --io simulated to do this on purpose");
  }
  drivers::CanIoConfig ic;
  ic.node_id = cfg_.io.node;
  ic.wiring = cfg_.io.wiring;
  ic.cycle_period_s = cfg_.sequencer.period_s;
  ic.heartbeat_producer_s = cfg_.can.heartbeat_ms * 1e-3;
  ic.heartbeat_consumer_s = cfg_.can.heartbeat_timeout_ms * 1e-3;
  ic.sdo_timeout_s = cfg_.can.sdo_timeout_ms * 1e-3;
  ic.boot_timeout_s = cfg_.io.boot_timeout_ms * 1e-3;
  ic.operational_timeout_s = cfg_.io.operational_timeout_ms * 1e-3;
  ic.master_node_id = cfg_.can.master_node;
  ic.master_consumer_s = cfg_.can.master_consumer_ms * 1e-3;
  if (io_kind == IoKind::kCan) {
    if (drivers::Status s = drivers::validate(ic); !s) throw ConfigError(cfg_.source + ": " + s.message());
  }

  drivers::CanAxisPortConfig cc;
  const double counts_per_rad = cfg_.can.counts_per_rev / (2.0 * M_PI);
  const std::array<std::uint8_t, 3> nodes{cfg_.can.node_beat_crank, cfg_.can.node_carriage, cfg_.can.node_helix};
  const std::array<double, 3> counts{counts_per_rad, cfg_.can.carriage_counts_per_m, counts_per_rad};
  for (std::size_t i = 0; i < hal::kAxisCount; ++i) {
    drivers::CanAxisConfig& a = cc.axes[i];
    a.node_id = nodes[i];
    a.counts_per_unit = counts[i];
    a.rated_effort = 0.0;
    a.ferror_min = cfg_.can.ferror_min[i];
    a.ferror_k_s = cfg_.can.ferror_k_s[i];
    a.boot_timeout_s = cfg_.can.boot_timeout_ms[i] * 1e-3;
    a.operational_timeout_s = cfg_.can.operational_timeout_ms[i] * 1e-3;
    if (io_kind == IoKind::kCan && a.node_id == ic.node_id) {
      throw ConfigError(cfg_.source + ": io.node = " + std::to_string(ic.node_id) + " is already the node of axis " +
                        hal::axis_name(static_cast<hal::Axis>(i)));
    }
  }
  cc.cycle_period_s = cfg_.sequencer.period_s;
  cc.heartbeat_producer_s = cfg_.can.heartbeat_ms * 1e-3;
  cc.heartbeat_consumer_s = cfg_.can.heartbeat_timeout_ms * 1e-3;
  cc.sdo_timeout_s = cfg_.can.sdo_timeout_ms * 1e-3;
  cc.bitrate_bps = cfg_.can.bitrate;
  cc.bus_load_budget = cfg_.can.bus_load_budget;
  cc.master_node_id = cfg_.can.master_node;
  cc.master_heartbeat_s = cfg_.can.master_heartbeat_ms * 1e-3;
  cc.master_consumer_s = cfg_.can.master_consumer_ms * 1e-3;
  if (io_kind == IoKind::kCan) cc.other_frames_per_cycle = drivers::io_frames_per_cycle(ic.wiring);
  if (drivers::Status s = drivers::validate(cc); !s) throw ConfigError(cfg_.source + ": can: " + s.message());

  // The interface's real bitrate, from the kernel, before anything is sent.
  auto link = drivers::read_can_link_info(opt.iface);
  if (!link) throw std::runtime_error(link.error());
  std::string note;
  if (drivers::Status s = drivers::check_can_bitrate(opt.iface, link.value(), cfg_.can.bitrate, note); !s) {
    throw ConfigError(cfg_.source + ": can.bitrate: " + s.message());
  }
  if (!note.empty()) notes_.push_back(note);

  auto bus = drivers::SocketCanBus::open(opt.iface);
  if (!bus) throw std::runtime_error(bus.error());
  bus_ = std::move(bus.value());
  can_port_ = std::make_unique<drivers::CanAxisPort>(cc);
  if (io_kind == IoKind::kCan) {
    io_port_ = std::make_unique<drivers::CanIoPort>(ic);
    can_port_->attach(*io_port_);
  }
  if (const drivers::Status st = can_port_->configure(*bus_); !st) throw std::runtime_error(st.message());
  notes_.push_back("CAN bus load: " + drivers::describe_bus_load(can_port_->bus_load()));
  notes_.insert(notes_.end(), can_port_->notes().begin(), can_port_->notes().end());
  if (io_port_) {
    drivers::MonotonicConfigureClock clock;
    if (const drivers::Status st = io_port_->configure(*bus_, clock); !st) throw std::runtime_error(st.message());
    notes_.insert(notes_.end(), io_port_->notes().begin(), io_port_->notes().end());
    hal_ = std::make_unique<hal::PortHal>(*can_port_, *io_port_);
  } else {
    // Asked for explicitly: the simulated I/O node follows the real helix shaft for its shuttle sensors.
    banner_ = kSimulatedIoBanner;
    hal_ = std::make_unique<hal::PortHal>(*can_port_, *sim_);
  }
}

void Machine::publish_recipe(const LoomConfig& next) {
  // What the running loop and its HAL were configured with cannot change between rows.
  if (next.sequencer.period_s != cfg_.sequencer.period_s || next.loom_id != cfg_.loom_id ||
      next.machine.width_m != cfg_.machine.width_m || next.profile.helix_lead_m != cfg_.profile.helix_lead_m) {
    throw ConfigError(next.source + ": period, loom id, width and helix lead change only with a restart");
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

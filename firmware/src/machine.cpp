// Machine assembly. The CAN path brings the drives up here (NMT, SDO) before the loop exists, so the
// loop never waits on the bus.
#include "loom/firmware/machine.hpp"

#include <cmath>
#include <stdexcept>

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
    auto bus = drivers::SocketCanBus::open(opt.iface);
    if (!bus) throw std::runtime_error(bus.error());
    bus_ = std::move(bus.value());
    drivers::CanAxisPortConfig cc;
    const double counts_per_rad = cfg_.can.counts_per_rev / (2.0 * M_PI);
    cc.axes[hal::index(hal::Axis::kBeatCrank)] = {cfg_.can.node_beat_crank, counts_per_rad, 0.0};
    cc.axes[hal::index(hal::Axis::kCarriage)] = {cfg_.can.node_carriage, cfg_.can.carriage_counts_per_m, 0.0};
    cc.axes[hal::index(hal::Axis::kHelix)] = {cfg_.can.node_helix, counts_per_rad, 0.0};
    cc.cycle_period_s = cfg_.sequencer.period_s;
    cc.heartbeat_producer_s = cfg_.can.heartbeat_ms * 1e-3;
    cc.heartbeat_consumer_s = cfg_.can.heartbeat_timeout_ms * 1e-3;
    cc.sdo_timeout_s = cfg_.can.sdo_timeout_ms * 1e-3;
    cc.bitrate_bps = cfg_.can.bitrate;
    cc.bus_load_budget = cfg_.can.bus_load_budget;
    can_port_ = std::make_unique<drivers::CanAxisPort>(cc);
    const drivers::Status st = can_port_->configure(*bus_);
    if (!st) throw std::runtime_error(st.message());
    // The I/O node is still simulated on this HAL: valves and sensors come from the sim world, which
    // follows the real helix shaft's position for the shuttle sensors.
    hal_ = std::make_unique<hal::PortHal>(*can_port_, *sim_);
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
  TelemetryContext tc;
  tc.beat_force_min_n = cfg_.sequencer.beat_force_min_n;
  tc.beat_force_max_n = cfg_.sequencer.beat_force_max_n;
  tc.rows_target = opt.rows;
  loop_->set_telemetry_context(tc);
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

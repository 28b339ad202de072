// Each module's projection of the loom file: the CAN master's config for the servo axes, the I/O
// modules' configs and buses, each bus' planned load, the knotting heads' program of the recipe's design.
#include <algorithm>
#include <utility>

#include "loom/config/config.hpp"
#include "loom/drivers/bus_load.hpp"
#include "loom/drivers/eds_check.hpp"
#include "loom/drivers/node_description.hpp"

namespace loom::firmware {

namespace {

// The node's EDS for the CAN master: its identity and the writes the loom makes (none when the EDS lacks
// what the loom needs: the profile's own bring-up then refuses the node as without an EDS). Null for a
// file that cannot be read (the config was refused for it when read).
std::shared_ptr<const drivers::NodeDescription> node_description(const std::string& path,
                                                                 const drivers::eds::NodeNeeds& needs,
                                                                 bool store) {
  if (path.empty()) return nullptr;
  auto d = std::make_shared<drivers::NodeDescription>();
  d->eds = drivers::eds::read_eds_file(path);
  if (d->eds.has_errors()) return nullptr;
  const drivers::eds::NodeCheck check = drivers::eds::check_node(d->eds, needs);
  if (check.ok()) d->writes = drivers::eds::loom_writes(d->eds, needs, check);
  d->store = store;
  return d;
}

// The module's input groups: io(_modules.<name>).input_group_bits when set, else what its EDS offers for
// the module's wiring (8-bit groups when it has them all, else 16-bit: drivers::eds::input_group_bits_of),
// else 8. A file with neither form keeps 8, whose missing group check_node() then names.
int input_group_bits(const std::string& eds_path, int key, const drivers::IoWiring& module_wiring) {
  if (key != 0) return key;
  if (eds_path.empty()) return drivers::kInputGroupBits8;
  const drivers::eds::Description d = drivers::eds::read_eds_file(eds_path);
  if (d.has_errors()) return drivers::kInputGroupBits8;
  const int bits = drivers::eds::input_group_bits_of(d, module_wiring);
  return bits != 0 ? bits : drivers::kInputGroupBits8;
}

}  // namespace

drivers::CanAxisPortConfig can_axis_config(const LoomConfig& c) {
  drivers::CanAxisPortConfig cc;
  cc.axes.clear();
  for (const AxisSpec& a : c.axes) {
    drivers::CanAxisConfig& d = cc.axes.emplace_back();
    d.name = a.name;
    d.bus = a.bus;
    d.node_id = a.node;
    d.counts_per_unit = a.counts_per_unit();
    d.rated_effort = 0.0;
    d.ferror_min = a.ferror_min;
    d.ferror_k_s = a.ferror_k_s;
    d.boot_timeout_s = a.boot_ms * 1e-3;
    d.operational_timeout_s = a.operational_ms * 1e-3;
    if (a.profile_position) {
      // The drive runs the selectors' own move limits (the ones the sequencer plans their moves with).
      d.mode = drivers::DriveMode::kProfilePosition;
      d.profile_velocity = c.sequencer.heads.selector.velocity;
      d.profile_acceleration = c.sequencer.heads.selector.acceleration;
      d.profile_jerk = c.sequencer.heads.selector.jerk;
    }
    if (a.homing) {  // CiA 402 homing run over CAN (0x6098, 0x607C, 0x6099, 0x609A)
      d.homing_method = static_cast<std::int8_t>(a.homing_method);
      d.home_offset = a.home_offset;
      d.homing_speed = a.homing_speed;
      d.homing_accel = a.homing_accel;
    }
  }
  cc.cycle_period_s = c.run.period_s;
  cc.heartbeat_producer_s = c.can.heartbeat_ms * 1e-3;
  cc.heartbeat_consumer_s = c.can.heartbeat_timeout_ms * 1e-3;
  cc.sdo_timeout_s = c.can.sdo_timeout_ms * 1e-3;
  cc.bitrate_bps = c.can.bitrate;
  cc.bus_load_budget = c.can.bus_load_budget;
  cc.master_node_id = c.can.master_node;
  cc.master_heartbeat_s = c.can.master_heartbeat_ms * 1e-3;
  cc.master_consumer_s = c.can.master_consumer_ms * 1e-3;
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    cc.axes[i].description =
        node_description(c.axes[i].eds, drivers::eds::drive_needs(cc.axes[i], cc), c.axes[i].store_config);
  }
  if (c.io.kind == IoKind::kCan) {
    const std::vector<drivers::CanIoConfig> modules = can_io_configs(c);
    const std::vector<std::size_t> buses = can_io_buses(c);
    for (std::size_t k = 0; k < modules.size(); ++k) {
      const auto frames = drivers::io_frames_per_cycle(
          drivers::module_wiring(modules[k].wiring, modules[k].module), modules[k].input_group_bits);
      std::vector<drivers::FrameGroup>& on_bus =
          cc.other_frames_per_cycle[std::min(buses[k], drivers::kMaxBuses - 1)];
      on_bus.insert(on_bus.end(), frames.begin(), frames.end());
      cc.other_nodes_per_bus[std::min(buses[k], drivers::kMaxBuses - 1)] += 1;  // its heartbeat
    }
  }
  return cc;
}

std::vector<std::size_t> can_io_buses(const LoomConfig& c) {
  std::vector<std::size_t> buses{0};  // the [io] module is on bus 0
  for (const IoModuleSpec& m : c.io.modules) buses.push_back(m.bus);
  return buses;
}

std::vector<drivers::CanIoConfig> can_io_configs(const LoomConfig& c) {
  drivers::CanIoConfig ic;
  ic.node_id = c.io.node;
  ic.wiring = c.io.wiring;
  // The heads' signals are on the module only when the heads are fitted (a loom without them keeps its
  // frames as they were).
  if (c.knotting.mode == sequencer::KnottingMode::kHeads) {
    drivers::IoWiring& w = ic.wiring;
    w.heads = std::clamp(c.knotting.heads, 0, static_cast<int>(hal::kMaxKnottingHeads));
    const auto fill = [&](const IoSettings::HeadSignals& from,
                          std::array<drivers::IoBit, hal::kMaxKnottingHeads>& to) {
      for (std::size_t h = 0; h < to.size(); ++h) {
        to[h] = drivers::IoBit{h < from.bits.size() ? from.bits[h] : -1, from.active_low, from.module};
      }
    };
    fill(c.io.gripper_close, w.gripper_close);
    fill(c.io.cutter, w.cutter);
    fill(c.io.yarn_present, w.yarn_present);
  }
  ic.cycle_period_s = c.run.period_s;
  ic.heartbeat_producer_s = c.can.heartbeat_ms * 1e-3;
  ic.heartbeat_consumer_s = c.can.heartbeat_timeout_ms * 1e-3;
  ic.sdo_timeout_s = c.can.sdo_timeout_ms * 1e-3;
  ic.boot_timeout_s = c.io.boot_timeout_ms * 1e-3;
  ic.operational_timeout_s = c.io.operational_timeout_ms * 1e-3;
  ic.master_node_id = c.can.master_node;
  ic.master_consumer_s = c.can.master_consumer_ms * 1e-3;
  std::vector<drivers::CanIoConfig> out{ic};
  out[0].input_group_bits =
      input_group_bits(c.io.eds, c.io.input_group_bits, drivers::module_wiring(ic.wiring, 0));
  out[0].description = node_description(c.io.eds, drivers::eds::io_module_needs(out[0]), c.io.store_config);
  for (std::size_t k = 0; k < c.io.modules.size(); ++k) {
    const IoModuleSpec& m = c.io.modules[k];
    drivers::CanIoConfig mc = ic;  // the same wiring, bus timing and master; its own node and windows
    mc.module = static_cast<std::uint8_t>(k + 1);
    mc.name = m.name;
    mc.node_id = m.node;
    mc.boot_timeout_s = m.boot_timeout_ms * 1e-3;
    mc.operational_timeout_s = m.operational_timeout_ms * 1e-3;
    mc.input_group_bits =
        input_group_bits(m.eds, m.input_group_bits, drivers::module_wiring(mc.wiring, mc.module));
    mc.description = node_description(m.eds, drivers::eds::io_module_needs(mc), m.store_config);
    out.push_back(std::move(mc));
  }
  return out;
}

drivers::BusLoad can_bus_load(const LoomConfig& c, std::size_t bus) {
  const drivers::CanAxisPortConfig cc = can_axis_config(c);
  return drivers::planned_bus_load(cc, bus);
}

sequencer::KnotProgram knot_program(const LoomConfig& c, std::uint64_t design_rows_done,
                                    std::uint32_t counter_rows) {
  const design::Design& d = *c.recipe.design;
  std::vector<std::string> codes;
  for (const auto& colour : d.palette()) codes.push_back(colour.code);
  std::vector<std::uint16_t> knots;
  knots.reserve(static_cast<std::size_t>(d.width()) * static_cast<std::size_t>(d.height()));
  for (int r = 0; r < d.height(); ++r) {
    const auto row = d.row(r);
    knots.insert(knots.end(), row.begin(), row.end());
  }
  return sequencer::KnotProgram::build(c.knotting, c.machine_spec.width_m, d.width(), d.height(), knots,
                                       codes, design_rows_done, counter_rows);
}

}  // namespace loom::firmware

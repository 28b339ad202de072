// Each node with an EDS: its description, what the loom needs of it, the comparison, and the writes the
// loom makes on it — the one place `loomctl check`, `loomctl dcf` and the tests take them from.
#include "loom/config/eds_nodes.hpp"

#include <utility>

namespace loom::firmware {

namespace eds = drivers::eds;

namespace {

EdsNode make_node(std::string key, std::uint8_t node_id, std::uint8_t bus, const std::string& path,
                  eds::NodeNeeds needs) {
  EdsNode n;
  n.key = std::move(key);
  n.node_id = node_id;
  n.bus = bus;
  n.eds = eds::read_eds_file(path);
  n.needs = std::move(needs);
  n.check = eds::check_node(n.eds, n.needs);
  if (n.check.ok()) n.writes = eds::loom_writes(n.eds, n.needs, n.check);
  return n;
}

}  // namespace

std::vector<EdsNode> eds_nodes(const LoomConfig& c) {
  std::vector<EdsNode> out;
  const drivers::CanAxisPortConfig port = can_axis_config(c);
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    const AxisSpec& a = c.axes[i];
    if (a.eds.empty()) continue;
    out.push_back(make_node("axes." + a.name, a.node, a.bus, a.eds, eds::drive_needs(port.axes[i], port)));
  }
  if (c.io.kind != IoKind::kCan) return out;
  const std::vector<drivers::CanIoConfig> modules = can_io_configs(c);
  const std::vector<std::size_t> buses = can_io_buses(c);
  for (std::size_t k = 0; k < modules.size(); ++k) {
    const std::string& path = k == 0 ? c.io.eds : c.io.modules[k - 1].eds;
    if (path.empty()) continue;
    out.push_back(make_node(k == 0 ? std::string("io") : "io_modules." + c.io.modules[k - 1].name,
                            modules[k].node_id, static_cast<std::uint8_t>(buses[k]), path,
                            eds::io_module_needs(modules[k])));
  }
  return out;
}

std::string dcf_text(const LoomConfig& c, const EdsNode& node) {
  return eds::write_dcf(node.eds, node.node_id, c.can.bitrate / 1000u, node.writes, node.key);
}

}  // namespace loom::firmware

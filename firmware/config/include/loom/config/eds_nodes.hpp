// The nodes a machine description names an electronic data sheet for (axes.<name>.eds, io.eds,
// io_modules.<name>.eds): each node's description, what the loom needs of it and the comparison of the
// two (drivers/eds_check.hpp). `loomctl check` prints the findings, `loomctl dcf` writes a DCF per node
// from them. Configure-time only.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/drivers/eds.hpp"
#include "loom/drivers/eds_check.hpp"
#include "loom/drivers/eds_dcf.hpp"

namespace loom::firmware {

struct EdsNode {
  std::string key;  // the machine description's table: "axes.carriage", "io", "io_modules.panel"
  std::uint8_t node_id = 0;
  std::uint8_t bus = 0;
  drivers::eds::Description eds;  // as read (non-strict: what vendors ship)
  drivers::eds::NodeNeeds needs;
  drivers::eds::NodeCheck check;
  // What the loom configures on the node (drivers::eds::loom_writes()); empty when check is not ok().
  std::vector<drivers::eds::SdoWrite> writes;
};

// Configure-time only. Every node with an EDS, axes in slot order, then the I/O modules (io first).
// An I/O module's node is listed only when io.kind = "can".
std::vector<EdsNode> eds_nodes(const LoomConfig& c);

// Configure-time only. The node's DCF: its description with the loom's writes as ParameterValues, its
// node id, the loom's bit rate and the table's name (`loomctl dcf` writes it; read_eds() reads it back).
std::string dcf_text(const LoomConfig& c, const EdsNode& node);

}  // namespace loom::firmware

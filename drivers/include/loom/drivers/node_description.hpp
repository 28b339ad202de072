// What the master knows of a node from its EDS (axes.<name>.eds, io.eds): the description, for the
// identity check at bring-up (0x1018 against the file's vendor, product code and revision), and the
// configuration writes the loom derived from it (eds_dcf.hpp's loom_writes()), made at bring-up with only
// the values that differ written. Configure-time only; carried by CanAxisConfig / CanIoConfig.
#pragma once

#include <vector>

#include "loom/drivers/eds.hpp"
#include "loom/drivers/eds_dcf.hpp"

namespace loom::drivers {

struct NodeDescription {
  eds::Description eds;
  std::vector<eds::SdoWrite> writes;  // empty when the EDS lacks what the loom needs (check_node not ok)
  bool store = false;                 // 0x1010:01 "save" after a bring-up that wrote anything
};

}  // namespace loom::drivers

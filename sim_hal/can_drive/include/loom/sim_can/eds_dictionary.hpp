// A simulated node described by an EDS: the slave dictionary table built from the description's
// objects, so the HIL rig and the tests run the master against drives that differ from the built-in one
// (fixed mappings, other PDO counts, no CSP, their own identity). Configure-time only.
#pragma once

#include <cstdint>
#include <vector>

#include "loom/drivers/eds.hpp"
#include "loom/sim_can/sim_drive_node.hpp"
#include "loom/sim_can/sim_io_node.hpp"
#include "loom/sim_can/slave_od.hpp"

namespace loom::sim_can {

// Every entry of an integer type of 1, 2 or 4 bytes (the simulated SDO server is expedited only), sorted:
// access const/ro/writable as described, PDO direction from PDOMapping (ro → transmit, writable →
// receive), default value as described with $NODEID left out (the dictionary adds the node id to PDO
// COB-IDs at reset communication, as the pre-defined connection set does).
std::vector<slave::Entry> dictionary_from_eds(const drivers::eds::Description& d);

// A simulated drive at `node_id` described by `d`: its dictionary, CSP and homing as 0x6502 says.
SimDriveConfig drive_from_eds(const drivers::eds::Description& d, std::uint8_t node_id);

// A simulated CiA 401 module at `node_id` described by `d`: its dictionary, and as many input terminals
// as its 0x6000 (8 per sub) or 0x6100 (16 per sub) has, whichever is more (at most 64).
SimIoConfig io_from_eds(const drivers::eds::Description& d, std::uint8_t node_id);

}  // namespace loom::sim_can

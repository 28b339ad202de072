// The object dictionary entries the master relies on, per kind of node: what a loom builder checks in
// a drive's or an I/O module's EDS before buying it. Built from the same od:: constants the master's
// configure steps use, so the list cannot drift from what is actually read and written.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace loom::drivers {

struct RequiredObject {
  std::uint16_t index;
  const char* name;
  bool optional;        // used when present, reported when absent
  const char* why;
};

// Configure-time only. A CiA 402 servo drive in cyclic synchronous position.
std::vector<RequiredObject> drive_objects();
// Configure-time only. The CiA 401 generic I/O module.
std::vector<RequiredObject> io_module_objects();
// "0x6041 statusword (TPDO1)" etc., one line per object.
std::string describe(const RequiredObject& o);

}  // namespace loom::drivers

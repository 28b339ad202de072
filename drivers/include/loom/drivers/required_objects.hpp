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
  bool optional;  // used when present, reported when absent
  std::string why;
  // An array object whose size depends on the wiring: the master uses sub-indices 1..subs (0 = the
  // object as a whole, nothing to count).
  std::uint8_t subs = 0;
};

struct IoWiring;

// Configure-time only. A CiA 402 servo drive in cyclic synchronous position.
std::vector<RequiredObject> drive_objects();
// Configure-time only. What a drive whose axis is referenced by a CiA 402 homing run (an incremental
// encoder) must support besides drive_objects().
std::vector<RequiredObject> homing_drive_objects();
// Configure-time only. The CiA 401 generic I/O module, objects only (no wiring: sub-indices not counted).
std::vector<RequiredObject> io_module_objects();
// Configure-time only. The same for `wiring` (one module's: drivers::module_wiring()): how many 8-bit input
// and output groups (0x6000:01..n, 0x6200:01..n) the module must have, e.g. 0x6000:01..03 when second
// channels sit on bits 16..21, and what each object carries on this module; the load cell's objects only
// when it is wired here.
// With `input_group_bits` 16 the inputs are 0x6100's 16-bit groups instead of 0x6000's.
std::vector<RequiredObject> io_module_objects(const IoWiring& wiring, int input_group_bits = 8);
// "0x6041 statusword (TPDO1)" etc., one line per object; "0x6000:01..03 …" for a counted array.
std::string describe(const RequiredObject& o);

}  // namespace loom::drivers

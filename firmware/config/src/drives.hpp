// The servo drives of a loom file: [drives.<model>] tables, each a drive as it is sold (the motor's speed,
// torque and rotor inertia, its gearbox), named by the axes it moves (axes.<name>.drive). From them the
// axes' speed limits and the knot cycle's envelope are derived; an explicit limit above what the drive
// delivers is refused at its line. Internal to loom::config.
#pragma once

#include <string>
#include <vector>

#include "keys.hpp"
#include "loom/config/config.hpp"
#include "loom/config/toml_reader.hpp"
#include "loom/motion/profile_set.hpp"

namespace loom::firmware::detail {

// The keys of one [drives.<model>] table with their ranges (the README's key table).
struct DriveKeyInfo {
  const char* path;
  const char* range;
};
const std::vector<DriveKeyInfo>& drive_keys();

// Reads every [drives.<model>] table over what `c` already holds (by model name).
void read_drives(TomlReader& r, LoomConfig& c);

// After read_axes: every axes.<name>.drive names a model; an axis with a drive and no max_speed of its own
// gets the drive's no-load speed at the output; one whose max_speed exceeds it is refused there. With
// knotting heads every knotter axis names a drive (the knot cycle is planned under its envelope). Then
// set_knot_cycle_servo.
void check_axis_drives(TomlReader& r, LoomConfig& c);
// The knot cycle's servo fields from the knotter axes' drives (the weakest of each fact) and speed caps.
void set_knot_cycle_servo(LoomConfig& c);

// After the profiles are built from `c`: each core axis that names a drive must get from it the speed its
// motion asks (the crank's fastest beat with the law and the beat regulator's top scale, the carriage's and
// the helix' speed limits) and the torque (force) to accelerate the drive's own rotor and gears (and the
// helix' shuttle) at the axis' acceleration limit; refused at the key that asks it (or the drive's fact).
void check_core_drives(const LoomConfig& c, const motion::ProfileSet& set, const Fail& fail);

// The canonical text of the drives, to tell a restart-only change.
std::string drives_text(const LoomConfig& c);

// The drive model `name` (nullptr: none of that name).
const DriveModel* find_drive(const LoomConfig& c, const std::string& name);

}  // namespace loom::firmware::detail

// What a simulation scene asks for, as plain data (the firmware parses scene files into this). Effects
// not named here are never constructed, so they cost nothing per tick.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "loom/hal/types.hpp"

namespace loom::sim_hal {

// Names of every effect this simulator knows; a scene naming anything else is rejected.
inline constexpr const char* kEffectIdeal = "ideal";          // axes track their targets exactly
inline constexpr const char* kEffectServoLag = "servo_lag";   // first-order lag of each servo axis
const std::vector<std::string>& known_effects();

struct ServoLag {
  double tau_s = 0.005;  // time constant of the position loop
};

enum class InjectedFault : std::uint8_t { kDriveFault, kEStop };

struct FaultInjection {
  double at_s = 0.0;                       // virtual time from start
  InjectedFault kind = InjectedFault::kDriveFault;
  hal::Axis axis = hal::Axis::kBeatCrank;  // for drive faults
  std::uint16_t code = 0x8611;             // EMCY code reported (default: following error)
};

// Physical facts of the simulated machine that are not effects (they come from the loom config).
struct SimMachine {
  double period_s = 0.002;
  double width_m = 1.2;
  double helix_lead_m = 0.10;
  double piston_travel_s = 0.25;          // heald frame stroke time with the nominal air supply
  double selvedge_sensor_window_m = 0.005;
};

struct SceneSpec {
  std::string name = "default";
  std::uint64_t seed = 1;
  std::vector<std::string> effects{kEffectIdeal};  // in the order named
  std::optional<ServoLag> servo_lag;               // present iff "servo_lag" is named
  std::vector<FaultInjection> faults;
};

}  // namespace loom::sim_hal

// loom-sim-drive's --io-control words (see io_control.hpp).
#include "loom/sim_can/io_control.hpp"

#include <array>
#include <cctype>
#include <cstddef>
#include <utility>

namespace loom::sim_can {

namespace {

constexpr std::string_view kStuckPrefix = "stuck=";
constexpr std::string_view kSecondSuffix = "_2";
constexpr std::string_view kStuckSyntax = "stuck=<sensor>[_2]:on|off";

// The on/off words and the control each sets: one table, so clearing (set_io_controls) and setting
// (apply_io_control_word) cannot miss one another's words.
constexpr std::array<std::pair<std::string_view, bool IoPlant::*>, 6> kFlags{{
    {"estop", &IoPlant::estop_open},
    {"start", &IoPlant::button_start},
    {"pause", &IoPlant::button_pause},
    {"ack", &IoPlant::button_ack},
    {"knotted", &IoPlant::row_knotted},
    {"silent", &IoPlant::silent},
}};

// The sensor names a stuck= word accepts, for the message that refuses an unknown one: the same table
// as the config's io keys (hal::safety_sensor_name), so the two cannot drift apart.
std::string known_sensors() {
  std::string s;
  for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i) {
    if (i != 0) s += ", ";
    s += hal::safety_sensor_name(static_cast<hal::SafetySensor>(i));
  }
  return s;
}

// `name` is a safety sensor's name, or that name with "_2" (its second switch): sets `sw`'s sensor and
// channel. Whole-name matches only (no sensor's name ends in "_2"), so none is mistaken for another.
bool find_switch(std::string_view name, StuckSwitch& sw) {
  for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i) {
    const auto sensor = static_cast<hal::SafetySensor>(i);
    const std::string_view base = hal::safety_sensor_name(sensor);
    const bool first = name == base;
    const bool second = name.size() == base.size() + kSecondSuffix.size() &&
                        name.substr(0, base.size()) == base && name.substr(base.size()) == kSecondSuffix;
    if (first || second) {
      sw.sensor = sensor;
      sw.second = second;
      return true;
    }
  }
  return false;
}

}  // namespace

std::optional<StuckSwitch> parse_stuck_switch(std::string_view value, std::string& error) {
  const std::size_t colon = value.find(':');
  if (colon == std::string_view::npos || colon == 0) {
    error = "expected " + std::string(kStuckSyntax);
    return std::nullopt;
  }
  const std::string_view name = value.substr(0, colon);
  const std::string_view level = value.substr(colon + 1);
  StuckSwitch sw;
  sw.active = true;
  if (!find_switch(name, sw)) {
    error = "unknown sensor '" + std::string(name) + "' (known: " + known_sensors() +
            "; add _2 for the second switch)";
    return std::nullopt;
  }
  if (level != "on" && level != "off") {
    error = "level '" + std::string(level) + "' is not on or off (" + std::string(kStuckSyntax) + ")";
    return std::nullopt;
  }
  sw.level = level == "on";
  return sw;
}

std::string apply_io_control_word(std::string_view word, IoPlant& controls) {
  for (const auto& [name, flag] : kFlags) {
    if (word == name) {
      controls.*flag = true;
      return {};
    }
  }
  if (word.substr(0, kStuckPrefix.size()) != kStuckPrefix)
    return "unknown word '" + std::string(word) + "' ignored";
  // The node models one stuck switch (IoPlant::stuck): a second word would silently replace the first.
  if (controls.stuck.active)
    return "'" + std::string(word) + "': only one switch can be stuck at a time; ignored";
  std::string error;
  const std::optional<StuckSwitch> sw = parse_stuck_switch(word.substr(kStuckPrefix.size()), error);
  if (!sw) return "'" + std::string(word) + "': " + error + "; ignored";
  controls.stuck = *sw;
  return {};
}

std::vector<std::string> set_io_controls(std::string_view text, IoPlant& controls) {
  for (const auto& [name, flag] : kFlags) controls.*flag = false;
  controls.stuck = StuckSwitch{};
  std::vector<std::string> ignored;
  std::size_t i = 0;
  while (i < text.size()) {
    const auto space = [&](std::size_t k) { return std::isspace(static_cast<unsigned char>(text[k])) != 0; };
    while (i < text.size() && space(i)) ++i;
    std::size_t end = i;
    while (end < text.size() && !space(end)) ++end;
    if (end > i) {
      if (std::string message = apply_io_control_word(text.substr(i, end - i), controls); !message.empty()) {
        ignored.push_back(std::move(message));
      }
    }
    i = end;
  }
  return ignored;
}

}  // namespace loom::sim_can

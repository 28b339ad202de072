// The words of loom-sim-drive's --io-control file (HIL fault tests), parsed into the I/O node's
// controls. Kept out of main.cpp so the parsing is unit-tested
// (tests/sim_hal/can_drive/test_sim_io_node.cpp).
//
// Whitespace-separated words; a word present is active, a word absent inactive (the whole file is the
// state, so removing a word undoes it):
//   estop   — the e-stop chain opens          start, pause, ack — the operator buttons are pressed
//   knotted — the "row knotted" pedal          silent            — the node sends and hears nothing
//   stuck=<sensor>[_2]:on|off — one switch of a safety sensor reads on/off whatever the plant does;
//       <sensor> as in the config's io keys (piston_a_extended … shuttle_at_right), `_2` = its second
//       switch (terminals 16..21), without it the first (0..5). One stuck switch at a time.
//
// Configure-time / control-file code (allocates): not for the real-time step.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "loom/sim_can/sim_io_node.hpp"

namespace loom::sim_can {

// The value of a `stuck=` word, e.g. "shuttle_at_right_2:on". The switch (active), or nullopt with
// `error` saying what is wrong (an unknown sensor lists the known ones).
std::optional<StuckSwitch> parse_stuck_switch(std::string_view value, std::string& error);

// Applies one word to `controls`. "" when understood; otherwise why it is ignored, naming the word.
std::string apply_io_control_word(std::string_view word, IoPlant& controls);

// The whole file: first every control this file sets is cleared (absent = inactive), then each word is
// applied. Returns one message per word ignored. Leaves the plant's positions (helix, crank) alone.
std::vector<std::string> set_io_controls(std::string_view text, IoPlant& controls);

}  // namespace loom::sim_can

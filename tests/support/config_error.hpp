// The refusal text of a loom config or a scene given as TOML text ("" when it is accepted): what the
// config tests compare against.
#pragma once

#include <string>

#include "loom/config/config.hpp"

namespace loom::test {

inline std::string config_error(const std::string& text, const std::string& source = "loom.toml") {
  try {
    (void)firmware::parse_loom_config(text, source);
  } catch (const firmware::ConfigError& e) {
    return e.what();
  }
  return "";
}

inline std::string scene_error(const std::string& text, const std::string& source = "scene.toml") {
  try {
    (void)firmware::parse_scene(text, source);
  } catch (const firmware::ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace loom::test

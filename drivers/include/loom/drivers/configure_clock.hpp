// Time for configure-time protocol exchanges (NMT boot-up waits, SDO timeouts). Injected so tests run
// a master against in-process simulated drives in virtual time: their idle() advances the clock and
// steps the simulated nodes; the real one sleeps briefly.
#pragma once

#include <cstdint>

namespace loom::drivers {

class ConfigureClock {
 public:
  virtual ~ConfigureClock() = default;
  // Configure-time only. Current time in µs on a monotonic base.
  virtual std::int64_t now_us() = 0;
  // Configure-time only. Called when no frame is waiting: let time pass (briefly) before polling again.
  virtual void idle() = 0;
};

// CLOCK_MONOTONIC with a 200 µs idle sleep: for bring-up on a real bus before the RT loop starts.
class MonotonicConfigureClock final : public ConfigureClock {
 public:
  std::int64_t now_us() override;  // configure-time only
  void idle() override;            // configure-time only
};

}  // namespace loom::drivers

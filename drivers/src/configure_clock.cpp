// The real configure-time clock. Relative sleeps are fine here: this runs before the RT loop exists.
#include "loom/drivers/configure_clock.hpp"

#include <time.h>

namespace loom::drivers {

std::int64_t MonotonicConfigureClock::now_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000 + ts.tv_nsec / 1000;
}

void MonotonicConfigureClock::idle() {
  const timespec ts{0, 200'000};
  ::nanosleep(&ts, nullptr);
}

}  // namespace loom::drivers

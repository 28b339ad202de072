// Bus-load arithmetic (see bus_load.hpp). Kept integer in bits so the reference table is reproduced
// exactly; only the utilisation is a ratio.
#include "loom/drivers/bus_load.hpp"

#include <cstdio>

namespace loom::drivers {

BusLoad compute_bus_load(std::span<const FrameGroup> frames, std::uint32_t bitrate_bps, double period_s) {
  BusLoad load;
  load.bitrate_bps = bitrate_bps;
  load.period_s = period_s;
  for (const FrameGroup& g : frames) {
    load.frames += g.count;
    load.bits_nominal += g.count * frame_bits_nominal(g.data_bytes);
    load.bits_worst += g.count * frame_bits_worst(g.data_bytes);
  }
  const double capacity = static_cast<double>(bitrate_bps) * period_s;
  if (capacity > 0.0) {
    load.utilisation_nominal = load.bits_nominal / capacity;
    load.utilisation_worst = load.bits_worst / capacity;
  }
  return load;
}

BusLoad servo_cycle_bus_load(std::uint32_t axes, bool tpdo2, std::uint32_t bitrate_bps, double period_s) {
  const FrameGroup groups[] = {{0, 1}, {6, axes}, {6, axes}, {6, tpdo2 ? axes : 0U}};
  return compute_bus_load(groups, bitrate_bps, period_s);
}

std::string describe_bus_load(const BusLoad& load) {
  char buf[200];
  std::snprintf(buf, sizeof(buf),
                "%u frames/cycle, %u nominal / %u worst-case bits per %.3g ms at %.0f kbit/s = "
                "%.1f %% / %.1f %%",
                load.frames, load.bits_nominal, load.bits_worst, load.period_s * 1e3, load.bitrate_bps / 1e3,
                load.utilisation_nominal * 100.0, load.utilisation_worst * 100.0);
  return buf;
}

Status check_bus_load(const BusLoad& load, double budget) {
  if (load.utilisation_worst <= budget) return Status::ok();
  char buf[120];
  std::snprintf(buf, sizeof(buf), " exceeds the bus-load budget of %.0f %%", budget * 100.0);
  return Status::error("CAN cycle refused: " + describe_bus_load(load) + buf +
                       " (lengthen the cycle, raise the bitrate or send fewer PDOs per cycle)");
}

}  // namespace loom::drivers

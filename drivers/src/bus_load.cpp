// Bus-load arithmetic (see bus_load.hpp). Kept integer in bits so the reference table is reproduced
// exactly; only the utilisation is a ratio.
//
// What a cycle must hold (Davis, Burns, Bril, Lukkien 2007, §3–4: response time = blocking + the
// transmission times of every frame that can be queued ahead in the window). The cycle is on time when the
// last synchronous frame has left the bus before the next SYNC; its worst-case response time, measured
// from SYNC, is at most the sum of
//   - the synchronous frames, all of them, each with worst-case stuffing (SYNC, cyclic RPDOs and TPDOs, the
//     I/O modules' PDOs, the master heartbeat). The master heartbeat (0x77F) is counted in full every cycle
//     although it has the lowest priority: the master writes it beside its SYNC and RPDOs into one host
//     queue, which is FIFO, so it can go out ahead of them;
//   - blocking: CAN is non-preemptive, so one frame of lower priority than the cycle's frames that has won
//     arbitration just before SYNC finishes first. The largest such frame is 8 bytes (an SDO request or
//     response, 0x580/0x600 + node, ranks below every PDO);
//   - the EMCY headroom (0x080 + node: outranks every PDO, so it is interference, not blocking);
//   - the asynchronous frames that can be queued within the window, at their rate: the nodes' heartbeats
//     and the event-driven PDOs.
// Summed over one period this is also the bus' utilisation, which the budget bounds with margin for
// what the arithmetic leaves out (error frames, a late host).
#include "loom/drivers/bus_load.hpp"

#include <cmath>
#include <cstdio>

namespace loom::drivers {

namespace {

std::uint64_t whole_us(double s) {
  return s > 0.0 ? static_cast<std::uint64_t>(std::llround(s * 1e6)) : 0;
}

// ⌈count · bits · period / interval⌉ in whole bits. An interval that rounds to 0 µs bounds nothing: then
// each frame is counted once per cycle.
std::uint32_t rate_bits(const RateGroup& g, std::uint32_t frame_bits, std::uint64_t period_us) {
  const std::uint64_t bits = static_cast<std::uint64_t>(g.count) * frame_bits;
  const std::uint64_t interval_us = whole_us(g.min_interval_s);
  if (interval_us == 0) return static_cast<std::uint32_t>(bits);
  return static_cast<std::uint32_t>((bits * period_us + interval_us - 1) / interval_us);
}

std::string count(std::uint32_t n, const char* what) {
  return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
}

void set_utilisation(BusLoad& load) {
  const double capacity = static_cast<double>(load.bitrate_bps) * load.period_s;
  if (capacity > 0.0) {
    load.utilisation_nominal = load.bits_nominal / capacity;
    load.utilisation_worst = load.bits_worst / capacity;
  }
}

}  // namespace

BusLoad compute_bus_load(std::span<const FrameGroup> frames, std::uint32_t bitrate_bps, double period_s) {
  BusLoad load;
  load.bitrate_bps = bitrate_bps;
  load.period_s = period_s;
  for (const FrameGroup& g : frames) {
    load.frames += g.count;
    load.bits_nominal += g.count * frame_bits_nominal(g.data_bytes);
    load.bits_worst += g.count * frame_bits_worst(g.data_bytes);
  }
  load.synchronous_bits_worst = load.bits_worst;
  set_utilisation(load);
  return load;
}

BusLoad compute_cycle_load(const CycleTraffic& t, std::uint32_t bitrate_bps, double period_s) {
  BusLoad load = compute_bus_load(t.synchronous, bitrate_bps, period_s);
  if (t.blocking) {
    load.blocking_bits_worst = frame_bits_worst(kMaxFrameBytes);
    load.bits_worst += load.blocking_bits_worst;
    load.bits_nominal += frame_bits_nominal(kMaxFrameBytes);
  }
  // EMCY headroom. A node sends EMCY only on an edge of its error state (a fault appears or is reset), and
  // its EMCY inhibit time (0x1015) spaces repeats. The first EMCY makes the master stop the machine, and a
  // stopping machine's cycles no longer carry motion that must be on time. So the cycle that must still be
  // on time holds the one EMCY that announces the fault (or, at most, one node's per cycle while the others
  // run on): one 8-byte frame per cycle is the headroom, and callers reserve at least that.
  load.emcy_frames = t.emcy_headroom;
  load.emcy_bits_worst = t.emcy_headroom * frame_bits_worst(kEmcyBytes);
  load.bits_worst += load.emcy_bits_worst;
  load.bits_nominal += t.emcy_headroom * frame_bits_nominal(kEmcyBytes);
  const std::uint64_t period_us = whole_us(period_s);
  // Heartbeats (0x700 + node) have the lowest priority of all: one already on the wire when SYNC comes is
  // the blocking term (whose 8 bytes cover a 1-byte heartbeat); the others only take bus time, which over a
  // cycle is their rate, count · bits · period / producer time, rounded up.
  for (const RateGroup& g : t.heartbeats) {
    load.heartbeats += g.count;
    load.heartbeat_bits_worst += rate_bits(g, frame_bits_worst(g.data_bytes), period_us);
    load.bits_nominal += rate_bits(g, frame_bits_nominal(g.data_bytes), period_us);
  }
  load.bits_worst += load.heartbeat_bits_worst;
  // Event-driven PDOs at their fastest rate (the caller says which interval bounds each: an inhibit time).
  for (const RateGroup& g : t.events) {
    load.event_pdos += g.count;
    load.event_bits_worst += rate_bits(g, frame_bits_worst(g.data_bytes), period_us);
    load.bits_nominal += rate_bits(g, frame_bits_nominal(g.data_bytes), period_us);
  }
  load.bits_worst += load.event_bits_worst;
  set_utilisation(load);
  return load;
}

std::string describe_bus_load(const BusLoad& load) {
  std::string terms;
  const auto add = [&terms](const std::string& term) { terms += (terms.empty() ? " incl. " : ", ") + term; };
  if (load.blocking_bits_worst != 0) add("blocking");
  if (load.emcy_frames != 0) add("EMCY headroom");
  if (load.heartbeats != 0) add(count(load.heartbeats, "heartbeat"));
  if (load.event_pdos != 0) add(count(load.event_pdos, "event-driven PDO"));
  char buf[200];
  std::snprintf(buf, sizeof(buf),
                "%u frames/cycle%s: %u nominal / %u worst-case bits per %.3g ms at %.0f kbit/s = "
                "%.1f %% / %.1f %%",
                load.frames, terms.c_str(), load.bits_nominal, load.bits_worst, load.period_s * 1e3,
                load.bitrate_bps / 1e3, load.utilisation_nominal * 100.0, load.utilisation_worst * 100.0);
  return buf;
}

std::string describe_bus_load_terms(const BusLoad& load) {
  std::string s = "worst-case bits: " + std::to_string(load.frames) + " cyclic frames " +
                  std::to_string(load.synchronous_bits_worst);
  if (load.blocking_bits_worst != 0) s += ", blocking " + std::to_string(load.blocking_bits_worst);
  if (load.emcy_frames != 0) {
    s += ", EMCY " + std::to_string(load.emcy_frames) + " × " +
         std::to_string(load.emcy_bits_worst / load.emcy_frames);
  }
  if (load.heartbeats != 0) {
    s += ", " + count(load.heartbeats, "heartbeat") + " " + std::to_string(load.heartbeat_bits_worst);
  }
  if (load.event_pdos != 0) {
    s += ", " + count(load.event_pdos, "event-driven PDO") + " " + std::to_string(load.event_bits_worst);
  }
  return s;
}

Status check_bus_load(const BusLoad& load, double budget) {
  if (load.utilisation_worst <= budget) return Status::ok();
  char buf[120];
  std::snprintf(buf, sizeof(buf), " exceeds the bus-load budget of %.0f %%", budget * 100.0);
  return Status::error("CAN cycle refused: " + describe_bus_load(load) + buf +
                       " (lengthen the cycle, raise the bitrate, move drives to another bus or run "
                       "point-to-point axes in profile position)");
}

}  // namespace loom::drivers

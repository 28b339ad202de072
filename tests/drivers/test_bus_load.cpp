// Bus-load arithmetic against the published table (classic CAN, worst-case stuffing per Davis et al. 2007),
// and the worst-case stuffing formula checked as a true upper bound by stuffing real frames bit by bit
// (CRC-15 included).
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <utility>
#include <vector>

#include "loom/drivers/bus_load.hpp"
#include "loom/drivers/can_axis_config.hpp"

namespace loom::drivers {
namespace {

TEST(BusLoad, FrameBitsMatchTheReferenceTable) {
  const std::uint32_t s[] = {0, 4, 6, 8};
  const std::uint32_t nominal[] = {47, 79, 95, 111};
  const std::uint32_t worst[] = {55, 95, 115, 135};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(frame_bits_nominal(s[i]), nominal[i]) << s[i];
    EXPECT_EQ(frame_bits_worst(s[i]), worst[i]) << s[i];
  }
}

struct Row {
  std::vector<FrameGroup> frames;
  std::uint32_t count, nominal, worst;
};

TEST(BusLoad, CycleRowsMatchTheReferenceTable) {
  const Row rows[] = {
      {{{8, 9}}, 9, 999, 1215},                            // 9 frames × 8 B
      {{{0, 1}, {8, 4}, {8, 4}}, 9, 935, 1135},            // SYNC + 4 RPDO 8 B + 4 TPDO 8 B
      {{{0, 1}, {6, 4}, {6, 4}}, 9, 807, 975},             // SYNC + 4 × {cw,target} + 4 × {sw,pos}
      {{{0, 1}, {6, 4}, {6, 4}, {6, 4}}, 13, 1187, 1435},  // … + 4 TPDO2
      {{{0, 1}, {4, 4}, {6, 4}}, 9, 743, 895},             // SYNC + 4 RPDO {target} + 4 TPDO {sw,pos}
  };
  for (const Row& r : rows) {
    const BusLoad l = compute_bus_load(r.frames, 1'000'000, 0.001);
    EXPECT_EQ(l.frames, r.count);
    EXPECT_EQ(l.bits_nominal, r.nominal);
    EXPECT_EQ(l.bits_worst, r.worst);
    EXPECT_DOUBLE_EQ(l.utilisation_nominal, r.nominal / 1000.0);
    EXPECT_DOUBLE_EQ(l.utilisation_worst, r.worst / 1000.0);
    const BusLoad half = compute_bus_load(r.frames, 500'000, 0.001);
    EXPECT_DOUBLE_EQ(half.utilisation_worst, 2.0 * r.worst / 1000.0);
  }
  // "SYNC + 4×6 B + 4×6 B at 1 ms, 1 Mbit/s = 81 % / 98 %".
  const BusLoad l = compute_bus_load(rows[2].frames, 1'000'000, 0.001);
  EXPECT_NEAR(l.utilisation_nominal, 0.807, 1e-12);
  EXPECT_NEAR(l.utilisation_worst, 0.975, 1e-12);
}

TEST(BusLoad, SynchronousFramesOfThisLoom) {
  // SYNC + 3 RPDO + 3 TPDO at 2 ms, 1 Mbit/s: (47 + 6·95) / 2000 and (55 + 6·115) / 2000.
  const FrameGroup servo[] = {{0, 1}, {6, 3}, {6, 3}};
  const BusLoad l = compute_bus_load(servo, 1'000'000, 0.002);
  EXPECT_EQ(l.frames, 7u);
  EXPECT_EQ(l.bits_nominal, 617u);
  EXPECT_EQ(l.bits_worst, 745u);
  EXPECT_NEAR(l.utilisation_nominal, 0.3085, 1e-12);
  EXPECT_NEAR(l.utilisation_worst, 0.3725, 1e-12);
  EXPECT_TRUE(check_bus_load(l, 0.70).is_ok());
  // Synchronous frames only: no other term is counted or named (37.25 % sits on a rounding edge).
  EXPECT_EQ(describe_bus_load(l).rfind("7 frames/cycle: 617 nominal / 745 worst-case bits per 2 ms at "
                                       "1000 kbit/s = 30.9 % / 37.",
                                       0),
            0u)
      << describe_bus_load(l);
}

// ---- the whole cycle, against closed forms computed by hand ----------------------------------------
// Worst-case bits of one frame, from 44 + 8s + ⌊(34 + 8s − 1)/4⌋ + 3 (the table above for 0, 4, 6, 8 B):
// 1 B 65, 2 B 75, 3 B 85, 6 B 115, 7 B 125, 8 B 135; nominal 44 + 8s + 3: 1 B 55, 2 B 63, 3 B 71, 6 B 95,
// 7 B 103, 8 B 111.

// A mixed bus at 2 ms, 1 Mbit/s: two cyclic drives and one homed cyclic drive, three profile-position
// drives and one homed, an I/O module with a 2-byte and a 3-byte PDO, the master's heartbeat; every node's
// heartbeat every 100 ms, the profile drives' inhibit 10 ms.
CanAxisPortConfig mixed_bus() {
  CanAxisPortConfig c;
  c.axes.clear();
  const auto axis = [&c](std::uint8_t node, DriveMode mode, bool homed) {
    CanAxisConfig& a = c.axes.emplace_back();
    a.name = "a" + std::to_string(node);
    a.bus = 1;
    a.node_id = node;
    a.mode = mode;
    if (homed) {
      a.homing_method = 34;
      a.homing_speed = 1.0;
      a.homing_accel = 1.0;
    }
  };
  axis(1, DriveMode::kCyclicPosition, false);
  axis(2, DriveMode::kCyclicPosition, false);
  axis(3, DriveMode::kCyclicPosition, true);
  axis(11, DriveMode::kProfilePosition, false);
  axis(12, DriveMode::kProfilePosition, false);
  axis(13, DriveMode::kProfilePosition, false);
  axis(14, DriveMode::kProfilePosition, true);
  c.other_frames_per_cycle[1] = {{2, 1}, {3, 1}};
  c.other_nodes_per_bus[1] = 1;
  c.cycle_period_s = 0.002;
  c.heartbeat_producer_s = 0.100;
  c.profile_tpdo_inhibit_s = 0.010;
  c.profile_tpdo_event_timer_s = 0.100;
  c.master_node_id = 127;
  return c;
}

TEST(BusLoad, MixedBusMatchesTheClosedForm) {
  const CanAxisPortConfig c = mixed_bus();
  ASSERT_TRUE(validate(c).is_ok()) << validate(c).message();
  const BusLoad l = planned_bus_load(c, 1);
  // Synchronous: SYNC 55 + 2·(115 + 115) + (125 + 125) + I/O (75 + 85) + master heartbeat 65 = 990 bits
  // in 1 + 4 + 2 + 2 + 1 = 10 frames; nominal 47 + 2·190 + 206 + (63 + 71) + 55 = 822.
  EXPECT_EQ(l.frames, 10u);
  EXPECT_EQ(l.synchronous_bits_worst, 990u);
  // Blocking: one 8-byte frame, 135. EMCY: one 8-byte frame, 135.
  EXPECT_EQ(l.blocking_bits_worst, 135u);
  EXPECT_EQ(l.emcy_frames, 1u);
  EXPECT_EQ(l.emcy_bits_worst, 135u);
  // Heartbeats: 7 drives + the I/O module = 8 nodes, ⌈8 · 65 · 2 / 100⌉ = ⌈10.4⌉ = 11 (nominal ⌈8.8⌉ = 9).
  EXPECT_EQ(l.heartbeats, 8u);
  EXPECT_EQ(l.heartbeat_bits_worst, 11u);
  // Profile drives, RPDO1 and TPDO1 each at 2 / 10 of a frame per cycle: the three absolute ones
  // ⌈3 · 115 · 0.2⌉ = 69 twice, the homed one ⌈125 · 0.2⌉ = 25 twice = 188 (nominal 57·2 + ⌈20.6⌉·2 = 156).
  EXPECT_EQ(l.event_pdos, 8u);
  EXPECT_EQ(l.event_bits_worst, 188u);
  EXPECT_EQ(l.bits_worst, 990u + 135u + 135u + 11u + 188u);    // 1459
  EXPECT_EQ(l.bits_nominal, 822u + 111u + 111u + 9u + 156u);   // 1209
  EXPECT_NEAR(l.utilisation_worst, 1459.0 / 2000.0, 1e-12);    // 72.95 %
  EXPECT_NEAR(l.utilisation_nominal, 1209.0 / 2000.0, 1e-12);  // 60.45 %
  EXPECT_FALSE(check_bus_load(l, 0.70).is_ok());
  EXPECT_TRUE(check_bus_load(l, 0.73).is_ok());
  // (The percentages, 60.45 and 72.95, sit on a rounding edge: the bits say it.)
  EXPECT_EQ(describe_bus_load(l).rfind("10 frames/cycle incl. blocking, EMCY headroom, 8 heartbeats, 8 "
                                       "event-driven PDOs: 1209 nominal / 1459 worst-case bits per 2 ms at "
                                       "1000 kbit/s = ",
                                       0),
            0u)
      << describe_bus_load(l);
  EXPECT_EQ(describe_bus_load_terms(l),
            "worst-case bits: 10 cyclic frames 990, blocking 135, EMCY 1 × 135, 8 heartbeats 11, "
            "8 event-driven PDOs 188");
  // Bus 0 carries nothing of it but its own SYNC, master heartbeat, blocking and EMCY: 55 + 65 + 270.
  EXPECT_EQ(planned_bus_load(c, 0).bits_worst, 390u);
  EXPECT_EQ(planned_bus_load(c, 0).heartbeats, 0u);
}

TEST(BusLoad, MixedBusTermsFollowTheirSettings) {
  const CanAxisPortConfig base = mixed_bus();
  const std::uint32_t worst = planned_bus_load(base, 1).bits_worst;  // 1459
  // TPDO2 on: every drive's, profile ones included (synchronous): + 7 · 115.
  CanAxisPortConfig c = base;
  c.tpdo2 = true;
  EXPECT_EQ(planned_bus_load(c, 1).bits_worst, worst + 7u * 115u);
  EXPECT_EQ(planned_bus_load(c, 1).frames, 17u);
  // A slower inhibit (20 ms) halves the profile drives' rate: ⌈34.5⌉ + ⌈34.5⌉ + ⌈12.5⌉ + ⌈12.5⌉ = 96.
  c = base;
  c.profile_tpdo_inhibit_s = 0.020;
  EXPECT_EQ(planned_bus_load(c, 1).event_bits_worst, 96u);
  // An event timer shorter than the inhibit time is the faster bound (5 ms: 2 · 138 + 2 · 50 = 376).
  c = base;
  c.profile_tpdo_event_timer_s = 0.005;
  EXPECT_EQ(planned_bus_load(c, 1).event_bits_worst, 376u);
  // A slower heartbeat: ⌈520 · 2 / 1000⌉ = ⌈1.04⌉ = 2.
  c = base;
  c.heartbeat_producer_s = 1.0;
  c.heartbeat_consumer_s = 2.5;
  EXPECT_EQ(planned_bus_load(c, 1).heartbeat_bits_worst, 2u);
  // No master heartbeat: one 65-bit frame less.
  c = base;
  c.master_node_id = 0;
  EXPECT_EQ(planned_bus_load(c, 1).bits_worst, worst - 65u);
  // A profile drive switched to cyclic position: + 115 + 115 synchronous, − ⌈345·0.2⌉ + ⌈230·0.2⌉
  // of the events (69 → 46 for each of RPDO1 and TPDO1).
  c = base;
  c.axes[3].mode = DriveMode::kCyclicPosition;
  EXPECT_EQ(planned_bus_load(c, 1).bits_worst, worst + 230u - 2u * (69u - 46u));
  // Without the I/O module's heartbeat: 7 nodes, ⌈9.1⌉ = 10.
  c = base;
  c.other_nodes_per_bus[1] = 0;
  EXPECT_EQ(planned_bus_load(c, 1).heartbeat_bits_worst, 10u);
}

TEST(BusLoad, RatesRoundUpOnlyWhatIsNotWhole) {
  // Ten heartbeats every 100 ms at 2 ms: 10 · 65 · 2 / 100 = 13 exactly; five: 6.5 → 7; one: 1.3 → 2.
  for (const auto& [n, bits] : {std::pair{10u, 13u}, std::pair{5u, 7u}, std::pair{1u, 2u}}) {
    const RateGroup hb[] = {{1, n, 0.100}};
    CycleTraffic t;
    t.heartbeats = hb;
    EXPECT_EQ(compute_cycle_load(t, 1'000'000, 0.002).heartbeat_bits_worst, bits) << n;
    EXPECT_EQ(compute_cycle_load(t, 1'000'000, 0.002).frames, 0u);
  }
}

TEST(BusLoad, FourCyclicDrivesPerBusAtTwoMilliseconds) {
  // The rule the shipped looms are wired by: SYNC + n cyclic drives + master heartbeat, blocking, EMCY,
  // n heartbeats every 100 ms, at 2 ms and 1 Mbit/s.
  const auto bus = [](std::uint32_t n, bool tpdo2) {
    CanAxisPortConfig c;
    c.axes.clear();
    for (std::uint8_t i = 1; i <= n; ++i) c.axes.push_back({"a" + std::to_string(i), 0, i});
    c.tpdo2 = tpdo2;
    return planned_bus_load(c, 0);
  };
  // 4: 55 + 4 · 230 + 65 + 135 + 135 + ⌈5.2⌉ = 1316 = 65.8 %.
  EXPECT_EQ(bus(4, false).bits_worst, 1316u);
  EXPECT_TRUE(check_bus_load(bus(4, false), 0.70).is_ok());
  // 5: 55 + 5 · 230 + 65 + 270 + ⌈6.5⌉ = 1547 = 77.4 %: refused.
  EXPECT_EQ(bus(5, false).bits_worst, 1547u);
  EXPECT_FALSE(check_bus_load(bus(5, false), 0.70).is_ok());
  // 4 with TPDO2: + 4 · 115 = 1776 = 88.8 %: refused; 3 with TPDO2: 55 + 3 · 345 + 65 + 270 + 4 = 1429.
  EXPECT_EQ(bus(4, true).bits_worst, 1776u);
  EXPECT_EQ(bus(3, true).bits_worst, 1429u);
  EXPECT_FALSE(check_bus_load(bus(3, true), 0.70).is_ok());
}

TEST(BusLoad, RefusalNamesTheNumbers) {
  const FrameGroup nine[] = {{0, 1}, {6, 4}, {6, 4}};
  const BusLoad l = compute_bus_load(nine, 1'000'000, 0.001);
  const Status s = check_bus_load(l, 0.70);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(s.message().find("9 frames"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("975"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("97.5 %"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("70 %"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("1000 kbit/s"), std::string::npos) << s.message();
  // Exactly at the budget is allowed.
  EXPECT_TRUE(check_bus_load(l, 0.975).is_ok());
}

// ---- independent check of the stuffing bound -------------------------------------------------------
// Bits of a classic data frame from SOF to the end of the CRC (the stuffed region), CRC-15/CAN
// (polynomial 0x4599) computed over SOF..data.
std::vector<int> stuffed_region(std::uint32_t id, const std::vector<std::uint8_t>& data) {
  std::vector<int> bits;
  const auto put = [&](std::uint32_t v, int n) {
    for (int i = n - 1; i >= 0; --i) bits.push_back(static_cast<int>((v >> i) & 1U));
  };
  put(0, 1);    // SOF
  put(id, 11);  // identifier
  put(0, 1);    // RTR
  put(0, 1);    // IDE
  put(0, 1);    // r0
  put(static_cast<std::uint32_t>(data.size()), 4);
  for (std::uint8_t b : data) put(b, 8);
  std::uint32_t crc = 0;
  for (int b : bits) {
    const std::uint32_t next = static_cast<std::uint32_t>(b) ^ ((crc >> 14) & 1U);
    crc = (crc << 1) & 0x7FFF;
    if (next != 0) crc ^= 0x4599;
  }
  put(crc, 15);
  return bits;
}

int count_stuff_bits(const std::vector<int>& bits) {
  int stuffed = 0, run = 0, last = -1;
  for (int b : bits) {
    if (b == last) {
      ++run;
    } else {
      last = b;
      run = 1;
    }
    if (run == 5) {  // insert the complement; it starts a new run
      ++stuffed;
      last = 1 - b;
      run = 1;
    }
  }
  return stuffed;
}

TEST(BusLoad, WorstCaseStuffingBoundsRealFrames) {
  std::mt19937 rng(402);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<std::uint32_t> ident(0, 0x7FF);
  for (std::uint32_t s = 0; s <= 8; ++s) {
    const std::uint32_t bound = frame_bits_worst(s) - frame_bits_nominal(s);
    std::vector<std::vector<std::uint8_t>> payloads;
    payloads.emplace_back(s, 0x00);
    payloads.emplace_back(s, 0xFF);
    payloads.emplace_back(s, 0x78);  // 0111 1000: runs of four, the classic worst-case pattern
    for (int i = 0; i < 3000; ++i) {
      std::vector<std::uint8_t> d(s);
      for (auto& x : d) x = static_cast<std::uint8_t>(byte(rng));
      payloads.push_back(d);
    }
    for (const auto& d : payloads) {
      for (std::uint32_t id : {0x000u, 0x080u, 0x7FFu, 0x181u, ident(rng)}) {
        const auto n = static_cast<std::uint32_t>(count_stuff_bits(stuffed_region(id, d)));
        EXPECT_LE(n, bound) << "s=" << s << " id=" << id;
      }
    }
  }
}

}  // namespace
}  // namespace loom::drivers

// Bus-load arithmetic against the published table (classic CAN, worst-case stuffing per Davis et al. 2007),
// and the worst-case stuffing formula checked as a true upper bound by stuffing real frames bit by bit
// (CRC-15 included).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "loom/drivers/bus_load.hpp"

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

TEST(BusLoad, ServoCycleOfThisLoom) {
  // SYNC + 3 RPDO + 3 TPDO at 2 ms, 1 Mbit/s: (47 + 6·95) / 2000 and (55 + 6·115) / 2000.
  const BusLoad l = servo_cycle_bus_load(3, false, 1'000'000, 0.002);
  EXPECT_EQ(l.frames, 7u);
  EXPECT_EQ(l.bits_nominal, 617u);
  EXPECT_EQ(l.bits_worst, 745u);
  EXPECT_NEAR(l.utilisation_nominal, 0.3085, 1e-12);
  EXPECT_NEAR(l.utilisation_worst, 0.3725, 1e-12);
  EXPECT_TRUE(check_bus_load(l, 0.70).is_ok());
  const BusLoad with_tpdo2 = servo_cycle_bus_load(3, true, 1'000'000, 0.002);
  EXPECT_EQ(with_tpdo2.frames, 10u);
  EXPECT_EQ(with_tpdo2.bits_worst, 745u + 3u * 115u);
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

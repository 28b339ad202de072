// Unit tests of the HIL judge (candump parser and protocol checks) on synthetic logs written from the
// CiA 301/402 rules, so the HIL tests can be trusted to fail: each broken rule must be caught and
// named, and a conforming exchange must pass.
#include "canlog.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <sstream>
#include <string>
#include <vector>

#include "protocol_checks.hpp"

namespace loom::hil {
namespace {

// ---------------------------------------------------------------------------------------------------
// Parser
// ---------------------------------------------------------------------------------------------------
TEST(HilJudgeCandumpLine, ReadsStandardFrame) {
  std::string err;
  const auto f = parse_candump_line("(1700000000.123456) vcan0 701#05", err);
  ASSERT_TRUE(f) << err;
  EXPECT_EQ(f->t_us, 1700000000123456LL);
  EXPECT_EQ(f->id, 0x701U);
  EXPECT_FALSE(f->extended);
  EXPECT_EQ(f->len, 1);
  EXPECT_EQ(f->data[0], 0x05);
}

TEST(HilJudgeCandumpLine, ReadsEmptyRemoteExtendedAndErrorFrames) {
  std::string err;
  auto sync = parse_candump_line("(0000000001.000000)  vcan0  080#", err);
  ASSERT_TRUE(sync) << err;
  EXPECT_EQ(sync->len, 0);
  auto rtr = parse_candump_line("(1.000001) vcan0 701#R", err);
  ASSERT_TRUE(rtr) << err;
  EXPECT_TRUE(rtr->rtr);
  auto ext = parse_candump_line("(1.000002) vcan0 18DAF110#0102", err);
  ASSERT_TRUE(ext) << err;
  EXPECT_TRUE(ext->extended);
  EXPECT_EQ(ext->id, 0x18DAF110U);
  auto errf = parse_candump_line("(1.000003) vcan0 20000004#0000000000000000", err);
  ASSERT_TRUE(errf) << err;
  EXPECT_TRUE(errf->error_frame);
}

TEST(HilJudgeCandumpLine, LittleEndianFields) {
  std::string err;
  const auto f = parse_candump_line("(1.000000) vcan0 201#0F00FEFFFFFF", err);
  ASSERT_TRUE(f) << err;
  EXPECT_EQ(f->u16(0), 0x000F);
  EXPECT_EQ(f->i32(2), -2);
}

TEST(HilJudgeCandumpLine, RejectsMalformedLinesNamingThePart) {
  std::string err;
  EXPECT_FALSE(parse_candump_line("(1.0) vcan0 701#05", err));
  EXPECT_NE(err.find("timestamp"), std::string::npos) << err;
  EXPECT_FALSE(parse_candump_line("(1.000000) vcan0 7010#05", err));
  EXPECT_NE(err.find("id"), std::string::npos) << err;
  EXPECT_FALSE(parse_candump_line("(1.000000) vcan0 801#05", err));
  EXPECT_NE(err.find("0x7FF"), std::string::npos) << err;
  EXPECT_FALSE(parse_candump_line("(1.000000) vcan0 701#0", err));
  EXPECT_NE(err.find("data"), std::string::npos) << err;
  EXPECT_FALSE(parse_candump_line("(1.000000) vcan0 701#000102030405060708", err));
  EXPECT_FALSE(parse_candump_line("(1.000000) vcan0 701#ZZ", err));
  EXPECT_FALSE(parse_candump_line("(1.000000) vcan0 123##1001122", err));
  EXPECT_NE(err.find("FD"), std::string::npos) << err;
  EXPECT_FALSE(parse_candump_line("(1.000000) vcan0", err));
}

TEST(HilJudgeCandumpLog, ReportsTheLineNumberOfABadLine) {
  std::istringstream in("(1.000000) vcan0 080#\n\n(1.004000) vcan0 080#\nnonsense\n");
  std::vector<Frame> frames;
  std::string err;
  EXPECT_FALSE(read_candump_log(in, frames, err));
  EXPECT_EQ(err.rfind("line 4:", 0), 0U) << err;
}

// ---------------------------------------------------------------------------------------------------
// Synthetic exchanges
// ---------------------------------------------------------------------------------------------------
class Bus {
 public:
  void at(std::int64_t t_us) { t_us_ = t_us; }
  void advance(std::int64_t dt_us) { t_us_ += dt_us; }
  void frame(unsigned id, std::initializer_list<unsigned> bytes) {
    char head[48];
    std::snprintf(head, sizeof head, "(%lld.%06lld) vcan0 %03X#", static_cast<long long>(t_us_ / 1000000),
                  static_cast<long long>(t_us_ % 1000000), id);
    out_ << head;
    for (unsigned b : bytes) {
      char byte[3];
      std::snprintf(byte, sizeof byte, "%02X", b & 0xFFU);
      out_ << byte;
    }
    out_ << "\n";
    t_us_ += 50;  // frames on a bus never share a timestamp
  }
  void pdo(unsigned id, unsigned word, std::int32_t value) {
    const auto v = static_cast<std::uint32_t>(value);
    frame(id, {word & 0xFFU, word >> 8U, v & 0xFFU, (v >> 8U) & 0xFFU, (v >> 16U) & 0xFFU, v >> 24U});
  }
  std::vector<Frame> frames() const {
    std::istringstream in(out_.str());
    std::vector<Frame> fs;
    std::string err;
    EXPECT_TRUE(read_candump_log(in, fs, err)) << err;
    return fs;
  }
  std::int64_t now() const { return t_us_; }

 private:
  std::ostringstream out_;
  std::int64_t t_us_ = 1'700'000'000'000'000;
};

const std::vector<int> kNodes{1, 2, 3};

// What a conforming master and drive say: reset, boot-ups, mode 8 set and confirmed, start, then 4 ms
// SYNC cycles where the drive answers with its TPDO and the master with its RPDO (the controlword
// computed from that statusword: shutdown, then enable once Ready to switch on).
struct Script {
  unsigned mode_read_back = 8;
  unsigned mode_ack_cs = 0x60;
  std::uint16_t sw_when_enabling = 0x0221;  // Ready to switch on
  std::int32_t enable_target_offset = 0;    // 0 = seeded from the reported position
  int cycles = 100;
};

void startup(Bus& bus, const Script& s) {
  bus.frame(0x000, {0x81, 0x00});
  for (int n : kNodes) bus.frame(0x700U + static_cast<unsigned>(n), {0x00});
  for (int n : kNodes) {
    const auto u = static_cast<unsigned>(n);
    bus.frame(0x600 + u, {0x2F, 0x60, 0x60, 0x00, 0x08, 0, 0, 0});
    bus.frame(0x580 + u, {s.mode_ack_cs, 0x60, 0x60, 0x00, 0, 0, 0, 0});
    bus.frame(0x600 + u, {0x2B, 0x17, 0x10, 0x00, 100, 0, 0, 0});
    bus.frame(0x580 + u, {0x60, 0x17, 0x10, 0x00, 0, 0, 0, 0});
    bus.frame(0x600 + u, {0x40, 0x61, 0x60, 0x00, 0, 0, 0, 0});
    bus.frame(0x580 + u, {0x4F, 0x61, 0x60, 0x00, s.mode_read_back, 0, 0, 0});
  }
  bus.frame(0x000, {0x01, 0x00});
}

// One 4 ms cycle; position[n] follows the target exactly (ideal drive).
void cycle(Bus& bus, int k, const Script& s, std::vector<std::int32_t>& position, bool drives_alive = true,
           unsigned cw_override = 0xFFFF, bool hold_target = false) {
  bus.frame(0x080, {});
  for (int n : kNodes) {
    const auto u = static_cast<unsigned>(n);
    std::int32_t& pos = position[static_cast<std::size_t>(n)];
    const unsigned sw = k == 0 ? 0x0240U : (k == 1 ? s.sw_when_enabling : 0x1237U);
    if (drives_alive) bus.pdo(0x180 + u, sw, pos);
    unsigned cw = k == 0 ? 0x0006U : 0x000FU;
    std::int32_t target = pos;
    if (k == 1) target = pos + s.enable_target_offset;
    if (k >= 2 && !hold_target) target = pos + 10 * n;
    if (cw_override != 0xFFFF) cw = cw_override;
    bus.pdo(0x200 + u, cw, target);
    if (drives_alive) pos = target;
  }
  if (drives_alive && k >= 2 && k % 25 == 0) {
    for (int n : kNodes) bus.frame(0x700U + static_cast<unsigned>(n), {0x05});
  }
  bus.advance(4000 - 50 * 7);
}

std::vector<Frame> weave_log(const Script& s) {
  Bus bus;
  startup(bus, s);
  std::vector<std::int32_t> pos{0, 1000, -2000, 3000};
  for (int k = 0; k < s.cycles; ++k) cycle(bus, k, s, pos);
  return bus.frames();
}

// ---------------------------------------------------------------------------------------------------
// Weave protocol
// ---------------------------------------------------------------------------------------------------
TEST(HilJudgeWeaveProtocol, ConformingExchangePasses) {
  const auto r = check_weave_protocol(weave_log({}), kNodes);
  EXPECT_TRUE(r.ok) << r.failure;
  EXPECT_EQ(r.notes.size(), kNodes.size());
}

TEST(HilJudgeWeaveProtocol, SummaryCountsEachService) {
  const auto s = summarize(weave_log({}));
  EXPECT_EQ(s.nmt, 2U);
  EXPECT_EQ(s.sync, 100U);
  EXPECT_EQ(s.rpdo, 300U);
  EXPECT_EQ(s.tpdo, 300U);
  EXPECT_EQ(s.sdo_request, 9U);
  EXPECT_EQ(s.sdo_reply, 9U);
  EXPECT_EQ(s.heartbeat, 3U + 3U * 3U);  // boot-ups + operational heartbeats at k = 25, 50, 75
  EXPECT_EQ(s.total, 2U + 100U + 600U + 18U + 12U);
}

TEST(HilJudgeWeaveProtocol, MissingBootUpIsCaught) {
  Bus bus;
  bus.frame(0x000, {0x81, 0x00});
  bus.frame(0x701, {0x00});
  bus.frame(0x702, {0x00});  // node 3 never boots
  const auto r = check_weave_protocol(bus.frames(), kNodes);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("node 1: no SDO download 0x6060"), std::string::npos) << r.failure;
  const auto r3 = check_weave_protocol(bus.frames(), {3});
  EXPECT_NE(r3.failure.find("node 3: no boot-up 0x703"), std::string::npos) << r3.failure;
}

TEST(HilJudgeWeaveProtocol, WrongModeReadBackIsCaught) {
  Script s;
  s.mode_read_back = 3;  // profile velocity, not CSP
  const auto r = check_weave_protocol(weave_log(s), kNodes);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("0x6061 reads 3"), std::string::npos) << r.failure;
}

TEST(HilJudgeWeaveProtocol, AbortedModeDownloadIsCaught) {
  Script s;
  s.mode_ack_cs = 0x80;
  const auto r = check_weave_protocol(weave_log(s), kNodes);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("not acknowledged"), std::string::npos) << r.failure;
}

TEST(HilJudgeWeaveProtocol, EnablingWithoutConfirmedStatuswordIsCaught) {
  Script s;
  s.sw_when_enabling = 0x0240;  // still Switch on disabled: 0x000F would be a blind sequence
  const auto r = check_weave_protocol(weave_log(s), kNodes);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("statusword 0x0240"), std::string::npos) << r.failure;
}

TEST(HilJudgeWeaveProtocol, TargetJumpOnEnableIsCaught) {
  Script s;
  s.enable_target_offset = 5000;
  const auto r = check_weave_protocol(weave_log(s), kNodes);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("jump on enable"), std::string::npos) << r.failure;
}

TEST(HilJudgeWeaveProtocol, OrderMattersNotJustPresence) {
  // NMT start before the mode was confirmed: every frame is there, the order is wrong.
  Bus bus;
  bus.frame(0x000, {0x81, 0x00});
  bus.frame(0x701, {0x00});
  bus.frame(0x000, {0x01, 0x00});
  bus.frame(0x601, {0x2F, 0x60, 0x60, 0x00, 0x08, 0, 0, 0});
  bus.frame(0x581, {0x60, 0x60, 0x60, 0x00, 0, 0, 0, 0});
  bus.frame(0x601, {0x40, 0x61, 0x60, 0x00, 0, 0, 0, 0});
  bus.frame(0x581, {0x4F, 0x61, 0x60, 0x00, 8, 0, 0, 0});
  bus.frame(0x080, {});
  const auto r = check_weave_protocol(bus.frames(), {1});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("no NMT start"), std::string::npos) << r.failure;
}

TEST(HilJudgeWeaveProtocol, MissingTpdosAreCaught) {
  Bus bus;
  Script s;
  startup(bus, s);
  std::vector<std::int32_t> pos{0, 0, 0, 0};
  for (int k = 0; k < 20; ++k) cycle(bus, k, s, pos);
  for (int k = 20; k < 40; ++k) cycle(bus, k, s, pos, /*drives_alive=*/false);
  const auto r = check_weave_protocol(bus.frames(), kNodes);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("40 SYNCs but 40 RPDOs and 20 TPDOs"), std::string::npos) << r.failure;
}

// ---------------------------------------------------------------------------------------------------
// Heartbeat loss: 100 ms heartbeat, drives killed after cycle 60; the master notices `detect_cycles`
// later and quick-stops (0x0002), holding the target.
// ---------------------------------------------------------------------------------------------------
struct Loss {
  int detect_cycles = 40;  // 160 ms after the kill
  bool moves_after_fault = false;
  bool reenables = false;
  bool reacts = true;
};

std::vector<Frame> loss_log(const Loss& loss) {
  Bus bus;
  Script s;
  startup(bus, s);
  std::vector<std::int32_t> pos{0, 0, 0, 0};
  int k = 0;
  for (; k <= 60; ++k) cycle(bus, k, s, pos);  // last heartbeat at k = 50
  for (int i = 0; i < loss.detect_cycles; ++i, ++k) cycle(bus, k, s, pos, false);
  if (!loss.reacts) return bus.frames();
  for (int i = 0; i < 30; ++i, ++k) {
    cycle(bus, k, s, pos, false, 0x0002, /*hold_target=*/!loss.moves_after_fault || i < 10);
  }
  if (loss.reenables) cycle(bus, k, s, pos, false, 0x000F, true);
  return bus.frames();
}

TEST(HilJudgeHeartbeatLoss, TimelyQuickStopHoldingTargetPasses) {
  // Last heartbeat at cycle 50; kill after cycle 60; fault at cycle 101 → ~204 ms ≤ 300 ms.
  const auto r = check_heartbeat_loss(loss_log({}), kNodes, 0.100, 3);
  EXPECT_TRUE(r.ok) << r.failure;
  ASSERT_EQ(r.notes.size(), 3U);
  EXPECT_NE(r.notes[0].find("0x0002"), std::string::npos) << r.notes[0];
}

TEST(HilJudgeHeartbeatLoss, LateReactionIsCaught) {
  Loss loss;
  loss.detect_cycles = 70;  // fault at cycle 131 → ~324 ms after the last heartbeat
  const auto r = check_heartbeat_loss(loss_log(loss), kNodes, 0.100, 3);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("limit 300 ms"), std::string::npos) << r.failure;
  // The same log is within four periods: the limit is what decides.
  EXPECT_TRUE(check_heartbeat_loss(loss_log(loss), kNodes, 0.100, 4).ok);
}

TEST(HilJudgeHeartbeatLoss, OnTheMastersClockTheLimitIsInItsCycles) {
  // The same late log (81 cycles of 4 ms wall after the last heartbeat), judged on a master whose loop
  // ran at half real time (2 ms of its clock per 4 ms of wall): 162 ms of master time, within 300 ms.
  Loss loss;
  loss.detect_cycles = 70;
  EXPECT_TRUE(check_heartbeat_loss(loss_log(loss), kNodes, 0.100, 3, {}, 0.002).ok);
  // ... and a master that needed 200 of its cycles (400 ms of its own time) is late whatever the wall says.
  loss.detect_cycles = 190;
  const auto r = check_heartbeat_loss(loss_log(loss), kNodes, 0.100, 3, {}, 0.002);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("master cycles"), std::string::npos) << r.failure;
}

TEST(HilJudgeHeartbeatLoss, MotionAfterTheFaultIsCaught) {
  Loss loss;
  loss.moves_after_fault = true;
  const auto r = check_heartbeat_loss(loss_log(loss), kNodes, 0.100, 3);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("instead of the held"), std::string::npos) << r.failure;
}

TEST(HilJudgeHeartbeatLoss, ReEnableAfterTheFaultIsCaught) {
  Loss loss;
  loss.reenables = true;
  const auto r = check_heartbeat_loss(loss_log(loss), kNodes, 0.100, 3);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("re-enabled"), std::string::npos) << r.failure;
}

TEST(HilJudgeHeartbeatLoss, NoReactionIsCaught) {
  Loss loss;
  loss.reacts = false;
  const auto r = check_heartbeat_loss(loss_log(loss), kNodes, 0.100, 3);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("not acted on"), std::string::npos) << r.failure;
}

}  // namespace
}  // namespace loom::hil

// ---- I/O node traffic, EMCY stop, master loss (judge's own unit tests) -----------------------------
namespace loom::hil {
namespace {

std::vector<Frame> parse_log(const std::string& text) {
  std::istringstream in(text);
  std::vector<Frame> frames;
  std::string error;
  EXPECT_TRUE(read_candump_log(in, frames, error)) << error;
  return frames;
}

TEST(HilJudgeIo, EverySignalSeenPassesAndAMissingOneIsNamed) {
  const std::string full =
      "(1.000000) vcan0 204#01\n(1.002000) vcan0 204#02\n(1.004000) vcan0 184#4A00\n"
      "(1.006000) vcan0 184#5500\n(1.008000) vcan0 184#6000\n(1.010000) vcan0 284#2C01\n";
  EXPECT_TRUE(check_io_traffic(parse_log(full), 4).ok);
  const std::string no_right =
      "(1.000000) vcan0 204#03\n(1.004000) vcan0 184#5F00\n(1.010000) vcan0 284#2C01\n";
  const CheckResult r = check_io_traffic(parse_log(no_right), 4);
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.failure, "never seen on the bus: shuttle at right");
}

TEST(HilJudgeIo, SecondSwitchesMustBeCarriedSeenAndAgreeWithTheirFirst) {
  // Byte 2 = the second switches of bits 0..5 of byte 0.
  const std::string ok =
      "(1.000000) vcan0 204#01\n(1.002000) vcan0 204#02\n(1.004000) vcan0 184#4A000A\n"
      "(1.006000) vcan0 184#550015\n(1.008000) vcan0 184#600020\n(1.010000) vcan0 284#2C01\n";
  EXPECT_TRUE(check_io_traffic(parse_log(ok), 4, true).ok);
  const std::string two_bytes =
      "(1.000000) vcan0 204#01\n(1.002000) vcan0 204#02\n(1.004000) vcan0 184#4A00\n"
      "(1.006000) vcan0 184#5500\n(1.008000) vcan0 184#6000\n(1.010000) vcan0 284#2C01\n";
  EXPECT_TRUE(check_io_traffic(parse_log(two_bytes), 4).ok);
  EXPECT_FALSE(check_io_traffic(parse_log(two_bytes), 4, true).ok);
  const std::string stuck =  // the second switch of "shuttle at right" never made
      "(1.000000) vcan0 204#01\n(1.002000) vcan0 204#02\n(1.004000) vcan0 184#4A000A\n"
      "(1.006000) vcan0 184#550015\n(1.008000) vcan0 184#600000\n(1.010000) vcan0 284#2C01\n";
  const CheckResult r = check_io_traffic(parse_log(stuck), 4, true);
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.failure, "never seen on the bus: shuttle at right (second switch)");
  const std::string apart =  // seen on, but once apart from its first switch
      "(1.000000) vcan0 204#01\n(1.002000) vcan0 204#02\n(1.004000) vcan0 184#4A000A\n"
      "(1.006000) vcan0 184#550015\n(1.008000) vcan0 184#600020\n(1.009000) vcan0 184#400020\n"
      "(1.010000) vcan0 284#2C01\n";
  const CheckResult a = check_io_traffic(parse_log(apart), 4, true);
  ASSERT_FALSE(a.ok);
  EXPECT_NE(a.failure.find("second switches 0x20 disagree with first switches 0x00"), std::string::npos)
      << a.failure;
}

// One head (gripper bit 8, cutter bit 20 in the I/O node's RPDO 0x204; yarn-present bit 24 in its TPDO
// 0x184; selector node 21, carriage node 2), two knots: select, grip, cut, knot seen, open, carriage on.
std::string knot_log(const std::string& middle = "") {
  return "(1.000000) vcan0 215#0F0000000000\n"  // selector at slot 0
         "(1.001000) vcan0 202#0F0000000000\n"  // carriage at knot 0
         "(1.002000) vcan0 204#000100\n"        // gripper closes
         "(1.003000) vcan0 204#000110\n"        // cutter fires
         "(1.004000) vcan0 184#00000001\n"      // knot seen
         "(1.005000) vcan0 204#000000\n"        // gripper opens, cutter back
         + middle +
         "(1.006000) vcan0 202#0F0010000000\n"  // carriage one pitch on
         "(1.007000) vcan0 184#00000000\n"
         "(1.008000) vcan0 215#0F0000080000\n"  // selector to slot 1
         "(1.009000) vcan0 204#000100\n"
         "(1.010000) vcan0 204#000110\n"
         "(1.011000) vcan0 184#00000001\n"
         "(1.012000) vcan0 204#000000\n";
}
KnottingWiring one_head() {
  KnottingWiring w;
  w.gripper_bits = {8};
  w.cutter_bits = {20};
  w.yarn_bits = {24};
  w.selector_nodes = {21};
  w.carriage_node = 2;
  w.knots_per_head = 2;
  return w;
}

TEST(HilJudgeKnotting, EveryCutIsAKnotSeenAndNothingMovesUnderAClosedGripper) {
  const CheckResult ok = check_knotting(parse_log(knot_log()), 4, one_head());
  EXPECT_TRUE(ok.ok) << ok.failure;
  KnottingWiring three = one_head();
  three.knots_per_head = 3;
  EXPECT_EQ(check_knotting(parse_log(knot_log()), 4, three).failure,
            "head 1: 2 cuts and 2 knots seen, expected 3 of each");
  // The carriage moved with the gripper closed.
  const CheckResult dragged =
      check_knotting(parse_log("(0.998000) vcan0 202#0F0030000000\n(0.999000) vcan0 204#000100\n"
                               "(0.999500) vcan0 202#0F0000000000\n" +
                               knot_log()),
                     4, one_head());
  EXPECT_NE(dragged.failure.find("the carriage moved while a gripper was closed"), std::string::npos)
      << dragged.failure;
  // The selector turned under held yarn.
  const CheckResult turned = check_knotting(
      parse_log(knot_log(
          "(1.005500) vcan0 204#000100\n(1.005600) vcan0 215#0F0000040000\n(1.005700) vcan0 204#000000\n")),
      4, one_head());
  EXPECT_NE(turned.failure.find("head 1's selector turned under its closed gripper"), std::string::npos)
      << turned.failure;
  // A cut with the gripper open, and a cut whose knot was never seen.
  const CheckResult open_cut = check_knotting(
      parse_log("(0.500000) vcan0 204#000010\n(0.600000) vcan0 204#000000\n" + knot_log()), 4, one_head());
  EXPECT_NE(open_cut.failure.find("head 1's cutter fired with its gripper open"), std::string::npos)
      << open_cut.failure;
  std::string missed = knot_log();
  missed.replace(missed.find("(1.011000) vcan0 184#00000001\n"), 30, "(1.011000) vcan0 184#00000000\n");
  EXPECT_EQ(check_knotting(parse_log(missed), 4, one_head()).failure,
            "head 1: 2 cuts and 1 knots seen, expected 2 of each");
}

TEST(HilJudgeEmcy, EveryDriveStopsWithinOneCycleOfTheEmcyAndStaysStopped) {
  // The EMCY lands after the master read the bus: SYNC and RPDO1s of the cycle in progress still enable
  // (decided before the EMCY), the next cycle stops both drives.
  const std::string ok =
      "(1.000000) vcan0 080#\n(1.000050) vcan0 201#0F0000000000\n(1.001000) vcan0 082#1023030000000000\n"
      "(1.004000) vcan0 080#\n(1.004050) vcan0 201#0F0000000000\n(1.004100) vcan0 202#0F0000000000\n"
      "(1.008000) vcan0 080#\n(1.008050) vcan0 201#020000000000\n(1.008100) vcan0 202#020000000000\n"
      "(1.012000) vcan0 080#\n(1.012050) vcan0 201#000000000000\n";
  const CheckResult pass = check_emcy_stop(parse_log(ok), {1, 2}, 2);
  EXPECT_TRUE(pass.ok) << pass.failure;
  std::string reaction;  // the reaction is reported: where and in which cycle after the EMCY drive 1 stopped
  for (const std::string& n : pass.notes) {
    if (n.rfind("node 1:", 0) == 0) reaction = n;
  }
  EXPECT_EQ(reaction.rfind("node 1: quick stop at line 8,", 0), 0U) << reaction;
  EXPECT_NE(reaction.find("in cycle 2 after it"), std::string::npos) << reaction;
  // Still enabling one whole cycle after the EMCY.
  const std::string late =
      "(1.001000) vcan0 082#1023030000000000\n(1.004000) vcan0 080#\n(1.004050) vcan0 201#020000000000\n"
      "(1.008000) vcan0 080#\n(1.008050) vcan0 201#0F0000000000\n(1.008100) vcan0 202#020000000000\n"
      "(1.012000) vcan0 080#\n";
  const CheckResult l = check_emcy_stop(parse_log(late), {1, 2}, 2);
  ASSERT_FALSE(l.ok);
  EXPECT_NE(l.failure.find("node 1: first RPDO1 of the next cycle"), std::string::npos) << l.failure;
  // Stopped, then enabled again.
  const std::string again =
      "(1.001000) vcan0 082#1023030000000000\n(1.004000) vcan0 080#\n(1.008000) vcan0 080#\n"
      "(1.008050) vcan0 201#020000000000\n(1.012000) vcan0 080#\n(1.012050) vcan0 201#0F0000000000\n";
  const CheckResult g = check_emcy_stop(parse_log(again), {1}, 2);
  ASSERT_FALSE(g.ok);
  EXPECT_NE(g.failure.find("re-enabled"), std::string::npos) << g.failure;
  // A drive the master stopped talking to, and a log that ends before the next cycle.
  EXPECT_FALSE(check_emcy_stop(parse_log(again), {1, 3}, 2).ok);
  EXPECT_FALSE(
      check_emcy_stop(parse_log("(1.001000) vcan0 082#1023030000000000\n(1.004000) vcan0 080#\n"), {1}, 2)
          .ok);
}

TEST(HilJudgeFeedbackLag, ATpdoTrailingItsSyncIsCountedAndOverTheLimitFails) {
  // Node 1 answers every SYNC at once; node 2's answers to two SYNCs arrive together after the second.
  const std::string log =
      "(1.000000) vcan0 080#\n(1.001000) vcan0 181#370000000000\n(1.002000) vcan0 182#370000000000\n"
      "(1.004000) vcan0 080#\n(1.005000) vcan0 181#370000000000\n"
      "(1.008000) vcan0 080#\n(1.009000) vcan0 181#370000000000\n(1.010000) vcan0 182#370000000000\n"
      "(1.011000) vcan0 182#370000000000\n";
  const std::vector<Frame> frames = parse_log(log);
  const CheckResult report = check_feedback_lag(frames, {1, 2}, 1000);
  EXPECT_TRUE(report.ok);
  ASSERT_EQ(report.notes.size(), 2U);
  EXPECT_EQ(report.notes[0], "node 1: 3 TPDO1s, each answering the SYNC right before it");
  EXPECT_EQ(report.notes[1], "node 2: 3 TPDO1s, 1 of them late (worst 1 cycle(s) behind, at line 8)")
      << report.notes[1];
  EXPECT_TRUE(check_feedback_lag(frames, {1}, 0).ok);
  const CheckResult strict = check_feedback_lag(frames, {1, 2}, 0);
  EXPECT_FALSE(strict.ok);
  EXPECT_NE(strict.failure.find("more than 0 cycle(s) late"), std::string::npos) << strict.failure;
  // A node that sent no TPDO1 cannot be judged: that is a failure, not a pass.
  const CheckResult silent = check_feedback_lag(frames, {1, 3}, 1000);
  EXPECT_FALSE(silent.ok);
  EXPECT_EQ(silent.failure, "node 3: no TPDO1 in the log");
}

TEST(HilJudgeMasterLoss, EveryConsumerMustReactInTime) {
  const std::string ok =
      "(1.000000) vcan0 77F#05\n(1.160000) vcan0 081#3081100000000000\n(1.170000) vcan0 "
      "084#3081110000000000\n";
  EXPECT_TRUE(check_master_loss(parse_log(ok), {1, 4}, 127, 0.150, 0.05).ok);
  EXPECT_FALSE(check_master_loss(parse_log(ok), {1, 2}, 127, 0.150, 0.05).ok);  // node 2 silent
  EXPECT_FALSE(check_master_loss(parse_log(ok), {1, 4}, 127, 0.100, 0.01).ok);  // too late for 100 ms
}

// ---------------------------------------------------------------------------------------------------
// Profile position
// ---------------------------------------------------------------------------------------------------
// A profile-position drive (node 21): mode 1 and the 10 ms inhibit time written, started; then 2 ms SYNC
// cycles in which the master sends an RPDO1 only on change: enable, one set-point (bit 4) that the drive
// acknowledges (bit 12) before its release, the move, reported every 10 ms by the event-driven TPDO1.
struct PpScript {
  bool repeat_rpdo = false;  // the master sends the enabled RPDO1 again unchanged
  bool release_before_ack = false;
  std::int64_t tpdo_every_us = 10000;
  unsigned inhibit = 100;  // 0x1800:03 written
};

std::vector<Frame> pp_log(const PpScript& s) {
  Bus bus;
  bus.frame(0x000, {0x81, 0x00});
  bus.frame(0x715, {0x00});
  bus.frame(0x615, {0x2F, 0x60, 0x60, 0x00, 0x01, 0, 0, 0});
  bus.frame(0x595, {0x60, 0x60, 0x60, 0x00, 0, 0, 0, 0});
  bus.frame(0x615, {0x2B, 0x00, 0x18, 0x03, s.inhibit & 0xFFU, s.inhibit >> 8U, 0, 0});
  bus.frame(0x595, {0x60, 0x00, 0x18, 0x03, 0, 0, 0, 0});
  bus.frame(0x000, {0x01, 0x00});
  std::int64_t next_tpdo = 0, t = 0;
  std::uint16_t sw = 0x0637;  // enabled, target reached
  for (int k = 0; k < 300; ++k, t += 2000) {
    bus.frame(0x080, {});
    if (k == 20) sw = 0x1237;  // the set-point acknowledged, moving
    if (k == 24) sw = 0x0237;
    if (k == 80) sw = 0x0637;  // arrived
    if (t >= next_tpdo) {
      bus.pdo(0x195, sw, 1000 + (k >= 20 ? std::min(k - 20, 60) * 100 : 0));
      next_tpdo = t + s.tpdo_every_us;
    }
    if (k == 2) bus.pdo(0x215, 0x000F, 1000);
    if (k == 3 && s.repeat_rpdo) bus.pdo(0x215, 0x000F, 1000);
    const int setpoint_k = s.release_before_ack ? 16 : 19;  // the acknowledge is in the TPDO of cycle 20
    if (k == setpoint_k) bus.pdo(0x215, 0x003F, 7000);
    if (k == setpoint_k + (s.release_before_ack ? 1 : 3)) bus.pdo(0x215, 0x000F, 7000);
    bus.advance(2000 - 50 * 3);
  }
  return bus.frames();
}

TEST(HilJudgeProfilePosition, AConformingExchangePasses) {
  const auto r = check_profile_position(pp_log({}), {21}, 0.010, 1);
  EXPECT_TRUE(r.ok) << r.failure;
  ASSERT_FALSE(r.notes.empty());
  EXPECT_NE(r.notes[0].find("1 set-points"), std::string::npos) << r.notes[0];
}

TEST(HilJudgeProfilePosition, EachBrokenRuleIsCaughtAndNamed) {
  PpScript repeat;
  repeat.repeat_rpdo = true;
  auto r = check_profile_position(pp_log(repeat), {21}, 0.010, 1);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("repeated unchanged"), std::string::npos) << r.failure;
  PpScript early;
  early.release_before_ack = true;
  r = check_profile_position(pp_log(early), {21}, 0.010, 1);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("before the drive acknowledged"), std::string::npos) << r.failure;
  PpScript close;
  close.tpdo_every_us = 6000;
  r = check_profile_position(pp_log(close), {21}, 0.010, 1);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("inhibit time"), std::string::npos) << r.failure;
  PpScript inhibit;
  inhibit.inhibit = 50;
  r = check_profile_position(pp_log(inhibit), {21}, 0.010, 1);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.failure.find("0x1800:03"), std::string::npos) << r.failure;
  EXPECT_FALSE(check_profile_position(pp_log({}), {21}, 0.010, 2).ok);  // one set-point, two wanted
}

}  // namespace
}  // namespace loom::hil

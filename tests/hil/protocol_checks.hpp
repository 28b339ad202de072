// Protocol checks over a candump log for the HIL tests: what loomctl and the simulated drives said on
// the bus, judged against CiA 301/402 facts (CiA 301 / CiA 402), in order and content rather
// than timing (the VM is not real-time). Configure-time only: test tooling, allocates freely.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "canlog.hpp"

namespace loom::hil {

// PDO layout the checks read (the mapping loomctl's master writes and the simulated drive uses):
//   RPDO1 0x200+id: controlword UINT16 at byte 0, target position INT32 at byte 2 (6 bytes)
//   TPDO1 0x180+id: statusword UINT16 at byte 0, position actual INT32 at byte 2 (6 bytes)
struct PdoLayout {
  std::size_t controlword_at = 0;
  std::size_t target_at = 2;
  std::size_t statusword_at = 0;
  std::size_t position_at = 2;
};

// Frames per CANopen service, for the "frames exchanged" lines of the test logs.
struct TrafficSummary {
  std::size_t total = 0;
  std::size_t nmt = 0, sync = 0, emcy = 0, tpdo = 0, rpdo = 0, sdo_request = 0, sdo_reply = 0;
  std::size_t heartbeat = 0, other = 0, error_frames = 0;
  double span_s = 0.0;  // first to last timestamp
};
TrafficSummary summarize(const std::vector<Frame>& frames);
std::string describe(const TrafficSummary& s);  // one line: "N frames in S s: nmt=…"

struct CheckResult {
  bool ok = true;
  std::vector<std::string> notes;  // what was found, in bus order, for the test log
  std::string failure;             // first violated expectation, naming frame line and content
};

// Start-up and cyclic exchange of a master with CiA 402 nodes, per node:
//   NMT reset-node (000#81 00|id) → boot-up 0x700+id [00] → SDO download 0x6060:00 = 8 acknowledged →
//   SDO upload 0x6061:00 answered with 8 → NMT start (000#01 00|id) → SYNC 0x080 with RPDOs and TPDOs
//   (each ≥ 90 % of SYNCs after start; the first TPDO after the first SYNC) → controlword 0x000F only
//   after a statusword Ready to switch on / Switched on, first enabled target = reported position
//   (±2 counts) → statusword Operation enabled.
CheckResult check_weave_protocol(const std::vector<Frame>& frames, const std::vector<int>& nodes,
                                 const PdoLayout& layout = {});

// Heartbeat loss of every node in `nodes` (the drive process was killed): each node's heartbeat was
// operational (05) while the master had it enabled (0x000F); the first controlword after its last
// heartbeat that is not 0x000F (quick stop/disable: the fault reaction) came within
// `periods` × `heartbeat_s`; and no RPDO after that fault commands a target other than the fault's own.
// With `master_cycle_s` > 0 the limit is on the master's own clock — the SYNCs it sent between the last
// heartbeat and the reaction, one per cycle — instead of wall time: a master that runs slower than real
// time (a loop in a non-real-time VM) supervises in its cycles; on a board the two agree. Both are reported.
CheckResult check_heartbeat_loss(const std::vector<Frame>& frames, const std::vector<int>& nodes,
                                 double heartbeat_s, int periods, const PdoLayout& layout = {},
                                 double master_cycle_s = 0.0);

// Profile position (CiA 402 mode 1) drives, per node: 0x6060:00 = 1 downloaded and acknowledged, and
// 0x1800:03 (TPDO1 inhibit time) = `inhibit_s` in 100 µs; after the NMT start, every RPDO1 to the node
// differs from the one before (sent on change only) and none shares a SYNC interval with another; every
// new set-point (controlword bit 4 rising) is acknowledged by a TPDO1 with statusword bit 12, and only
// then released (bit 4 falling, same target); at least `min_moves` set-points; far fewer RPDO1s than
// SYNCs (not cyclic); and no two TPDO1s closer than the inhibit time (less `slack_s` for timestamping).
CheckResult check_profile_position(const std::vector<Frame>& frames, const std::vector<int>& nodes,
                                   double inhibit_s, int min_moves, double slack_s = 0.001,
                                   const PdoLayout& layout = {});

}  // namespace loom::hil

namespace loom::hil {

// Every actuator and sensor of the CiA 401 I/O node `io_node` crossed the bus (pre-defined PDO ids, the
// HIL wiring: outputs bit 0/1 = valves A/B; inputs bit 0..6 = A extended, A retracted, B extended,
// B retracted, shuttle left, shuttle right, e-stop chain closed; TPDO2 = load cell, signed 16 bit).
// With `second_switches`: every input TPDO also carries byte 2 (0x6000:03, the safety sensors' second
// switches at inputs 16..21), each second switch is seen on, and in every input TPDO it reads as its
// first switch (byte 0, bits 0..5) does: the simulated module's two switches see the same truth.
CheckResult check_io_traffic(const std::vector<Frame>& frames, int io_node, bool second_switches = false);

// The knotting heads' row, judged from the wire alone. Per head h (its gripper and cutter bits in the I/O
// node's output RPDO, its yarn-present bit in the input TPDO, its colour selector drive `selector_nodes[h]`):
// the cutter fired exactly `knots_per_head` times, each time with its gripper closed; after every cut the
// yarn-present switch rose before the next cut (a knot seen for every cut, `knots_per_head` in all); the
// selector's target never changed while its gripper was closed (no turn under held yarn) and changed at
// least once (the stripe has more than one colour). The carriage drive's target never changed while any
// gripper was closed (the carriage does not drag a gripper through the warp). Bits count across the PDO's
// bytes (bit b in byte b / 8); drive RPDO1 layout as PdoLayout.
struct KnottingWiring {
  std::vector<int> gripper_bits, cutter_bits, yarn_bits;  // one per head
  std::vector<int> selector_nodes;                        // one per head
  int carriage_node = 2;
  int knots_per_head = 0;
};
CheckResult check_knotting(const std::vector<Frame>& frames, int io_node, const KnottingWiring& w);

// An EMCY with a non-zero code from `emcy_node` (the first such frame in the log): within one cycle the
// master stops every drive in `nodes`. RPDO1s before the second SYNC after the EMCY belong to the cycle in
// progress (decided before the EMCY could be read) and are not judged; the first RPDO1 after that SYNC
// carries quick stop (controlword bits 2 and 7 clear, bit 1 set: 0x0002) or disable voltage (0x0000), and
// no later RPDO1 enables operation again.
CheckResult check_emcy_stop(const std::vector<Frame>& frames, const std::vector<int>& nodes, int emcy_node);

// How late the drives' feedback reached the bus (a check of the rig, not of the master): each
// synchronous TPDO1 of `nodes` should answer the SYNC right before it. Counts, per node, the TPDO1s that
// trail by more (a TPDO1 with k SYNCs outstanding since that node's previous one is k − 1 cycles late;
// the first after a silence counts from that silence). Fails when one trails by more than
// `max_cycles_late` cycles, or a node sent no TPDO1 at all (nothing to judge).
CheckResult check_feedback_lag(const std::vector<Frame>& frames, const std::vector<int>& nodes,
                               int max_cycles_late);

// The master's heartbeat (0x700 + master) stops (it was killed): every node in `nodes` sends an EMCY
// 0x8130 (heartbeat consumer) within `consumer_s` + `slack_s` of the master's last heartbeat.
CheckResult check_master_loss(const std::vector<Frame>& frames, const std::vector<int>& nodes, int master,
                              double consumer_s, double slack_s);

}  // namespace loom::hil

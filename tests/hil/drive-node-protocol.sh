#!/usr/bin/env bash
# HIL: the simulated CiA 402 drive node (loom-sim-drive) speaks CANopen on a real vcan0, driven by
# can-utils alone, so the node is judged by CiA 301/402 facts rather than by our own master: boot-up
# after NMT reset, expedited SDO replies and aborts, heartbeat states, and PDOs only when operational.
# usage: drive-node-protocol.sh BUILD_DIR   (exit 77 = skipped: no vcan0 here)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
hil_init drive_node_protocol "${1:-}"
hil_require_vcan
sim=${LOOM_HIL_SIM_DRIVE:-$HIL_BUILD/bin/loom-sim-drive}
hil_need_exec "$sim" loom-sim-drive
hil_need_exec "$HIL_BUILD/bin/loom-hil-canlog" loom-hil-canlog
hil_start_candump

send() { cansend "$HIL_IFACE" "$1"; }
hex_le16() { echo $((16#${1:2:2}${1:0:2})); }  # "4002" → 0x0240

# --- Power-on: every node announces itself (boot-up = heartbeat with state 00) ---------------------
mark=$(hil_mark)
hil_spawn sim "$sim" --iface "$HIL_IFACE" --nodes 1,2,3
for n in 1 2 3; do hil_expect "$mark" "70$n#00" 10 "power-on boot-up of node $n" >/dev/null; done
hil_note "power-on boot-ups of nodes 1, 2, 3 seen"

# --- NMT reset-node, all nodes and one node --------------------------------------------------------
mark=$(hil_mark)
send 000#8100
for n in 1 2 3; do hil_expect "$mark" "70$n#00" 5 "boot-up of node $n after NMT reset-all (000#8100)" >/dev/null; done
mark=$(hil_mark)
send 000#8102
hil_expect "$mark" '702#00' 5 "boot-up of node 2 after NMT reset-node 2 (000#8102)" >/dev/null
sleep 0.3
others=$(hil_frames_after "$mark" '70[13]#00')
[[ -z $others ]] || hil_fail "NMT reset of node 2 also rebooted: $others"
hil_note "NMT reset-node: all → 3 boot-ups; node 2 only → only 702#00"

# --- SDO, expedited (client 0x601 → server 0x581) ---------------------------------------------------
# Statusword 0x6041 after reset: Switch on disabled (&0x4F = 0x40), a 2-byte expedited reply (0x4B).
mark=$(hil_mark)
send 601#4041600000000000
reply=$(hil_expect "$mark" '581#..416000.{8}' 5 "SDO reply for 0x6041")
[[ $reply == 581#4B416000* ]] || hil_fail "0x6041 upload: expected expedited 2-byte reply 581#4B416000…, got $reply"
sw=$(hex_le16 "${reply:12:4}")
(((sw & 0x4F) == 0x40)) || hil_fail "statusword after reset is $(printf 0x%04X "$sw"), not Switch on disabled (&0x4F = 0x40)"

# Modes of operation 0x6060 = 8 (CSP), acknowledged (0x60) and read back through 0x6061 (0x4F, 1 byte).
mark=$(hil_mark)
send 601#2F60600008000000
reply=$(hil_expect "$mark" '581#..606000.{8}' 5 "SDO reply for the 0x6060 download")
[[ $reply == 581#60606000* ]] || hil_fail "0x6060 := 8: expected 581#60606000…, got $reply"
mark=$(hil_mark)
send 601#4061600000000000
reply=$(hil_expect "$mark" '581#..616000.{8}' 5 "SDO reply for 0x6061")
[[ $reply == 581#4F61600008* ]] || hil_fail "0x6061 after 0x6060 := 8: expected 581#4F61600008…, got $reply"

# Heartbeat producer time 0x1017 := 100 ms (UNSIGNED16), acknowledged and read back (0x4B, 2 bytes).
mark=$(hil_mark)
send 601#2B17100064000000
reply=$(hil_expect "$mark" '581#..171000.{8}' 5 "SDO reply for the 0x1017 download")
[[ $reply == 581#60171000* ]] || hil_fail "0x1017 := 100: expected 581#60171000…, got $reply"
mark=$(hil_mark)
send 601#4017100000000000
reply=$(hil_expect "$mark" '581#..171000.{8}' 5 "SDO reply for 0x1017")
[[ $reply == 581#4B1710006400* ]] || hil_fail "0x1017 read back: expected 581#4B1710006400…, got $reply"

# An object the node does not have: abort 0x80 with code 0x06020000 (object does not exist).
mark=$(hil_mark)
send 601#40FF2F0000000000
reply=$(hil_expect "$mark" '581#..FF2F00.{8}' 5 "SDO reply for the missing object 0x2FFF")
[[ $reply == 581#80FF2F0000000206 ]] || hil_fail "upload of 0x2FFF:00: expected abort 581#80FF2F0000000206, got $reply"
hil_note "SDO: 0x6041 = $(printf 0x%04X "$sw"), 0x6060 := 8 → 0x6061 = 8, 0x1017 := 100 ms, 0x2FFF → abort 0x06020000"

# --- Heartbeat: pre-operational (7F) at the producer time, then operational (05), stopped (04) ------
mark=$(hil_mark)
sleep 1.0
beats=$(hil_frames_after "$mark" '701#7F' | wc -l)
((beats >= 3)) || hil_fail "only $beats pre-operational heartbeats 701#7F in 1 s at a 100 ms producer time"
hil_note "heartbeat: $beats × 701#7F in 1 s (100 ms producer time; timing not asserted in a VM)"

mark=$(hil_mark)
send 000#0101
hil_expect "$mark" '701#05' 5 "operational heartbeat 701#05 after NMT start of node 1" >/dev/null

# --- PDOs: only an operational node answers SYNC ---------------------------------------------------
mark=$(hil_mark)
for _ in 1 2 3 4 5; do send 080#; sleep 0.05; done
sleep 0.3
tpdo1=$(hil_frames_after "$mark" '181#.*' | wc -l)
tpdo_pre=$(hil_frames_after "$mark" '18[23]#.*' | wc -l)
((tpdo1 == 5)) || hil_fail "node 1 (operational) sent $tpdo1 TPDO1 frames for 5 SYNCs, expected 5"
((tpdo_pre == 0)) || hil_fail "pre-operational nodes 2/3 sent $tpdo_pre TPDOs (PDOs only in Operational)"
first=$(hil_frames_after "$mark" '181#.*' | head -n1)
((${#first} >= 8)) || hil_fail "TPDO1 $first carries no statusword"
tsw=$(hex_le16 "${first:4:4}")
(((tsw & 0x4F) == 0x40)) || hil_fail "TPDO1 statusword $(printf 0x%04X "$tsw") is not Switch on disabled"
hil_note "SYNC ×5 → 5 × TPDO1 from operational node 1 (statusword $(printf 0x%04X "$tsw")), none from pre-op nodes"

mark=$(hil_mark)
send 000#0201
hil_expect "$mark" '701#04' 5 "stopped heartbeat 701#04 after NMT stop of node 1" >/dev/null
mark=$(hil_mark)
send 080#
sleep 0.3
[[ -z $(hil_frames_after "$mark" '181#.*') ]] || hil_fail "stopped node 1 still answers SYNC with a TPDO"
hil_note "NMT start → 701#05, NMT stop → 701#04 and no PDOs"

kill -0 "$HIL_LAST_PID" 2>/dev/null || hil_fail "loom-sim-drive died: $(tail -n 5 "$HIL_WORK/sim.out")"
hil_stop_candump
hil_report_frames

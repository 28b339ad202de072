#!/usr/bin/env bash
# HIL: two knotting heads tie a row over SocketCAN with their colour selectors in CiA 402 profile
# position (hil_knotting_pp_loom.toml: drive_mode = "profile"), then the loom sheds, picks and beats it.
# As knot-row.sh, and judged from candump as well (loom-hil-canlog profile-position): the selectors'
# RPDO1s only on change (none in a tick where the selector stands still, never two in one cycle), each
# set-point acknowledged (statusword bit 12) before its release, their TPDO1s never closer than the
# inhibit time (30 ms, the master's default); the cyclic drives' exchange as before.
#
# (knot-row.sh:) Two knotting heads tie a row over SocketCAN, then the loom sheds, picks and beats it. Everything is
# on vcan0 (hil_knotting_loom.toml): the three loom drives, each head's knotting servo and colour selector
# (nodes 11, 12, 21, 22) and the I/O node carrying each head's gripper, cutter and yarn-present switch.
# loom-sim-drive reads the same machine description (--loom), so its I/O node's heads follow the carriage
# and the heads' servos through the linkage's geometry.
# Judged from candump's record of the bus (loom-hil-canlog knotting): each head cut 15 times, each time
# with its gripper closed, and its yarn-present switch showed a knot after every cut; no selector turned
# under a closed gripper and the carriage never moved while one was closed; the bring-up and cyclic
# exchange of all seven drives (loom-hil-canlog weave). And from loomctl's exit status, its row line and
# counters (30 knots, none by hand), and the carpet the simulated heads knotted: equal to the design's
# first woven row (its last line), slot by slot.
# usage: knot-row-pp.sh BUILD_DIR   (exit 77 = skipped: no vcan0 here)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
hil_init knot_row_pp "${1:-}"
hil_require_vcan
hil_find_binaries
hil_start_candump

HIL_CONFIG=$HIL_SRC/hil_knotting_pp_loom.toml
nodes=1,2,3,11,12,21,22
cyclic_nodes=1,2,3,11,12
profile_nodes=21,22
HIL_IO_CONTROL=$HIL_WORK/io-control
: >"$HIL_IO_CONTROL"
mark=$(hil_mark)
rt=()
chrt -f 90 true 2>/dev/null && rt=(chrt -f 90)
hil_spawn sim "${rt[@]}" "$HIL_SIM" --iface "$HIL_IFACE" --loom "$HIL_CONFIG" --io-control "$HIL_IO_CONTROL" \
  --plant-cycle-ms "$HIL_PERIOD_MS"
sim_pid=$HIL_LAST_PID
for n in ${nodes//,/ } 4; do
  hil_expect "$mark" "$(printf '%03X' $((0x700 + n)))#00" 10 "boot-up of simulated node $n" >/dev/null
done
hil_note "loom-sim-drive --loom up: drives $nodes and the I/O node 4 with two knotting heads behind it"

counters=$HIL_WORK/counters.json
hil_weave_cmd 1 "$counters"
hil_run_weave "${LOOM_HIL_WEAVE_TIMEOUT_S:-400}"
status=$HIL_STATUS
kill -0 "$sim_pid" 2>/dev/null || hil_fail "loom-sim-drive died during the row: $(tail -n 5 "$HIL_WORK/sim.out")"
hil_stop_candump
# Stopped, the simulator prints the carpet its heads knotted.
kill -TERM "$sim_pid"
for ((i = 0; i < 100; i++)); do kill -0 "$sim_pid" 2>/dev/null || break; sleep 0.05; done
hil_forget_pid "$sim_pid"
cp "$HIL_WORK/sim.out" "$HIL_LOGDIR/$HIL_NAME.sim.out"

case $status in
  0) ;;
  124|137) hil_fail "loomctl did not knot and weave one row within ${LOOM_HIL_WEAVE_TIMEOUT_S:-400} s" ;;
  3) hil_fail "loomctl ended in a fault (exit 3) instead of completing the row" ;;
  *) hil_fail "loomctl exited with status $status (0 = row completed)" ;;
esac
grep -q '^row ' "$HIL_WORK/loomctl.out" || hil_fail "no per-row summary line"
[[ $(hil_json_int "$counters" rows) == 1 ]] || hil_fail "counters: rows is not 1: $(cat "$counters")"
[[ $(hil_json_int "$counters" knots) == 30 ]] || hil_fail "counters: knots is not 30: $(cat "$counters")"
[[ $(hil_json_int "$counters" knots_by_hand) == 0 ]] || hil_fail "counters: knots tied by hand: $(cat "$counters")"
hil_note "loomctl knotted and wove 1 row (exit 0); counters: $(tr -d '\n' <"$counters")"

# The design's first woven row is its file's last line; slot letters A, B, C = slot_colours R, I, B.
expected=$(grep -v '^#\|^palette' "$HIL_SRC/hil_knot_design.csv" | tail -n 1 | tr -d ',' | tr 'RIB' 'ABC')
knotted=$(sed -n 's/^loom-sim-drive: knotted row 0: //p' "$HIL_WORK/sim.out")
[[ -n $knotted ]] || hil_fail "loom-sim-drive printed no knotted row: $(tail -n 5 "$HIL_WORK/sim.out")"
[[ $knotted == "$expected" ]] || hil_fail "knotted row 0 is $knotted, the design's is $expected"
hil_note "the carpet knotted over CAN equals the design row: $knotted"

"$HIL_CANLOG" knotting "$HIL_LOG" --node 4 --gripper-bits 8,9 --cutter-bits 20,21 --yarn-bits 24,25 \
  --selector-nodes 21,22 --carriage-node 2 --knots-per-head 15 || hil_fail "knotting judged from the bus failed; log: $HIL_LOG"
"$HIL_CANLOG" weave "$HIL_LOG" --nodes "$cyclic_nodes" || hil_fail "bus protocol check failed; log: $HIL_LOG"
"$HIL_CANLOG" profile-position "$HIL_LOG" --nodes "$profile_nodes" --inhibit-ms 30 --min-moves 2 ||
  hil_fail "the selectors' profile-position exchange judged from the bus failed; log: $HIL_LOG"
hil_report_frames

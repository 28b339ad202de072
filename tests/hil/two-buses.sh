#!/usr/bin/env bash
# HIL: a 4-axis loom whose take-up roller and operator-panel I/O module are on a second bus
# (hil_four_axis_loom.toml) weaves one row with --iface vcan0,vcan1: one CANopen master per bus, two CiA
# 401 modules. vcan1's nodes are simulated by `loom-sim-drive --loom … --bus 1` from the same machine
# description. Judged from candump's record of each bus: vcan1 carries its own NMT bring-up of nodes 5 and
# 6, SYNC, the master heartbeat, node 5's RPDO1/TPDO1 and the panel module's outputs (the green lamp lit
# while weaving) and inputs, and none of bus 0's nodes; vcan0 none of theirs, and bus 0's module is never
# told to light a lamp (those outputs are the panel's now); and from loomctl's exit status (0).
# usage: two-buses.sh BUILD_DIR   (exit 77 = skipped: no vcan0 and vcan1 here)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
hil_init two_buses "${1:-}"
hil_require_vcan
HIL_IFACE2=${LOOM_HIL_IFACE2:-vcan1}
if [[ $(cat "/sys/class/net/$HIL_IFACE2/type" 2>/dev/null) != 280 ]]; then
  printf 'SKIP [%s]: no second CAN interface %s here (tools/vcan/vm-run makes vcan0 and vcan1).\n' "$HIL_NAME" "$HIL_IFACE2"
  exit "$HIL_SKIP"
fi
hil_find_binaries
hil_start_candump
log2=$HIL_WORK/$HIL_NAME.bus1.candump.log
stdbuf -oL candump -L -d -r 8388608 "$HIL_IFACE2" >"$log2" &
HIL_PIDS+=($!)
hil_start_sim_drives
rt=()
chrt -f 90 true 2>/dev/null && rt=(chrt -f 90)
mark2=$(wc -l <"$log2")
hil_spawn sim2 "${rt[@]}" "$HIL_SIM" --iface "$HIL_IFACE2" --loom "$HIL_SRC/hil_four_axis_loom.toml" --bus 1 \
  --plant-cycle-ms "$HIL_PERIOD_MS"
for node in 705 706; do
  for ((i = 0; i < 100; i++)); do
    tail -n +"$((mark2 + 1))" "$log2" | grep -q " $node#00" && break
    sleep 0.1
  done
  ((i < 100)) || hil_fail "node ${node#70} (take-up drive 5, panel module 6) did not boot on $HIL_IFACE2"
done

counters=$HIL_WORK/counters.json
HIL_CONFIG=$HIL_SRC/hil_four_axis_loom.toml
HIL_IFACES=$HIL_IFACE,$HIL_IFACE2
hil_weave_cmd 1 "$counters"
hil_run_weave "${LOOM_HIL_WEAVE_TIMEOUT_S:-150}"
status=$HIL_STATUS
hil_stop_candump
sleep 0.2
cp "$log2" "$HIL_LOGDIR/$HIL_NAME.bus1.candump.log"
((status == 0)) || hil_fail "loomctl exited with status $status (0 = row completed on two buses)"
grep -q '^row ' "$HIL_WORK/loomctl.out" || hil_fail "no per-row summary line"

grep -q " 000#8105" "$log2" || hil_fail "no NMT reset-node of node 5 on $HIL_IFACE2"
grep -q " 000#0105" "$log2" || hil_fail "no NMT start of node 5 on $HIL_IFACE2"
syncs=$(grep -c " 080#\$" "$log2" || true)
((syncs > 100)) || hil_fail "only $syncs SYNC frames on $HIL_IFACE2: the second bus has no cycle of its own"
grep -q " 77F#05" "$log2" || hil_fail "no master heartbeat on $HIL_IFACE2"
grep -qE " 205#[0-9A-F]{12}\$" "$log2" || hil_fail "no RPDO1 to node 5 on $HIL_IFACE2"
grep -qE " 185#[0-9A-F]{12}\$" "$log2" || hil_fail "no TPDO1 from node 5 on $HIL_IFACE2"
! grep -qE " (20[1-4]|18[1-4])#" "$log2" || hil_fail "bus 0's PDOs appeared on $HIL_IFACE2"
! grep -qE " (20[56]|18[56])#" "$HIL_LOG" || hil_fail "node 5's or 6's PDOs appeared on $HIL_IFACE"
# The panel module: brought up in bus 1's sequence, told its outputs every cycle (one byte: the lamps and
# the buzzer on bits 4..7, green lit while weaving), its inputs (two groups: the buttons on bits 8..10)
# heard every cycle; bus 0's module never told to light a lamp.
grep -q " 000#8106" "$log2" || hil_fail "no NMT reset-node of the panel module (node 6) on $HIL_IFACE2"
grep -q " 000#0106" "$log2" || hil_fail "no NMT start of the panel module (node 6) on $HIL_IFACE2"
panel_out=$(grep -cE " 206#[0-9A-F]{2}\$" "$log2" || true)
((panel_out > 100)) || hil_fail "only $panel_out output RPDOs to the panel module on $HIL_IFACE2"
grep -qE " 206#10\$" "$log2" || hil_fail "the panel module was never told to light the green lamp (206#10)"
! grep -qE " 206#[0-9A-F][1-9A-F]\$" "$log2" || hil_fail "the panel module was told to drive a bit below 4 (a valve's)"
panel_in=$(grep -cE " 186#[0-9A-F]{4}\$" "$log2" || true)
((panel_in > 100)) || hil_fail "only $panel_in two-byte input TPDOs from the panel module on $HIL_IFACE2"
! grep -qE " 204#[1-9A-F][0-9A-F]\$" "$HIL_LOG" || hil_fail "bus 0's module was told to light a lamp (the panel's outputs)"
grep -qE " 204#0[1-3]\$" "$HIL_LOG" || hil_fail "bus 0's module never had a valve energised"
"$HIL_CANLOG" weave "$HIL_LOG" --nodes "$HIL_NODES" || hil_fail "bus 0 protocol check failed; log: $HIL_LOG"
hil_note "one row on two buses: $syncs SYNCs on $HIL_IFACE2, nodes 5 and 6 brought up and cycled there only; the panel module got $panel_out output RPDOs and sent $panel_in input TPDOs"
hil_report_frames

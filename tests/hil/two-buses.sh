#!/usr/bin/env bash
# HIL: a 4-axis loom whose take-up roller is on a second bus (hil_four_axis_loom.toml) weaves one row
# with --iface vcan0,vcan1: one CANopen master per bus. Judged from candump's record of each bus: vcan1
# carries its own NMT bring-up of node 5, SYNC, the master heartbeat and node 5's RPDO1/TPDO1, and none
# of bus 0's nodes; vcan0 none of node 5's; and from loomctl's exit status (0).
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
hil_spawn sim2 "${rt[@]}" "$HIL_SIM" --iface "$HIL_IFACE2" --nodes 5 --counts-per-unit 651.8986469044033
for ((i = 0; i < 100; i++)); do
  tail -n +"$((mark2 + 1))" "$log2" | grep -q " 705#00" && break
  sleep 0.1
done
((i < 100)) || hil_fail "the take-up drive (node 5) did not boot on $HIL_IFACE2"

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
! grep -qE " (205|185)#" "$HIL_LOG" || hil_fail "node 5's PDOs appeared on $HIL_IFACE"
"$HIL_CANLOG" weave "$HIL_LOG" --nodes "$HIL_NODES" || hil_fail "bus 0 protocol check failed; log: $HIL_LOG"
hil_note "one row on two buses: $syncs SYNCs on $HIL_IFACE2, node 5 brought up and cycled there only"
hil_report_frames

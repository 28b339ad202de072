# The two knotting HIL tests' common row (sourced after hil-lib.sh by knot-row.sh and knot-row-pp.sh; they
# differ only in the loom file and in how the bus is judged afterwards).
#
# hil_knot_row LOOM_FILE NODES — two knotting heads tie a row over SocketCAN, then the loom sheds, picks
# and beats it. Everything is on vcan0 (LOOM_FILE): the three loom drives, each head's knotting servo and
# colour selector (NODES: 1,2,3 and 11, 12, 21, 22) and the I/O node 4 carrying each head's gripper, cutter
# and yarn-present switch. loom-sim-drive reads the same machine description (--loom), so its I/O node's
# heads follow the carriage and the heads' servos through the linkage's geometry. Judged from loomctl's
# exit status, its row line and counters (30 knots, none by hand), the carpet the simulated heads knotted
# (equal to the design's first woven row, its file's last line, slot by slot) and candump's record of the
# bus (loom-hil-canlog knotting): each head cut 15 times, each time with its gripper closed, and its
# yarn-present switch showed a knot after every cut; no selector turned under a closed gripper and the
# carriage never moved while one was closed. Leaves the candump log in HIL_LOG for the caller's checks.
hil_knot_row() {
  HIL_CONFIG=$1
  local nodes=$2 n
  hil_start_candump
  HIL_IO_CONTROL=$HIL_WORK/io-control
  : >"$HIL_IO_CONTROL"
  local mark rt=()
  mark=$(hil_mark)
  chrt -f 90 true 2>/dev/null && rt=(chrt -f 90)
  hil_spawn sim "${rt[@]}" "$HIL_SIM" --iface "$HIL_IFACE" --loom "$HIL_CONFIG" --io-control "$HIL_IO_CONTROL" \
    --plant-cycle-ms "$HIL_PERIOD_MS"
  local sim_pid=$HIL_LAST_PID
  for n in ${nodes//,/ } 4; do
    hil_expect "$mark" "$(printf '%03X' $((0x700 + n)))#00" 10 "boot-up of simulated node $n" >/dev/null
  done
  hil_note "loom-sim-drive --loom up: drives $nodes and the I/O node 4 with two knotting heads behind it"

  local counters=$HIL_WORK/counters.json
  hil_weave_cmd 1 "$counters"
  hil_run_weave "${LOOM_HIL_WEAVE_TIMEOUT_S:-400}"
  local status=$HIL_STATUS
  kill -0 "$sim_pid" 2>/dev/null || hil_fail "loom-sim-drive died during the row: $(tail -n 5 "$HIL_WORK/sim.out")"
  hil_stop_candump
  # Stopped, the simulator prints the carpet its heads knotted.
  kill -TERM "$sim_pid"
  for ((n = 0; n < 100; n++)); do kill -0 "$sim_pid" 2>/dev/null || break; sleep 0.05; done
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
  local expected knotted
  expected=$(grep -v '^#\|^palette' "$HIL_SRC/hil_knot_design.csv" | tail -n 1 | tr -d ',' | tr 'RIB' 'ABC')
  knotted=$(sed -n 's/^loom-sim-drive: knotted row 0: //p' "$HIL_WORK/sim.out")
  [[ -n $knotted ]] || hil_fail "loom-sim-drive printed no knotted row: $(tail -n 5 "$HIL_WORK/sim.out")"
  [[ $knotted == "$expected" ]] || hil_fail "knotted row 0 is $knotted, the design's is $expected"
  hil_note "the carpet knotted over CAN equals the design row: $knotted"

  "$HIL_CANLOG" knotting "$HIL_LOG" --node 4 --gripper-bits 8,9 --cutter-bits 20,21 --yarn-bits 24,25 \
    --selector-nodes 21,22 --carriage-node 2 --knots-per-head 15 ||
    hil_fail "knotting judged from the bus failed; log: $HIL_LOG"
}

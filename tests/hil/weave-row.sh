#!/usr/bin/env bash
# HIL: loomctl weaves one row over SocketCAN against the simulated CiA 402 drives and the simulated
# CiA 401 I/O node on a real vcan0 (drive personality from LOOM_HIL_PERSONALITY: standard or fixed), so
# every valve, sensor, e-stop and load-cell value crosses the bus.
# Judged from candump's record of the bus (loom-hil-canlog weave): NMT reset → boot-ups → 0x6060 = 8
# confirmed by 0x6061 → NMT start → SYNC with RPDOs and TPDOs → Operation enabled; and from loomctl's
# exit status (0), its per-row summary line and the counters file it writes.
# usage: weave-row.sh BUILD_DIR   (exit 77 = skipped: no vcan0 here)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
hil_init "weave_row_${LOOM_HIL_PERSONALITY:-standard}" "${1:-}"
hil_require_vcan
hil_find_binaries
hil_start_candump
hil_start_sim_drives

counters=$HIL_WORK/counters.json
hil_weave_cmd 1 "$counters"
hil_run_weave "${LOOM_HIL_WEAVE_TIMEOUT_S:-150}"
status=$HIL_STATUS
kill -0 "$HIL_SIM_PID" 2>/dev/null || hil_fail "loom-sim-drive died during the row: $(tail -n 5 "$HIL_WORK/sim.out")"
hil_stop_candump

case $status in
  0) ;;
  124|137) hil_fail "loomctl did not finish one row within ${LOOM_HIL_WEAVE_TIMEOUT_S:-150} s" ;;
  3) hil_fail "loomctl ended in a fault (exit 3) instead of completing the row" ;;
  *) hil_fail "loomctl exited with status $status (0 = row completed)" ;;
esac

rows=$(grep -c '^row ' "$HIL_WORK/loomctl.out" || true)
((rows == 1)) || hil_fail "expected 1 per-row summary line starting with 'row ', found $rows"
[[ -f $counters ]] || hil_fail "loomctl wrote no counters file at $counters"
cp "$counters" "$HIL_LOGDIR/$HIL_NAME.counters.json"
counted=$(hil_json_int "$counters" rows)
[[ $counted == 1 ]] || hil_fail "counters file says rows=${counted:-<missing>}, expected 1: $(cat "$counters")"
for key in picks beats; do
  [[ -n $(hil_json_int "$counters" "$key") ]] || hil_fail "counters file lacks integer key \"$key\": $(cat "$counters")"
done
hil_note "loomctl completed 1 row (exit 0); counters: $(tr -d '\n' <"$counters")"

"$HIL_CANLOG" weave "$HIL_LOG" --nodes "$HIL_NODES" || hil_fail "bus protocol check failed (see above); log: $HIL_LOG"
"$HIL_CANLOG" io "$HIL_LOG" --node "$HIL_IO_NODE" --second-switches || hil_fail "I/O node traffic incomplete (see above); log: $HIL_LOG"
hil_report_frames

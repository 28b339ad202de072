#!/usr/bin/env bash
# HIL: an incremental-encoder loom (hil_incremental_loom.toml) homes and weaves over vcan0. loom-sim-drive
# powers the crank and carriage drives up at random counts (--homing-nodes 1,2; its seed is in the log);
# loomctl must reference both by CiA 402 homing over the bus before anything moves, then weave one row.
# Judged from candump's record: the homing parameters written by SDO (0x6098 method 19 to node 1, 21 to
# node 2), homed axes' 7-byte RPDO1 carrying 0x6060 = 6 and 7-byte TPDO1 with 0x6061 = 6 and "homing
# attained" (statusword bit 12), then the usual weave protocol; and from loomctl's exit status (0).
# usage: homing.sh BUILD_DIR   (exit 77 = skipped: no vcan0 here)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
hil_init homing "${1:-}"
hil_require_vcan
hil_find_binaries
hil_start_candump
# The crank 0.5 rad past its home switch and the carriage 5 cm right of its own: the runs travel.
HIL_SIM_EXTRA=(--homing-nodes 1,2 --initial-position 0.5,0.05,0)
hil_start_sim_drives
grep -m1 'power-up seed' "$HIL_WORK/sim.out" 2>/dev/null | sed 's/^/  sim| /' || true

counters=$HIL_WORK/counters.json
HIL_CONFIG=$HIL_SRC/hil_incremental_loom.toml
hil_weave_cmd 1 "$counters"
hil_run_weave "${LOOM_HIL_WEAVE_TIMEOUT_S:-180}"
status=$HIL_STATUS
kill -0 "$HIL_SIM_PID" 2>/dev/null || hil_fail "loom-sim-drive died during the row: $(tail -n 5 "$HIL_WORK/sim.out")"
hil_stop_candump
case $status in
  0) ;;
  124|137) hil_fail "loomctl did not home and finish one row within ${LOOM_HIL_WEAVE_TIMEOUT_S:-180} s" ;;
  *) hil_fail "loomctl exited with status $status (0 = homed and row completed)" ;;
esac
rows=$(grep -c '^row ' "$HIL_WORK/loomctl.out" || true)
((rows == 1)) || hil_fail "expected 1 per-row summary line starting with 'row ', found $rows"

# SDO expedited download of 1 byte (2F) to 0x6098:00: method 19 (0x13) to node 1, 21 (0x15) to node 2.
grep -q " 601#2F98600013" "$HIL_LOG" || hil_fail "no SDO write 0x6098 = 19 (homing method) to node 1"
grep -q " 602#2F98600015" "$HIL_LOG" || hil_fail "no SDO write 0x6098 = 21 (homing method) to node 2"
for n in 1 2; do
  # RPDO1 of a homed axis: controlword, target, 0x6060 — 7 bytes, the last 06 while homing, with bit 4.
  grep -qE " 20$n#[13579BDF][0-9A-F]{11}06\$" "$HIL_LOG" ||
    hil_fail "no RPDO1 to node $n in homing mode (0x6060 = 6) with controlword bit 4 (start homing)"
  # TPDO1: statusword (bit 12 = byte 1 bit 4), position, 0x6061 = 06.
  grep -qE " 18$n#[0-9A-F]{2}[13579BDF][0-9A-F]{9}06\$" "$HIL_LOG" ||
    hil_fail "no TPDO1 from node $n saying homing attained (statusword bit 12) in homing mode"
  # Back to CSP for weaving: 0x6060 = 8 in the RPDO1 after homing.
  grep -qE " 20$n#[0-9A-F]{12}08\$" "$HIL_LOG" || hil_fail "node $n never switched back to CSP (0x6060 = 8)"
done
# The absolute helix keeps the 6-byte layout.
grep -qE " 203#[0-9A-F]{12}\$" "$HIL_LOG" || hil_fail "no 6-byte RPDO1 to the absolute helix (node 3)"
hil_note "crank and carriage homed over CAN (0x6098 by SDO, mode 6 in the PDOs, homing attained), then 1 row"
"$HIL_CANLOG" io "$HIL_LOG" --node "$HIL_IO_NODE" --second-switches || hil_fail "I/O node traffic incomplete; log: $HIL_LOG"
hil_report_frames

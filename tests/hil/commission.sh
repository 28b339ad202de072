#!/usr/bin/env bash
# HIL: `loomctl commission` over SocketCAN. The simulated drives power up at known positions (SI, turned
# into counts by loom-sim-drive's own scaling); commissioning configures the bus with every drive left
# disabled, reads the positions back through the master's PDOs and scaling, and writes them into a copy
# of the HIL config as the calibration. Judged against the positions given to the drives, and from
# candump: no controlword that enables a drive (0x000F) was ever sent.
# usage: commission.sh BUILD_DIR   (exit 77 = skipped: no vcan0 here)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
hil_init commission "${1:-}"
hil_require_vcan
hil_find_binaries
hil_start_candump
# Crank a quarter turn, carriage 50 mm, helix one turn back.
HIL_SIM_EXTRA=(--initial-position 1.5707963268,0.05,-6.2831853072)
hil_start_sim_drives

cfg=$HIL_WORK/loom.toml
cp "$HIL_SRC/hil_loom.toml" "$cfg"
status=0
timeout -k 5 60 "$HIL_LOOMCTL" commission --hal socketcan --iface "$HIL_IFACE" --io can --config "$cfg" \
  --capture park,home,left --write >"$HIL_WORK/commission.out" 2>&1 || status=$?
sed 's/^/  loomctl| /' "$HIL_WORK/commission.out"
hil_stop_candump
((status == 0)) || hil_fail "loomctl commission exited $status"

value() { sed -n "s/^$1 = \\([-0-9.]*\\).*/\\1/p" "$cfg"; }
near() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= t) }'; }
near "$(value crank_park_position_rad)" 1.5707963268 1e-5 || hil_fail "crank: $(value crank_park_position_rad), want 1.5707963"
near "$(value home_position_m)" 0.05 1e-7 || hil_fail "carriage: $(value home_position_m), want 0.05"
near "$(value left_position_rad)" -6.2831853072 1e-5 || hil_fail "helix: $(value left_position_rad), want -6.2831853"
"$HIL_LOOMCTL" check --config "$cfg" >/dev/null || hil_fail "the written config does not check"
# RPDO1 of each drive carries the controlword first (little-endian): 0F 00 would enable operation.
if grep -Eq ' 20[123]#0F00' "$HIL_LOG"; then hil_fail "a drive was sent Enable Operation while commissioning"; fi
grep -Eq ' 20[123]#' "$HIL_LOG" || hil_fail "no RPDO to any drive: the bus was not cycling"
hil_note "calibration written: crank $(value crank_park_position_rad) rad, carriage $(value home_position_m) m, helix $(value left_position_rad) rad; no enable sent"
hil_report_frames

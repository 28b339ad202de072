#!/usr/bin/env bash
# HIL: two knotting heads tie a row over SocketCAN with their colour selectors in CiA 402 profile
# position (hil_knotting_pp_loom.toml: drive_mode = "profile"), then the loom sheds, picks and beats it
# (the row and its checks: hil_knot_row in knot-row-lib.sh, as knot-row.sh). Judged from candump as well
# (loom-hil-canlog profile-position): the selectors' RPDO1s only on change (none in a tick where the
# selector stands still, never two in one cycle), each set-point acknowledged (statusword bit 12) before
# its release, their TPDO1s never closer than the inhibit time (30 ms, the master's default); the cyclic
# drives' exchange as before (loom-hil-canlog weave).
# usage: knot-row-pp.sh BUILD_DIR   (exit 77 = skipped: no vcan0 here)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
. "$(dirname "$0")/knot-row-lib.sh"
hil_init knot_row_pp "${1:-}"
hil_require_vcan
hil_find_binaries

cyclic_nodes=1,2,3,11,12
profile_nodes=21,22
hil_knot_row "$HIL_SRC/hil_knotting_pp_loom.toml" "$cyclic_nodes,$profile_nodes"
"$HIL_CANLOG" weave "$HIL_LOG" --nodes "$cyclic_nodes" || hil_fail "bus protocol check failed; log: $HIL_LOG"
"$HIL_CANLOG" profile-position "$HIL_LOG" --nodes "$profile_nodes" --inhibit-ms 30 --min-moves 2 ||
  hil_fail "the selectors' profile-position exchange judged from the bus failed; log: $HIL_LOG"
hil_report_frames

#!/usr/bin/env bash
# HIL: two knotting heads tie a row over SocketCAN, then the loom sheds, picks and beats it
# (hil_knotting_loom.toml: every drive cyclic; the row and its checks: hil_knot_row in knot-row-lib.sh).
# Judged from candump as well (loom-hil-canlog weave): the bring-up and cyclic exchange of all seven drives.
# usage: knot-row.sh BUILD_DIR   (exit 77 = skipped: no vcan0 here)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
. "$(dirname "$0")/knot-row-lib.sh"
hil_init knot_row "${1:-}"
hil_require_vcan
hil_find_binaries

nodes=1,2,3,11,12,21,22
hil_knot_row "$HIL_SRC/hil_knotting_loom.toml" "$nodes"
"$HIL_CANLOG" weave "$HIL_LOG" --nodes "$nodes" || hil_fail "bus protocol check failed; log: $HIL_LOG"
hil_report_frames

#!/usr/bin/env bash
# HIL: bring-up from the machine description's EDS files (issue 32) on a real vcan0. The simulated drives
# are built from a shipped vendor-style EDS (loom-sim-drive --eds: acme_ax400_dynamic.eds, dynamic
# mapping, its own 0x1018 identity); the I/O node is the built-in one.
#  1. Every axis names that EDS: loomctl checks each node's 0x1018 against it, writes only the values that
#     differ from what the node holds and weaves one row. Judged from candump: each drive's 0x1018:01 read
#     before NMT start; no download to a mapping object (0x1600/0x1A00: the file's default mapping is the
#     loom's); the 0x1017 heartbeat written (the file says 0).
#  2. The helix names brick_bx2_fixed.eds (another maker's drive): bring-up stops naming node 3 and both
#     identities, loomctl exits 4, and candump shows no SDO download to node 3 and no NMT start.
# usage: eds-bring-up.sh BUILD_DIR   (exit 77 = skipped: no vcan0 here)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
hil_init "eds_bring_up" "${1:-}"
hil_require_vcan
hil_find_binaries
eds_dir=$(cd "$HIL_SRC/../drivers/eds" && pwd)
hil_start_candump
HIL_SIM_EDS=$eds_dir/acme_ax400_dynamic.eds
hil_start_sim_drives

# The HIL loom with every axis' EDS named (relative to the loom file, as a builder writes it).
cp "$eds_dir/acme_ax400_dynamic.eds" "$eds_dir/brick_bx2_fixed.eds" "$HIL_WORK/"
config=$HIL_WORK/eds_loom.toml
{ cat "$HIL_SRC/hil_loom.toml"
  printf '\n[axes.beat_crank]\neds = "acme_ax400_dynamic.eds"\n'
  printf '\n[axes.carriage]\neds = "acme_ax400_dynamic.eds"\n'
  printf '\n[axes.helix]\neds = "acme_ax400_dynamic.eds"\n'; } >"$config"
"$HIL_LOOMCTL" check --config "$config" >"$HIL_WORK/check.out" || hil_fail "loomctl check refused the EDS loom: $(tail -n 5 "$HIL_WORK/check.out")"

# 1. The row, with the nodes configured from their description.
mark=$(hil_mark)
HIL_CONFIG=$config
hil_weave_cmd 1 "$HIL_WORK/counters.json"
hil_run_weave "${LOOM_HIL_WEAVE_TIMEOUT_S:-150}"
(($HIL_STATUS == 0)) || hil_fail "loomctl exited $HIL_STATUS weaving against the described nodes (0 = row completed)"
rows=$(grep -c '^row ' "$HIL_WORK/loomctl.out" || true)
((rows == 1)) || hil_fail "expected 1 per-row summary line, found $rows"
for n in 1 2 3; do
  hil_frames_after "$mark" "$(printf '%03X' $((0x600 + n)))#4018100100000000" | grep -q . ||
    hil_fail "node $n: no SDO read of 0x1018:01 (identity) before its configuration"
  tx=$(printf '%03X' $((0x600 + n)))
  # Initiate-download requests (command byte 0x2x) to the mapping objects, which the file already holds as
  # the loom wants them.
  bad=$(hil_frames_after "$mark" "${tx}#2[0-9A-F](0016|001A)[0-9A-F]*")
  [[ -z $bad ]] || hil_fail "node $n: wrote values its dictionary already held: $bad"
  hil_frames_after "$mark" "${tx}#2B171000[0-9A-F]*" | grep -q . || hil_fail "node $n: 0x1017 (heartbeat) not written"
done
hil_note "row woven; identity read and only differing values written on nodes 1-3"

# 2. Another maker's drive named for the helix: bring-up stops at node 3.
{ cat "$HIL_SRC/hil_loom.toml"
  printf '\n[axes.helix]\neds = "brick_bx2_fixed.eds"\n'; } >"$config"
mark=$(hil_mark)
hil_weave_cmd 1 "$HIL_WORK/counters2.json"
hil_run_weave 60
(($HIL_STATUS == 4)) || hil_fail "loomctl exited $HIL_STATUS with a mismatched node 3 (4 = hardware not armed)"
grep -q 'node 3 (helix) is vendor 0x000004A2 product 0x00401234' "$HIL_WORK/loomctl.out" ||
  hil_fail "the refusal does not name node 3 and the identity it reported"
grep -q 'brick_bx2_fixed.eds describes vendor 0x00000B1C product 0x00000202' "$HIL_WORK/loomctl.out" ||
  hil_fail "the refusal does not name the EDS's identity"
after=$(hil_frames_after "$mark" "603#2[0-9A-F]*")
[[ -z $after ]] || hil_fail "SDO downloads reached the mismatched node 3: $after"
starts=$(hil_frames_after "$mark" "000#01[0-9A-F]{2}")
[[ -z $starts ]] || hil_fail "NMT start sent although bring-up was refused: $starts"
hil_stop_candump
hil_note "mismatched node 3 refused before any write; no NMT start"
hil_report_frames

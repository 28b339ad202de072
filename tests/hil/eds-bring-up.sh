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
#  3. Drives simulated from brick_bx2_fixed.eds (fixed mappings, 1 RPDO / 2 TPDOs): a row is woven, no
#     download to a mapping object.
#  4. Drives simulated from stepwise_sd7_no_csp.eds (no CSP): loomctl check refuses with the EDS's line,
#     bring-up refuses node 1 with the reason, no NMT start.
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
hil_note "mismatched node 3 refused before any write; no NMT start"

# hil_restart_sim EDS — the simulated drives rebuilt from another maker's EDS.
hil_restart_sim() {
  kill "$HIL_SIM_PID" 2>/dev/null || true
  wait "$HIL_SIM_PID" 2>/dev/null || true
  hil_forget_pid "$HIL_SIM_PID"
  HIL_SIM_EDS=$1
  hil_start_sim_drives
}

# 3. Drives with fixed mappings and an odd PDO count (brick_bx2_fixed.eds: one RPDO, two TPDOs where
#    NrOfTXPDO says 3, no 0x1016): the mapping is read back, never written, and the row is woven.
hil_restart_sim "$eds_dir/brick_bx2_fixed.eds"
{ cat "$HIL_SRC/hil_loom.toml"
  for axis in beat_crank carriage helix; do printf '\n[axes.%s]\neds = "brick_bx2_fixed.eds"\n' "$axis"; done; } >"$config"
"$HIL_LOOMCTL" check --config "$config" >"$HIL_WORK/check3.out" || hil_fail "loomctl check refused the fixed-mapping loom: $(tail -n 5 "$HIL_WORK/check3.out")"
mark=$(hil_mark)
hil_weave_cmd 1 "$HIL_WORK/counters3.json"
hil_run_weave "${LOOM_HIL_WEAVE_TIMEOUT_S:-150}"
(($HIL_STATUS == 0)) || hil_fail "loomctl exited $HIL_STATUS weaving against fixed-mapping drives (0 = row completed)"
for n in 1 2 3; do
  tx=$(printf '%03X' $((0x600 + n)))
  hil_frames_after "$mark" "${tx}#4018100100000000" | grep -q . || hil_fail "node $n (fixed): no 0x1018:01 read"
  bad=$(hil_frames_after "$mark" "${tx}#2[0-9A-F](0016|001A)[0-9A-F]*")
  [[ -z $bad ]] || hil_fail "node $n (fixed): a download to its read-only mapping: $bad"
done
hil_note "fixed-mapping drives: mapping read back, row woven"

# 4. A drive without CSP (stepwise_sd7_no_csp.eds: PP and PV only): loomctl check says why before any
#    frame, and bring-up refuses node 1 with the reason.
hil_restart_sim "$eds_dir/stepwise_sd7_no_csp.eds"
cp "$eds_dir/stepwise_sd7_no_csp.eds" "$HIL_WORK/"
# (A heartbeat within its 0x1017 limits, 500..65535 ms: the HIL loom's 200 ms is refused at can.heartbeat_ms.)
printf 'extends = "default"\n[can]\nheartbeat_ms = 500\nheartbeat_timeout_ms = 1400\n[axes.beat_crank]\neds = "stepwise_sd7_no_csp.eds"\n' \
  >"$HIL_WORK/no_csp.toml"
rc=0
"$HIL_LOOMCTL" check --config "$HIL_WORK/no_csp.toml" >"$HIL_WORK/check4.out" 2>&1 || rc=$?
((rc == 2)) || hil_fail "loomctl check of a drive without CSP exited $rc, not 2"
grep -q 'stepwise_sd7_no_csp.eds:[0-9]*: error: .*0x6502 supported drive modes 0x00000005 (PP, PV) lacks CSP' "$HIL_WORK/check4.out" ||
  hil_fail "loomctl check did not name the missing CSP: $(tail -n 5 "$HIL_WORK/check4.out")"
HIL_CONFIG=$HIL_SRC/hil_loom.toml
mark=$(hil_mark)
hil_weave_cmd 1 "$HIL_WORK/counters4.json"
hil_run_weave 60
(($HIL_STATUS == 4)) || hil_fail "loomctl exited $HIL_STATUS against drives without CSP (4 = hardware not armed)"
grep -q 'node 1 (beat_crank): the drive does not support cyclic synchronous position (0x6502 = 0x00000005' "$HIL_WORK/loomctl.out" ||
  hil_fail "bring-up did not refuse node 1 for its missing CSP"
starts=$(hil_frames_after "$mark" "000#01[0-9A-F]{2}")
[[ -z $starts ]] || hil_fail "NMT start sent to drives without CSP: $starts"
hil_stop_candump
hil_note "drive without CSP: refused by check (file:line) and at bring-up (node 1), no NMT start"
hil_report_frames

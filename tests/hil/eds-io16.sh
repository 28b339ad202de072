#!/usr/bin/env bash
# HIL: an I/O module whose digital inputs are CiA 401 16-bit groups (issue 32 item 4), described by a
# vendor-style EDS, on a real vcan0. loom-sim-drive builds the module from kordis_dio32w.eds (--io-eds:
# 0x6100:01..02 and no 0x6000, a factory TPDO1 with the first word only, 0x1010 store parameters); the
# drives are the built-in ones. The loom names the file (io.eds) and asks for storing (io.store_config).
#  1. loomctl check lists 0x6100:01..02 (16-bit groups) as what the module must have, and no error.
#  2. A row is woven. Judged from candump: node 4's 0x1018:01 read; TPDO1 re-mapped to both words
#     (0x1A00:02 = 0x61000210, as CiA 301 writes the download: 604#23001A0210020061); no SDO access to
#     0x6000 at all; every TPDO1 of node 4 after NMT start carries 4 bytes, with the e-stop chain's
#     terminal 6 closed; "save" written to 0x1010:01 once, after every other download to node 4 and
#     before NMT start (604#2310100173617665, acknowledged by 584#60101001).
# usage: eds-io16.sh BUILD_DIR   (exit 77 = skipped: no vcan0 here)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
hil_init "eds_io16" "${1:-}"
hil_require_vcan
hil_find_binaries
eds_dir=$(cd "$HIL_SRC/../drivers/eds" && pwd)
hil_start_candump
HIL_SIM_EXTRA=(--io-eds "$eds_dir/kordis_dio32w.eds")
hil_start_sim_drives

cp "$eds_dir/kordis_dio32w.eds" "$HIL_WORK/"
config=$HIL_WORK/io16_loom.toml
{ cat "$HIL_SRC/hil_loom.toml"
  printf '\n[io]\neds = "kordis_dio32w.eds"\nstore_config = true\n'; } >"$config"

# 1. What check says of the module.
"$HIL_LOOMCTL" check --config "$config" >"$HIL_WORK/check.out" 2>&1 ||
  hil_fail "loomctl check refused the 16-bit module: $(tail -n 5 "$HIL_WORK/check.out")"
grep -q '0x6100:01..02 read digital inputs, 16-bit' "$HIL_WORK/check.out" ||
  hil_fail "loomctl check does not list 0x6100:01..02: $(grep -n '0x6[01]00' "$HIL_WORK/check.out" || true)"
! grep -q '0x6000:0' "$HIL_WORK/check.out" || hil_fail "loomctl check still asks the module for 0x6000"
hil_note "check: 0x6100:01..02 (16-bit input groups) required, nothing lacking"

# 2. The row.
mark=$(hil_mark)
HIL_CONFIG=$config
hil_weave_cmd 1 "$HIL_WORK/counters.json"
hil_run_weave "${LOOM_HIL_WEAVE_TIMEOUT_S:-150}"
(($HIL_STATUS == 0)) || hil_fail "loomctl exited $HIL_STATUS weaving against the 16-bit module (0 = row completed)"
rows=$(grep -c '^row ' "$HIL_WORK/loomctl.out" || true)
((rows == 1)) || hil_fail "expected 1 per-row summary line, found $rows"
hil_stop_candump

hil_frames_after "$mark" '604#4018100100000000' | grep -q . || hil_fail "no SDO read of node 4's 0x1018:01"
hil_frames_after "$mark" '604#23001A0210020061' | grep -q . ||
  hil_fail "TPDO1 of node 4 not mapped to 0x6100:02 (no download 604#23001A0210020061)"
bad=$(hil_frames_after "$mark" '604#[0-9A-F]{2}0060[0-9A-F]*')
[[ -z $bad ]] || hil_fail "SDO access to 0x6000 (the module has no 8-bit inputs): $bad"

# In log order: the frames after the mark with their line numbers (ID#DATA only).
frames=$HIL_WORK/frames.txt
tail -n "+$((mark + 1))" "$HIL_LOG" | awk '{ print NR, $3 }' >"$frames"
start=$(awk '$2 ~ /^000#01/ { print $1; exit }' "$frames")
[[ -n $start ]] || hil_fail "no NMT start"
save=$(awk '$2 == "604#2310100173617665" { print $1 }' "$frames")
[[ $(wc -w <<<"$save") == 1 ]] || hil_fail "0x1010:01 \"save\" written $(wc -w <<<"$save") times to node 4, not once"
grep -qE '^[0-9]+ 584#60101001' "$frames" || hil_fail "node 4 did not acknowledge the save"
last_other=$(awk '$2 ~ /^604#2/ && $2 != "604#2310100173617665" { n = $1 } END { print n }' "$frames")
((save > last_other)) || hil_fail "save (line $save) before the last configuration write (line $last_other)"
((save < start)) || hil_fail "save (line $save) after NMT start (line $start)"

tpdo=$(awk -v s="$start" '$1 > s && $2 ~ /^184#/ { print $2 }' "$frames")
[[ -n $tpdo ]] || hil_fail "no TPDO1 from node 4 after NMT start"
wrong=$(grep -vE '^184#[0-9A-F]{8}$' <<<"$tpdo" | head -n 3 || true)
[[ -z $wrong ]] || hil_fail "TPDO1 of node 4 not two words (4 bytes): $wrong"
# Terminal 6 (e-stop chain closed) is bit 6 of the first word's low byte.
closed=$(grep -cE '^184#([4-7C-F][0-9A-F])' <<<"$tpdo" || true)
((closed > 0)) || hil_fail "no TPDO1 shows the e-stop chain closed (terminal 6): $(head -n 3 <<<"$tpdo")"
hil_note "row woven; TPDO1 of node 4 = two 16-bit words ($(wc -l <<<"$tpdo") frames), mapped by the master; configuration stored once before NMT start"
hil_report_frames

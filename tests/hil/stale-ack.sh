#!/usr/bin/env bash
# HIL (issue 22): a stale acknowledgement over a real vcan0. While loomctl weaves against loom-sim-drive's
# CiA 402 drives and CiA 401 I/O module, the module's ack button is pressed for 0.3 s and released (no
# fault: not an acknowledgement), then the e-stop chain opens 1.5 s later. The fault must be latched
# and recorded as if there had been no press (before the fix the drives got controlword 0x0000 and the
# loom went idle, fault=none, and weave never ended):
#   - loomctl exits 3 with a first FAULT line naming estop;
#   - judged from candump: the press and the release crossed the bus (the module's TPDO1, input 10);
#     after the chain opened every drive's first controlword that is not Enable Operation is a quick
#     stop (bit 1 set, bit 2 clear — not 0x0000 disable voltage); the red lamp comes on (output 6) and
#     the amber lamp goes off; and it stays latched: no drive is enabled (0x000F) again and no output
#     frame after the first red one turns the red lamp off, to the end of the record.
# usage: stale-ack.sh BUILD_DIR   (exit 77 = skipped: no vcan0 here)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
hil_init stale_ack "${1:-}"
hil_require_vcan
hil_find_binaries
press_s=${LOOM_HIL_ACK_PRESS_S:-0.3}
gap_s=${LOOM_HIL_ACK_TO_ESTOP_S:-1.5}
io_tpdo=$(printf '%03X' $((0x180 + HIL_IO_NODE)))  # inputs: estop_ok = bit 6, button_ack = bit 10
io_rpdo=$(printf '%03X' $((0x200 + HIL_IO_NODE)))  # outputs: lamp_amber = bit 5, lamp_red = bit 6

hil_start_candump
hil_start_sim_drives
counters=$HIL_WORK/counters.json
# Rows enough that the loom still weaves when the e-stop opens (it ends the run): with 2 rows (20 s of machine
# time) a slow VM, whose shell steps starve beside the SCHED_FIFO loop, once saw the run end before the e-stop.
hil_weave_until_armed stale_ack 8 "$counters"

# --- the press while weaving, without a fault ----------------------------------------------------------
mark=$(hil_mark)
hil_io_control ack
hil_sim_took_controls press ack
hil_loom_alive stale_ack "before the ack press reached the bus (a late master heartbeat in a loaded VM: EMCY 0x8130)"
# input 10 = byte 1, bit 2: the low hex digit of byte 1 is one of 4-7, C-F
hil_expect "$mark" "$io_tpdo#[0-9A-F]{3}[4-7C-F][0-9A-F]*" 5 "ack button pressed on the module's TPDO1" >/dev/null
sleep "$press_s"
mark=$(hil_mark)
hil_io_control ""
hil_expect "$mark" "$io_tpdo#[0-9A-F]{3}[0-38-B][0-9A-F]*" 5 "ack button released on the module's TPDO1" >/dev/null
hil_note "ack button pressed for ${press_s} s and released while weaving"
sleep "$gap_s"
hil_loom_alive stale_ack "after the ack press, before the e-stop (a press without a fault must change nothing)"
! grep -q '^FAULT' "$HIL_LOOM_OUT" || hil_fail "a fault before the e-stop: $(grep '^FAULT' "$HIL_LOOM_OUT")"

# --- the e-stop chain opens ----------------------------------------------------------------------------
hil_io_control estop
hil_sim_took_controls estop estop
hil_expect_fault stale_ack '^FAULT estop ' "$counters"
hil_io_control ""

# --- judged from the bus --------------------------------------------------------------------------------
# The fields of candump -L lines: "(t) iface ID#DATA". awk reads the kept log once and reports.
read -r -d '' judge <<'AWK' || true
  function hex(c) { return index("0123456789ABCDEF", c) - 1 }
  function byte(data, k) { return 16 * hex(substr(data, 2 * k + 1, 1)) + hex(substr(data, 2 * k + 2, 1)) }
  function bit(x, k) { return int(x / 2 ^ k) % 2 }
  function fail(why) { print "FAIL " why; bad = 1; exit }
  BEGIN { n = split(drives, d, ","); for (i = 1; i <= n; ++i) drive[sprintf("%03X", 512 + d[i])] = d[i] }
  {
    split($3, f, "#"); id = f[1]; data = f[2]; t = substr($1, 2, length($1) - 2)
    if (id == tpdo && length(data) >= 4) {
      ack = bit(byte(data, 1), 2) == 1
      if (ack && !opened) pressed = 1
      if (!ack && pressed && !opened) released = 1
      if (bit(byte(data, 0), 6) == 0 && released && !opened) { opened = NR; t_open = t }  # after the press
      next
    }
    if (!opened) next
    if (id in drive && length(data) >= 4) {
      cw = byte(data, 0) + 256 * byte(data, 1)
      if (!(id in first) && cw % 16 != 15) {
        first[id] = cw; t_first[id] = t
        if (bit(cw, 1) == 0 || bit(cw, 2) == 1)
          fail(sprintf("drive %d got controlword 0x%04X after the chain opened (line %d): not a quick stop", drive[id], cw, NR))
      } else if ((id in first) && cw % 16 == 15) {
        fail(sprintf("drive %d enabled again (0x%04X, line %d) after its stop: the fault did not stay latched", drive[id], cw, NR))
      }
    }
    if (id == rpdo && length(data) >= 2) {
      out = byte(data, 0)
      if (bit(out, 6)) { if (!red) { red = NR; t_red = t }; if (bit(out, 5)) fail(sprintf("amber lamp with red at line %d", NR)) }
      else if (red) fail(sprintf("red lamp off again at line %d: the fault did not stay latched", NR))
    }
  }
  END {
    if (bad) exit 1
    if (!pressed || !released) { print "FAIL the ack press/release is not in the record"; exit 1 }
    if (!opened) { print "FAIL the e-stop chain never opened on the module TPDO1"; exit 1 }
    for (id in drive) if (!(id in first)) { print "FAIL drive " drive[id] " got no stop after the chain opened"; exit 1 }
    if (!red) { print "FAIL no red lamp after the chain opened"; exit 1 }
    s = sprintf("chain opened at line %d; red lamp %.1f ms later", opened, (t_red - t_open) * 1e3)
    for (id in drive) s = s sprintf("; drive %d quick stop 0x%04X %.1f ms later", drive[id], first[id], (t_first[id] - t_open) * 1e3)
    print "OK " s
  }
AWK
verdict=$(awk -v tpdo="$io_tpdo" -v rpdo="$io_rpdo" -v drives="$HIL_NODES" "$judge" "$HIL_LOG") || true
[[ $verdict == OK* ]] || hil_fail "bus check: ${verdict#FAIL }; log: $HIL_LOG"
hil_note "bus: ${verdict#OK }"
hil_report_frames

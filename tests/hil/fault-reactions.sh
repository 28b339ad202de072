#!/usr/bin/env bash
# HIL: the fault reactions over a real vcan0, each on a fresh machine: a new loom-sim-drive (drives and
# I/O node, shuttle at the left selvedge, shed closed) and fresh counters, so what one fault left behind
# (a shuttle stopped mid-shed by the e-stop, rightly refused as shuttle_lost) cannot decide the next:
#   estop     — the I/O node's e-stop input opens → exit 3, first fault estop, counters kept;
#   io_silent — the I/O node goes silent → exit 3, first fault heartbeat_lost, counters kept;
#   emcy      — an EMCY 0x2310 from drive 2 while its statusword stays Operation Enabled → exit 3,
#               drive_emcy (the drive is not in Fault); judged from candump: within one cycle every drive
#               gets quick stop;
#   stuck     — the second switch of shuttle_at_left sticks on (loom-sim-drive's io-control word
#               stuck=shuttle_at_left_2:on) → exit 3, first fault sensor_discrepancy naming
#               shuttle_at_left: the two-channel check over the real CAN path (terminal 20, in TPDO1's third byte);
#   master    — loomctl is killed (SIGKILL) → every node's 0x1016 consumer reacts (EMCY 0x8130 each),
#               judged from candump against the consumer time.
# Reaction times are printed from candump's timestamps (the VM is not real-time: order is asserted,
# times are reported with a generous bound).  usage: fault-reactions.sh BUILD_DIR  (77 = no vcan0)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
hil_init fault_reactions "${1:-}"
hil_require_vcan
hil_find_binaries
BASE=$HIL_NAME

# fresh_machine — (re)start the simulated drives and I/O node: the machine as it comes from the builder.
fresh_machine() {
  if [[ -n ${HIL_SIM_PID:-} ]]; then
    kill "$HIL_SIM_PID" 2>/dev/null || true
    local i
    for i in $(seq 1 100); do kill -0 "$HIL_SIM_PID" 2>/dev/null || break; sleep 0.05; done
    hil_forget_pid "$HIL_SIM_PID"
  fi
  hil_start_sim_drives  # (its I/O control file starts empty: e-stop closed, nothing silenced)
}

# run_until_armed NAME — on a fresh machine, start loomctl (2 rows) and return once it has been weaving
# for a while.
run_until_armed() {
  HIL_NAME=${BASE}_$1
  hil_start_candump
  fresh_machine
  counters=$HIL_WORK/$1.counters.json
  hil_weave_until_armed "$1" 2 "$counters"
  loom_pid=$HIL_LOOM_PID
}

# expect_fault NAME REGEX — loomctl stops by itself with exit 3 and a FAULT line matching REGEX; the
# counters file is kept.
expect_fault() { hil_expect_fault "$1" "$2" "$counters"; }

# --- e-stop input -------------------------------------------------------------------------------------
run_until_armed estop
hil_io_control estop
expect_fault estop 'estop'
hil_io_control ""

# --- I/O node silenced --------------------------------------------------------------------------------
run_until_armed io_silent
hil_io_control silent
expect_fault io_silent 'heartbeat'
hil_io_control ""
sleep 0.2

# --- EMCY while the drive stays enabled ---------------------------------------------------------------
run_until_armed emcy
cansend "$HIL_IFACE" 082#1023030000000000
expect_fault emcy 'drive_emcy.*0x2310|0x2310.*drive_emcy'
"$HIL_CANLOG" emcy-stop "$HIL_LOG" --nodes "$HIL_NODES" --emcy-node 2 ||
  hil_fail "emcy: the bus does not show a quick stop of every drive right after the EMCY; log: $HIL_LOG"

# --- a stuck second switch ----------------------------------------------------------------------------
# shuttle_at_left's second switch sticks on. Row 1 is shed (0.3 s machine time), one pick to the right
# (0.7 s), then 8 beats (8.4 s) with the shuttle at the right: 2 s after arming (about 1 s machine time
# in the VM) the shuttle has left the left selvedge, its first switch is off and the two disagree at
# once; were it still there, they disagree as it leaves. (Stuck shuttle_at_right_2 would wait out the
# beats, its first switch on through them.) The loom acts on the sensor only while both switches agree,
# so nothing else trips first.
case_start=$SECONDS
run_until_armed stuck
hil_io_control stuck=shuttle_at_left_2:on
hil_sim_took_controls stuck 'stuck=shuttle_at_left_2:on'
expect_fault stuck '^FAULT sensor_discrepancy \(code 0x1020, sensor shuttle_at_left,'
hil_io_control ""
hil_note "stuck: case took $((SECONDS - case_start)) s (fresh machine, bring-up, 2 s weaving, fault)"

# --- the master dies ----------------------------------------------------------------------------------
run_until_armed master
kill -KILL "$loom_pid"
sleep 1
hil_forget_pid "$loom_pid"
hil_stop_candump
nodes=$HIL_NODES,$HIL_IO_NODE
[[ $HIL_PERSONALITY == fixed ]] && nodes=$HIL_IO_NODE  # the fixed personality has no 0x1016
"$HIL_CANLOG" master-loss "$HIL_LOG" --nodes "$nodes" --master 127 --consumer-ms 500 --slack-ms 1000 ||
  hil_fail "master: the nodes' heartbeat consumers did not react; log: $HIL_LOG"
kill -0 "$HIL_SIM_PID" 2>/dev/null || hil_fail "loom-sim-drive died: $(tail -n 5 "$HIL_WORK/sim.out")"
hil_report_frames

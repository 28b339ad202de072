#!/usr/bin/env bash
# HIL (issue 22): the I/O module's buttons are audited like every other station. `loomctl serve` runs the
# HIL loom over a real vcan0 against loom-sim-drive (drives and CiA 401 I/O module) with telemetry on a
# private LCM group that lcm-logger records. The module's buttons are pressed through loom-sim-drive's
# --io-control file, 0.3 s each:
#   ack while idle (no fault)            → refused, the loom stays idle;
#   start                                → accepted, the loom weaves;
#   ack with the e-stop chain open (the fault latched) → refused, the fault stays;
#   ack after the chain closed           → accepted, the loom idles (faults.log names the ack button).
# Each press is a COMMAND event on LOOM.<id>.COMMAND with station "button", who "the I/O module's ...
# button", the verdict and the state it was pressed in — read back from lcm-logger's file by
# telemetry_command_log — and a journal line "operator: WORD by the I/O module's ... button".
# usage: button-audit.sh BUILD_DIR   (exit 77 = skipped: no vcan0 here)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
hil_init button_audit "${1:-}"
hil_require_vcan
hil_find_binaries
COMMAND_LOG=$HIL_BUILD/tests/telemetry_command_log
hil_need_exec "$COMMAND_LOG" telemetry_command_log
command -v lcm-logger >/dev/null || hil_fail "lcm-logger not found (Debian package liblcm-bin)"

# The HIL loom at the HIL period (serve takes its period from the config).
config=$HIL_WORK/loom.toml
sed "s/^\[timing\]\$/[timing]\nperiod_ms = $HIL_PERIOD_MS/" "$HIL_SRC/hil_loom.toml" >"$config"
grep -q "^period_ms = $HIL_PERIOD_MS\$" "$config" || hil_fail "could not set the period in $config"
url="udpm://239.255.76.67:$((20000 + ($$ * 7) % 20000))?ttl=0"
id=hilbtn$$
sock=$HIL_WORK/loom.sock
ctl() { "$HIL_LOOMCTL" ctl --socket "$sock" "$@"; }
field() { ctl status 2>/dev/null | tr ' ' '\n' | sed -n "s/^$1=//p"; }
wait_for() {  # wait_for FIELD REGEX SECONDS
  local deadline=$((SECONDS + $3))
  until [[ $(field "$1") =~ ^($2)$ ]]; do
    kill -0 "$serve_pid" 2>/dev/null || { tail -n 20 "$HIL_WORK/serve.out"; hil_fail "serve ended waiting for $1=$2"; }
    ((SECONDS < deadline)) || { tail -n 20 "$HIL_WORK/serve.out"; hil_fail "waited $3 s for $1=$2: $(ctl status 2>&1)"; }
    sleep 0.05
  done
}
# press WORD [HELD] — the module's WORD button pressed for 0.3 s (with the words HELD active throughout).
press() {
  hil_io_control "$1" "${@:2}"
  hil_sim_took_controls "$1" "$*"
  sleep 0.3
  hil_io_control "${@:2}"
  sleep 0.5
}

hil_start_candump
hil_start_sim_drives
hil_spawn logger lcm-logger -q -f --flush-interval=20 --lcm-url="$url" "$HIL_WORK/audit.lcmlog"
hil_spawn serve "$HIL_LOOMCTL" serve --hal socketcan --iface "$HIL_IFACE" --config "$config" \
  --state-dir "$HIL_WORK/state" --socket "$sock" --group "" --loom-id "$id" --lcm-url "$url" --allow-degraded
serve_pid=$HIL_LAST_PID
deadline=$((SECONDS + 60))
until grep -q "armed, waiting for the operator" "$HIL_WORK/serve.out"; do
  kill -0 "$serve_pid" 2>/dev/null || { cat "$HIL_WORK/serve.out"; hil_fail "serve ended before arming"; }
  ((SECONDS < deadline)) || { cat "$HIL_WORK/serve.out"; hil_fail "serve did not arm within 60 s"; }
  sleep 0.1
done
wait_for state idle 30
hil_note "serve armed over $HIL_IFACE, waiting for the operator"

press ack
[[ $(field state) == idle ]] || hil_fail "an ack press without a fault changed the state: $(ctl status)"
press start
wait_for state 'enabling|homing|positioning|shed_test|shed|pick|beat_sweep|row_end' 30
hil_note "the start button set the loom weaving: $(field state)"
sleep 2
hil_io_control estop
hil_sim_took_controls estop estop
wait_for state fault 20
[[ $(field fault) == estop ]] || hil_fail "the e-stop latched $(field fault)"
press ack estop
[[ $(field state) == fault ]] || hil_fail "an ack press with the chain open re-armed: $(ctl status)"
hil_io_control ""
sleep 0.5
press ack
wait_for state idle 30
hil_note "the ack button acknowledged the e-stop once the chain was closed"
ctl faults | grep -q " ack $id estop .*acknowledged by the I/O module's ack button" ||
  hil_fail "faults.log does not name the ack button: $(ctl faults)"
kill -TERM "$serve_pid"
for _ in $(seq 1 100); do kill -0 "$serve_pid" 2>/dev/null || break; sleep 0.1; done
sleep 0.5  # lcm-logger flushes every 20 ms
hil_stop_candump
cp "$HIL_WORK/serve.out" "$HIL_LOGDIR/$HIL_NAME.serve.out"

"$COMMAND_LOG" "$HIL_WORK/audit.lcmlog" "$id" >"$HIL_WORK/commands.txt" || hil_fail "COMMAND events did not decode"
sed 's/^/  /' "$HIL_WORK/commands.txt"
mapfile -t got < <(grep ' station=button ' "$HIL_WORK/commands.txt")
want=(
  "^COMMAND ack station=button accepted=0 state=idle who=the I/O module's reset/acknowledge button reply=refused: ack: no fault is latched"
  "^COMMAND start station=button accepted=1 state=idle who=the I/O module's start button reply=ok start$"
  "^COMMAND ack station=button accepted=0 state=fault who=the I/O module's reset/acknowledge button reply=refused: ack: the e-stop chain is still open"
  "^COMMAND ack station=button accepted=1 state=fault who=the I/O module's reset/acknowledge button reply=ok ack$"
)
((${#got[@]} == ${#want[@]})) || hil_fail "${#got[@]} button COMMAND events, want ${#want[@]} (one per press)"
for i in "${!want[@]}"; do
  [[ ${got[$i]} =~ ${want[$i]} ]] || hil_fail "button event $((i + 1)): '${got[$i]}', want /${want[$i]}/"
done
for w in "ack by the I/O module's reset/acknowledge button (state idle)" "start by the I/O module's start button" \
  "ack by the I/O module's reset/acknowledge button (state fault)"; do
  grep -qF "operator: $w" "$HIL_WORK/serve.out" || hil_fail "no journal line 'operator: $w'"
done
hil_note "${#got[@]} button presses audited on LOOM.$id.COMMAND (station button, verdict, state) and in the journal"
hil_report_frames

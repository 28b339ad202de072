#!/usr/bin/env bash
# HIL: the drive node vanishes mid-row (SIGKILL: no goodbye on the bus) while loomctl weaves 2 rows.
# loomctl must stop with exit 3 and a FAULT line naming the heartbeat and the rows completed, keep the
# row counter in its counters file, and — judged from candump's record — react within three heartbeat
# periods of the last heartbeat with a quick-stop/disable controlword and command no further motion.
# usage: heartbeat-loss.sh BUILD_DIR   (exit 77 = skipped: no vcan0 here)
set -euo pipefail
. "$(dirname "$0")/hil-lib.sh"
hil_init heartbeat_loss "${1:-}"
hil_require_vcan
hil_find_binaries
heartbeat_ms=${LOOM_HIL_HEARTBEAT_MS:-200}  # the drives' producer time in hil_loom.toml
hil_start_candump
hil_start_sim_drives

counters=$HIL_WORK/counters.json
out=$HIL_WORK/loomctl.out
hil_weave_cmd 2 "$counters"
hil_note "running: ${HIL_CMD[*]}"
us_now() { local t=$EPOCHREALTIME; echo "${t/[.,]/}"; }
t0=$(us_now)
"${HIL_CMD[@]}" >"$out" 2>&1 &
loom_pid=$!
HIL_PIDS+=("$loom_pid")

show_output() { sed 's/^/  loomctl| /' "$out"; cp "$out" "$HIL_LOGDIR/$HIL_NAME.loomctl.out"; }

# --- Let row 1 complete, then kill the drives a little way into row 2 ---------------------------------
deadline=$((SECONDS + ${LOOM_HIL_WEAVE_TIMEOUT_S:-150}))
until grep -q '^row ' "$out"; do
  kill -0 "$loom_pid" 2>/dev/null || { show_output; hil_fail "loomctl exited before completing row 1"; }
  ((SECONDS < deadline)) || { show_output; hil_fail "row 1 did not complete within ${LOOM_HIL_WEAVE_TIMEOUT_S:-150} s"; }
  sleep 0.05
done
row1_us=$(($(us_now) - t0))
# A few seconds into row 2, but surely before it ends: at most a third of row 1's duration.
kill_after_us=$((${LOOM_HIL_KILL_AFTER_MS:-2000} * 1000))
((kill_after_us <= row1_us / 3)) || kill_after_us=$((row1_us / 3))
sleep "$((kill_after_us / 1000000)).$(printf '%06d' $((kill_after_us % 1000000)))"
kill -0 "$loom_pid" 2>/dev/null || { show_output; hil_fail "loomctl ended before the drive node was killed"; }
kill -KILL "$HIL_SIM_PID"
hil_note "row 1 done after $((row1_us / 1000)) ms; killed loom-sim-drive (SIGKILL) $((kill_after_us / 1000)) ms into row 2"

# --- loomctl must notice and stop on its own ------------------------------------------------------------
deadline=$((SECONDS + 30))
while kill -0 "$loom_pid" 2>/dev/null && ((SECONDS < deadline)); do sleep 0.05; done
if kill -0 "$loom_pid" 2>/dev/null; then
  show_output
  hil_fail "loomctl still running 30 s after the drive node vanished"
fi
status=0
wait "$loom_pid" || status=$?
show_output
hil_stop_candump
((status == 3)) || hil_fail "loomctl exited with status $status after the heartbeat loss, expected 3 (fault)"

rows=$(grep -c '^row ' "$out" || true)
((rows == 1)) || hil_fail "expected exactly 1 completed row before the fault, loomctl printed $rows 'row ' lines"
fault_line=$(grep 'FAULT' "$out" | grep -i 'heartbeat' | head -n1 || true)
[[ -n $fault_line ]] || hil_fail "no output line containing both FAULT and heartbeat"
# "rows completed 1", "rows=1", "rows: 1" or "1 rows" — the count must be next to the word.
grep -qiE "\brows?[ _]*(completed|done)?[ :=]*$rows\b|\b$rows rows?\b" <<<"$fault_line" ||
  hil_fail "the FAULT line does not state the rows completed ($rows): $fault_line"
hil_note "loomctl: exit 3, '$fault_line'"

[[ -f $counters ]] || hil_fail "no counters file at $counters after the fault"
cp "$counters" "$HIL_LOGDIR/$HIL_NAME.counters.json"
counted=$(hil_json_int "$counters" rows)
[[ $counted == "$rows" ]] || hil_fail "counters file says rows=${counted:-<missing>} after the fault, expected $rows: $(cat "$counters")"
hil_note "counters kept: $(tr -d '\n' <"$counters")"

# On the master's clock (its SYNCs): the VM runs the loop slower than real time (the overrun policy is
# off there), and the master supervises heartbeats in its own cycles, as it does on a board in real time.
"$HIL_CANLOG" heartbeat-loss "$HIL_LOG" --nodes "$HIL_NODES" --heartbeat-ms "$heartbeat_ms" --periods 3 \
  --master-cycle-ms "$HIL_PERIOD_MS" ||
  hil_fail "bus check of the fault reaction failed (see above); log: $HIL_LOG"
hil_report_frames

#!/usr/bin/env bash
# LCM's own tools work with our channels: lcm-logger records a scripted weaving run published by the
# real Telemetry publisher over udpm, lcm-logplayer replays the log, and loom-monitor prints exactly
# the STATUS messages that were published, with rows and states advancing in order.
# Usage: logger_replay.sh <loom-monitor> <telemetry_feed>
MONITOR=$1
FEED=$2
source "$(dirname "$0")/../../telemetry/lcm_script_lib.sh"

ROWS=3
ID="replay$$"

start_logger
# --tick-us 500: a loop-like pace; AXES every 10 ticks, RT every 50.
FEED_OUT=$("$FEED" --lcm-url "$URL" --loom-id "$ID" --rows "$ROWS" --tick-us 500 --axes-every 10 \
  --rt-every 50) || fail "telemetry_feed failed: $FEED_OUT"
echo "feed: $FEED_OUT"
stop_logger

field() { sed -n "s/.* $1=\([0-9]*\).*/\1/p" <<<"$FEED_OUT"; }
N_STATUS=$(field status)
N_AXES=$(field axes)
N_RT=$(field rt)
[ "${N_STATUS:-0}" -gt 0 ] || fail "feed published no STATUS"

# Everything the feed published must be in the log: the monitor stops after exactly that many lines.
start_monitor "$WORK/monitor.out" --loom-id "$ID" --count $((N_STATUS + N_AXES + N_RT)) --channel status,axes,rt \
  --timeout-s 30
lcm-logplayer --lcm-url="$REPLAY_URL" "$LOG" >/dev/null
rc=0
wait "$MONITOR_PID" || rc=$?
cat "$WORK/monitor.out.err" >&2
[ "$rc" -eq 0 ] || fail "loom-monitor exit $rc: fewer messages came back from the log than were published"

grep "^loom=$ID " "$WORK/monitor.out" >"$WORK/status.lines" || true
got=$(wc -l <"$WORK/status.lines")
[ "$got" -eq "$N_STATUS" ] || fail "replayed $got STATUS lines, published $N_STATUS"
check_rows "$WORK/status.lines" "$ROWS"

# The sequencer states appear in row-cycle order: shed → pick → beat_sweep → row_end, repeating.
states=$(sed -n 's/.* state=\([^ ]*\) .*/\1/p' "$WORK/status.lines" | uniq | tr '\n' ' ')
want=""
for _ in $(seq 1 "$ROWS"); do want+="shed pick beat_sweep row_end "; done
want+="shed "
[ "$states" = "$want" ] || fail "state order '$states', expected '$want'"

# AXES and RT came through too, every one of them.
n_axes=$(grep -c "^axes loom=$ID " "$WORK/monitor.out" || true)
n_rt=$(grep -c "^rt loom=$ID " "$WORK/monitor.out" || true)
[ "$n_axes" -eq "$N_AXES" ] || fail "AXES lines $n_axes, published $N_AXES"
[ "$n_rt" -eq "$N_RT" ] || fail "RT lines $n_rt, published $N_RT"
grep -q " | beat_crank pos=.* | carriage pos=.* | helix pos=" "$WORK/monitor.out" || fail "AXES lines lack the three axes"

echo "PASS: lcm-logger recorded $N_STATUS STATUS, lcm-logplayer replayed them in order into loom-monitor" \
  "($n_axes AXES, $n_rt RT lines)"

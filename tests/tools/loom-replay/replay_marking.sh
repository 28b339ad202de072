#!/usr/bin/env bash
# A recording replayed onto the live group never passes for the live loom in loom-monitor: a run of loom
# R is recorded (file://), and seconds later, while loom R publishes live on a group, the recording is
# replayed onto that same group (the mistake the README's old instructions invited). loom-monitor
# --replay-after-s 2 must print every replayed STATUS marked replayed=1 and every live one unmarked —
# as many of each as were published — and its event view must keep two histories: the live rows in
# order, the replayed ones under "REPLAY". And tools/loom-replay refuses the live group and replays onto
# its own group by default.
# Usage: replay_marking.sh <loom-monitor> <telemetry_feed> <tools/loom-replay>
MONITOR=$1
FEED=$2
REPLAY=$3
source "$(dirname "$0")/../../telemetry/lcm_script_lib.sh"

ID="marked$$"
REC="$WORK/old.lcmlog"
OLD=$("$FEED" --lcm-url "file://$REC?mode=w" --loom-id "$ID" --rows 2 --tick-us 0 --max-rate 0)
N_OLD=$(sed -n 's/.* status=\([0-9]*\).*/\1/p' <<<"$OLD")
[ "${N_OLD:-0}" -gt 0 ] || fail "recording has no STATUS: $OLD"
sleep 3  # the recording is now older than --replay-after-s 2

# The "live" loom publishes on $URL while the recording is replayed onto the same $URL.
"$MONITOR" --lcm-url "$URL" --loom-id "$ID" --channel status --replay-after-s 2 --timeout-s 40 \
  >"$WORK/raw" 2>"$WORK/raw.err" &
RAW_PID=$!
"$MONITOR" --lcm-url "$URL" --loom-id "$ID" --replay-after-s 2 --status-every-s 0 --timeout-s 40 \
  >"$WORK/view" 2>"$WORK/view.err" &
VIEW_PID=$!
PIDS+=("$RAW_PID" "$VIEW_PID")
for _ in $(seq 1 100); do
  grep -q listening "$WORK/raw.err" 2>/dev/null && grep -q listening "$WORK/view.err" 2>/dev/null && break
  sleep 0.05
done
lcm-logplayer --lcm-url="$URL" --speed=4 "$REC" >/dev/null &
PLAYER=$!
LIVE=$("$FEED" --lcm-url "$URL" --loom-id "$ID" --rows 2 --tick-us 200) || fail "live feed failed: $LIVE"
wait "$PLAYER" || fail "lcm-logplayer failed"
N_LIVE=$(sed -n 's/.* status=\([0-9]*\).*/\1/p' <<<"$LIVE")
sleep 1
kill -INT "$RAW_PID" "$VIEW_PID" 2>/dev/null || true
wait "$RAW_PID" "$VIEW_PID" 2>/dev/null || true

marked=$(grep -c ' replayed=1 recorded_s_ago=' "$WORK/raw" || true)
unmarked=$(grep -vc ' replayed=1' "$WORK/raw" || true)
[ "$marked" -eq "$N_OLD" ] || fail "$marked STATUS lines marked replayed, the recording holds $N_OLD"
[ "$unmarked" -eq "$N_LIVE" ] || fail "$unmarked unmarked STATUS lines, the live loom published $N_LIVE"
grep -q "replayed messages (recorded .* s ago) on this group" "$WORK/raw.err" || fail "no warning on stderr"
# The live history alone is a clean run: rows 0..2 in order (the replay did not interleave into it).
grep -v ' replayed=1' "$WORK/raw" >"$WORK/live.lines"
check_rows "$WORK/live.lines" 2
grep ' replayed=1' "$WORK/raw" | sed 's/ replayed=1 .*//' >"$WORK/old.lines"
check_rows "$WORK/old.lines" 2
# The event view: replayed lines are marked, live lines are not, and each history has its own rows.
grep -q "^REPLAY recorded [0-9]* s ago: " "$WORK/view" || fail "the event view does not mark replayed lines"
grep -v "^REPLAY" "$WORK/view" | grep -q "$ID" || fail "the event view lost the live loom"

# loom-replay: never the live group; its own group by default.
rc=0
"$REPLAY" "$REC" --onto 'udpm://239.255.76.67:7667?ttl=0' 2>"$WORK/refuse" || rc=$?
[ "$rc" -eq 2 ] && grep -q "is the live group" "$WORK/refuse" || fail "loom-replay replayed onto the live group (exit $rc)"
"$MONITOR" --lcm-url 'udpm://239.255.76.67:7668?ttl=0' --loom-id "$ID" --channel status --count "$N_OLD" \
  --timeout-s 30 >"$WORK/default" 2>"$WORK/default.err" &
DEF_PID=$!
PIDS+=("$DEF_PID")
for _ in $(seq 1 100); do grep -q listening "$WORK/default.err" 2>/dev/null && break; sleep 0.05; done
"$REPLAY" "$REC" --speed 4 2>/dev/null || fail "loom-replay failed"
wait "$DEF_PID" || fail "loom-replay's default group did not carry the recording: $(cat "$WORK/default.err")"

echo "PASS: $N_OLD replayed STATUS marked and $N_LIVE live unmarked on one group, each history in order;" \
  "loom-replay refuses the live group and replays onto its own"

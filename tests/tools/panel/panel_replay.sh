#!/usr/bin/env bash
# A recording replayed onto the live group never mixes with the live loom in loom-panel (issue 22, item 2):
# a 3-row run of loom R is recorded (file://); seconds later, while loom R weaves 2 rows live on a group,
# the recording is replayed onto that same group, and the live loom's picture is sampled meanwhile. With --replay-after-s 2 the panel must show the live
# loom R (2 rows, not marked) and, apart from it, R~replay (3 rows, marked REPLAY, recorded >= 2 s ago,
# no controls, no command accepted), and serve R~replay's page. Without the fix the replay's older ticks
# reset the live loom's picture and no R~replay existed.
# Usage: panel_replay.sh <loom-panel> <telemetry_feed>
set -euo pipefail
PANEL=$1
FEED=$2
fail() { echo "FAIL: $*" >&2; for f in "$WORK"/*.err; do echo "--- $f" >&2; tail -15 "$f" >&2; done; exit 1; }
command -v lcm-logplayer >/dev/null || { echo "SKIP: lcm-logplayer not found (liblcm-bin)"; exit 77; }
. "$(dirname "$0")/browser_lib.sh"  # panel_up (no browser needed here)
WORK=$(mktemp -d "${TMPDIR:-/tmp}/loom_panel_replay.XXXXXX")
PIDS=()
cleanup() {
  for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
  rm -rf "$WORK"
}
trap cleanup EXIT

PORT=$((20000 + ($$ * 11) % 20000))
URL="udpm://239.255.76.67:${PORT}?ttl=0"
ID="replay$$"
REC="$WORK/old.lcmlog"
"$FEED" --lcm-url "file://$REC?mode=w" --loom-id "$ID" --rows 3 --tick-us 2000 --max-rate 0 >/dev/null
sleep 3  # the recording is now older than --replay-after-s 2

panel_up panel.err --lcm-url "$URL" --replay-after-s 2 --control-dir "$WORK"
BASE=$PANEL_BASE

get() { curl -s -m 5 "$BASE$1"; }
json() {  # json PATH EXPR: a field of a JSON reply, by python
  get "$1" | python3 -c "import json,sys; d=json.load(sys.stdin); print($2)"
}
# The live loom (about 4 s: 190 ticks of 20 ms) and the replay (about 2.3 s: the 0.6 s recording at a
# quarter speed) publish at once; the live loom's picture is sampled every 50 ms meanwhile.
"$FEED" --lcm-url "$URL" --loom-id "$ID" --rows 2 --tick-us 20000 >"$WORK/live.out" 2>&1 &
LIVE=$!
sleep 0.3
lcm-logplayer --lcm-url="$URL" --speed=0.25 "$REC" >/dev/null &
PLAYER=$!
: >"$WORK/live.samples"
# (raw replies, one a line, parsed once afterwards: a python per sample took ~0.6 s on a loaded host and left
# too few samples)
while kill -0 "$LIVE" 2>/dev/null; do
  { get "/api/loom/$ID"; echo; } >>"$WORK/live.json" 2>/dev/null || true
  sleep 0.05
done
python3 - "$WORK/live.json" >"$WORK/live.samples" <<'PY'
import json, sys
for line in open(sys.argv[1]):
    try:
        d = json.loads(line)
    except ValueError:
        continue
    if d.get("status"):
        print(d["status"]["tick"], d["status"]["rows_done"])
PY
wait "$LIVE" || fail "live feed failed: $(cat "$WORK/live.out")"
wait "$PLAYER" || fail "lcm-logplayer failed"
sleep 0.5
[[ $(json "/api/loom/$ID" 'd["replay"]') == False ]] || fail "the live loom is marked replay: $(get "/api/loom/$ID")"
[[ $(json "/api/loom/$ID" 'd["status"]["rows_done"]') == 2 ]] ||
  fail "the live loom shows $(json "/api/loom/$ID" 'd["status"]["rows_done"]') rows, it wove 2 (the replay mixed in)"
# While both published, the live loom's picture only ever moved forward and never showed the replay's row 3.
python3 - "$WORK/live.samples" <<'PY' || fail "the live loom's picture mixed with the replay: $(tr '\n' ' ' <"$WORK/live.samples")"
import sys
ticks, rows = [], []
for line in open(sys.argv[1]):
    t, r = line.split()
    ticks.append(int(t)); rows.append(int(r))
assert len(ticks) >= 10, f"only {len(ticks)} samples"
assert all(a <= b for a, b in zip(ticks, ticks[1:])), "tick went backwards"
assert max(rows) <= 2, "rows_done above the live run's 2"
PY
[[ $(json "/api/loom/$ID~replay" 'd["replay"]') == True ]] || fail "no replay kept apart: $(get "/api/loom/$ID~replay")"
[[ $(json "/api/loom/$ID~replay" 'd["loom"]') == "$ID" ]] || fail "the replay does not name its loom"
[[ $(json "/api/loom/$ID~replay" 'd["status"]["rows_done"]') == 3 ]] || fail "the replay shows the wrong rows"
[[ $(json "/api/loom/$ID~replay" 'int(d["recorded_s_ago"] >= 2)') == 1 ]] || fail "recorded_s_ago below 2 s"
[[ $(json "/api/loom/$ID~replay" 'd["controls"]') == False ]] || fail "a replay offers controls"
[[ $(json "/api/hall" '" ".join(l["id"] + ":" + str(l["replay"]) for l in d["looms"])') == "$ID:False $ID~replay:True" ]] ||
  fail "the hall: $(get /api/hall)"
[[ $(curl -s -m 5 -o /dev/null -w '%{http_code}' "$BASE/loom/$ID~replay") == 200 ]] || fail "the replay's page is not served"
[[ $(curl -s -m 5 -o /dev/null -w '%{http_code}' -X POST -H 'X-Loom-Panel: 1' -d '' "$BASE/api/loom/$ID~replay/ctl/pause") == 404 ]] ||
  fail "a command on a replay was not refused"
[[ $(curl -s -m 5 -o /dev/null -w '%{http_code}' "$BASE/events?loom=$ID~bad") == 400 ]] || fail "a bad loom id in /events accepted"
kill -0 "$PANEL_PID" || fail "loom-panel died"
echo "PASS: live $ID 2 rows unmarked, $ID~replay 3 rows marked REPLAY (recorded $(json "/api/loom/$ID~replay" 'round(d["recorded_s_ago"])') s ago), no controls"

#!/usr/bin/env bash
# The panel shows the loom's persisted fault history after a restart (issue 22, item 7): serve weaves
# into a drive fault (scene) and is stopped; serve and a fresh panel start again — the panel never heard
# the fault on LCM — and GET /api/loom/<id>/history (serve's faults.log through its control socket)
# holds the fault, the start command and who gave it, with UTC times; headless Chromium shows them in the
# page's "Fault history" table with wall-clock times (skipped without chromium/node). A read-only panel
# (no --control-dir) answers 404 saying why. The same page plots the scope strip of the first axis and,
# picked from its list, of the carriage (units, no scientific notation). Writes <out>/loom_panel_history.png.
# The row report (rows.csv) and the last minutes as an lcmlog (read back by loom-monitor) are downloaded.
# Usage: panel_history.sh <loomctl> <loom-panel> <drive_fault scene> <out dir> <loom-monitor>
set -euo pipefail
LOOMCTL=$1
PANEL=$2
SCENE=$3
OUT=$4
MONITOR=$5
WORK=$(mktemp -d "${TMPDIR:-/tmp}/loom_panel_history.XXXXXX")
PIDS=()
fail() { echo "FAIL: $*" >&2; for f in "$WORK"/*.log; do echo "--- $f" >&2; tail -15 "$f" >&2; done; exit 1; }
cleanup() {
  for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${PIDS[@]}"; do wait "$p" 2>/dev/null || true; done
  rm -rf "$WORK"
}
trap cleanup EXIT
mkdir -p "$OUT" "$WORK/run"
PORT=$((20000 + ($$ * 17) % 20000))
URL="udpm://239.255.76.67:${PORT}?ttl=0"
ID="hist$$"
SOCK="$WORK/run/$ID.sock"
ctl() { "$LOOMCTL" ctl --socket "$SOCK" "$@"; }
field() { ctl status | tr ' ' '\n' | sed -n "s/^$1=//p"; }
wait_for() {
  for _ in $(seq 1 $(($3 * 20))); do [[ $(field "$1" 2>/dev/null) == "$2" ]] && return 0; sleep 0.05; done
  fail "waited $3 s for $1=$2: $(ctl status 2>&1)"
}
. "$(dirname "$0")/browser_lib.sh"  # panel_up, panel_serve_up; have_browser for the browser part
start_serve() {  # start_serve LOG [args]; sets SERVE
  local log=$1; shift
  panel_serve_up "$SOCK" "$log" --state-dir "$WORK/state" --loom-id "$ID" --lcm-url "$URL" --pace 4 "$@"
  SERVE=$SERVE_PID
}
start_panel() {  # start_panel LOG [args]; sets BASE
  local log=$1; shift
  panel_up "$log" --lcm-url "$URL" "$@"
  BASE=$PANEL_BASE
}

start_serve serve1.log --scene "$SCENE"
ctl start >/dev/null
wait_for state fault 60
kill -TERM "$SERVE"; wait "$SERVE" || true

start_serve serve2.log
# A restart is no reset: the fault is latched again until it is acknowledged at the loom (before this
# panel starts, so it never hears the fault).
wait_for state fault 10
ctl ack >/dev/null || fail "ack refused after the restart: $(ctl status)"
wait_for state idle 30
start_panel panel.log --control-dir "$WORK/run"
json() { curl -s -m 5 "$BASE$1" | python3 -c "import json,sys; d=json.load(sys.stdin); print($2)"; }
# (the ack's audit line and its record are written by two threads: either comes first)
[[ $(json "/api/loom/$ID/history" '" ".join(l.get("kind","?") + ":" + l.get("name","?") for l in d["lines"][:2]) + " " + " ".join(sorted(l.get("kind","?") + ":" + l.get("name","?") for l in d["lines"][2:]))') == \
  "command:start fault:drive_fault ack:drive_fault command:ack" ]] || fail "history: $(curl -s "$BASE/api/loom/$ID/history")"
[[ $(json "/api/loom/$ID/history" 'd["lines"][1]["time"]') =~ ^[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9:]{8}Z$ ]] ||
  fail "no UTC time on the fault line"
json "/api/loom/$ID/history" 'd["lines"][0]["detail"]' | grep -q "by local user .*: ok start" ||
  fail "the start line does not say who gave it"
json "/api/loom/$ID/history" 'd["lines"][1]["detail"]' | grep -q "axis=carriage" || fail "the fault line lacks its axis"

# The download: the whole faults.log, as `ctl faults` gives it, as an attachment.
curl -s -m 5 -D "$WORK/dl.headers" -o "$WORK/dl.log" "$BASE/api/loom/$ID/faults.log"
grep -qi "^content-disposition: attachment; filename=\"$ID-faults.log\"" "$WORK/dl.headers" || fail "faults.log is not offered as a file"
cmp -s "$WORK/dl.log" <(ctl faults) || fail "the download differs from ctl faults"
ctl start >/dev/null  # the axes move while the browser looks at the scope strip
# The row report: once a row is woven (heard by this panel), it is in rows.csv, offered as a file.
for _ in $(seq 1 200); do (( $(curl -s -m 2 "$BASE/api/loom/$ID/rows.csv" | wc -l) >= 2 )) && break; sleep 0.1; done
curl -s -m 5 -D "$WORK/rows.headers" -o "$WORK/rows.csv" "$BASE/api/loom/$ID/rows.csv"
grep -qi "^content-disposition: attachment; filename=\"$ID-rows.csv\"" "$WORK/rows.headers" || fail "rows.csv is not offered as a file"
head -1 "$WORK/rows.csv" | grep -q '^utc,loop_time_s,row,row_s,' || fail "rows.csv header: $(head -1 "$WORK/rows.csv")"
sed -n 2p "$WORK/rows.csv" | grep -Eq '^[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9:]{8}Z,[0-9.]+,[0-9]+,' || fail "rows.csv line: $(sed -n 2p "$WORK/rows.csv")"
grep -Eq '[0-9][eE][-+][0-9]' "$WORK/rows.csv" && fail "scientific notation in rows.csv"
# The last minutes as an lcmlog: read back by loom-monitor through LCM's file provider (its own reader).
curl -s -m 5 -D "$WORK/lcmlog.headers" -o "$WORK/last.lcmlog" "$BASE/api/loom/$ID/last.lcmlog"
grep -qi "^content-disposition: attachment; filename=\"$ID-last.lcmlog\"" "$WORK/lcmlog.headers" || fail "last.lcmlog not offered as a file"
"$MONITOR" --lcm-url "file://$WORK/last.lcmlog?mode=r" --loom-id "$ID" --channel status \
  --timeout-s 10 >"$WORK/monitor.out" 2>"$WORK/monitor.log" || true
grep -q "^loom=$ID .*state=" "$WORK/monitor.out" || fail "the downloaded lcmlog holds no STATUS of $ID: $(head -3 "$WORK/monitor.out")"
lcmlog_status=$(grep -c "^loom=$ID " "$WORK/monitor.out")
if have_browser >/dev/null; then
  for _ in $(seq 1 100); do curl -s -m 2 "$BASE/api/loom/$ID" | grep -q '"status":{' && break; sleep 0.1; done
  node --experimental-websocket "$(dirname "$0")/panel_history.mjs" "$CHROMIUM" "$BASE" "$ID" \
    "$OUT/loom_panel_history.png" 70 2>&1 | grep -v ExperimentalWarning | grep -v "node --trace-warnings" ||
    fail "browser check failed"
  [[ ${PIPESTATUS[0]} == 0 ]] || fail "browser check failed"
else
  echo "browser part skipped (no chromium or node)"
fi

start_panel panel_ro.log
[[ $(curl -s -m 5 -o "$WORK/ro" -w '%{http_code}' "$BASE/api/loom/$ID/history") == 404 ]] || fail "a read-only panel read the history"
[[ $(curl -s -m 5 -o /dev/null -w '%{http_code}' "$BASE/api/loom/$ID/faults.log") == 404 ]] || fail "a read-only panel gave faults.log"
grep -q "control socket" "$WORK/ro" || fail "the read-only refusal does not say why: $(cat "$WORK/ro")"
echo "panel_history: ok (the fault and the start command from before the restart, shown by a fresh panel;" \
  "rows.csv; last.lcmlog with $lcmlog_status STATUS messages)"

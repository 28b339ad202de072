# Shared shell steps for the telemetry script tests: a private udpm URL, starting lcm-logger and
# proving it is recording before the real run starts, and replaying a log into loom-monitor.
# Sourced, not run. Callers set FEED (telemetry_feed) and MONITOR (loom-monitor) first.

set -euo pipefail

fail() { echo "FAIL: $*" >&2; exit 1; }

for tool in lcm-logger lcm-logplayer; do
  command -v "$tool" >/dev/null || fail "$tool not found (Debian package liblcm-bin; tools/ installs it)"
done

WORK=$(mktemp -d "${TMPDIR:-/tmp}/loom_lcm_script.XXXXXX")
PIDS=()
cleanup() {
  for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
  rm -rf "$WORK"
}
trap cleanup EXIT

# A port and loom id of our own: parallel tests and other users of the default group stay apart.
PORT=$((20000 + $$ % 20000))
URL="udpm://239.255.76.67:${PORT}?ttl=0"
REPLAY_URL="udpm://239.255.76.67:$((PORT + 1))?ttl=0"
LOG="$WORK/run.lcmlog"

# start_logger: lcm-logger on $URL into $LOG. Returns once a probe message (a one-row scripted run on a
# separate loom id) has reached the log file, so the real run cannot start before the logger listens.
start_logger() {
  lcm-logger -q -f --flush-interval=20 --lcm-url="$URL" "$LOG" &
  LOGGER_PID=$!
  PIDS+=("$LOGGER_PID")
  for _ in $(seq 1 50); do
    "$FEED" --lcm-url "$URL" --loom-id "probe$$" --rows 1 --tick-us 0 >/dev/null
    sleep 0.1
    if [ -s "$LOG" ]; then return 0; fi
    kill -0 "$LOGGER_PID" 2>/dev/null || fail "lcm-logger exited early (multicast route? see reference/lcm.md)"
  done
  fail "lcm-logger recorded nothing on $URL within 5 s"
}

# stop_logger: SIGINT, as a technician would; lcm-logger flushes and closes the log.
stop_logger() {
  sleep 0.3  # let the last datagrams reach the logger before it stops
  kill -INT "$LOGGER_PID"
  wait "$LOGGER_PID" || true
  [ -s "$LOG" ] || fail "lcm-logger left an empty log"
}

# start_monitor <out-file> <args...>: loom-monitor on $REPLAY_URL in the background; returns once it
# has subscribed (it says so on stderr).
start_monitor() {
  local out=$1; shift
  "$MONITOR" --lcm-url "$REPLAY_URL" "$@" >"$out" 2>"$out.err" &
  MONITOR_PID=$!
  PIDS+=("$MONITOR_PID")
  for _ in $(seq 1 100); do
    grep -q "listening" "$out.err" 2>/dev/null && return 0
    kill -0 "$MONITOR_PID" 2>/dev/null || { cat "$out.err" >&2; fail "loom-monitor exited before listening"; }
    sleep 0.05
  done
  fail "loom-monitor did not start listening within 5 s"
}

# check_rows <status-lines-file> <final-row>: completed rows (done=) start at 0, never go back, rise by
# at most one per line, and end at <final-row>; the row in progress (row=) is always done + 1 except
# once the run is done.
check_rows() {
  awk -v final="$2" '
    { for (i = 1; i <= NF; i++) { if ($i ~ /^done=/) r = substr($i, 6) + 0; if ($i ~ /^row=/) p = substr($i, 5) + 0;
                                  if ($i ~ /^state=/) st = substr($i, 7) } }
    st != "done" && p != r + 1 { print "row in progress " p " with " r " done at line " NR; bad = 1 }
    NR == 1 && r != 0 { print "first row " r " is not 0"; bad = 1 }
    NR > 1 && (r < prev || r > prev + 1) { print "row went " prev " -> " r " at line " NR; bad = 1 }
    { prev = r }
    END { if (NR == 0) { print "no STATUS lines"; bad = 1 }
          else if (prev != final) { print "last row " prev ", expected " final; bad = 1 }
          exit bad }' "$1" || { cat "$1" >&2; fail "row sequence wrong in $1"; }
}

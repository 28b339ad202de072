#!/usr/bin/env bash
# loom-monitor's command line: bad arguments exit 2 naming the option, a timeout with nothing exits
# 1, and a log read straight through LCM's file:// provider prints one line per STATUS in order.
# No network: the log is written by the real publisher through file://...?mode=w.
# Usage: monitor_cli.sh <loom-monitor> <telemetry_feed>
set -euo pipefail
MONITOR=$1
FEED=$2
fail() { echo "FAIL: $*" >&2; exit 1; }
WORK=$(mktemp -d "${TMPDIR:-/tmp}/loom_monitor_cli.XXXXXX")
trap 'rm -rf "$WORK"' EXIT

# expect <code> <stderr must contain> <args...>
expect() {
  local want=$1 text=$2; shift 2
  local rc=0
  "$MONITOR" "$@" >"$WORK/out" 2>"$WORK/err" || rc=$?
  [ "$rc" -eq "$want" ] || fail "loom-monitor $* exited $rc, expected $want: $(cat "$WORK/err")"
  grep -qF -- "$text" "$WORK/err" || fail "loom-monitor $* did not say '$text': $(cat "$WORK/err")"
}
expect 2 "--count -1" --count -1
expect 2 "--count" --count many
expect 2 "--timeout-s" --timeout-s nan
expect 2 "--timeout-s" --timeout-s -3
expect 2 "'a.b'" --loom-id a.b
expect 2 "'LOOM..X'" --channel-prefix LOOM..X
expect 2 "'nosuch://x'" --lcm-url nosuch://x
expect 2 "stray" stray
expect 2 "--channel 'beats'" --channel beats
expect 2 "--status-every-s" --status-every-s -1
"$MONITOR" --help >/dev/null || fail "--help did not exit 0"

LOG="$WORK/run.lcmlog"
FEED_OUT=$("$FEED" --lcm-url "file://$LOG?mode=w" --loom-id L1 --rows 2 --tick-us 0 --max-rate 0)
N=$(sed -n 's/.* status=\([0-9]*\).*/\1/p' <<<"$FEED_OUT")
[ "${N:-0}" -gt 0 ] || fail "feed wrote no STATUS: $FEED_OUT"

# Another loom's id sees nothing: exit 1 at the end of the log.
expect 1 "no message" --lcm-url "file://$LOG?mode=r" --loom-id L2 --timeout-s 20
# The log's own loom: exactly N lines, the first at row 0, the last at row 2; --count N exits 0.
"$MONITOR" --lcm-url "file://$LOG?mode=r" --loom-id L1 --channel status --count "$N" --timeout-s 20 >"$WORK/lines" 2>"$WORK/err" ||
  fail "reading the log with --count $N failed: $(cat "$WORK/err")"
[ "$(grep -c '^loom=L1 ' "$WORK/lines")" -eq "$N" ] || fail "expected $N STATUS lines"
head -1 "$WORK/lines" | grep -q " state=shed row=1 done=0 pick=0 beat=0 fault=none fault_code=0x0000$" ||
  fail "first line: $(head -1 "$WORK/lines")"
tail -1 "$WORK/lines" | grep -q " state=shed row=3 done=2 " || fail "last line: $(tail -1 "$WORK/lines")"
# Asking for more than the log holds: exit 1, saying how many came.
expect 1 "of $((N + 1)) lines" --lcm-url "file://$LOG?mode=r" --channel status --count $((N + 1)) --timeout-s 20
# The event view of the same log: one line per state change (the script's states) and compact status
# lines at most once per second of loop time.
"$MONITOR" --lcm-url "file://$LOG?mode=r" --loom-id L1 --timeout-s 20 >"$WORK/view" 2>"$WORK/err" ||
  fail "event view of the log failed: $(cat "$WORK/err")"
grep -q "^L1 t=0.000s state - -> shed, row 1$" "$WORK/view" || fail "event view: first line $(head -1 "$WORK/view")"
n_changes=$(grep -c " state " "$WORK/view")
[ "$n_changes" -eq 9 ] || fail "event view: $n_changes state changes, expected 9 (shed pick beat_sweep row_end x2, shed)"
echo "PASS: loom-monitor CLI errors exit 2, empty runs exit 1, $N STATUS lines read from a log"

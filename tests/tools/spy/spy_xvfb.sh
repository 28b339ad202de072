#!/usr/bin/env bash
# lcm-spy in one command: loom-spy decodes every loom channel. (1) A faulting run (drive_fault scene:
# one row, then a drive fault) is logged through LCM's file provider; LoomSpyCheck decodes every
# message of the log by fingerprint with loomlcm.jar, as lcm-spy does, and every channel kind must be
# there. (2) loom-spy runs under Xvfb while lcm-logplayer replays the log to it; a screenshot of the
# screen is written to <out>/loom_spy.png. Exit 77 (skip) without java, xvfb-run or imagemagick.
# Usage: spy_xvfb.sh <loomctl> <loom-spy> <loomlcm.jar> <lcm.jar> <scene> <out dir>
set -euo pipefail
LOOMCTL=$1 SPY=$2 TYPES=$3 LCMJAR=$4 SCENE=$5 OUT=$6
fail() { echo "FAIL: $*" >&2; exit 1; }
for t in java javac xvfb-run import lcm-logplayer; do
  command -v "$t" >/dev/null || { echo "SKIP: $t not installed (tools/deps.sh installs it)"; exit 77; }
done
mkdir -p "$OUT"
WORK=$(mktemp -d "${TMPDIR:-/tmp}/loom_spy.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
LOG="$WORK/run.lcmlog"

rc=0
"$LOOMCTL" weave --scene "$SCENE" --rows 3 --quiet --lcm-url "file://$LOG?mode=w" >"$WORK/weave.out" 2>&1 || rc=$?
[ "$rc" -eq 3 ] || { cat "$WORK/weave.out" >&2; fail "expected the drive_fault scene to end in a fault (exit 3), got $rc"; }

javac -nowarn -cp "$LCMJAR" -d "$WORK" "$(dirname "$0")/LoomSpyCheck.java"
java -cp "$LCMJAR:$TYPES:$WORK" LoomSpyCheck "$TYPES" "$LOG" STATUS AXES RT BEAT ROW FAULT >"$WORK/decoded" ||
  { cat "$WORK/decoded"; fail "loomlcm.jar does not decode every channel"; }
cat "$WORK/decoded"

# The viewer itself, on a private multicast port, fed the log.
PORT=$((20000 + ($$ * 13) % 20000))
URL="udpm://239.255.76.67:${PORT}?ttl=0"
cat >"$WORK/screen.sh" <<INNER
set -e
"$SPY" --lcm-url "$URL" >"$WORK/spy.out" 2>&1 &
spy=\$!
sleep 4
lcm-logplayer --speed=4 --lcm-url="$URL" "$LOG" >/dev/null 2>&1 || true
sleep 1
kill -0 \$spy || { cat "$WORK/spy.out"; exit 1; }
import -window root "$OUT/loom_spy.png"
kill \$spy
INNER
timeout 50 xvfb-run -a -s "-screen 0 1280x800x24" bash "$WORK/screen.sh" || { cat "$WORK/spy.out" >&2; fail "loom-spy did not run under Xvfb"; }
[ -s "$OUT/loom_spy.png" ] || fail "no screenshot"
echo "PASS: loomlcm.jar decodes $(wc -l <"$WORK/decoded") channels; loom-spy ran, screenshot $OUT/loom_spy.png"

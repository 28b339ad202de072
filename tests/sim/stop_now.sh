#!/usr/bin/env bash
# SIGINT/SIGTERM once stops at the end of the row; a second one stops at once: every axis quick-stops,
# the run ends in the named fault stop_requested (exit 3), and the counters on disk are kept.
set -euo pipefail
loomctl=$1
work=$(mktemp -d)
trap 'kill %1 2>/dev/null || true; rm -rf "$work"' EXIT
"$loomctl" weave --rows 5 --realtime --pace 4 --no-telemetry --quiet --counters "$work/c.json" >"$work/out" 2>&1 &
pid=$!
for _ in $(seq 1 200); do grep -q '^row 1/5' "$work/out" && break; sleep 0.05; done
grep -q '^row 1/5' "$work/out" || { echo "FAIL: row 1 never finished"; cat "$work/out"; exit 1; }
# Row 2 starts only once row 1's counters are on disk; a signal before that lands between rows, where
# stopping at the row end is stopping at once. Signal inside row 2 (about 1.9 s long at 4x).
for _ in $(seq 1 200); do grep -q '"rows":1,' "$work/c.json" 2>/dev/null && break; sleep 0.05; done
sleep 0.3
kill -INT "$pid"
sleep 0.2
kill -INT "$pid"
set +e
wait "$pid"
rc=$?
set -e
cat "$work/out"
[[ $rc == 3 ]] || { echo "FAIL: exit $rc, expected 3"; exit 1; }
grep -q '^FAULT stop_requested' "$work/out" || { echo "FAIL: no stop_requested fault"; exit 1; }
[[ $(grep -c '^row ' "$work/out") == 1 ]] || { echo "FAIL: the row in progress was finished, not stopped"; exit 1; }
grep -q '"rows":1,' "$work/c.json" || { echo "FAIL: counters lost: $(cat "$work/c.json")"; exit 1; }
echo "PASS: a second signal stops at once, counters kept"

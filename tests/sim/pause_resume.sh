#!/usr/bin/env bash
# The operator pauses the loom (SIGUSR1) during row 2 and resumes it (SIGUSR2): it holds at the next
# safe point — after the row in progress, before a shed change — weaves nothing while paused, and then
# finishes the run with every row and pick counted once.
set -euo pipefail
loomctl=$1
work=$(mktemp -d)
trap 'kill %1 2>/dev/null || true; rm -rf "$work"' EXIT
printf 'extends = "default"\n[loom]\nwidth_m = 0.4\n' >"$work/loom.toml"
"$loomctl" weave --config "$work/loom.toml" --rows 4 --realtime --pace 8 --no-telemetry --quiet >"$work/out" 2>&1 &
pid=$!
for _ in $(seq 1 200); do grep -q '^row 1/4' "$work/out" && break; sleep 0.05; done
kill -USR1 "$pid"
for _ in $(seq 1 200); do grep -q '^paused' "$work/out" && break; sleep 0.05; done
grep -q '^paused after row 2, pick 2' "$work/out" || { echo "FAIL: no pause at the end of row 2"; cat "$work/out"; exit 1; }
rows_at_pause=$(grep -c '^row ' "$work/out")
sleep 1.5   # 12 s of loom time: three rows' worth if it were still weaving
[[ $(grep -c '^row ' "$work/out") == "$rows_at_pause" ]] || { echo "FAIL: rows woven while paused"; cat "$work/out"; exit 1; }
kill -USR2 "$pid"
wait "$pid" || { echo "FAIL: loomctl exited $?"; cat "$work/out"; exit 1; }
cat "$work/out"
grep -q '^resumed after row 2' "$work/out" || { echo "FAIL: resume not reported"; exit 1; }
grep -q 'woven 4 rows (total 4).*picks 4, beats 20' "$work/out" || { echo "FAIL: rows or picks lost or repeated"; exit 1; }
echo "PASS: paused at a safe point, held, resumed"

#!/usr/bin/env bash
# Power loss mid-row: loomctl (simulated loom, paced in real time ×4) is killed with SIGKILL at several
# points of the row cycle and restarted each time with the same counters file and the same simulated
# machine state. The rows and picks at the end must be exactly what was asked: nothing lost, nothing
# repeated, whatever phase the kill hit (shed change, pick, beat sweep, between rows).
set -euo pipefail
loomctl=$1
config=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
counters=$work/counters.json
state=$work/machine.state
rows_wanted=6
picks_per_row=2
kills=(0.15 0.3 0.45 0.6 0.75 0.9 1.05 1.2)  # wall seconds after each start (a row takes ~0.95 s at pace 4)

run() {  # run [kill_after_s]; prints loomctl's exit code
  local rows_done=0
  [[ -f $counters ]] && rows_done=$(grep -o '"rows":[0-9]*' "$counters" | cut -d: -f2)
  local left=$((rows_wanted - rows_done))
  ((left > 0)) || { echo done; return; }
  "$loomctl" weave --config "$config" --rows "$left" --counters "$counters" --sim-state "$state" \
    --realtime --pace 4 --no-telemetry --quiet >>"$work/log" 2>&1 &
  local pid=$!
  if [[ -n ${1:-} ]]; then
    sleep "$1"
    kill -KILL "$pid" 2>/dev/null || true
  fi
  local rc=0
  wait "$pid" || rc=$?
  echo "$rc"
}

killed=0
for t in "${kills[@]}"; do
  rc=$(run "$t")
  [[ $rc == done ]] && break
  [[ $rc == 137 ]] && killed=$((killed + 1))
  echo "cut power after ${t}s: exit $rc; counters now $(cat "$counters" 2>/dev/null || echo none)"
done
rc=$(run)
[[ $rc == done || $rc == 0 ]] || { echo "FAIL: final run exited $rc"; cat "$work/log"; exit 1; }
final=$(cat "$counters")
echo "final counters: $final after $killed power cuts"
rows=$(grep -o '"rows":[0-9]*' "$counters" | cut -d: -f2)
picks=$(grep -o '"picks":[0-9]*' "$counters" | cut -d: -f2)
in_row=$(grep -o '"picks_in_row":[0-9]*' "$counters" | cut -d: -f2)
((killed >= 5)) || { echo "FAIL: only $killed kills landed mid-run; the test proves nothing"; exit 1; }
[[ $rows == "$rows_wanted" ]] || { echo "FAIL: rows $rows, wanted $rows_wanted"; cat "$work/log"; exit 1; }
[[ $picks == $((rows_wanted * picks_per_row)) ]] || { echo "FAIL: picks $picks, wanted $((rows_wanted * picks_per_row)) (lost or repeated)"; cat "$work/log"; exit 1; }
[[ $in_row == 0 ]] || { echo "FAIL: picks_in_row $in_row after the last row"; exit 1; }
echo "PASS: $rows rows, $picks picks after $killed power cuts"

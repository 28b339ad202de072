#!/usr/bin/env bash
# A whole carpet in the simulator, as a carpet job: the six heads of the knotting loom tie a 1.2 × 1.8 m
# medium carpet (360 × 540 knots = 194,400), made here from a fixed formula, queued as a job (`loomctl job
# add`: the design once, 540 rows) and woven with `loomctl weave --state-dir` (serve's state: job queue,
# counters, magazines, production record, simulated machine) through at least CUTS power cuts (the scene's
# power_cut fault: SIGKILL at a tick drawn per run), knots slipping off every head (miss_probability) and
# small magazines (reloads on every head). Each restart resumes the job where the counters say. At the end
# the job is carpet_done, the carpet the simulator knotted — every row, across every run — equals the design
# knot for knot (each knot tied once, none missing, none doubled), the counters' tallies are the carpet's,
# and the job's production record (SQLite) has its 540 rows and machine states whose times add up to its
# wall time (±1 tick).
# Usage: whole_carpet.sh LOOMCTL CONFIG [CUTS] [SEED]   (SEED replays a run; printed at the start)
# Env: WHOLE_CARPET_ROWS (540) weaves a shorter carpet (a quick look, not the test); KEEP=1 keeps the work dir.
set -euo pipefail
loomctl=$(readlink -f "$1")
config=$(readlink -f "$2")
cuts_wanted=${3:-20}
seed=${4:-$(($(date +%s%N) % 1000000007))}
rows_wanted=${WHOLE_CARPET_ROWS:-540}
knots_per_row=360
echo "whole carpet: seed $seed (replay: $0 $1 $2 $cuts_wanted $seed)"
RANDOM=$((seed % 32768))
# A tmpfs when there is one: the counters are fsync'd at every knot, which on a disk (not on a board's
# SD card, where the machine time is the same) would make this a test of the disk.
base=/dev/shm
[[ -d $base && -w $base ]] || base=${TMPDIR:-/tmp}
work=$(mktemp -d "$base/whole_carpet.XXXXXX")
trap '[[ -n ${KEEP:-} ]] || rm -rf "$work"' EXIT
state=$work/state
counters=$state/counters.json
mkdir -p "$state"

# The design: 540 rows of 360 knots in the loom's three yarns, a field with a border, diagonal bands and a
# lozenge lattice, so that every head changes colour within its stripe on most rows.
awk -v rows="$rows_wanted" -v w="$knots_per_row" 'BEGIN {
  print "# whole_carpet.sh: " w " x " rows " knots (generated)"
  print "palette,R,#a52a2a"; print "palette,I,#f3ead6"; print "palette,B,#1f3a6e"
  for (r = 0; r < rows; ++r) {
    line = ""
    for (k = 0; k < w; ++k) {
      if (k < 6 || k >= w - 6 || r < 6 || r >= rows - 6) c = "B"
      else {
        dx = (k % 60) - 30; dy = (r % 60) - 30
        if (dx < 0) dx = -dx
        if (dy < 0) dy = -dy
        if (dx + dy < 12) c = "I"
        else if ((k + r) % 23 < 4) c = "B"
        else c = "R"
      }
      line = line (k ? "," : "") c
    }
    print line
  }
}' >"$work/carpet.csv"
# The knotting loom with that design and small magazines (150 knots a slot: a head reloads every few rows).
sed -e 's|^design = .*|design = "carpet.csv"|' "$config" >"$work/loom.toml"
grep -q '^design = "carpet.csv"' "$work/loom.toml" || { echo "FAIL: $config has no recipe.design line to replace"; exit 1; }
sed -i -e 's|^\[knotting\]$|[knotting]\nknots_per_slot = 150|' "$work/loom.toml"
grep -q '^knots_per_slot = 150' "$work/loom.toml" || { echo "FAIL: $config has no [knotting] table"; exit 1; }

# The job: the design once (its rows), yarn from the loom's magazines.
"$loomctl" job add "$work/carpet.csv" --config "$work/loom.toml" --state-dir "$state" >"$work/job.log" ||
  { echo "FAIL: job add: $(cat "$work/job.log")"; exit 1; }
"$loomctl" job list --state-dir "$state" | grep -q "^1 .*queued.* of $rows_wanted next" ||
  { echo "FAIL: the queued job: $("$loomctl" job list --state-dir "$state")"; exit 1; }

field() { grep -o "\"$1\": *[0-9]*" "$counters" 2>/dev/null | grep -o '[0-9]*$' || echo 0; }
rand30() { echo $(((RANDOM << 15) | RANDOM)); }

run() {  # run [cut_tick]; prints loomctl's exit code (137 when the power cut killed it) or "done"
  local left=$((rows_wanted - $(field rows)))
  ((left > 0)) || { echo done; return; }
  {
    printf 'name = "whole_carpet"\nseed = %s\neffects = ["ideal", "knotter"]\n' "$RANDOM"
    printf '[knotter]\nmiss_probability = 0.05\nweaver_s = 0.5\n'
    [[ -n ${1:-} ]] && printf '\n[[fault]]\nkind = "power_cut"\nat_tick = %s\n' "$1"
  } >"$work/scene.toml"
  local rc=0
  "$loomctl" weave --config "$work/loom.toml" --scene "$work/scene.toml" --state-dir "$state" \
    --no-telemetry --quiet --report "$work/report" >>"$work/log" 2>&1 || rc=$?
  echo "$rc"
}

start=$(date +%s)
# A row's time from the machine description, not a copied figure (a copied 56 s outlived the rows, which
# became faster, and a cut drawn past the carpet's end failed the test): loomctl check's estimate of a
# whole row of this loom and design, against an ideal plant. Misses and reloads only add to it; half of
# it is a floor no row goes under (shed, pick and beat alone are a fifth of it, and every knot a head
# ties is a whole knot cycle).
check=$("$loomctl" check --config "$work/loom.toml") || { echo "FAIL: loomctl check refused the test's loom"; exit 1; }
row_s=$(sed -n 's/.*about \([0-9.]*\) s per whole row.*/\1/p' <<<"$check" | head -1)
period_ms=$(sed -n 's/.*control period \([0-9.]*\) ms.*/\1/p' <<<"$check" | head -1)
[[ -n $row_s && -n $period_ms ]] || { echo "FAIL: loomctl check gave no row estimate: $check"; exit 1; }
ticks_per_row=$(awk -v s="$row_s" -v p="$period_ms" 'BEGIN { printf "%d", s * 1000 / p }')
fastest_row_ticks=$((ticks_per_row / 2))
echo "whole carpet: a row about $row_s s ($ticks_per_row ticks); cuts drawn within the rows left at $fastest_row_ticks ticks a row"
killed=0 mid_knot=0 runs=0 cut_ticks=0
while ((killed < cuts_wanted && runs < 3 * cuts_wanted)); do
  runs=$((runs + 1))
  # Spread the cuts over the carpet: each lands within twice the rows left per cut still wanted.
  left=$((rows_wanted - $(field rows)))
  # (Never beyond the rows left but one at the fastest row, so a cut always strikes before the carpet is done.)
  span=$((2 * ticks_per_row * (left / (cuts_wanted - killed + 1) + 1)))
  max_span=$((fastest_row_ticks * (left - 1)))
  ((span <= max_span)) || span=$max_span
  ((span > 0)) || span=1
  t=$((300 + $(rand30) % span))
  rc=$(run "$t")
  [[ $rc == done ]] && break
  if [[ $rc == 137 ]]; then
    killed=$((killed + 1))
    cut_ticks=$((cut_ticks + t))  # the power failed at that tick of the run: its machine time
    if (($(field knot_cycles_started) > 0 && $(field picks_in_row) == 0)); then mid_knot=$((mid_knot + 1)); fi
  else
    [[ $rc == 0 ]] || { echo "FAIL: run with a cut at tick $t exited $rc"; tail -20 "$work/log"; exit 1; }
  fi
done
((killed >= cuts_wanted)) || { echo "FAIL: only $killed power cuts in $runs runs (the carpet was done first)"; exit 1; }
rc=$(run)
[[ $rc == 0 || $rc == done ]] || { echo "FAIL: the final run exited $rc"; tail -20 "$work/log"; exit 1; }
wall=$(($(date +%s) - start))
line=$(grep "^carpet:" "$work/log" | tail -1)
echo "$line"
echo "counters: $(tr -d '\n ' <"$counters")"
[[ $line == *"equals the design knot for knot"* ]] || { echo "FAIL: the carpet is not the design"; tail -30 "$work/log"; exit 1; }
[[ $(field rows) == "$rows_wanted" ]] || { echo "FAIL: rows $(field rows), wanted $rows_wanted"; exit 1; }
[[ $line == *": $rows_wanted rows from production row 0 "* ]] || { echo "FAIL: the carpet compared is not all $rows_wanted rows: $line"; exit 1; }
knots_in_carpet=$(grep -oE '[0-9]+ knots \(' <<<"$line" | grep -oE '^[0-9]+')
((knots_in_carpet == rows_wanted * knots_per_row)) || { echo "FAIL: $knots_in_carpet knots in the carpet, not $((rows_wanted * knots_per_row))"; exit 1; }
counted=$(($(field knots) + $(field knots_by_hand)))
((counted == knots_in_carpet)) || { echo "FAIL: the counters count $counted knots (heads $(field knots), by hand $(field knots_by_hand)) in a carpet of $knots_in_carpet"; exit 1; }
# Every head missed (the weaver tied for it) and had a slot reloaded, as the loom asked.
for ((h = 1; h <= 6; h++)); do
  ties=$(grep -c "^weaver asked: .*(head $h) by hand" "$work/log" || true)
  reloads=$(grep -cE "^weaver asked: .*reload colour . into slot . of head $h( before|\$)" "$work/log" || true)
  echo "head $h: $ties knots tied by hand, $reloads reloads asked"
  ((ties > 0 && reloads > 0)) || { echo "FAIL: head $h had no hand tie or no reload"; exit 1; }
done
# The job: done, and its production record (SQLite) adds up: every state's time to the job's wall time
# (each state's time is whole ticks of the record's clock: a tick of slack, not a rounding of the sum).
grep -q "^carpet done: " "$work/log" || { echo "FAIL: no carpet done line"; tail -5 "$work/log"; exit 1; }
"$loomctl" job list --state-dir "$state" | grep -q "^1 .*carpet_done" ||
  { echo "FAIL: the job is not carpet_done: $("$loomctl" job list --state-dir "$state")"; exit 1; }
"$loomctl" report job 1 --state-dir "$state" --format json >"$work/record.json" ||
  { echo "FAIL: no production record for the job"; exit 1; }
python3 - "$work/record.json" "$rows_wanted" <<'PY' || { echo "FAIL: the job's record: $(head -c 2000 "$work/record.json")"; exit 1; }
import json, sys
r = json.load(open(sys.argv[1]))
rows = int(sys.argv[2])
states_ns = sum(v["ns"] for v in r["states"].values())
wall_ns = round(r["wall_s"] * 1e9)
tick_ns = 2_000_000
assert r["rows"] == {"recorded": rows, "last": rows}, r["rows"]
assert r["ended"], "the record has no end"
assert abs(states_ns - wall_ns) <= tick_ns, f"states {states_ns} ns, wall {wall_ns} ns"
assert r["knots"]["by_heads"] + r["knots"]["by_hand"] == rows * 360, r["knots"]
split = ", ".join("%s %.0f s" % (k, v["ns"] / 1e9) for k, v in r["states"].items() if v["ns"])
print("record: %d rows, wall %.3f s = %.3f s in states (%s); knots by heads %d, by hand %d"
      % (rows, r["wall_s"], states_ns / 1e9, split, r["knots"]["by_heads"], r["knots"]["by_hand"]))
PY
# Machine time: the runs that ended (their loop line) and the runs cut short (the tick the power failed at).
# (The period from the loops' own lines: machine seconds over ticks.)
machine_s=$(sed -n 's/^loop: \([0-9]*\) ticks (\([0-9.]*\) s machine time).*/\1 \2/p' "$work/log" |
  awk -v cut="$cut_ticks" '{ n += $1; s += $2 } END { printf "%.0f", s + (n > 0 ? cut * s / n : 0) }')
echo "PASS: $rows_wanted rows, $knots_in_carpet knots, each tied once; $killed power cuts ($mid_knot while a row was being knotted) in $((runs + 1)) runs"
echo "whole carpet: machine time ${machine_s} s ($(awk -v s="$machine_s" 'BEGIN { printf "%.1f", s / 3600 }') h), wall ${wall} s"

#!/usr/bin/env bash
# The kill campaign of the knotting heads: loomctl (simulated loom, virtual time) ties the narrow knotting
# loom's rows while a power_cut fault kills it (SIGKILL) at a tick drawn per run, again and again, each
# restart with the same counters file and the same simulated machine (whose carpet survives the cut, as a
# real one would). At least CUTS of the cuts must land while a row is being knotted (the counters say a
# knot cycle was started and no pick of the row happened). Then the loom weaves on to the end, and the
# carpet it knotted — across every cut — must equal the design knot for knot: no knot lost, none tied twice
# (a cycle cut mid-knot is checked by the weaver, never tied again by the loom).
# Usage: knot_power_cut.sh LOOMCTL CONFIG [CUTS] [SEED]
set -euo pipefail
loomctl=$1
config=$2
cuts_wanted=${3:-50}
seed=${4:-$(( $(date +%s%N) % 1000000007 ))}
echo "knot power-cut campaign: seed $seed (replay: $0 $loomctl $config $cuts_wanted $seed)"
RANDOM=$((seed % 32768))
work=$(mktemp -d)
trap '[[ -n ${KEEP:-} ]] || rm -rf "$work"' EXIT
counters=$work/counters.json
state=$work/machine.state
rows_wanted=6

field() { grep -o "\"$1\": *[0-9]*" "$counters" 2>/dev/null | grep -o '[0-9]*$' || echo 0; }

run() {  # run [cut_tick]; prints loomctl's exit code (137 when the power cut killed it) or "done"
  local left=$((rows_wanted - $(field rows)))
  ((left > 0)) || { echo done; return; }
  {
    printf 'name = "knot_power_cut"\nseed = %s\neffects = ["ideal", "knotter"]\n[knotter]\nmiss_probability = 0.05\nweaver_s = 0.5\n' "$RANDOM"
    [[ -n ${1:-} ]] && printf '\n[[fault]]\nkind = "power_cut"\nat_tick = %s\n' "$1"
  } >"$work/scene.toml"
  local rc=0
  "$loomctl" weave --config "$config" --scene "$work/scene.toml" --rows "$left" --counters "$counters" \
    --sim-state "$state" --no-telemetry --quiet --report "$work/report" >>"$work/log" 2>&1 || rc=$?
  echo "$rc"
}

mid_knot=0 killed=0 runs=0
while ((mid_knot < cuts_wanted && runs < 4 * cuts_wanted)); do
  runs=$((runs + 1))
  t=$((200 + RANDOM % 6000))  # ticks after the restart: bring-up takes a few hundred, a knot ~400
  rc=$(run "$t")
  [[ $rc == done ]] && { rm -f "$counters" "$state" "$work/designs.json" "$work"/report/*; continue; }  # woven: a new carpet
  if [[ $rc == 137 ]]; then
    killed=$((killed + 1))
    if (($(field knot_cycles_started) > 0 && $(field picks_in_row) == 0)); then mid_knot=$((mid_knot + 1)); fi
  else
    [[ $rc == 0 ]] || { echo "FAIL: run with a cut at tick $t exited $rc"; tail -20 "$work/log"; exit 1; }
  fi
done
((mid_knot >= cuts_wanted)) || { echo "FAIL: only $mid_knot of $killed cuts landed mid-knotting"; exit 1; }
rc=$(run)
[[ $rc == 0 || $rc == done ]] || { echo "FAIL: the final run exited $rc"; tail -20 "$work/log"; exit 1; }
line=$(grep "^carpet:" "$work/log" | tail -1)
echo "$line"
echo "counters: $(tr -d '\n ' <"$counters")"
[[ $line == *"equals the design knot for knot"* ]] || { echo "FAIL: the carpet is not the design"; tail -30 "$work/log"; exit 1; }
[[ $(field rows) == "$rows_wanted" ]] || { echo "FAIL: rows $(field rows), wanted $rows_wanted"; exit 1; }
# The counters' tallies are the carpet's: every knot counted once, by a head or by the weaver (a head's knot in
# a cycle the cut interrupted is the weaver's to check only when the counters did not hold it already).
knots_in_carpet=$(grep -oE '[0-9]+ knots \(' <<<"$line" | grep -oE '^[0-9]+')
[[ -n $knots_in_carpet ]] || { echo "FAIL: no knot count in '$line'"; exit 1; }
counted=$(($(field knots) + $(field knots_by_hand)))
((counted == knots_in_carpet)) || { echo "FAIL: the counters count $counted knots (heads $(field knots), by hand $(field knots_by_hand)) in a carpet of $knots_in_carpet"; exit 1; }
echo "PASS: $killed power cuts ($mid_knot while a row was being knotted) in $runs runs; every knot tied once"

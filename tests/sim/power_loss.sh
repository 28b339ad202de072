#!/usr/bin/env bash
# Power loss at every phase of the row cycle: loomctl (simulated loom, virtual time) runs a scene whose
# power_cut fault kills it at a chosen tick, and is restarted each time with the same counters file and
# the same simulated machine state. The cut ticks are deterministic, and the machine state left by each
# cut is classified (shed change: a frame mid-stroke; pick: the shuttle in the shed; beat sweep: the
# crank off park or the carriage between selvedges), so the test proves it hit every phase. The rows
# and picks at the end must be exactly what was asked: nothing lost, nothing repeated.
set -euo pipefail
loomctl=$1
config=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
counters=$work/counters.json
state=$work/machine.state
rows_wanted=6
picks_per_row=2
width=0.4
cuts=(150 420 700 1200 1900 2600 3300 300 900 1500 2100 80)  # ticks after each (re)start

scene() {  # scene [cut_tick]: the default scene's effects, with a power cut when given
  cat <<SCENE
name = "power_loss"
seed = 1
effects = ["servo_lag", "pneumatics", "beat_contact"]
SCENE
  [[ -n ${1:-} ]] && printf '\n[[fault]]\nkind = "power_cut"\nat_tick = %s\n' "$1"
  return 0
}

phase_of_state() {  # the phase the machine was cut in, from the state file's physical state
  # PersistedMachine: magic, crank, carriage, helix, piston A, piston B, shuttle x (doubles after the magic)
  od -A n -t f8 -j 8 -N 48 -v "$state" | tr -s ' \n' ' ' | awk -v w="$width" '
    { crank=$1; carriage=$2; pa=$4; pb=$5; x=$6
      two_pi = 6.283185307179586; ph = crank - two_pi * int(crank / two_pi); if (ph < 0) ph += two_pi
      if (x > 0.005 && x < w - 0.005) { print "pick"; exit }
      if ((pa > 0 && pa < 1) || (pb > 0 && pb < 1)) { print "shed"; exit }
      if ((ph > 1e-3 && ph < two_pi - 1e-3) || (carriage > 1e-3 && carriage < w - 0.1 - 1e-3)) { print "beat"; exit }
      print "between" }'
}

run() {  # run [cut_tick]; prints loomctl's exit code (137 when the power cut killed it)
  local rows_done=0
  [[ -f $counters ]] && rows_done=$(grep -o '"rows": *[0-9]*' "$counters" | grep -o '[0-9]*$')
  local left=$((rows_wanted - rows_done))
  ((left > 0)) || { echo done; return; }
  scene "${1:-}" >"$work/scene.toml"
  local rc=0
  "$loomctl" weave --config "$config" --scene "$work/scene.toml" --rows "$left" --counters "$counters" \
    --sim-state "$state" --no-telemetry --quiet >>"$work/log" 2>&1 || rc=$?
  echo "$rc"
}

killed=0
declare -A hit=()
for t in "${cuts[@]}"; do
  rc=$(run "$t")
  [[ $rc == done ]] && break
  if [[ $rc == 137 ]]; then
    killed=$((killed + 1))
    p=$(phase_of_state)
    hit[$p]=1
  else
    p="(ran to the end)"
    [[ $rc == 0 ]] || { echo "FAIL: run with a cut at tick $t exited $rc"; tail -20 "$work/log"; exit 1; }
  fi
  echo "cut power at tick $t: exit $rc, phase $p; counters now $(tr -d "\n " 2>/dev/null <"$counters" || echo none)"
done
rc=$(run)
[[ $rc == done || $rc == 0 ]] || { echo "FAIL: final run exited $rc"; tail -20 "$work/log"; exit 1; }
echo "final counters: $(tr -d '\n ' <"$counters") after $killed power cuts"
rows=$(grep -o '"rows": *[0-9]*' "$counters" | grep -o '[0-9]*$')
picks=$(grep -o '"picks": *[0-9]*' "$counters" | grep -o '[0-9]*$')
in_row=$(grep -o '"picks_in_row": *[0-9]*' "$counters" | grep -o '[0-9]*$')
for p in shed pick beat; do
  [[ -n ${hit[$p]:-} ]] || { echo "FAIL: no power cut landed in the $p phase; the cut ticks need revisiting"; exit 1; }
done
[[ $rows == "$rows_wanted" ]] || { echo "FAIL: rows $rows, wanted $rows_wanted"; tail -20 "$work/log"; exit 1; }
[[ $picks == $((rows_wanted * picks_per_row)) ]] || { echo "FAIL: picks $picks, wanted $((rows_wanted * picks_per_row)) (lost or repeated)"; tail -20 "$work/log"; exit 1; }
[[ $in_row == 0 ]] || { echo "FAIL: picks_in_row $in_row after the last row"; exit 1; }
echo "PASS: $rows rows, $picks picks after $killed power cuts (phases hit: ${!hit[*]})"

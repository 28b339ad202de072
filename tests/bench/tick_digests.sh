#!/usr/bin/env bash
# Every scene's behaviour digest from the instruction harness (loom_bench_tick_instructions --digest):
# a hash of every tick's inputs, outputs and snapshot. An optimisation of the tick must leave every line
# of this output unchanged; compare the output of a build before and after it:
#
#   tests/bench/tick_digests.sh --bin old/bin > before.txt
#   tests/bench/tick_digests.sh > after.txt && diff before.txt after.txt
#
# Cases: all scenes in sim_hal/scenes/ on the default loom, tests/sim/four_axis_loom.toml and
# tests/sim/incremental_loom.toml, telemetry off and on; the knotting scenes on the 6- and 12-head looms.
#     --bin DIR     build/bin with loom_bench_tick_instructions (default: build/bin)
#     --ticks N     ticks after the warm-up (default 8000; warm-up 4000)
#     -j N          cases run at once (default 2)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=$root/build/bin
ticks=8000
jobs=2
while [[ $# -gt 0 ]]; do
  case $1 in
    --bin) bin=$2; shift 2 ;;
    --ticks) ticks=$2; shift 2 ;;
    -j) jobs=$2; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "tick_digests.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
harness=$bin/loom_bench_tick_instructions
[[ -x $harness ]] || { echo "tick_digests.sh: $harness not built" >&2; exit 2; }
scenes=$root/sim_hal/scenes
cases=()
for cfg in "" "$root/tests/sim/four_axis_loom.toml" "$root/tests/sim/incremental_loom.toml"; do
  for s in "$scenes"/*.toml; do
    case $(basename "$s") in knotting*) continue ;; esac
    for tele in 0 1; do cases+=("$s|$cfg|$tele"); done
  done
done
for cfg in "$root/firmware/config/knotting_loom.toml" "$here/twelve_head_loom.toml"; do
  for s in "$scenes"/knotting*.toml; do
    for tele in 0 1; do cases+=("$s|$cfg|$tele"); done
  done
done
run_case() {  # scene|config|telemetry
  IFS='|' read -r scene cfg tele <<<"$1"
  args=(--scene "$scene" --warmup 4000 --ticks "$ticks" --digest)
  [[ -n $cfg ]] && args+=(--config "$cfg")
  [[ $tele == 1 ]] && args+=(--telemetry)
  local res
  res=$("$harness" "${args[@]}" 2>&1 | tr '\n' ' ') || res="FAILED $res"
  printf '%s %s tele=%s: %s\n' "$(basename "$scene" .toml)" "$(basename "${cfg:-default}" .toml)" "$tele" "$res"
}
export -f run_case
export harness ticks
printf '%s\n' "${cases[@]}" | xargs -P "$jobs" -I{} bash -c 'run_case "$@"' _ {} | LC_ALL=C sort

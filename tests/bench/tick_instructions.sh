#!/usr/bin/env bash
# The control tick's cost in instructions (callgrind), per scene, telemetry off and on, and per axis.
# Instruction counts, not time: the same binary gives the same count on a loaded or an idle host, so a
# change of a few percent is real. See tests/bench/README.md.
#
#   tests/bench/tick_instructions.sh [options]
#     --bin DIR        build/bin with loom_bench_tick_instructions (default: build/bin)
#     --ticks N        ticks measured per case (default 4000: a row and more of the default loom)
#     --warmup N       ticks woven before measuring (default 4000: bring-up done, weaving)
#     --smoke          a short run: the default scene, telemetry off and on, N = 500
#     --ceiling N      fail when any case costs more than N instructions per tick (default: none)
#     --split          add the per-module split (callgrind_annotate, inclusive counts)
#     --out DIR        keep the callgrind.out files here (default: a temporary folder, removed)
#
# Exit status: 0; 1 when a case costs more than the ceiling; 2 when valgrind or the harness failed
# (non-zero exit, a valgrind error line, or no counts).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=$root/build/bin
ticks=4000
warmup=4000
smoke=0
ceiling=0
split=0
out=""
while [[ $# -gt 0 ]]; do
  case $1 in
    --bin) bin=$2; shift 2 ;;
    --ticks) ticks=$2; shift 2 ;;
    --warmup) warmup=$2; shift 2 ;;
    --smoke) smoke=1; shift ;;
    --ceiling) ceiling=$2; shift 2 ;;
    --split) split=1; shift ;;
    --out) out=$2; shift 2 ;;
    -h|--help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "tick_instructions.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done

harness=$bin/loom_bench_tick_instructions
command -v valgrind >/dev/null || { echo "tick_instructions.sh: valgrind is not installed (tools/deps.sh)" >&2; exit 2; }
[[ -x $harness ]] || { echo "tick_instructions.sh: $harness not built (cmake --build build --target loom_bench_tick_instructions)" >&2; exit 2; }
if [[ -z $out ]]; then
  out=$(mktemp -d)
  trap 'rm -rf "$out"' EXIT
fi
mkdir -p "$out"

scenes=$root/sim_hal/scenes
# case: name | scene | config ("" = embedded default) | telemetry (0/1)
cases=()
if [[ $smoke == 1 ]]; then
  ticks=500
  warmup=1500
  cases+=("default|$scenes/default.toml||0" "default|$scenes/default.toml||1")
else
  for s in ideal default dynamics; do
    cases+=("$s|$scenes/$s.toml||0" "$s|$scenes/$s.toml||1")
  done
  cases+=("default, 4 axes|$scenes/default.toml|$root/tests/sim/four_axis_loom.toml|0")
  cases+=("default, 8 axes|$scenes/default.toml|$here/eight_axis_loom.toml|0")
  # Knotting heads, in the knotting state (the knotting scene: ideal + knotter).
  cases+=("6 heads|$scenes/knotting.toml|$root/firmware/config/knotting_loom.toml|0")
  cases+=("12 heads|$scenes/knotting.toml|$here/twelve_head_loom.toml|0")
fi

# Inclusive instructions of a function, from callgrind_annotate --inclusive=yes: the largest entry whose
# name matches the extended regex (a virtual call shows as a thunk that includes the function's clone,
# and code inlined from other files as further, partial entries of the same name: the largest is whole).
inclusive() {  # annotate-file regex
  awk -v re="$2" '$0 ~ re { n = $1; gsub(",", "", n); if (n ~ /^[0-9]+$/ && n + 0 > m) m = n + 0 } END { print m + 0 }' "$1"
}

status=0
printf '%-16s %-9s %14s' "scene" "telemetry" "instr/tick"
[[ $split == 1 ]] && printf ' %10s %10s %10s %10s %10s %10s' "step" "read_axes" "read_io" "analog" "write" "loop"
printf '\n'
i=0
for c in "${cases[@]}"; do
  IFS='|' read -r name scene config tele <<<"$c"
  i=$((i + 1))
  args=(--scene "$scene" --warmup "$warmup" --ticks "$ticks")
  [[ -n $config ]] && args+=(--config "$config")
  [[ $tele == 1 ]] && args+=(--telemetry)
  cg=$out/callgrind.out.$i
  if ! valgrind --tool=callgrind --collect-atstart=no --toggle-collect=measured_tick \
       --callgrind-out-file="$cg" "$harness" "${args[@]}" >"$out/run.$i.log" 2>&1; then
    echo "tick_instructions.sh: valgrind or the harness failed for $name (telemetry $tele):" >&2
    cat "$out/run.$i.log" >&2
    exit 2
  fi
  # Callgrind reports its own trouble as "==pid== ..." lines beyond its banner and summary.
  if grep -E '^==[0-9]+== .*(error|Error|ERROR|unhandled|Unrecognised|Invalid|Warning: )' "$out/run.$i.log" >&2; then
    echo "tick_instructions.sh: valgrind reported the lines above for $name (telemetry $tele)" >&2
    exit 2
  fi
  total=$(sed -n 's/^totals: \([0-9]*\).*/\1/p;s/^summary: \([0-9]*\).*/\1/p' "$cg" | head -n1)
  if [[ -z $total || $total == 0 ]]; then
    echo "tick_instructions.sh: no instructions counted for $name (is measured_tick in the harness?)" >&2
    exit 2
  fi
  per=$(( (total + ticks / 2) / ticks ))
  printf '%-16s %-9s %14d' "$name" "$([[ $tele == 1 ]] && echo on || echo off)" "$per"
  if [[ $split == 1 ]]; then
    ann=$out/annotate.$i
    callgrind_annotate --inclusive=yes --threshold=100 "$cg" >"$ann"
    parts=()
    for re in 'Sequencer::step\(long' 'SimWorld::read_axes\(' 'SimWorld::read_io\(' 'SimWorld::read_analog\(' \
              'SimWorld::write_axes\(' 'SimWorld::write_io\('; do
      parts+=("$(inclusive "$ann" "$re")")
    done
    rest=$(( total - parts[0] - parts[1] - parts[2] - parts[3] - parts[4] - parts[5] ))
    for v in "${parts[0]}" "${parts[1]}" "${parts[2]}" "${parts[3]}" $(( parts[4] + parts[5] )) "$rest"; do
      printf ' %10d' $(( (v + ticks / 2) / ticks ))
    done
  fi
  printf '\n'
  if [[ $ceiling -gt 0 && $per -gt $ceiling ]]; then
    echo "tick_instructions.sh: $name (telemetry $tele) costs $per instructions per tick, over the ceiling $ceiling" >&2
    status=1
  fi
done
echo "($ticks ticks measured after $warmup woven; $(valgrind --version))"
exit $status

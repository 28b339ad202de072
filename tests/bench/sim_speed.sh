#!/usr/bin/env bash
# The simulator's speed, two builds side by side: `loomctl weave --rows R --no-telemetry` on the default
# scene (sim_hal/scenes/default.toml, the same file for both) and each build's default loom, N runs each,
# alternating A and B so that a busy host slows both alike. Each run gives machine seconds per wall second
# of the loop (its "loop: … s machine time … s wall" line); prints every run, both medians and B/A.
#
#   tests/bench/sim_speed.sh A/bin/loomctl B/bin/loomctl [N=9] [ROWS=300]
#
# Wall time, not instructions: run both in the same minutes on the same host, and read the ratio.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
scene=$(cd "$here/../.." && pwd)/sim_hal/scenes/default.toml
a=${1:?usage: sim_speed.sh A_LOOMCTL B_LOOMCTL [N] [ROWS]} b=${2:?usage: sim_speed.sh A_LOOMCTL B_LOOMCTL [N] [ROWS]}
a=$(readlink -f "$a") b=$(readlink -f "$b")  # the runs start in /tmp
n=${3:-9} rows=${4:-300}
run() {
  (cd /tmp && "$1" weave --scene "$scene" --rows "$rows" --no-telemetry --quiet 2>&1) |
    sed -n 's/^loop: [0-9]* ticks (\([0-9.]*\) s machine time) in \([0-9.]*\) s wall.*/\1 \2/p' |
    awk '{ if ($2 > 0) printf "%.0f\n", $1 / $2 }'
}
median() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
ra=() rb=()
for ((i = 0; i < n; i++)); do
  ra+=("$(run "$a")")
  rb+=("$(run "$b")")
done
ma=$(median "${ra[@]}") mb=$(median "${rb[@]}")
echo "A $a: ${ra[*]}"
echo "B $b: ${rb[*]}"
echo "machine s per wall s, median of $n: A $ma, B $mb, B/A $(awk -v x="$mb" -v y="$ma" 'BEGIN { printf "%.2f", x / y }')"

#!/usr/bin/env bash
# A whole carpet's time: the machine time the six-head knotting loom takes to tie a 360 × 540 medium carpet
# (tests/sim/whole_carpet.sh: the same generated design, small magazines, knots slipping off every head), and
# the wall time the simulator takes to weave it — once straight through, once through CUTS power cuts (each
# restart re-arms the simulated machine from its state file). A fixed seed by default, so the machine time is
# the same on every host (to within what the counters had on disk when the power failed).
#
#   tests/bench/whole_carpet_time.sh build/bin/loomctl [CUTS=20] [SEED=1]
#
# Wall time, not instructions: it depends on the host (2 cores shared with a build make it slower).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
loomctl=${1:?usage: whole_carpet_time.sh LOOMCTL [CUTS] [SEED]}
cuts=${2:-20} seed=${3:-1}
for c in 0 "$cuts"; do
  out=$(bash "$root/tests/sim/whole_carpet.sh" "$loomctl" "$root/firmware/config/knotting_loom.toml" "$c" "$seed")
  line=$(grep '^whole carpet: machine time' <<<"$out") || { echo "$out"; exit 1; }
  echo "$c power cuts: ${line#whole carpet: }; $(grep -o '[0-9]* knots ([0-9]* by hand)' <<<"$out" | head -1)"
done

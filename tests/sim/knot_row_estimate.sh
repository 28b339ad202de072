#!/usr/bin/env bash
# `loomctl check`'s knotting time per row against the simulator's: the estimate runs the heads' own
# sequence against an ideal plant (sequencer/row_time.hpp); the simulated loom (scene "knotting": ideal
# drives, no misses) weaves rows 1 and 2 and its run report says how long the heads knotted each. They
# must agree (the simulated drives trail their commands a little: 0.5 %), row by row — and the knot cycles alone, the estimate before, must not (the carriage's steps outlast the grippers'
# return on the shipped loom), or this test would not tell the two apart.
# Usage: knot_row_estimate.sh LOOMCTL SOURCE_DIR
set -euo pipefail
loomctl=$1
src=$2
work=$(mktemp -d /tmp/loom_knot_row_estimate.XXXXXX)
trap 'rm -rf "$work"' EXIT
loom=$src/firmware/config/knotting_loom.toml
"$loomctl" check --config "$loom" >"$work/check.txt"
"$loomctl" weave --config "$loom" --scene "$src/sim_hal/scenes/knotting.toml" --rows 2 --report "$work/report" \
  --no-telemetry --quiet >"$work/weave.txt"
python3 - "$work/check.txt" "$work/report/rows.jsonl" <<'PY'
import json, re, sys
check = open(sys.argv[1]).read()
m = re.search(r"knotting about ([0-9.]+) s per row, from the heads' own sequence against an ideal plant: "
              r"row 1 ([0-9.]+) s, row 2 ([0-9.]+) s", check)
assert m, "no sequenced estimate in loomctl check:\n" + check
cycles = re.search(r"the ([0-9]+) knot cycles take ([0-9.]+) s", check)
assert cycles, check
estimate = [float(m.group(2)), float(m.group(3))]
rows = [json.loads(line) for line in open(sys.argv[2])]
sim = [r["knotting_s"] for r in rows]
assert len(sim) == 2 and all(r["weaver_s"] == 0 for r in rows), rows
for row, (e, s) in enumerate(zip(estimate, sim), 1):
    assert abs(e - s) <= 0.005 * s + 0.01, f"row {row}: check says {e} s, the simulated heads took {s} s"
    print(f"row {row}: check {e:.2f} s, simulated {s:.3f} s ({100 * (e - s) / s:+.2f} %)")
only_cycles = float(cycles.group(2))
assert min(sim) - only_cycles > 0.05 * only_cycles, (only_cycles, sim)
print(f"the knot cycles alone ({only_cycles} s) would be {100 * (min(sim) - only_cycles) / min(sim):.0f} % short")
PY

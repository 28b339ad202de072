#!/usr/bin/env bash
# A carpet job woven from the command line as on a board (`loomctl weave --state-dir`, serve's state):
#   1. two designs with the same file name and other knots are two jobs;
#   2. weave starts the next queued job (it runs at the machine), weaves its rows and no more: across a
#      power cut (SIGKILL from the scene's power_cut fault) it resumes where the counters say, and at the
#      job's last row it says "carpet done" and the job is carpet_done — the design does not repeat;
#   3. the next weave starts the next queued job; a design file changed under the current job is refused
#      (exit 2, both hashes) with nothing changed;
#      the job's production record (production.sqlite) has its rows, its end, and states adding up to its
#      wall time;
#   4. with nothing queued a weave is refused, naming the finished job; `job start-over` weaves it again
#      from row 1; the production counters only ever grow; the magazines' levels kept in the state
#      directory are the ones the restarted loom counts from (an emptied slot is asked for at once).
# Usage: weave_job.sh LOOMCTL SOURCE_DIR
set -euo pipefail
loomctl=$1
src=$2
work=$(mktemp -d /tmp/loom_weave_job.XXXXXX)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
loom=$src/tests/sim/knotting_sample_loom.toml
state=$work/state
mkdir -p "$state" "$work/a" "$work/b"
cat >"$work/scene.toml" <<'TOML'
name = "weave_job"
seed = 11
effects = ["ideal", "knotter"]
[knotter]
miss_probability = 0.02
weaver_s = 0.5
TOML
weave() { "$loomctl" weave --config "$loom" --state-dir "$state" --no-telemetry --quiet "$@"; }
job() { "$loomctl" job "$@" --state-dir "$state"; }
counter() { grep -o "\"$1\": *[0-9]*" "$state/counters.json" | grep -o '[0-9]*$'; }

# 1. two files called rug.csv, other knots: two jobs
cp "$src/tests/sim/knot_sample.csv" "$work/a/rug.csv"
sed '0,/^B,B,B,R/s//B,B,B,I/' "$src/tests/sim/knot_sample.csv" >"$work/b/rug.csv"
cmp -s "$work/a/rug.csv" "$work/b/rug.csv" && fail "the second design is not different"
job add "$work/a/rug.csv" --config "$loom" --rows 3 >/dev/null
job add "$work/b/rug.csv" --config "$loom" --rows 2 >/dev/null
[[ $(job list | grep -c ' rug.csv ') == 2 ]] || fail "two rug.csv designs are not two jobs: $(job list)"
h1=$(job show 1 | sed -n 's/^  sha256 *//p')
h2=$(job show 2 | sed -n 's/^  sha256 *//p')
[[ -n $h1 && $h1 != "$h2" ]] || fail "the jobs' hashes: '$h1' '$h2'"

# 2. the first job, through a power cut in its second row
weave --scene "$work/scene.toml" --rows 1 >"$work/w1.log" || fail "first weave: $(cat "$work/w1.log")"
grep -q "job 1 (design rug.csv.*(started now)" "$work/w1.log" || fail "weave did not start job 1: $(cat "$work/w1.log")"
[[ $(counter rows) == 1 ]] || fail "rows after the first weave: $(counter rows)"
{ cat "$work/scene.toml"; printf '\n[[fault]]\nkind = "power_cut"\nat_tick = 3000\n'; } >"$work/cut.toml"
rc=0
weave --scene "$work/cut.toml" >"$work/w2.log" 2>&1 || rc=$?
[[ $rc == 137 ]] || fail "the power cut did not kill the weave (exit $rc): $(tail -5 "$work/w2.log")"
job list | grep -q '^1 .*current .*row 2 of 3 next' || fail "job 1 after the cut: $(job list)"
weave --scene "$work/scene.toml" >"$work/w3.log" || fail "the weave after the cut: $(tail -5 "$work/w3.log")"
grep -q "^carpet done: " "$work/w3.log" || fail "no carpet done line: $(tail -5 "$work/w3.log")"
[[ $(counter rows) == 3 ]] || fail "job 1 of 3 rows left the counters at rows $(counter rows)"
job list | grep -q '^1 .*carpet_done .*all 3 rows woven' || fail "job 1 is not carpet_done: $(job list)"
job list | grep -q '^2 .*queued' || fail "job 2 is not queued: $(job list)"
# The job's production record (SQLite): its 3 rows, ended, and the machine states' times adding up to its
# wall time (to the millisecond the report prints; the record adds them exactly) across the power cut.
"$loomctl" report job 1 --state-dir "$state" --format json >"$work/r1.json" || fail "no record of job 1"
python3 - "$work/r1.json" <<'PY' || fail "job 1's record: $(cat "$work/r1.json")"
import json, sys
r = json.load(open(sys.argv[1]))
states = sum(v["ns"] for v in r["states"].values())
assert r["rows"] == {"recorded": 3, "last": 3}, r["rows"]
assert r["ended"], "not ended"
assert r["knots"]["by_heads"] + r["knots"]["by_hand"] > 0, r["knots"]
assert abs(states / 1e9 - r["wall_s"]) <= 0.0015, (states, r["wall_s"])
assert r["states"]["knotting"]["ns"] > 0 and r["states"]["weaving"]["ns"] > 0, r["states"]
print(f"record of job 1: {r['wall_s']} s wall = {states / 1e9} s in states; yarn {r['yarn_knots']}")
PY

# 3. the next weave starts job 2; its file changed under it is refused, nothing changed
weave --scene "$work/scene.toml" --rows 1 >"$work/w4.log" || fail "job 2's first row: $(tail -5 "$work/w4.log")"
grep -q "job 2 (design rug.csv.*(started now)" "$work/w4.log" || fail "weave did not start job 2"
echo "# edited" >>"$work/b/rug.csv"
before=$(cat "$state/jobs.txt" "$state/counters.json")
rc=0
weave --scene "$work/scene.toml" >"$work/w5.log" 2>&1 || rc=$?
[[ $rc == 2 ]] || fail "a changed design was not refused (exit $rc)"
grep -q "the design file changed under job 2: hash [0-9a-f]\{64\}, was $h2" "$work/w5.log" ||
  fail "the refusal does not name both hashes: $(cat "$work/w5.log")"
[[ $(cat "$state/jobs.txt" "$state/counters.json") == "$before" ]] || fail "the refused weave changed the state"
sed -i '$d' "$work/b/rug.csv"  # the bytes it was added with
weave --scene "$work/scene.toml" >"$work/w6.log" || fail "job 2's last row: $(tail -5 "$work/w6.log")"
grep -q "^carpet done: " "$work/w6.log" || fail "job 2 did not end in carpet done"
[[ $(counter rows) == 5 ]] || fail "rows after both jobs: $(counter rows), want 3 + 2"

# 4. nothing queued: refused, naming the finished job; start-over weaves job 1 again from row 1
rc=0
weave --scene "$work/scene.toml" >"$work/w7.log" 2>&1 || rc=$?
[[ $rc == 2 ]] && grep -q "no carpet job to weave: job 2 is carpet_done" "$work/w7.log" ||
  fail "a weave with nothing queued: exit $rc, $(cat "$work/w7.log")"
# The magazines' levels are kept in the state directory and a restart starts from them: an empty slot
# (head 1's slot 0, colour R) is asked for before the first R knot of head 1, not taken as full.
grep -q '^head.1 = ' "$state/magazines.txt" || fail "no magazines' levels kept: $(cat "$state/magazines.txt" 2>&1)"
sed -i 's/^head.1 = [0-9]*/head.1 = 0/' "$state/magazines.txt"
job start-over 1 >/dev/null
job list | grep -q '^1 .*queued .*row 1 of 3 next' || fail "start-over: $(job list)"
weave --scene "$work/scene.toml" >"$work/w8.log" 2>&1 || fail "job 1 again: $(tail -5 "$work/w8.log")"
grep -q "job 1 (design rug.csv, sha256 [0-9a-f]*\.\.): row 1 of 3 next (started now)" "$work/w8.log" || fail "job 1 again did not start at its row 1"
[[ $(counter rows) == 8 ]] || fail "the counters went back or skipped: rows $(counter rows), want 8"
grep -q "weaver asked: row [0-9]* (design row 1): reload colour R into slot 0 of head 1" "$work/w8.log" ||
  fail "the emptied slot kept over the restart was not asked for in row 1: $(grep 'weaver asked' "$work/w8.log")"
# The second weaving has a record of its own from row 1; the first is kept as it was (3 rows, ended).
grep -q "WARNING" "$work/w8.log" && fail "job 1 again: $(grep WARNING "$work/w8.log")"
job show 1 | grep -qF "weaving     2 (started over 1 time;" || fail "job 1 is not in its weaving 2: $(job show 1)"
"$loomctl" report job 1 --state-dir "$state" >"$work/r2.txt" || fail "no record of job 1's second weaving"
grep -qF "weaving   2 of 2" "$work/r2.txt" || fail "the report does not say weaving 2 of 2: $(cat "$work/r2.txt")"
for w in 1 2; do
  "$loomctl" report job 1 --weaving $w --state-dir "$state" --format json >"$work/rw$w.json" ||
    fail "report job 1 --weaving $w"
done
python3 - "$work/rw1.json" "$work/rw2.json" "$work/r1.json" <<'PY' || fail "job 1's two weavings: $(cat "$work/rw1.json" "$work/rw2.json")"
import json, sys
w1, w2, before = (json.load(open(p)) for p in sys.argv[1:])
assert w1 == {**before, "weaving": 1, "weavings": 2}, "the first weaving's record changed"
assert (w2["weaving"], w2["weavings"]) == (2, 2), w2
assert w2["rows"] == {"recorded": 3, "last": 3} and w2["ended"], w2
assert w2["started"] > w1["ended"], (w2["started"], w1["ended"])
states = sum(v["ns"] for v in w2["states"].values())
assert abs(states / 1e9 - w2["wall_s"]) <= 0.0015, (states, w2["wall_s"])
PY
"$loomctl" report job 1 --weaving 3 --state-dir "$state" >/dev/null 2>"$work/rw3.err" && fail "weaving 3 reported"
grep -qF -- "--weaving 3: job 1 has no such weaving" "$work/rw3.err" || fail "weaving 3: $(cat "$work/rw3.err")"
echo "weave_job: ok (jobs $h1 / $h2; one power cut; carpet_done twice; start-over as weaving 2, both recorded)"

#!/usr/bin/env bash
# loomctl job add|list|show|remove|start-over on a state directory: a happy path (two designs of one file
# name are two jobs, start-over, remove) and the refusals — each with exit 2, a message naming file:line,
# field and value (or the colour, the width, the job), and the queue file left byte for byte as it was.
# usage: job_cli.sh LOOMCTL SOURCE_DIR
set -euo pipefail
loomctl=$1
src=$2
fail() { printf 'FAIL: %s\n' "$*" >&2; exit 1; }
out=$(mktemp -d "${TMPDIR:-/tmp}/loom_job_cli.XXXXXX")
lock_pid=""
trap '[[ -n $lock_pid ]] && kill "$lock_pid" 2>/dev/null; rm -rf "$out"' EXIT
state=$out/state
mkdir -p "$state" "$out/a" "$out/b"
loom=$src/firmware/config/knotting_loom.toml
demo=$src/firmware/config/designs/knot_demo.csv

# refused CMD... : exit 2, stderr has every TEXT given by --want, jobs.txt unchanged.
refused() {
  local wants=()
  while [[ $1 == --want ]]; do wants+=("$2"); shift 2; done
  local before=""
  [[ -f $state/jobs.txt ]] && before=$(sha256sum <"$state/jobs.txt")
  local rc=0
  "$loomctl" "$@" >"$out/stdout" 2>"$out/stderr" || rc=$?
  [[ $rc == 2 ]] || fail "loomctl $* exited $rc, want 2: $(cat "$out/stderr")"
  for w in "${wants[@]}"; do grep -qF -- "$w" "$out/stderr" || fail "loomctl $*: no '$w' in: $(cat "$out/stderr")"; done
  local after=""
  [[ -f $state/jobs.txt ]] && after=$(sha256sum <"$state/jobs.txt")
  [[ $before == "$after" ]] || fail "loomctl $* changed jobs.txt although refused"
}

# --- happy path ---------------------------------------------------------------------------------------
"$loomctl" job list --state-dir "$state" | grep -qF "no jobs in $state/jobs.txt" || fail "empty list"
"$loomctl" job add "$demo" --config "$loom" --state-dir "$state" >"$out/add1"
grep -qF "added job 1: knot_demo.csv (sha256 $(sha256sum <"$demo" | cut -c1-64)), 8 rows, queued" "$out/add1" ||
  fail "add 1: $(cat "$out/add1")"
# The same file name, other knots: another job with another hash.
sed 's/^B,/I,/' "$demo" >"$out/a/knot_demo.csv"
cp "$demo" "$out/b/knot_demo.csv"
"$loomctl" job add "$out/a/knot_demo.csv" --config "$loom" --repeat 3 --state-dir "$state" | grep -qF "added job 2" ||
  fail "add 2"
"$loomctl" job add "$out/b/knot_demo.csv" --config "$loom" --metres 1.8 --state-dir "$state" |
  grep -qF "540 rows, queued" || fail "add 3 (1.8 m at 30 rows/dm)"
"$loomctl" job list --state-dir "$state" >"$out/list"
[[ $(grep -c "knot_demo.csv" "$out/list") == 3 ]] || fail "list: $(cat "$out/list")"
h1=$(sed -n 's/^sha256 = //p' "$state/jobs.txt" | sed -n 1p)
h2=$(sed -n 's/^sha256 = //p' "$state/jobs.txt" | sed -n 2p)
[[ $h1 != "$h2" ]] || fail "two designs of one name share a hash"
"$loomctl" job show 2 --state-dir "$state" >"$out/show2"
grep -qF "length      24 rows (the design 3 times)" "$out/show2" || fail "show 2: $(cat "$out/show2")"
grep -qF "file check  unchanged since the job was added" "$out/show2" || fail "show 2 file check"
grep -qF "yarn head 6 B in slot 2, I in slot 1, R in slot 0" "$out/show2" || fail "show 2 yarn: $(cat "$out/show2")"
# The design edited in place: show says so, with both hashes.
echo "# edited" >>"$out/a/knot_demo.csv"
"$loomctl" job show 2 --state-dir "$state" >"$out/show2b"
grep -qF "the design file changed under job 2: hash $(sha256sum <"$out/a/knot_demo.csv" | cut -c1-64), was $h2" \
  "$out/show2b" || fail "changed design: $(cat "$out/show2b")"
# Progress back to row 1; a removed job stays listed as removed.
sed -i '0,/^rows_done = 0/s//rows_done = 5/' "$state/jobs.txt"
"$loomctl" job show 1 --state-dir "$state" | grep -qF "row 6 of 8 next" || fail "progress"
"$loomctl" job start-over 1 --state-dir "$state" | grep -qF "job 1 starts over at row 1 (queued, weaving 2)" ||
  fail "start-over"
"$loomctl" job show 1 --state-dir "$state" >"$out/show1"
grep -qF "row 1 of 8 next" "$out/show1" || fail "start-over did not reach row 1"
grep -qF "weaving     2 (started over 1 time;" "$out/show1" || fail "start-over: no weaving 2: $(cat "$out/show1")"
"$loomctl" job remove 3 --state-dir "$state" | grep -qF "removed job 3" || fail "remove"
"$loomctl" job list --state-dir "$state" | grep -qE "^3 +removed" || fail "removed job not listed as removed"

# --- refusals -----------------------------------------------------------------------------------------
refused --want "no job 9 in $state/jobs.txt" job show 9 --state-dir "$state"
refused --want "job 3 is already removed" job remove 3 --state-dir "$state"
refused --want "--state-dir $out/nowhere: not a directory" job list --state-dir "$out/nowhere"
refused --want "job show abc: not a job number" job show abc --state-dir "$state"
refused --want "job remove needs the job's number" job remove --state-dir "$state"
refused --want "--rows: only with job add" job list --rows 3 --state-dir "$state"
refused --want "verb: bogus not in {add,list,show,remove,start-over}" job bogus --state-dir "$state"
refused --want "excludes" job add "$demo" --rows 5 --repeat 2 --state-dir "$state"
refused --want "$out/a/narrow.csv: the design is 4 knots wide; the loom" --want "ties 360 knots per row" \
  job add "$(printf 'palette,R,#ff0000\nR,R,R,R\n' >"$out/a/narrow.csv"; echo "$out/a/narrow.csv")" --config "$loom" \
  --state-dir "$state"
# Two colours in no magazine slot, both named at once with their knot counts.
awk -F, 'BEGIN{OFS=","} /^palette/ {print; next} /^#/ {print; next} NF>1 {$1="G"; $2="Y"} {print}' "$demo" |
  sed '1i palette,G,#00ff00\npalette,Y,#ffff00' >"$out/a/green.csv"
refused --want "colours in no magazine slot: G (8 knots), Y (8 knots); the magazines hold R in slot 0, I in slot 1, B in slot 2" \
  job add "$out/a/green.csv" --config "$loom" --state-dir "$state"
# The current job cannot be removed.
cp "$state/jobs.txt" "$out/jobs.good"
sed -i '0,/^state = queued/s//state = current/' "$state/jobs.txt"
refused --want "job 1 is the current job (row 1 of 8)" job remove 1 --state-dir "$state"
cp "$out/jobs.good" "$state/jobs.txt"
# A damaged queue: refused naming file:line, field and value, for reading and changing verbs alike.
line=$(grep -n "^knots_per_row" "$state/jobs.txt" | head -1 | cut -d: -f1)
sed -i "${line}s/.*/knots_per_row = 36O/" "$state/jobs.txt"
refused --want "$state/jobs.txt:$line: field \"knots_per_row\" = \"36O\": want 1..4000" job list --state-dir "$state"
refused --want "$state/jobs.txt:$line: field \"knots_per_row\" = \"36O\"" job add "$demo" --config "$loom" --state-dir "$state"
cp "$out/jobs.good" "$state/jobs.txt"
line=$(grep -n "^state = queued" "$state/jobs.txt" | head -1 | cut -d: -f1)
sed -i "${line}s/.*/state = weaving/" "$state/jobs.txt"
refused --want "$state/jobs.txt:$line: field \"state\" = \"weaving\": want queued, current, carpet_done or removed" \
  job remove 2 --state-dir "$state"
cp "$out/jobs.good" "$state/jobs.txt"
# While serve holds the state directory the queue is not changed from here.
flock "$state/serve.lock" sleep 30 &
lock_pid=$!
for _ in $(seq 50); do flock -n "$state/serve.lock" true 2>/dev/null || break; sleep 0.1; done
refused --want "the job queue was not changed: state directory $state is in use" job start-over 1 --state-dir "$state"
"$loomctl" job list --state-dir "$state" >/dev/null || fail "list refused while the directory is locked (it only reads)"
echo "job_cli: PASS"

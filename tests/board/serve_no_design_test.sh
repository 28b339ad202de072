#!/usr/bin/env bash
# A loom with knotting heads and no design in its config: the carpet jobs bring the designs.
#   1. the config loads (loomctl check passes it; an offline `loomctl job add` with it works);
#   2. weave without a job is refused at the config's line: "loom.toml:11:8: knotting.mode = heads: the heads
#      tie a design's knots: ...", exit 2;
#   3. serve with an empty queue stands without a session: ctl status answers (state idle), a start is
#      refused with the same words (exit 1); ctl job add arms the loom with the job (no start); a start
#      then weaves it.
# Usage: serve_no_design_test.sh LOOMCTL SOURCE_DIR
set -euo pipefail
loomctl=$1
src=$2
. "$(dirname "$0")/lib.sh"  # board_work, fail, ctl, logged
board_work serve_no_design
field() { ctl status | head -1 | tr ' ' '\n' | sed -n "s/^$1=//p"; }
# The sample knotting loom without its [recipe] (the default's design is "": none).
sed '/^\[recipe\]/,$d' "$src/tests/sim/knotting_sample_loom.toml" >"$work/loom.toml"
grep -q '^mode = "heads"' "$work/loom.toml" || fail "the sample loom is not a heads loom any more"
line=$(grep -n '^mode = "heads"' "$work/loom.toml" | cut -d: -f1)
design=$src/tests/sim/knot_sample.csv
cat >"$work/scene.toml" <<'TOML'
name = "serve_no_design"
seed = 5
effects = ["ideal", "knotter"]
TOML

# 1. the config loads
"$loomctl" check --config "$work/loom.toml" >"$work/check.txt" 2>&1 || fail "check refused it: $(cat "$work/check.txt")"
mkdir -p "$work/offline" "$work/state"
"$loomctl" job add "$design" --config "$work/loom.toml" --state-dir "$work/offline" --rows 1 >/dev/null ||
  fail "offline job add with a heads loom without a design"

# 2. weave without a job
rc=0
"$loomctl" weave --config "$work/loom.toml" --scene "$work/scene.toml" --rows 1 >"$work/weave.txt" 2>&1 || rc=$?
grep -q "loom.toml:$line:8: knotting.mode = heads: the heads tie a design's knots: set recipe.design" "$work/weave.txt" &&
  [[ $rc == 2 ]] || fail "weave without a design or a job (exit $rc): $(cat "$work/weave.txt")"

# 3. serve stands until a job comes
"$loomctl" serve --config "$work/loom.toml" --scene "$work/scene.toml" --state-dir "$work/state" --socket "$sock" --group "" --no-telemetry \
  --pace "${LOOM_BOARD_PACE:-40}" >"$work/serve.log" 2>&1 &
pid=$!
end=$((SECONDS + 20))
until [[ -S $sock ]] && ctl status >/dev/null 2>&1; do
  ((SECONDS < end)) || fail "serve did not open its control socket"
  kill -0 "$pid" 2>/dev/null || fail "serve exited early"
  sleep 0.05
done
[[ $(field state) == idle ]] || fail "standing serve's status: $(ctl status)"
logged "standing, no session armed: .*loom.toml:$line:8: knotting.mode = heads" "$work/serve.log" ||
  fail "the journal does not say why the loom stands"
rc=0
reply=$(ctl start 2>&1) || rc=$?
[[ $rc == 1 && $reply == "refused: start: "*"loom.toml:$line:8: knotting.mode = heads: the heads tie a design's knots"* ]] ||
  fail "start of a loom with nothing to tie: '$reply' (exit $rc)"
reply=$(ctl job add "$design" --rows 1) || fail "ctl job add: $reply"
[[ $reply == *"queued; the loom arms it (start it at the machine)" ]] || fail "ctl job add: $reply"
end=$((SECONDS + 30))
until [[ $(ctl status | head -1) == *" job=1 job_row=1/1 job_state=queued"* ]]; do
  ((SECONDS < end)) || fail "the job was not armed: $(ctl status | head -1)"
  sleep 0.05
done
[[ $(field state) == idle && $(field rows) == 0 ]] || fail "job add moved the loom: $(ctl status | head -1)"
reply=$(ctl start 2>&1) || fail "start with the job armed: $reply"
end=$((SECONDS + 30))
while [[ $(field state) == idle ]]; do
  ((SECONDS < end)) || fail "the armed job does not weave: $(ctl status | head -1)"
  sleep 0.05
done
logged "job 1 (design knot_sample.csv, sha256 [0-9a-f]*\.\.): row 1 of 1 next: started at the machine" \
  "$work/serve.log" || fail "the job's start is not in the journal"
kill -TERM "$pid"
wait "$pid" || fail "serve exited $? on SIGTERM"
pid=
echo "serve_no_design: ok"

#!/usr/bin/env bash
# Runs one libFuzzer harness on its committed seed corpus plus a working corpus, so the committed one is
# never written to. The random seed is printed and taken from LOOM_FUZZ_SEED when set (to replay a run).
#   run_fuzzer.sh [--fresh] HARNESS SEED_CORPUS_DIR WORK_DIR [libFuzzer options...]
# --fresh empties WORK_DIR first (the test suite: every run starts from the seeds alone). Crashes, leaks
# and timeouts are written to WORK_DIR/artifacts/; the exit status is libFuzzer's (0 = nothing found).
set -euo pipefail
fresh=0
if [[ ${1:-} == --fresh ]]; then
  fresh=1
  shift
fi
harness=$1 seeds=$2 work=$3
shift 3
[[ $fresh == 1 ]] && rm -rf "$work"
mkdir -p "$work/corpus" "$work/artifacts"
seed=${LOOM_FUZZ_SEED:-$(( $(od -An -N4 -tu4 /dev/urandom) % 2147483646 + 1 ))}
echo "$(basename "$harness"): seed $seed (replay with LOOM_FUZZ_SEED=$seed), artifacts in $work/artifacts/"
exec "$harness" -seed="$seed" -artifact_prefix="$work/artifacts/" -print_final_stats=1 "$@" "$work/corpus" "$seeds"

#!/usr/bin/env bash
# Minimise a harness' committed seed corpus to the inputs that reach its coverage edges: the named seeds
# (reproducers and hand-made ones: any file whose name is not a 40-hex digest) are always kept, and of the
# digest-named ones only those that add an edge over them (libFuzzer -merge=1, edges only, no hit counters
# or value profile: a seed that only hits an edge more often adds nothing a campaign does not rebuild).
# usage: tests/fuzz/minimise_corpus.sh HARNESS [BUILD_DIR]   (BUILD_DIR default build-fuzz, built first)
set -euo pipefail
harness=${1:?usage: minimise_corpus.sh HARNESS [BUILD_DIR]}
src=$(cd "$(dirname "$0")/../.." && pwd)
build=${2:-$src/build-fuzz}
fuzzer=$build/fuzz/fuzz_$harness
corpus=$src/tests/fuzz/corpus/$harness
[[ -x $fuzzer ]] || { echo "minimise_corpus: no $fuzzer (tools/loom fuzz builds it)" >&2; exit 2; }
[[ -d $corpus ]] || { echo "minimise_corpus: no corpus $corpus" >&2; exit 2; }
work=$(mktemp -d "${TMPDIR:-/tmp}/loom_minimise.XXXXXX")
trap 'rm -rf "$work"' EXIT
mkdir "$work/keep" "$work/digests"
for f in "$corpus"/*; do
  if [[ $(basename "$f") =~ ^[0-9a-f]{40}$ ]]; then cp "$f" "$work/digests/"; else cp "$f" "$work/keep/"; fi
done
before=$(find "$corpus" -type f | wc -l)
"$fuzzer" -merge=1 -use_counters=0 -use_value_profile=0 -artifact_prefix="$work/" "$work/keep" "$work/digests" >"$work/merge.log" 2>&1 ||
  { cat "$work/merge.log" >&2; exit 1; }
find "$corpus" -type f -delete
cp "$work/keep"/* "$corpus/"
printf 'minimise_corpus: %s: %d -> %d seeds (%s)\n' "$harness" "$before" "$(find "$corpus" -type f | wc -l)" \
  "$(grep -o 'MERGE-OUTER: .*' "$work/merge.log" | tail -1)"

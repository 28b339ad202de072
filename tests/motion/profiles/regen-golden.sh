#!/usr/bin/env bash
# Regenerates the committed golden dumps (tests/motion/profiles/golden/<case>/) from golden/cases.txt —
# the one command for a deliberate change in motion. Review the diff before committing it.
# Usage: tests/motion/profiles/regen-golden.sh [BUILD_DIR]   (default: build; builds loom-profile first)
set -euo pipefail
src=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)
build=${1:-$src/build}
cmake --build "$build" --target loom-profile >/dev/null
tool=$build/bin/loom-profile
while IFS='|' read -r name args; do
  name=${name//[[:space:]]/}
  [[ -z $name || $name == \#* ]] && continue
  read -r -a argv <<<"$args"
  rm -rf "$src/tests/motion/profiles/golden/$name"
  (cd "$src" && "$tool" dump "${argv[@]}" --out "tests/motion/profiles/golden/$name")
done <"$src/tests/motion/profiles/golden/cases.txt"
echo "regenerated; review with: git diff --stat -- tests/motion/profiles/golden"

#!/usr/bin/env bash
# Golden-file test: dumps every case of golden/cases.txt with loom-profile and compares the result
# with the committed copy, number by number (tests/motion/profiles/golden_diff). A failure names the file,
# line and column that moved; if the change is intended, run tests/motion/profiles/regen-golden.sh.
# Usage: golden_test.sh LOOM_PROFILE GOLDEN_DIFF SOURCE_DIR
set -euo pipefail
tool=$1 diff=$2 src=$3
here=$src/tests/motion/profiles
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0
while IFS='|' read -r name args; do
  name=${name//[[:space:]]/}
  [[ -z $name || $name == \#* ]] && continue
  read -r -a argv <<<"$args"
  (cd "$src" && "$tool" dump "${argv[@]}" --out "$work/$name" >/dev/null)
  if "$diff" "$here/golden/$name" "$work/$name"; then
    echo "golden $name: identical within tolerance"
  else
    echo "golden $name: DIFFERS (intended? regenerate with tests/motion/profiles/regen-golden.sh)"
    status=1
  fi
done <"$here/golden/cases.txt"
# Negative control: the diff must see a change as small as one knot more in the rocker table.
(cd "$src" && "$tool" dump --config firmware/config/default_loom.toml --table-size 257 --out "$work/control" >/dev/null)
if "$diff" "$here/golden/default" "$work/control" >/dev/null; then
  echo "golden negative control: a 257-knot table was NOT told apart from the 256-knot golden copy"
  status=1
else
  echo "golden negative control: a one-knot change is caught"
fi
exit $status

#!/usr/bin/env bash
# loom-profile's command-line contract: bad arguments, unreadable configs and infeasible recipes exit
# 2 with a message naming what is wrong; `report` writes accuracy.csv with exactly the contract's
# header, the chart and the summary, and prints the default choice per profile (a tiny grid here:
# the full report is `loom-profile report --out DIR`).
# Usage: cli_test.sh LOOM_PROFILE SOURCE_DIR
set -uo pipefail
tool=$1 src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
expect_exit() {  # expect_exit CODE NEEDLE ARGS...
  local code=$1 needle=$2
  shift 2
  local out rc
  out=$("$tool" "$@" 2>&1)
  rc=$?
  if [[ $rc -ne $code ]]; then
    echo "FAIL: loom-profile $* exited $rc, expected $code: $out"
    fail=1
  elif [[ -n $needle && $out != *"$needle"* ]]; then
    echo "FAIL: loom-profile $*: output lacks '$needle': $out"
    fail=1
  else
    echo "ok: loom-profile $* -> $rc"
  fi
}
cd "$src"
expect_exit 2 "" frobnicate
expect_exit 2 "--out" report
expect_exit 2 "--config" dump --out "$work/x"
expect_exit 2 "cannot open" dump --config "$work/none.toml" --out "$work/x"
expect_exit 2 "--ellipse-e" dump --config firmware/config/default_loom.toml --out "$work/x" --ellipse-e 1.5
# NaN is refused, never read as "not given" (the config's value) nor passed on to Google Benchmark.
expect_exit 2 "--ellipse-e" dump --config firmware/config/default_loom.toml --out "$work/x" --ellipse-e nan
expect_exit 2 "--ellipse-phi02-deg" dump --config firmware/config/default_loom.toml --out "$work/x" --ellipse-phi02-deg nan
expect_exit 2 "--min-time" report --out "$work/x" --min-time nan
expect_exit 2 "--interp" dump --config firmware/config/default_loom.toml --out "$work/x" --interp cubicle
expect_exit 2 "profiles.max_table_error_rad" dump --config firmware/config/default_loom.toml --out "$work/x" \
  --table-size 16 --interp linear
printf 'extends = "default"\n[recipe]\ncrank_speed_rad_s = "fast"\n' >"$work/bad.toml"
expect_exit 2 "recipe.crank_speed_rad_s" dump --config "$work/bad.toml" --out "$work/x"
expect_exit 0 "" --help

expect_exit 0 "default choice per profile" report --out "$work/report" --sizes 64 256 --min-time 0.0005 \
  --repetitions 1 --check-points 4096
header=$(head -n 1 "$work/report/accuracy.csv")
want="profile,interp,table_size,precision,max_pos_err,max_vel_err,max_acc_err,rms_pos_err,lookup_ns,build_us,bytes"
if [[ $header != "$want" ]]; then
  echo "FAIL: accuracy.csv header is '$header'"
  fail=1
fi
# 5 profiles (rocker, crank law, carriage cam, pick, knot cycle) x (1 exact + 2 sizes x 3 orders x 2 precisions) rows.
rows=$(($(wc -l <"$work/report/accuracy.csv") - 1))
[[ $rows -eq 65 ]] || { echo "FAIL: $rows rows, expected 65"; fail=1; }
grep -q "<svg" "$work/report/pareto.svg" || { echo "FAIL: no SVG chart"; fail=1; }
grep -q "| rocker |" "$work/report/summary.md" || { echo "FAIL: summary lacks the rocker row"; fail=1; }
exit $fail

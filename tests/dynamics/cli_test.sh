#!/bin/sh
# The loom-dynamics command-line contract: CSV headers on stdout, a speed for a target force that
# really gives that force, bad arguments named on stderr with exit status 2, SVG files written.
set -u
BIN="$1"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# beatup over a turn: header, one row per sample, all numbers finite.
"$BIN" beatup --crank-rad-s 15.5 --samples 36 --svg "$TMP/b.svg" > "$TMP/b.csv" || fail "beatup exit $?"
head -1 "$TMP/b.csv" | grep -q '^crank_deg,tip_acc_m_s2,beater_force_n,crank_torque_nm,pin_a0_n,pin_a_n,pin_b_n,pin_b0_n$' \
  || fail "beatup header: $(head -1 "$TMP/b.csv")"
[ "$(wc -l < "$TMP/b.csv")" -eq 37 ] || fail "beatup rows"
grep -qi 'nan\|inf' "$TMP/b.csv" && fail "beatup non-finite"
grep -q '<svg' "$TMP/b.svg" || fail "beatup svg"

# target force: the speed it prints, run over a fine turn, peaks at the target (within 0.1 %).
"$BIN" beatup --target-force-n 90 > "$TMP/t.csv" || fail "target exit"
head -1 "$TMP/t.csv" | grep -q '^target_force_n,crank_rad_s' || fail "target header"
W=$(sed -n 2p "$TMP/t.csv" | cut -d, -f2)
"$BIN" beatup --crank-rad-s "$W" --samples 7200 --extra > "$TMP/w.csv" || fail "beatup at target speed"
PEAK=$(awk -F, 'NR>1 && $10==1 && $3>m {m=$3} END {print m}' "$TMP/w.csv")
awk -v p="$PEAK" 'BEGIN {exit !(p > 89.9 && p <= 90.0000001)}' || fail "peak in warp $PEAK at $W rad/s"

# needle, batten, balance, mass headers.
"$BIN" needle --samples 12 | head -1 | grep -q '^theta1_deg,balancing_torque_nm,pin_' || fail "needle header"
"$BIN" batten --e 0.2 --phi02-rad 0.5 | head -1 | grep -q '^e,phi02_rad,phi02_deg,side,beat_accel_rad_s2,circular_accel_rad_s2,gain' \
  || fail "batten header"
"$BIN" batten --e 0.2 --search --scan-points 30 | awk -F, 'NR==2 {exit !($7 > 2.2499 && $7 < 2.2501)}' || fail "batten search gain"
"$BIN" balance --w1 0.5 --w2 0.5 --samples 90 --trace "$TMP/tr.csv" > "$TMP/bal.csv" || fail "balance exit"
head -1 "$TMP/bal.csv" | grep -q '^method,link,mass_kg,radius_m,angle_deg' || fail "balance header"
grep -q '^counterweight,crank,' "$TMP/bal.csv" || fail "balance crank counterweight"
grep -q '^redistribution,rocker,' "$TMP/bal.csv" || fail "balance redistribution"
[ "$(wc -l < "$TMP/tr.csv")" -gt 5 ] || fail "balance trace"
"$BIN" mass | grep -q '^crank,0.058,' || fail "mass"

# Bad input: exit 2 and the argument named on stderr.
expect_bad() {
  name="$1"; shift
  "$BIN" "$@" > /dev/null 2> "$TMP/err"
  rc=$?
  [ $rc -eq 2 ] || fail "$* -> exit $rc (want 2)"
  grep -q -- "$name" "$TMP/err" || fail "$* -> stderr does not name $name: $(cat "$TMP/err")"
}
expect_bad --crank-rad-s beatup --crank-rad-s -3
expect_bad --crank-rad-s beatup --crank-rad-s nan
expect_bad --crank-rad-s beatup
expect_bad --target-force-n beatup --target-force-n abc
expect_bad --samples needle --samples 0
expect_bad --e batten --e 1.5 --phi02-rad 0
expect_bad --phi02-rad batten --e 0.2
expect_bad --w1 balance --w1 -1
expect_bad --method balance --method magic
expect_bad --svg beatup --crank-rad-s 10 --svg /nonexistent-dir/x.svg
echo "dynamics CLI contract: ok"

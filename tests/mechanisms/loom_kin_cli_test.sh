#!/usr/bin/env bash
# loom-kin's command-line contract, as scripts depend on it: exact CSV headers, one row per sample,
# rows that agree with the mechanism's own equations, and bad input -> stderr naming the argument,
# exit status 2. Usage: loom_kin_cli_test.sh /path/to/loom-kin
set -u
KIN=${1:?usage: $0 /path/to/loom-kin}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
FAILS=0
fail() { echo "FAIL: $*"; FAILS=$((FAILS + 1)); }

# ---- needle ------------------------------------------------------------------------------------
"$KIN" needle --samples 3600 >"$TMP/needle.csv" 2>"$TMP/err" || fail "needle exited $?: $(cat "$TMP/err")"
[ "$(head -1 "$TMP/needle.csv")" = "theta1_deg,theta2_deg,theta3_deg,theta4_deg,theta5_deg,needle_mm" ] ||
  fail "needle header: $(head -1 "$TMP/needle.csv")"
[ "$(wc -l <"$TMP/needle.csv")" -eq 3601 ] || fail "needle rows: $(wc -l <"$TMP/needle.csv")"
# Each row closes 002's eqn 14 with Table 1 (l4 = 125, l5 = 120, l6 = 440, x2 = 100 mm; β1 = 168°), and
# every column moves by less than a degree (or a millimetre) between samples: no branch jumps.
awk -F, 'NR > 1 {
  r = 3.14159265358979 / 180
  b = $4 - $3 - 168 + 360
  if (b > 1e-6 || b < -1e-6) { print "theta4 != theta3 + beta1 - 360 at row " NR; bad = 1; exit }
  x = 125 * cos($4 * r) + 120 * cos($5 * r) - 100
  y = 440 - 125 * sin($4 * r) - 120 * sin($5 * r) - $6
  if (x > 1e-6 || x < -1e-6 || y > 1e-6 || y < -1e-6) { print "eqn 14 residual at row " NR ": " x ", " y; bad = 1; exit }
  if (NR > 2) for (i = 2; i <= 6; ++i) { d = $i - p[i]; if (d > 1 || d < -1) { print "jump in column " i " at row " NR; bad = 1; exit } }
  for (i = 1; i <= 6; ++i) p[i] = $i
} END { exit bad }' "$TMP/needle.csv" || fail "needle rows inconsistent"
[ "$(sed -n 2p "$TMP/needle.csv" | cut -d, -f1)" = "0" ] || fail "needle first theta1 is not 0"
[ "$(tail -1 "$TMP/needle.csv" | cut -d, -f1)" = "359.9" ] || fail "needle last theta1 is not 359.9"
"$KIN" needle --samples 12 --rates | head -1 | grep -q ',needle_v_m_s,needle_a_m_s2$' || fail "needle --rates header"

# ---- batten ------------------------------------------------------------------------------------
"$KIN" batten --e 0.2 --phi02-rad 1.0 --samples 3600 >"$TMP/batten.csv" 2>"$TMP/err" ||
  fail "batten exited $?: $(cat "$TMP/err")"
[ -s "$TMP/err" ] && fail "batten e=0.2 wrote to stderr: $(cat "$TMP/err")"
[ "$(head -1 "$TMP/batten.csv")" = "phi1_rad,phi2_rad,psi_rad,psi_dot_rad_s,psi_ddot_rad_s2" ] ||
  fail "batten header: $(head -1 "$TMP/batten.csv")"
[ "$(wc -l <"$TMP/batten.csv")" -eq 3601 ] || fail "batten rows: $(wc -l <"$TMP/batten.csv")"
[ "$(sed -n 2p "$TMP/batten.csv" | cut -d, -f1,2)" = "0,1" ] || fail "batten first row is not phi1=0, phi2=phi02"
# ψ' integrates to ψ (trapezoid over 0.1° steps at ω1 = 1 rad/s), so the columns belong together.
awk -F, 'NR > 2 { acc += 0.5 * ($4 + pv) * ($1 - p1); d = ($3 - p0) - acc; if (d > 1e-5 || d < -1e-5) { print "psi_dot does not integrate to psi at row " NR ": " d; bad = 1; exit } }
  NR == 2 { p0 = $3 } NR > 1 { pv = $4; p1 = $1 } END { exit bad }' "$TMP/batten.csv" || fail "batten psi_dot inconsistent with psi"
"$KIN" batten --e 0.2 --phi02-rad 1.0 --samples 3600 --solver newton >"$TMP/newton.csv" || fail "batten newton exited $?"
paste -d, "$TMP/batten.csv" "$TMP/newton.csv" | awk -F, 'NR > 1 { d = $3 - $8; if (d > 1e-10 || d < -1e-10) { bad = 1 } } END { exit bad }' ||
  fail "Newton and closed-form psi differ"
# e = 0: the circular gear turns the crank uniformly, φ2 = φ02 + φ1.
"$KIN" batten --e 0 --phi02-rad 0.5 --samples 360 | awk -F, 'NR > 1 { d = $2 - 0.5 - $1; if (d > 1e-11 || d < -1e-11) bad = 1 } END { exit bad }' ||
  fail "e = 0 is not a uniform crank"
"$KIN" batten --e 0.99999 --samples 36 >/dev/null 2>"$TMP/err" || fail "e near 1 must still succeed"
grep -q "near 1" "$TMP/err" || fail "e near 1 is not flagged on stderr"
[ "$("$KIN" batten-phase --e 0.2 --step-deg 30 | wc -l)" -eq 13 ] || fail "batten-phase rows"

# ---- bad input: exit 2, stderr names the argument ------------------------------------------------
expect_rejected() {
  local needle_text=$1
  shift
  "$KIN" "$@" >"$TMP/out" 2>"$TMP/err"
  local rc=$?
  [ "$rc" -eq 2 ] || fail "'$*' exited $rc, expected 2"
  grep -q -- "$needle_text" "$TMP/err" || fail "'$*' stderr does not name '$needle_text': $(cat "$TMP/err")"
  [ -s "$TMP/out" ] && fail "'$*' wrote to stdout"
}
expect_rejected "--samples" needle --samples 0
expect_rejected "--l5-mm" needle --l5-mm -3
expect_rejected "--l5-mm" needle --l5-mm nan
expect_rejected "--beta1-deg" needle --beta1-deg inf
expect_rejected "l5" needle --l5-mm 20
expect_rejected "--rocker-side" needle --rocker-side up
expect_rejected "--e" batten --e 1
expect_rejected "--e" batten --e 1.5
expect_rejected "--e" batten --e -0.1
expect_rejected "--phi02-rad" batten --phi02-rad abc
expect_rejected "L1" batten --l1-m 0.07
expect_rejected "--newton-tol" batten --newton-tol 0
expect_rejected "subcommand" --samples 10
"$KIN" --help >/dev/null 2>&1 || fail "--help exited non-zero"

[ "$FAILS" -eq 0 ] && echo "loom-kin CLI contract: all checks passed"
[ "$FAILS" -eq 0 ]

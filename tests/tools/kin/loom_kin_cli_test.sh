#!/usr/bin/env bash
# loom-kin's command-line contract, as scripts depend on it: exact CSV headers, one row per sample,
# rows that agree with the mechanism's own equations, and bad input -> stderr naming the argument,
# exit status 2; with loom-synth too, a synthesised beat-up linkage analysed back by loom-kin.
# Usage: loom_kin_cli_test.sh /path/to/loom-kin [/path/to/loom-synth]
set -u
KIN=${1:?usage: $0 /path/to/loom-kin [/path/to/loom-synth]}
SYNTH=${2:-}
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

# ---- fourbar -------------------------------------------------------------------------------------
# Thesis Table 5.1 beat-up (ground 213, crank 58, coupler 189, rocker 232 mm).
FB="--ground 0.213 --crank 0.058 --coupler 0.189 --rocker 0.232"
"$KIN" fourbar $FB --samples 3600 >"$TMP/fourbar.csv" 2>"$TMP/err" || fail "fourbar exited $?: $(cat "$TMP/err")"
[ "$(head -1 "$TMP/fourbar.csv")" = "theta2_deg,theta3_deg,theta4_deg,k3,k4,k3p,k4p,transmission_deg" ] ||
  fail "fourbar header: $(head -1 "$TMP/fourbar.csv")"
[ "$(wc -l <"$TMP/fourbar.csv")" -eq 3601 ] || fail "fourbar rows: $(wc -l <"$TMP/fourbar.csv")"
# Every row closes the loop a e^{i t2} + b e^{i t3} = d + c e^{i t4}; k4 integrates to theta4 and k4p to k4
# (trapezoid over 0.1 deg steps); the transmission angle is the coupler-rocker angle.
awk -F, -v a=0.058 -v b=0.189 -v c=0.232 -v d=0.213 'NR > 1 {
  r = 3.14159265358979 / 180
  x = a * cos($1 * r) + b * cos($2 * r) - d - c * cos($3 * r)
  y = a * sin($1 * r) + b * sin($2 * r) - c * sin($3 * r)
  if (x > 1e-10 || x < -1e-10 || y > 1e-10 || y < -1e-10) { print "loop residual at row " NR ": " x ", " y; bad = 1; exit }
  m = $3 - $2; while (m > 180) m -= 360; while (m < -180) m += 360; if (m < 0) m = -m
  if (m - $8 > 1e-6 || $8 - m > 1e-6) { print "transmission at row " NR; bad = 1; exit }
  if (NR > 2) {
    acc4 += 0.5 * ($5 + k4) * ($1 - t2) * r; acc5 += 0.5 * ($7 + k4p) * ($1 - t2) * r
    e4 = ($3 - th4) * r - acc4; e5 = ($5 - k40) - acc5
    if (e4 > 1e-6 || e4 < -1e-6) { print "k4 does not integrate to theta4 at row " NR ": " e4; bad = 1; exit }
    if (e5 > 1e-6 || e5 < -1e-6) { print "k4p does not integrate to k4 at row " NR ": " e5; bad = 1; exit }
  } else { th4 = $3; k40 = $5 }
  t2 = $1; k4 = $5; k4p = $7
} END { exit bad }' "$TMP/fourbar.csv" || fail "fourbar rows inconsistent"
# Summary: swing from the law of cosines at the dead centres (|A0 B| = b +- a), independent of loom-kin.
"$KIN" fourbar $FB --summary >"$TMP/sum.csv" || fail "fourbar --summary exited $?"
[ "$(head -1 "$TMP/sum.csv")" = "grashof,mu_min_deg,mu_max_deg,crank_extended_deg,crank_folded_deg,rocker_extended_deg,rocker_folded_deg,swing_deg,crank_rotation_deg,time_ratio" ] ||
  fail "fourbar summary header: $(head -1 "$TMP/sum.csv")"
awk -F, 'NR == 2 {
  pi = 3.14159265358979; a = 0.058; b = 0.189; c = 0.232; d = 0.213
  ce = ((b + a)^2 - d^2 - c^2) / (2 * d * c); cf = ((b - a)^2 - d^2 - c^2) / (2 * d * c)
  psi = (atan2(sqrt(1 - cf^2), cf) - atan2(sqrt(1 - ce^2), ce)) * 180 / pi; if (psi < 0) psi = -psi
  if ($1 != "crank-rocker") { print "class " $1; exit 1 }
  if ($8 - psi > 1e-6 || psi - $8 > 1e-6) { print "swing " $8 " vs " psi; exit 1 }
  if ($10 - $9 / (360 - $9) > 1e-9 || $9 / (360 - $9) - $10 > 1e-9) { print "time ratio"; exit 1 }
}' "$TMP/sum.csv" || fail "fourbar summary wrong"
[ "$("$KIN" fourbar --crank 3 --coupler 3.5 --rocker 3.2 --summary | tail -1 | cut -d, -f1,4)" = "double-crank," ] ||
  fail "double-crank summary must name the class and leave dead centres empty"
"$KIN" fourbar $FB --samples 4 --point-link rocker --point-x 0.301 | head -1 | grep -q ',point_x,point_y,point_vx,point_vy,point_ax,point_ay$' ||
  fail "fourbar point header"
# The beater tip at 0.301 m on the rocker moves perpendicular to the rocker: v . (P - B0) = 0.
"$KIN" fourbar $FB --samples 36 --point-link rocker --point-x 0.301 --omega 15.5 | awk -F, 'NR > 1 {
  dot = $11 * ($9 - 0.213) + $12 * $10; if (dot > 1e-9 || dot < -1e-9) bad = 1 } END { exit bad }' ||
  fail "rocker point velocity not perpendicular to the rocker"

# ---- slider-crank -------------------------------------------------------------------------------
"$KIN" slider-crank --crank 0.3 --coupler 1 --offset 0.2 --samples 3600 >"$TMP/slider.csv" ||
  fail "slider-crank exited $?"
[ "$(head -1 "$TMP/slider.csv")" = "theta_deg,x,x_dot,x_ddot,coupler_deg,coupler_rate_rad_s,coupler_accel_rad_s2,transmission_deg" ] ||
  fail "slider-crank header: $(head -1 "$TMP/slider.csv")"
[ "$(wc -l <"$TMP/slider.csv")" -eq 3601 ] || fail "slider-crank rows"
awk -F, 'NR > 1 {
  r = 3.14159265358979 / 180; q = 0.2 - 0.3 * sin($1 * r); x = 0.3 * cos($1 * r) + sqrt(1 - q * q)
  if ($2 - x > 1e-9 || x - $2 > 1e-9) { print "slider position at row " NR; bad = 1; exit }
  if (NR > 2) { acc += 0.5 * ($3 + v) * ($1 - t) * r; e = ($2 - x0) - acc; if (e > 1e-6 || e < -1e-6) { print "x_dot does not integrate to x at row " NR; bad = 1; exit } }
  else x0 = $2
  t = $1; v = $3
} END { exit bad }' "$TMP/slider.csv" || fail "slider-crank rows inconsistent"
"$KIN" slider-crank --crank 0.3 --coupler 1 --offset 0.2 --summary | awk -F, 'NR == 2 {
  s = sqrt(1.3^2 - 0.04) - sqrt(0.7^2 - 0.04); if ($5 - s > 1e-12 || s - $5 > 1e-12) { print "stroke " $5 " vs " s; exit 1 } }' ||
  fail "slider-crank summary stroke"

# ---- synthesis round trip: loom-synth designs, loom-kin analyses it back ---------------------------
if [ -n "$SYNTH" ]; then
  row=$("$SYNTH" design --swing 30 --phi 180 --beta 48 --ground 10 --full-precision | tail -1)
  IFS=, read -r _ _ _ _ a b c d _ <<<"$row"
  "$KIN" fourbar --ground "$d" --crank "$a" --coupler "$b" --rocker "$c" --summary | awk -F, 'NR == 2 {
    if ($8 - 30 > 1e-9 || 30 - $8 > 1e-9) { print "swing " $8; exit 1 }
    if ($9 - 180 > 1e-9 || 180 - $9 > 1e-9) { print "crank rotation " $9; exit 1 } }' ||
    fail "loom-synth crank-rocker (psi 30, phi 180, beta 48) does not analyse back to psi 30, phi 180"
  row=$("$SYNTH" design --stroke 12 --phi 169 --full-precision | tail -1)
  IFS=, read -r _ _ _ a b c _ <<<"$row"
  "$KIN" slider-crank --crank "$a" --coupler "$b" --offset "$c" --summary | awk -F, 'NR == 2 {
    if ($5 - 12 > 1e-9 || 12 - $5 > 1e-9) { print "stroke " $5; exit 1 }
    if ($7 - 169 > 1e-9 || 169 - $7 > 1e-9) { print "phi " $7; exit 1 } }' ||
    fail "loom-synth slider-crank (stroke 12, phi 169) does not analyse back to stroke 12, phi 169"
fi

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
expect_rejected "--crank" fourbar --crank -1 --coupler 1 --rocker 1
expect_rejected "--coupler" fourbar --crank 0.2 --coupler nan --rocker 1
expect_rejected "--rocker" fourbar --crank 0.2 --coupler 1
expect_rejected "--branch" fourbar --crank 0.2 --coupler 0.9 --rocker 0.8 --branch up
# A double-rocker whose input cannot turn fully: one pose it cannot reach is refused, naming the options.
expect_rejected "--start-deg" fourbar --ground 3 --crank 3.5 --coupler 1 --rocker 3.2 --samples 1 --start-deg 0
expect_rejected "--ground/--crank/--coupler/--rocker" fourbar --ground 2 --crank 1 --coupler 2 --rocker 1
expect_rejected "--point-link" fourbar --crank 0.2 --coupler 0.9 --rocker 0.8 --point-x 1
expect_rejected "--samples" fourbar --crank 0.2 --coupler 0.9 --rocker 0.8 --samples 0
expect_rejected "--coupler" slider-crank --crank 0.3 --coupler 0.4 --offset 0.2
expect_rejected "--offset" slider-crank --crank 0.3 --coupler 1 --offset inf
"$KIN" --help >/dev/null 2>&1 || fail "--help exited non-zero"


# ---- issue 13: the paper's needle assembly, near toggle, extreme magnitudes ----------------------
# Default: the rod hangs from D down to the needle bar (002's Fig. 2): theta5 in the third quadrant
# (printed in (-180, -90)), the needle 0.5-0.6 m below C; --rod-side standing is the mirror (~102 deg).
"$KIN" needle --samples 360 | awk -F, 'NR > 1 { if (!($5 > -180 && $5 < -90) || !($6 > 500 && $6 < 600)) { print "row " NR ": " $0; bad = 1; exit } } END { exit bad }' ||
  fail "needle default is not the paper's assembly (theta5 third quadrant)"
"$KIN" needle --samples 36 --rod-side standing | awk -F, 'NR > 1 { if (!($5 > 90 && $5 < 120)) bad = 1 } END { exit bad }' ||
  fail "needle --rod-side standing is not the mirror"
expect_rejected "--rod-side" needle --rod-side above
# Near toggle: mu_min = 1.4e-4 deg is flagged with its value, and the run still succeeds.
"$KIN" fourbar --ground 1 --crank 0.249999999999 --coupler 0.25 --rocker 1 --summary >"$TMP/nt.csv" 2>"$TMP/err" ||
  fail "near-toggle summary exited $?"
grep -q "near toggle" "$TMP/err" || fail "near toggle not flagged: $(cat "$TMP/err")"
grep -q "0.00014" "$TMP/err" || fail "near toggle does not give mu: $(cat "$TMP/err")"
"$KIN" fourbar --ground 0.213 --crank 0.058 --coupler 0.189 --rocker 0.232 --summary >/dev/null 2>"$TMP/err"
[ -s "$TMP/err" ] && fail "thesis linkage flagged: $(cat "$TMP/err")"
# Extreme magnitudes: scale-free where the mechanism is (1e155 slider-crank, 1e80 four-bar), a typed
# error where the numbers themselves overflow (omega 1e200: acceleration ~ omega^2); never NaN/inf.
no_nonfinite() { grep -qi 'nan\|inf' "$1" && fail "$2 printed a non-finite number"; return 0; }
"$KIN" slider-crank --crank 1e155 --coupler 3e155 --offset 5e154 --samples 36 >"$TMP/x.csv" 2>"$TMP/err" ||
  fail "slider-crank 1e155 exited $?: $(cat "$TMP/err")"
no_nonfinite "$TMP/x.csv" "slider-crank 1e155"
"$KIN" slider-crank --crank 1e155 --coupler 3e155 --offset 5e154 --summary >"$TMP/x.csv" || fail "slider-crank 1e155 summary"
no_nonfinite "$TMP/x.csv" "slider-crank 1e155 summary"
"$KIN" slider-crank --crank 0.3 --coupler 1 --offset 0.2 --omega 1e200 --samples 36 >"$TMP/x.csv" 2>"$TMP/err"
rc=$?
[ "$rc" -eq 2 ] || fail "--omega 1e200 exited $rc (want 2: accelerations overflow)"
grep -q "non-finite" "$TMP/err" || fail "--omega 1e200 error does not say why: $(cat "$TMP/err")"
[ -s "$TMP/x.csv" ] && fail "--omega 1e200 wrote a partial table"
"$KIN" fourbar --ground 2.13e79 --crank 5.8e78 --coupler 1.89e79 --rocker 2.32e79 --summary >"$TMP/x.csv" 2>"$TMP/err" ||
  fail "1e80 four-bar exited $?: $(cat "$TMP/err")"
grep -q '^crank-rocker,' "$TMP/x.csv" || fail "1e80 four-bar: $(cat "$TMP/x.csv")"
[ -s "$TMP/err" ] && fail "1e80 four-bar flagged: $(cat "$TMP/err")"
"$KIN" fourbar --ground 2.13e79 --crank 5.8e78 --coupler 1.89e79 --rocker 2.32e79 --samples 360 >"$TMP/x.csv" ||
  fail "1e80 four-bar sweep"
no_nonfinite "$TMP/x.csv" "1e80 four-bar sweep"
cmp -s <("$KIN" fourbar --ground 2.13e79 --crank 5.8e78 --coupler 1.89e79 --rocker 2.32e79 --samples 36 | cut -d, -f1-8) \
       <("$KIN" fourbar --ground 0.213 --crank 0.058 --coupler 0.189 --rocker 0.232 --samples 36 | cut -d, -f1-8) ||
  fail "1e80 four-bar angles and coefficients differ from the 0.2 m one"
# e -> 1 keeps the extreme-ratio flag.
"$KIN" batten-phase --e 0.999999 --step-deg 90 --samples 64 >/dev/null 2>"$TMP/err" || fail "batten-phase e near 1 exited $?"
grep -q "near 1" "$TMP/err" || fail "batten-phase e near 1 not flagged"

# ---- a double-rocker at the poses it reaches: the knotting chain's example -------------------------
# Links r0 = 78.105 (ground), r1 = 82.345 (input), r2 = 15.688 (coupler), r3 = 65.426 (output) mm, drawn
# at theta1 = 135 deg, theta2 = 10 deg. The pose and the rates from the example's own closed forms
# (diagonal s = r1 + r2, theta3 = theta_s + acos((s^2 + r3^2 - r0^2)/(2 s r3)), omega3/omega1 =
# (r1/r3) sin(theta1 - theta2)/sin(theta3 - theta2)), then the same pose through loom-kin.
read -r crank_deg branch w3 w2 < <(awk 'BEGIN {
  pi = atan2(0, -1); r = pi / 180
  r0 = 78.105; r1 = 82.345; r2 = 15.688; r3 = 65.426; t1 = 135 * r; t2 = 10 * r
  sx = r1 * cos(t1) + r2 * cos(t2); sy = r1 * sin(t1) + r2 * sin(t2); s = sqrt(sx * sx + sy * sy)
  c = (s * s + r3 * r3 - r0 * r0) / (2 * s * r3); t3 = atan2(sy, sx) + atan2(sqrt(1 - c * c), c)
  g = atan2(sy - r3 * sin(t3), sx - r3 * cos(t3))
  printf "%.15f %s %.15g %.15g\n", (t1 - g) / r, (sin(t2 - t3) > 0 ? "positive" : "negative"),
    r1 / r3 * sin(t1 - t2) / sin(t3 - t2), -r1 / r2 * sin(t1 - t3) / sin(t2 - t3) }')
"$KIN" fourbar --ground 78.105 --crank 82.345 --coupler 15.688 --rocker 65.426 --samples 1 \
  --start-deg "$crank_deg" --branch "$branch" >"$TMP/dr.csv" 2>"$TMP/err" || fail "double-rocker pose exited $?: $(cat "$TMP/err")"
awk -F, -v w3="$w3" -v w2="$w2" 'NR == 2 {
  if (w3 > -22.8505 || w3 < -22.8515) { print "closed form omega3/omega1 " w3 " is not -22.851"; bad = 1 }
  d3 = $5 - w3; d2 = $4 - w2
  if (d3 * d3 > 1e-14 || d2 * d2 > 1e-10) { print "k4 " $5 " vs " w3 ", k3 " $4 " vs " w2; bad = 1 }
  n = NR } END { exit bad || n != 2 }' "$TMP/dr.csv" || fail "double-rocker example: $(cat "$TMP/dr.csv")"
# Over a whole turn it prints the poses it reaches and says how many it left out (exit 0).
"$KIN" fourbar --ground 78.105 --crank 82.345 --coupler 15.688 --rocker 65.426 --samples 360 >"$TMP/dr.csv" 2>"$TMP/err" ||
  fail "double-rocker sweep exited $?: $(cat "$TMP/err")"
rows=$(($(wc -l <"$TMP/dr.csv") - 1))
grep -q "double-rocker's crank cannot reach every angle: $((360 - rows)) of 360 samples left out" "$TMP/err" ||
  fail "double-rocker sweep note ($rows rows): $(cat "$TMP/err")"
[ "$rows" -gt 0 ] && [ "$rows" -lt 360 ] || fail "double-rocker sweep rows: $rows"

# ---- slider-crank near a toggle: mu_min = acos((a + e)/b) = 0.0018 deg is warned about ----------
b=$(awk 'BEGIN { printf "%.17g", 2 / cos(0.0018 * atan2(0, -1) / 180) }')
"$KIN" slider-crank --crank 1 --coupler "$b" --offset 1 --summary >"$TMP/sc.csv" 2>"$TMP/err" || fail "slider-crank near toggle exit"
grep -q "warning: near toggle: the transmission angle reaches 0.0018 deg" "$TMP/err" ||
  fail "slider-crank near toggle not warned: $(cat "$TMP/err")"
awk -F, 'NR == 2 { d = $9 - 0.0018; exit (d * d > 1e-16) }' "$TMP/sc.csv" || fail "slider-crank mu_min: $(cat "$TMP/sc.csv")"
"$KIN" slider-crank --crank 1 --coupler 3 --summary >/dev/null 2>"$TMP/err"
[ -s "$TMP/err" ] && fail "slider-crank far from toggle warned: $(cat "$TMP/err")"

[ "$FAILS" -eq 0 ] && echo "loom-kin CLI contract: all checks passed"
[ "$FAILS" -eq 0 ]

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

# ---- issue 13 -------------------------------------------------------------------------------------
# The builder's own linkage: --config reads the loom's [beatup] section (keys as loomctl names them);
# the thesis values in a config reproduce the default run exactly, and an explicit length wins.
cat > "$TMP/loom.toml" <<'TOML'
extends = "default"
[loom]
id = "mine"
[beatup]
crank_m = 0.058
coupler_m = 0.189
rocker_m = 0.232
ground_m = 0.213
beater_arm_m = 0.301
beater_mass_kg = 2.5
[recipe]
beat_force_target_n = 90.0
TOML
"$BIN" beatup --crank-rad-s 15.5 --samples 36 > "$TMP/def.csv" || fail "beatup default"
"$BIN" beatup --config "$TMP/loom.toml" --crank-rad-s 15.5 --samples 36 > "$TMP/cfg.csv" || fail "beatup --config exit"
cmp -s "$TMP/def.csv" "$TMP/cfg.csv" || fail "beatup --config with the thesis values differs from the default"
"$BIN" beatup --config "$TMP/loom.toml" > "$TMP/cfgt.csv" || fail "beatup --config (target from config) exit"
"$BIN" beatup --target-force-n 90 > "$TMP/deft.csv" || fail "beatup target"
cmp -s "$TMP/cfgt.csv" "$TMP/deft.csv" || fail "the config's beat_force_target_n does not give the same speed"
"$BIN" beatup --config "$TMP/loom.toml" --crank-m 0.05 --crank-rad-s 15.5 --samples 36 > "$TMP/c5.csv" || fail "beatup --crank-m"
cmp -s "$TMP/c5.csv" "$TMP/def.csv" && fail "--crank-m did not change the linkage"
"$BIN" beatup --crank-m 0.05 --coupler-m 0.19 --rocker-m 0.23 --ground-m 0.21 --beater-kg 3 --crank-kg 0.2 \
  --crank-rad-s 15.5 --samples 36 > "$TMP/own.csv" || fail "beatup with explicit lengths and masses"
grep -qi 'nan\|inf' "$TMP/own.csv" && fail "own linkage non-finite"
"$BIN" balance --config "$TMP/loom.toml" --samples 36 --method counterweight > "$TMP/bc.csv" || fail "balance --config"
grep -q '^counterweight,crank,' "$TMP/bc.csv" || fail "balance --config rows"
sed 's/^crank_m = 0.058/crank_m = -0.058/' "$TMP/loom.toml" > "$TMP/bad.toml"
expect_bad "bad.toml:5:11: beatup.crank_m = -0.058: must be in" beatup --config "$TMP/bad.toml" --crank-rad-s 10
printf '[loom]\nid = "x"\n' > "$TMP/nobeat.toml"
expect_bad "missing: a config file must be complete" beatup --config "$TMP/nobeat.toml" --crank-rad-s 10
expect_bad --config beatup --config "$TMP/missing.toml" --crank-rad-s 10
# No NaN/inf with exit 0: an overflowing crank speed is refused, not printed and not a crash.
expect_bad "not finite" balance --crank-rad-s 1e100 --samples 12
expect_bad "non-finite" beatup --target-force-n 1e300
# The optimiser's trace file: evaluations it probed outside the model (a 1e300 kg counterweight bound
# drives the masses out of range) are left out and counted on stderr, never written as NaN/inf.
"$BIN" balance --samples 12 --max-evaluations 200 --max-counterweight-kg 1e300 --trace "$TMP/trace.csv" > "$TMP/bal.csv" 2> "$TMP/err" ||
  fail "balance with a huge bound exit: $(cat "$TMP/err")"
grep -Eiq '(^|[^a-z])[-+]?(nan|inf)([^a-z]|$)' "$TMP/trace.csv" "$TMP/bal.csv" && fail "balance --trace wrote NaN/inf"
grep -q "note: --trace: [1-9][0-9]* evaluations with a non-finite objective" "$TMP/err" ||
  fail "balance --trace did not count the left-out evaluations: $(cat "$TMP/err")"
# Equimomental point masses of the scraping machine's links (003 Table 1). Link 4 by hand: m = 1.706 kg,
# d = 0.1714 m, I_O = 0.06824 kg m^2: l = sqrt(I_O/m) = 0.2 m; facing the centre, m1 = (m/3)(1 + 2d/l)
# = 1.5433613 kg and m2 = m3 = (m/3)(1 - d/l) = 0.0813193 kg; every row rebuilds its own link.
"$BIN" equimomental > "$TMP/eq.csv" 2> "$TMP/err" || fail "equimomental exit: $(cat "$TMP/err")"
[ "$(wc -l < "$TMP/eq.csv")" -eq 8 ] || fail "equimomental rows: $(cat "$TMP/eq.csv")"
awk -F, 'NR == 5 {
  m = 1.706; d = 0.1714; l = 0.2
  if ($1 != "4" || ($6 - l)^2 > 1e-24 || ($7 - m / 3 * (1 + 2 * d / l))^2 > 1e-22 || ($8 - m / 3 * (1 - d / l))^2 > 1e-22) bad = 1 }
  NR > 1 && (($12 - $2)^2 > 1e-24 * $2^2 || ($13 - $3)^2 > 1e-24 || ($15 - $5)^2 > 1e-24 * $5^2 || $11 != "yes") { bad = 1 }
  END { exit bad }' "$TMP/eq.csv" || fail "equimomental values: $(cat "$TMP/eq.csv")"
"$BIN" equimomental --table balanced > /dev/null 2> "$TMP/err" || fail "equimomental balanced exit"
grep -q "link 5: inertia about the origin 0.0525 kg m^2 is below m d^2" "$TMP/err" ||
  fail "equimomental balanced: link 5 at the m d^2 <= I bound not flagged: $(cat "$TMP/err")"
expect_bad "--inertia" equimomental --mass 1
# e -> 1: the extreme-ratio flag.
"$BIN" batten --e 0.999999 --search --scan-points 8 --samples 64 > /dev/null 2> "$TMP/err" || fail "batten e near 1 exit"
grep -q "extreme ratio" "$TMP/err" || fail "batten --e 0.999999 --search not flagged: $(cat "$TMP/err")"
"$BIN" beatup --crank-rad-s 15.5 --cam-e 0.999999 --samples 12 > /dev/null 2> "$TMP/err" || fail "beatup cam-e near 1 exit"
grep -q "extreme ratio" "$TMP/err" || fail "beatup --cam-e 0.999999 not flagged: $(cat "$TMP/err")"
# ... already at e = 0.99: speed ratio (1+e)/(1-e) = 199 > 100 (gain 39601); e = 0.98 (ratio 99) is not flagged.
"$BIN" batten --e 0.99 --phi02-rad 0 --samples 64 > /dev/null 2> "$TMP/err" || fail "batten e 0.99 exit"
grep -q "extreme ratio" "$TMP/err" || fail "batten --e 0.99 not flagged: $(cat "$TMP/err")"
"$BIN" beatup --crank-rad-s 15.5 --cam-e 0.99 --samples 12 > /dev/null 2> "$TMP/err" || fail "beatup cam-e 0.99 exit"
grep -q "extreme ratio" "$TMP/err" || fail "beatup --cam-e 0.99 not flagged: $(cat "$TMP/err")"
"$BIN" batten --e 0.98 --phi02-rad 0 --samples 64 > /dev/null 2> "$TMP/err" || fail "batten e 0.98 exit"
grep -q "extreme ratio" "$TMP/err" && fail "batten --e 0.98 flagged: $(cat "$TMP/err")"
# Seed 004 per visit: two visits of the beat side per turn, each with its own gain; the beat's gain
# is one of them and none exceeds ((1+e)/(1-e))^2 = 2.25 at e = 0.2.
"$BIN" batten --e 0.2 --search --scan-points 60 > "$TMP/v.csv" || fail "batten per visit"
head -1 "$TMP/v.csv" | grep -q ',visits,visit1_crank_deg,visit1_gain,visit2_crank_deg,visit2_gain,beat_visit,beat_visit_gain$' ||
  fail "batten per-visit header: $(head -1 "$TMP/v.csv")"
awk -F, 'NR == 2 { if ($9 != 2) { print "visits " $9; exit 1 }
  if ($11 > 2.2500001 || $13 > 2.2500001 || $11 < 0.1975 || $13 < 0.1975) { print "visit gains " $11 " " $13; exit 1 }
  g = ($14 == 1) ? $11 : $13; if (g != $15) { print "beat visit gain"; exit 1 } }' "$TMP/v.csv" || fail "batten per-visit values"
# The needle's reactions on the paper's assembly by default; the mirror on request.
"$BIN" needle --samples 12 > "$TMP/n1.csv" || fail "needle default"
"$BIN" needle --samples 12 --rod-side standing > "$TMP/n2.csv" || fail "needle standing"
cmp -s "$TMP/n1.csv" "$TMP/n2.csv" && fail "loom-dynamics needle ignores the rod side"
echo "dynamics CLI contract: ok"

#!/usr/bin/env bash
# loomctl design fit end to end, with ImageMagick as the peer that draws and measures: an anti-aliased
# 40 x 20 drawing in the knotting loom's three yarn colours (ImageMagick's convert) is brought to the loom's
# 360 knots per row. Without a way to fit the width, or with two, it is refused naming the figures; with
# the default colour limit every colour ImageMagick counts in the drawing is mapped or listed in one go
# (nothing written); with a wide limit the knot map is written, the loom accepts it as its design
# (loomctl check), and the preview has the carpet's true aspect (ImageMagick's identify).
# usage: design_fit_cli.sh LOOMCTL SOURCE_DIR
set -euo pipefail
loomctl=$1
src=$2
fail() { printf 'FAIL: %s\n' "$*" >&2; exit 1; }
expect() {  # expect FILE TEXT
  grep -qF -- "$2" "$1" || { cat "$1" >&2; fail "$(basename "$1"): no line with: $2"; }
}
command -v convert >/dev/null || fail "ImageMagick's convert is not installed (tools/deps.sh installs it)"
out=$(mktemp -d "${TMPDIR:-/tmp}/loom_design_fit.XXXXXX")
trap 'rm -rf "$out"' EXIT
loom=$src/firmware/config/knotting_loom.toml

# An ivory ground, a madder-red disc and an indigo bar: ImageMagick anti-aliases the edges.
convert -size 40x20 xc:'#f3ead6' -fill '#a52a2a' -draw 'circle 12,10 12,3' -fill '#1f3a6e' \
  -draw 'polygon 24,0 29,0 33,19 28,19' -depth 8 "PNG24:$out/rug.png"
colours=$(identify -format '%k' "$out/rug.png")
(( colours > 10 )) || fail "the drawing has only $colours colours: not anti-aliased"

fit() {  # fit NAME ARGS... : runs design fit, stdout/stderr to NAME.out/NAME.err, prints the exit code
  local name=$1
  shift
  set +e
  "$loomctl" design fit "$@" >"$out/$name.out" 2>"$out/$name.err"
  echo $?
  set -e
}
nothing_written() { [[ ! -e $out/rug_map.csv && ! -e $out/rug_preview.png && ! -e $out/rug_map.png && ! -e $out/rug.csv ]] || fail "$1: a file was written"; ls "$out" | grep -q fit-new && fail "$1: a temporary file was left"; true; }

# No way to fit the width, and two at once: refused, naming the widths and the options.
[[ $(fit none "$out/rug.png" --loom "$loom" --out "$out/rug_map.csv" --preview "$out/rug_preview.png") == 2 ]] || fail "no mode accepted"
expect "$out/none.err" "rug.png: 40 knots wide; the loom ties 360 per row: give one of --tile (9 repeats), --scale"
[[ $(fit two "$out/rug.png" --loom "$loom" --tile --scale --out "$out/rug_map.csv") == 2 ]] || fail "--tile --scale accepted"
expect "$out/two.err" "--tile and --scale together: give one of --tile, --scale and --centre"
[[ $(fit ground "$out/rug.png" --loom "$loom" --centre --ground Q --out "$out/rug_map.csv") == 2 ]] || fail "--ground Q accepted"
expect "$out/ground.err" "--ground Q: not one of the yarns (R, I, B)"
[[ $(fit over "$out/rug.png" --loom "$loom" --tile --out "$out/rug.csv") == 2 ]] || fail "the picture was overwritten"
expect "$out/over.err" "--out/--preview would overwrite the picture $out/rug.png"
# A loom that names no yarns (the default: a flat weave, no design, no magazines).
[[ $(fit noyarns "$out/rug.png" --loom "$src/firmware/config/default_loom.toml" --scale --out "$out/rug_map.csv") == 2 ]] || fail "no yarns accepted"
expect "$out/noyarns.err" "default_loom.toml: recipe.design = \"\": no design whose palette names the loom's yarns"
[[ $(fit nomag "$out/rug.png" --loom "$src/firmware/config/default_loom.toml" --scale --palette-from-magazines --out "$out/rug_map.csv") == 2 ]] || fail "no magazines accepted"
expect "$out/nomag.err" "default_loom.toml: knotting.slot_colours = []: the loom has no magazine yarns for --palette-from-magazines"
nothing_written "refusals"

# The default limit: every colour of the drawing is mapped or listed, each once, in one run.
[[ $(fit strict "$out/rug.png" --loom "$loom" --palette-from-magazines --scale --out "$out/rug_map.csv" \
  --preview "$out/rug_preview.png") == 2 ]] || fail "the blended edges were all within the default limit (expected some unmapped)"
nothing_written "unmapped colours"
mapped=$(grep -c ' knots -> ' "$out/strict.out" || true)
unmapped=$(grep -c ' knots, e.g. at pixel (' "$out/strict.err" || true)
(( mapped + unmapped == colours )) || fail "mapped $mapped + listed $unmapped != the drawing's $colours colours"
expect "$out/strict.err" "further than ΔE00 10.0 from every yarn; nothing written:"
expect "$out/strict.out" "#a52a2a"
grep -q '^  #a52a2a .* -> R madder red #a52a2a (slot 0) *ΔE00  0.00' "$out/strict.out" || fail "red is not its own yarn"
# Each listed pixel has that colour in the drawing (ImageMagick reads it back).
while read -r hex x y; do
  got=$(convert "$out/rug.png" -format "%[hex:p{$x,$y}]" info:)
  [[ ${got,,} == "${hex#\#}"* ]] || fail "pixel ($x, $y) is #$got, listed as $hex"
done < <(sed -n 's/^  \(#[0-9a-f]*\) .* at pixel (\([0-9]*\), \([0-9]*\)).*/\1 \2 \3/p' "$out/strict.err")

# A wide limit: written, 360 x 180 knots, accepted by the loom as its design, the preview at the true aspect.
[[ $(fit wide "$out/rug.png" --loom "$loom" --palette-from-magazines --scale --max-delta-e 60 --out "$out/rug_map.csv" \
  --preview "$out/rug_preview.png") == 0 ]] || { cat "$out/wide.err" >&2; fail "the wide limit refused"; }
expect "$out/wide.out" "fit: scaled x9.00 to 180 rows (nearest pixel): 360 knots x 180 rows (1.20 m x 0.60 m)"
[[ $(grep -c '^[RIB]\(,[RIB]\)\{359\}$' "$out/rug_map.csv") == 180 ]] || fail "rug_map.csv is not 180 rows of 360 yarn codes"
[[ $(identify -format '%w %h' "$out/rug_preview.png") == "1440 720" ]] || fail "preview $(identify -format '%w x %h' "$out/rug_preview.png"), not 1440 x 720"
sed "s|^design = .*|design = \"$out/rug_map.csv\"|" "$loom" >"$out/loom.toml"
"$loomctl" check --config "$out/loom.toml" >"$out/check.txt" 2>&1 || { cat "$out/check.txt" >&2; fail "the loom refuses the fitted design"; }

# Rows of 40 per dm (knots 3/4 as tall as wide): 240 rows for the same 1.2 x 0.6 m, the same preview size.
sed -e 's|^\[knotting\]$|[knotting]\nrows_per_dm = 40.0|' "$loom" >"$out/tall.toml"
sed -i "s|^design = \"designs/|design = \"$src/firmware/config/designs/|" "$out/tall.toml"
[[ $(fit tall "$out/rug.png" --loom "$out/tall.toml" --scale --max-delta-e 60 --out "$out/tall.csv") == 0 ]] || { cat "$out/tall.err" >&2; fail "tall refused"; }
[[ $(grep -c '^[RIB]' "$out/tall.csv") == 240 ]] || fail "tall.csv does not have 240 rows"
[[ $(identify -format '%w %h' "$out/tall.png") == "1440 720" ]] || fail "tall preview $(identify -format '%w x %h' "$out/tall.png")"

# Tiled and centred: the width filled, the rows as drawn; a centred picture on its ground.
[[ $(fit tile "$out/rug.png" --loom "$loom" --tile --max-delta-e 60 --out "$out/tile.csv") == 0 ]] || fail "tile refused"
[[ $(grep -c '^[RIB]' "$out/tile.csv") == 20 ]] || fail "tile.csv does not have 20 rows"
[[ $(fit centre "$out/rug.png" --loom "$loom" --centre --ground I --max-delta-e 60 --out "$out/centre.csv") == 0 ]] || fail "centre refused"
expect "$out/centre.out" "centred: 160 knots of ground on the left, 160 on the right"
expect "$out/centre.out" "ground I: 6400 knots"
grep -q '^\(I,\)\{160\}' "$out/centre.csv" || fail "centre.csv does not start with 160 ground knots"

# A CSV picture: an unmapped colour is named at its file:line:col.
printf 'palette,R,#a52a2a\npalette,G,#2e8b57\nR,R,G,R\nR,G,R,R\n' >"$out/small.csv"
[[ $(fit csv "$out/small.csv" --loom "$loom" --tile --out "$out/small_out.csv") == 2 ]] || fail "green accepted"
expect "$out/csv.err" "#2e8b57      180 knots, e.g. at $out/small.csv:3:5"
[[ ! -e $out/small_out.csv ]] || fail "small_out.csv written"
echo "design_fit_cli: PASS"

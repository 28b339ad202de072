#!/usr/bin/env bash
# Every numeric option of every offline tool, fed the values that break numerics: NaN, ±inf, ±0,
# ±denormal, 1e-300 and ±1e300. Each run must end in a typed refusal (exit 2 with a message on stderr)
# or in finite output (exit 0, no NaN/inf on stdout or in any file it wrote) — never a crash, an abort,
# a hang, or NaN/inf with exit 0.
# The subcommands and their numeric options are read from each tool's --help, so a new subcommand
# without a baseline below fails the test, and a new numeric option is swept without anyone adding it.
#   option_sweep_test.sh SRC_DIR LOOM_KIN LOOM_SYNTH LOOM_DYNAMICS LOOM_PROFILE
set -uo pipefail
src=$1
declare -A tool=([loom-kin]=$2 [loom-synth]=$3 [loom-dynamics]=$4 [loom-profile]=$5)
work=$(mktemp -d /tmp/loom_option_sweep.XXXXXX)
trap 'rm -rf "$work"' EXIT
out=$work/out
failures=0
runs=0
last_rc=0
expect_stdout=0
declare -A stdout_of=()
fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}

# Cheap, valid invocations per subcommand ("tool sub"); ';' separates alternatives (options that
# exclude each other get a baseline each). @OUT@ is a scratch directory whose files are checked too.
declare -A base=(
  ["loom-kin fourbar"]="--crank 0.3 --coupler 1 --rocker 0.8 --samples 8 --point-link coupler --point-x 0.1 --point-y 0.1"
  ["loom-kin slider-crank"]="--crank 1 --coupler 3 --samples 8"
  ["loom-kin needle"]="--samples 8 --rates"
  ["loom-kin batten"]="--samples 8 --pose"
  ["loom-kin batten-phase"]="--samples 16 --step-deg 45"
  ["loom-synth slider-crank"]="--phi 120"
  ["loom-synth crank-rocker"]="--psi 45 --phi 190 --beta 20"
  ["loom-synth design"]="--stroke 1 --phi 120;--swing 45 --phi 190 --beta 20"
  ["loom-synth three-point"]="--theta0-deg 275 --point 0,0,10 --point 25,15,3 --point 30,1,-25"
  ["loom-synth knotter"]=""
  ["loom-dynamics beatup"]="--crank-rad-s 15.5 --samples 8 --extra --svg @OUT@/b.svg;--target-force-n 90 --samples 8"
  ["loom-dynamics needle"]="--samples 8 --svg @OUT@/n.svg"
  ["loom-dynamics batten"]="--phi02-rad 0 --samples 32;--search --scan-points 6 --samples 32"
  ["loom-dynamics balance"]="--samples 8 --max-evaluations 20 --trace @OUT@/t.csv --svg-force @OUT@/f.svg --svg-moment @OUT@/m.svg"
  ["loom-dynamics mass"]=""
  ["loom-dynamics equimomental"]="--mass 1 --inertia 0.1 --centre-d 0.1;--table original"
  ["loom-profile report"]="--out @OUT@/r --sizes 16 --min-time 0.0001 --repetitions 1 --check-points 16"
  ["loom-profile dump"]="--config $src/firmware/config/default_loom.toml --out @OUT@/d --crank-law elliptic --table-size 256"
)
# Text options that carry numbers: the sweep value replaces the first number in them.
declare -A numeric_text=([--point]=1 [--phi-range]=1)

values=(nan -nan inf -inf 0 -0 4.9e-324 -4.9e-324 1e-300 1e300 -1e300)
# LOOM_SWEEP_VALUES="v1 v2 ..." sweeps a subset (the sanitizer build's, see CMakeLists.txt); "all" or unset: all.
if [[ -n ${LOOM_SWEEP_VALUES:-} && $LOOM_SWEEP_VALUES != all ]]; then
  read -r -a values <<<"$LOOM_SWEEP_VALUES"
fi
bad_token='(^|[^a-z])[-+]?(nan|inf|infinity)([^a-z]|$)'

subcommands() {  # the names under "Subcommands:" in a tool's --help
  "$1" --help | awk '/^Subcommands:/ { on = 1; next } on && /^  [a-z]/ { print $1 }'
}
numeric_options() {  # "--name" of every option whose type is a number (or a number in text)
  "$1" "$2" --help | awk '
    /^  *--[a-z0-9-]+ (FLOAT|INT|UINT|NUMBER)/ { print $1; next }
    /^  *--[a-z0-9-]+ TEXT/ { print $1 " text" }'
}

# Replace (or append) --opt VALUE in an argument list.
with_value() {  # with_value OPT VALUE ARGS...
  local opt=$1 val=$2
  shift 2
  local -a res=()
  local replaced=0
  while (($#)); do
    if [[ $1 == "$opt" && $replaced == 0 ]]; then
      if [[ -n ${numeric_text[$opt]:-} ]]; then
        res+=("$opt=$(sed -E "s/^[-+0-9.eE]+/$val/" <<<"$2")")
      else
        res+=("$opt=$val")
      fi
      replaced=1
      shift 2
      continue
    fi
    res+=("$1")
    shift
  done
  ((replaced)) || res+=("$opt=$val")
  printf '%s\n' "${res[@]}"
}

check_run() {  # check_run LABEL TOOL ARGS...
  local label=$1
  shift
  rm -rf "$out"
  mkdir -p "$out"
  runs=$((runs + 1))
  timeout 60 "$@" >"$work/stdout" 2>"$work/stderr"
  local rc=$?
  last_rc=$rc
  case $rc in
    0)
      if ((expect_stdout)) && [[ ! -s $work/stdout ]]; then
        fail "$label: exit 0 with nothing on stdout (the baseline prints a result)"
      fi
      if grep -Eiq "$bad_token" "$work/stdout"; then
        fail "$label: exit 0 with NaN/inf on stdout: $(grep -Eim1 "$bad_token" "$work/stdout")"
      fi
      local f
      while IFS= read -r -d '' f; do
        if grep -Eiq "$bad_token" "$f"; then
          fail "$label: exit 0 with NaN/inf in ${f#"$out"/}: $(grep -Eim1 -o ".{0,40}$bad_token.{0,20}" "$f" | head -1)"
        fi
      done < <(find "$out" -type f -print0)
      ;;
    2)
      [[ -s $work/stderr ]] || fail "$label: exit 2 without a message on stderr"
      ;;
    124) fail "$label: still running after 60 s" ;;
    *) fail "$label: exit $rc (neither a result nor a typed refusal): $(head -c 300 "$work/stderr")" ;;
  esac
}

sweep_tool() {  # sweep_tool TOOL: every subcommand and numeric option of one tool
  local t=$1 exe=${tool[$1]} sub key alt opt kind v
  local -a subs alternatives args argv
  mapfile -t subs < <(subcommands "$exe")
  ((${#subs[@]} > 0)) || fail "$t: no subcommands found in --help"
  for sub in "${subs[@]}"; do
    key="$t $sub"
    if [[ ! -v base[$key] ]]; then
      fail "$key: no baseline invocation in option_sweep_test.sh (add one)"
      continue
    fi
    IFS=';' read -r -a alternatives <<<"${base[$key]}"
    ((${#alternatives[@]} > 0)) || alternatives=("")
    # The baselines themselves must succeed, or the sweep proves nothing.
    for alt in "${alternatives[@]}"; do
      read -r -a args <<<"${alt//@OUT@/$out}"
      expect_stdout=0
      check_run "$key ${alt//@OUT@/OUT} (baseline)" "$exe" "$sub" "${args[@]}"
      ((last_rc == 0)) || fail "$key baseline '${alt//@OUT@/OUT}' did not succeed: $(head -c 300 "$work/stderr")"
      [[ -s $work/stdout ]] && stdout_of["k$alt"]=1 || stdout_of["k$alt"]=0
    done
    while read -r opt kind; do
      [[ -z $opt ]] && continue
      [[ $kind == text && -z ${numeric_text[$opt]:-} ]] && continue
      for alt in "${alternatives[@]}"; do
        read -r -a args <<<"${alt//@OUT@/$out}"
        expect_stdout=${stdout_of["k$alt"]}
        for v in "${values[@]}"; do
          mapfile -t argv < <(with_value "$opt" "$v" "${args[@]}")
          check_run "$key $opt=$v (baseline: ${alt//@OUT@/OUT})" "$exe" "$sub" "${argv[@]}"
        done
      done
    done < <(numeric_options "$exe" "$sub")
  done
}

# Two tools at a time (the machine has two cores), each in its own scratch directory.
run_group() {  # run_group NAME TOOL...
  local name=$1
  shift
  work=$work_root/$name
  out=$work/out
  mkdir -p "$work"
  for t in "$@"; do sweep_tool "$t"; done
  echo "$runs $failures" >"$work_root/$name.count"
}
work_root=$work
run_group a loom-dynamics loom-synth &
run_group b loom-kin loom-profile &
wait
read -r runs_a failures_a <"$work_root/a.count" || failures_a=1
read -r runs_b failures_b <"$work_root/b.count" || failures_b=1
echo "option sweep: $((runs_a + runs_b)) runs (values: ${values[*]}), $((failures_a + failures_b)) failures"
((failures_a + failures_b == 0))

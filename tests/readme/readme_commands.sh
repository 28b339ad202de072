#!/usr/bin/env bash
# The docs cannot drift from the tools: every command line that any Markdown file of the repository
# (tests/readme/markdown_files.sh: every *.md outside build trees and fuzz corpora) shows in a code block
# (```sh/```bash blocks, and "$ "-prompted lines in plain ones) that runs one of ours is checked against
# the real thing —
#   loomctl / build/bin/<tool> [subcommand]: the subcommand exists and every --option on the line is in
#     that (sub)command's --help;
#   a command word after a subcommand (loomctl ctl next) is among those its --help lists;
#   tools/..., tests/... scripts: the file exists and is executable, a subcommand word (tools/loom test)
#     and every --option on the line appear in the script.
# Lines inside other blocks (TOML, CSV, output) are not commands and are skipped.
# Usage: readme_commands.sh SOURCE_DIR BUILD_DIR
set -uo pipefail
src=$1
build=$2
md=""  # the file being read, relative to src
fails=0 checked=0
fail() { echo "$md:$1: $2" >&2; fails=$((fails + 1)); }

# --help of a binary (or of one of its subcommands) into $HELP, asked once per run: the docs repeat
# programs. (Not a $(...) function: a subshell would forget the cache.)
declare -A help_cache=()
HELP=""
load_help() {  # BIN [SUBCOMMAND]
  local key="$1 ${2:-}"
  if [[ -z ${help_cache[$key]+set} ]]; then
    help_cache[$key]=$("$1" ${2:+"$2"} --help 2>&1 </dev/null)
  fi
  HELP=${help_cache[$key]}
}

# Subcommands listed in a --help text (first word after the program that names one).
subcommands_in() {
  awk '/^Subcommands:/{on=1; next} on && /^  [a-z]/{print $1} on && /^$/{on=0}' <<<"$1"
}

check_binary_line() {  # LINE_NO PROGRAM ARGS...
  local n=$1 prog=$2
  shift 2
  local bin=$build/bin/$prog
  [[ -x $bin ]] || { fail "$n" "'$prog' is not built (no $bin)"; return; }
  local subs sub="" help
  load_help "$bin"
  subs=$(subcommands_in "$HELP")
  if [[ -n $subs && $# -gt 0 && $1 != -* ]]; then
    if grep -qx -- "$1" <<<"$subs"; then
      sub=$1
    else
      fail "$n" "'$prog $1': no such subcommand (has: $(tr '\n' ' ' <<<"$subs"))"
      return
    fi
  fi
  load_help "$bin" "$sub"
  help=$HELP
  # A subcommand that takes a command word (loomctl ctl status): the word is in its help.
  if [[ -n $sub && $# -gt 1 && $2 =~ ^[a-z]+$ ]] && grep -q '^Positionals:' <<<"$help"; then
    grep -qw -- "$2" <<<"$help" || fail "$n" "'$prog $sub $2': '$2' is not among the commands its --help lists"
  fi
  local a opt
  for a in "$@"; do
    [[ $a == --* ]] || continue
    opt=${a%%=*}
    grep -q -- "$opt\b" <<<"$help" || fail "$n" "'$prog${sub:+ $sub}' has no option $opt"
  done
  checked=$((checked + 1))
}

check_script_line() {  # LINE_NO PATH ARGS...
  local n=$1 path=$2
  shift 2
  [[ -f $src/$path ]] || { fail "$n" "$path does not exist"; return; }
  [[ -x $src/$path ]] || { fail "$n" "$path is not executable"; return; }
  # A subcommand word (tools/loom test): the script handles it.
  if [[ $# -gt 0 && $1 =~ ^[a-z][a-z0-9-]*$ ]]; then
    grep -qw -- "$1" "$src/$path" || fail "$n" "$path does not know '$1'"
  fi
  local a
  for a in "$@"; do
    [[ $a == --* ]] || continue
    grep -q -- "${a%%=*}" "$src/$path" || fail "$n" "$path does not know ${a%%=*}"
  done
  checked=$((checked + 1))
}

check_line() {  # LINE_NO TEXT
  local n=$1 text=$2
  text=${text%%#*}                     # a comment
  text=${text#\$ }                     # a prompt
  local -a w
  read -r -a w <<<"$text" || true
  [[ ${#w[@]} -gt 0 ]] || return 0
  [[ ${w[0]} == sudo ]] && w=("${w[@]:1}")
  [[ ${#w[@]} -gt 0 ]] || return 0
  local prog=${w[0]}
  case $prog in
    loomctl) check_binary_line "$n" loomctl "${w[@]:1}" ;;
    build/bin/*) check_binary_line "$n" "${prog#build/bin/}" "${w[@]:1}" ;;
    tools/*|tests/*) check_script_line "$n" "$prog" "${w[@]:1}" ;;
    *) ;;  # someone else's tool (ip, systemctl, candump, cyclictest ...)
  esac
}

check_file() {  # reads $src/$md
  local lang="" inblock=0 n=0 pending="" pending_at=0 line
  while IFS= read -r line || [[ -n $line ]]; do
    n=$((n + 1))
    if [[ $line =~ ^\`\`\`([a-z]*)$ ]]; then
      if ((inblock)); then inblock=0; else inblock=1; lang=${BASH_REMATCH[1]}; fi
      continue
    fi
    ((inblock)) || continue
    [[ $lang == sh || $lang == bash || ( -z $lang && $line == '$ '* ) || -n $pending ]] || continue
    # Join backslash continuations into one command.
    if [[ $line == *\\ ]]; then
      [[ -z $pending ]] && pending_at=$n
      pending+="${line%\\} "
      continue
    fi
    if [[ -n $pending ]]; then
      check_line "$pending_at" "$pending$line"
      pending=""
    else
      check_line "$n" "$line"
    fi
  done <"$src/$md"
}

files=0
while IFS= read -r md; do
  check_file
  files=$((files + 1))
done < <("$(dirname "$0")/markdown_files.sh" "$src")

echo "readme_commands: $checked command lines in $files Markdown files checked, $fails problems"
((checked >= 20)) || { echo "FAIL: only $checked command lines found: is the docs' format still what this script reads?" >&2; exit 1; }
((fails == 0))

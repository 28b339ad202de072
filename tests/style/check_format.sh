#!/usr/bin/env bash
# The format check (.clang-format): every C++ file of the repository is as clang-format writes it,
# except the files listed in unformatted.txt — code from before the check, reformatted when next worked
# on. The list only shrinks: a listed file that is now formatted, or no longer exists, fails the check
# until it is taken off, so nothing slips back. A new file is checked from its first commit.
# usage: check_format.sh SOURCE_DIR            (exit 1 names every file to fix; 2 = no clang-format)
#        check_format.sh SOURCE_DIR --fix FILE...   reformats FILE... in place
set -euo pipefail
src=$(cd "${1:?usage: check_format.sh SOURCE_DIR}" && pwd)
list=$src/tests/style/unformatted.txt
command -v clang-format >/dev/null || { echo "check_format: clang-format is not installed (tools/deps.sh installs it)" >&2; exit 2; }
if [[ ${2:-} == --fix ]]; then
  shift 2
  (cd "$src" && clang-format -i "$@")
  exit 0
fi
cd "$src"
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h' | sort)
else
  mapfile -t files < <(find . -path ./build -prune -o -path './build-*' -prune -o \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) -print | sed 's|^\./||' | sort)
fi
declare -A legacy=()
while IFS= read -r f; do
  [[ -z $f || $f == \#* ]] && continue
  legacy[$f]=1
done <"$list"
status=0
# One clang-format per file, two at a time; prints the files that differ.
mapfile -t differ < <(printf '%s\0' "${files[@]}" |
  xargs -0 -P 2 -n 8 sh -c 'for f; do clang-format --dry-run -Werror "$f" >/dev/null 2>&1 || echo "$f"; done' sh | sort)
declare -A is_differ=()
for f in "${differ[@]}"; do is_differ[$f]=1; done
for f in "${differ[@]}"; do
  if [[ -z ${legacy[$f]:-} ]]; then
    echo "check_format: $f is not as clang-format writes it (tests/style/check_format.sh . --fix $f)"
    status=1
  fi
done
for f in "${!legacy[@]}"; do
  if [[ ! -e $f ]]; then
    echo "check_format: $f is listed in tests/style/unformatted.txt but no longer exists: take it off"
    status=1
  elif [[ -z ${is_differ[$f]:-} ]]; then
    echo "check_format: $f is formatted now: take it off tests/style/unformatted.txt"
    status=1
  fi
done
echo "check_format: ${#files[@]} files, ${#differ[@]} not yet formatted (all listed: $((status == 0)))"
exit "$status"

#!/usr/bin/env bash
# The format check (.clang-format): every C++ file of the repository is as clang-format writes it, and
# no line of it is longer than the project's 110 columns (clang-format leaves long string literals and
# comments it cannot break, so the column limit is checked on its own).
# usage: check_format.sh SOURCE_DIR            (exit 1 names every file or line to fix; 2 = no clang-format)
#        check_format.sh SOURCE_DIR --fix FILE...   reformats FILE... in place
set -euo pipefail
src=$(cd "${1:?usage: check_format.sh SOURCE_DIR}" && pwd)
readonly max_columns=110
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
status=0
# One clang-format per file, two at a time; prints the files that differ.
mapfile -t differ < <(printf '%s\0' "${files[@]}" |
  xargs -0 -P 2 -n 8 sh -c 'for f; do clang-format --dry-run -Werror "$f" >/dev/null 2>&1 || echo "$f"; done' sh | sort)
for f in "${differ[@]}"; do
  echo "check_format: $f is not as clang-format writes it (tests/style/check_format.sh . --fix $f)"
  status=1
done
# Columns are counted in characters, not bytes (comments carry "°", "–", "≤"): grep in a UTF-8 locale does
# (Debian's default awk, mawk, counts bytes).
mapfile -t long_lines < <(LC_ALL=C.UTF-8 grep -nE "^.{$((max_columns + 1)),}" "${files[@]}" | cut -d: -f1,2)
for line in "${long_lines[@]}"; do
  echo "check_format: $line: longer than $max_columns columns"
  status=1
done
echo "check_format: ${#files[@]} files, ${#differ[@]} not as clang-format writes them, ${#long_lines[@]} lines over $max_columns columns"
exit "$status"

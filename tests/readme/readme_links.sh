#!/usr/bin/env bash
# Every relative link in every Markdown file of the repository (tests/readme/markdown_files.sh) leads
# somewhere: the file or folder exists, and a #fragment into a Markdown file names one of its headings
# (GitHub's anchors: lower case, punctuation dropped, spaces to '-'). Code blocks are skipped.
# Usage: readme_links.sh SOURCE_DIR
set -uo pipefail
src=$1
fails=0 links=0

# The anchors of one Markdown file, one per line.
anchors_of() {
  awk '/^```/{code=!code; next} !code && /^#+ /{sub(/^#+ +/, ""); print}' "$1" |
    tr '[:upper:]' '[:lower:]' | sed -e 's/[^[:alnum:] _-]//g' -e 's/ /-/g'
}

while IFS= read -r md; do
  dir=$(dirname "$md")
  # "LINE<TAB>TARGET" for every ](target) outside code blocks.
  while IFS=$'\t' read -r n target; do
    case $target in http://*|https://*|mailto:*) continue ;; esac
    links=$((links + 1))
    path=${target%%#*}
    frag=""
    [[ $target == *#* ]] && frag=${target#*#}
    if [[ -z $path ]]; then file=$md; else file=$dir/$path; fi
    if [[ ! -e $src/$file ]]; then
      echo "$md:$n: link to $target: $file does not exist" >&2; fails=$((fails + 1)); continue
    fi
    if [[ -n $frag && $file == *.md ]] && ! anchors_of "$src/$file" | grep -qxF -- "$frag"; then
      echo "$md:$n: link to $target: $file has no heading with the anchor #$frag" >&2; fails=$((fails + 1))
    fi
  done < <(awk '/^```/{code=!code; next} !code {
             line = $0
             while (match(line, /\]\([^) \t]+\)/)) {
               print NR "\t" substr(line, RSTART + 2, RLENGTH - 3)
               line = substr(line, RSTART + RLENGTH)
             }
           }' "$src/$md")
done < <("$(dirname "$0")/markdown_files.sh" "$src")

echo "readme_links: $links relative links checked, $fails broken"
((links >= 20)) || { echo "FAIL: only $links links found: is the docs' format still what this script reads?" >&2; exit 1; }
((fails == 0))

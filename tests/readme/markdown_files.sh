#!/usr/bin/env bash
# Every Markdown file of the product under SOURCE_DIR, one path per line (relative, sorted): build trees,
# git's own folder and fuzz corpora (inputs, not docs) left out. Shared by the README tests and
# tools/doctables/regen.sh so they read the same files.
# Usage: markdown_files.sh SOURCE_DIR
set -euo pipefail
cd "$1"
find . \( -path ./.git -o -path './build*' -o -path '*/corpus' -o -path '*/campaign' -o -name node_modules \) -prune \
  -o -type f -name '*.md' -print | sed 's|^\./||' | LC_ALL=C sort

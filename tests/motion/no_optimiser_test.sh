#!/bin/sh
# The firmware links the runtime kernel only: loomctl must not need an optimiser library (NLopt lives
# in loom::motion_design, which only the offline tools link). Reads the ELF dynamic section, so it
# checks what the loader would load, not what the build files say.
set -eu
exe=${1:?usage: no_optimiser_test.sh path/to/loomctl}
[ -x "$exe" ] || { echo "FAIL: $exe is not an executable (build loomctl first)"; exit 1; }
needed=$(readelf -d "$exe" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
[ -n "$needed" ] || { echo "FAIL: readelf found no NEEDED entries in $exe"; exit 1; }
echo "$exe needs: $(echo $needed)"
if echo "$needed" | grep -qi 'nlopt'; then
  echo "FAIL: loomctl links an optimiser library"
  exit 1
fi
# Also what the loader actually resolves (transitive dependencies), when ldd can run it.
if command -v ldd >/dev/null 2>&1 && ldd "$exe" >/dev/null 2>&1; then
  if ldd "$exe" | grep -qi 'nlopt'; then
    echo "FAIL: ldd resolves an optimiser library for loomctl"
    exit 1
  fi
fi
echo "PASS: no optimiser in loomctl"

#!/usr/bin/env bash
# Checks that every public header compiles on its own (includes what it uses), in both modes of
# the precompiled packages: header-only, and with CMGEOM_COMPACT_MODEL_PRECOMPILED and
# CMGEOM_TEXTURED_SIMPLIFICATION_PRECOMPILED (as programs linking CMGeom::Compact_model see it). Syntax and semantic checks only (-fsyntax-only), two
# headers at a time. Not part of the CI run (about 10 min on 2 cores); run it after adding or
# reorganising headers.
# Usage: bash scripts/check-headers.sh [header ...]   (default: every header under include/)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [[ $# -gt 0 ]]; then
  printf '%s\n' "$@" > "$work/list"
else
  (cd include && find CMGeom -name '*.h' | sort) > "$work/list"
fi
check() {
  local header=$1 mode=$2 root=$3 work=$4
  local name defines=()
  name=$(echo "$header" | tr '/.' '__')_$mode
  [[ $mode == precompiled ]] &&
    defines+=(-DCMGEOM_COMPACT_MODEL_PRECOMPILED=1 -DCMGEOM_TEXTURED_SIMPLIFICATION_PRECOMPILED=1)
  printf '#include <%s>\n' "$header" > "$work/$name.cpp"
  if ! g++ -std=c++17 -fsyntax-only -DCGAL_EIGEN3_ENABLED -DCGAL_USE_GMPXX=1 "${defines[@]}" \
       -I"$root/include" -isystem /usr/include/eigen3 "$work/$name.cpp" 2> "$work/$name.err"; then
    echo "FAIL ($mode) $header"
    head -5 "$work/$name.err"
    return 1
  fi
}
export -f check
failed=0
for mode in header-only precompiled; do
  xargs -P 2 -I{} bash -c 'check "$@"' _ {} "$mode" "$root" "$work" < "$work/list" || failed=1
done
n=$(wc -l < "$work/list")
if [[ $failed == 0 ]]; then
  echo "all $n headers compile on their own (header-only and precompiled modes)"
else
  echo "some headers do not compile on their own (see above)"
  exit 1
fi

#!/usr/bin/env bash
# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
#
# CMGeom's textured simplification side by side with meshoptimizer peers (0.18 from Debian, 1.3.0
# from npm in three variants): writes benchmark/Textured_simplification/RESULTS-peers.md through
# run_textured_peers.py (see its header for what is measured and how).
#
# Usage: bash benchmark/Textured_simplification/run_textured_peers.sh <build-dir> [--quick] [--peer-build DIR]
#   build-dir     holds bin/cmgeom (built beforehand: cmake --build <build-dir> --target cmgeom)
#   --quick       spot and fuze at 10 % only
#   --peer-build  build dir configured with -DCMGEOM_BUILD_BENCHMARKS=ON in which the peer program
#                 meshopt018_simplify is built (default: build-dir); only that target is built
# Installs the npm package of peers/ when missing (node and npm needed; without them the mo13-*
# columns are "n/a", said in the table). Needs python3; the models of ../shared/data/textured
# (or $CMGEOM_DATA_DIR/textured).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
usage="usage: run_textured_peers.sh <build-dir> [--quick] [--peer-build DIR]"
build="${1:?$usage}"
shift
quick=0
peer_build="$build"
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1 ;;
    --peer-build) peer_build="${2:?--peer-build needs a directory}"; shift ;;
    *) echo "run_textured_peers.sh: unknown argument '$1'" >&2; echo "$usage" >&2; exit 2 ;;
  esac
  shift
done
build="$(cd "$build" && pwd)"
peer_build="$(cd "$peer_build" && pwd)"
if [ ! -x "$build/bin/cmgeom" ]; then
  echo "run_textured_peers.sh: no $build/bin/cmgeom; build it first: cmake --build $build --target cmgeom" >&2
  exit 1
fi

# meshoptimizer 1.3.0 (npm)
peers="$here/peers"
if command -v node >/dev/null 2>&1 && command -v npm >/dev/null 2>&1; then
  have=$(node -p "try { require('$peers/node_modules/meshoptimizer/package.json').version } catch (e) { '' }" 2>/dev/null || true)
  if [ "$have" != "1.3.0" ]; then
    echo "installing meshoptimizer 1.3.0 in $peers (npm)" >&2
    if ! npm install --prefix "$peers" --no-audit --no-fund --loglevel=error >/dev/null; then
      echo "run_textured_peers.sh: npm install failed in $peers: the mo13-* columns will be n/a" >&2
    fi
  fi
else
  echo "run_textured_peers.sh: node or npm not found: the mo13-* columns will be n/a" >&2
fi

# meshoptimizer 0.18 (Debian): the peer program, built alone
if grep -q '^CMGEOM_BUILD_BENCHMARKS:BOOL=ON' "$peer_build/CMakeCache.txt" 2>/dev/null; then
  cmake --build "$peer_build" --target meshopt018_simplify >&2
else
  echo "run_textured_peers.sh: $peer_build is not configured with -DCMGEOM_BUILD_BENCHMARKS=ON:" \
       "meshopt018_simplify is not built and its column will be n/a (see --peer-build)" >&2
fi

args=()
if [ "$quick" = 1 ]; then args+=(--models spot,fuze --ratios 0.1); fi
exec python3 "$here/run_textured_peers.py" "$build" --meshopt018 "$peer_build/bin/meshopt018_simplify" \
  --out "$here/RESULTS-peers.md" "${args[@]}"

#!/usr/bin/env bash
# Writes benchmark/Cage_deformation/RESULTS.md: coordinate speed (bind, deform, 1 and 2 threads) and
# the *Cages tables (thesis Table 5.2 style: memory and times of grid systems and the prism twist
# against the single union cage, for several h, mean value and Green).
#   bash benchmark/Cage_deformation/run.sh <build-dir> [--quick]   (called by benchmark/run.sh)
set -euo pipefail
build=${1:?usage: run.sh <build-dir> [--quick]}
here=$(cd "$(dirname "$0")" && pwd)
data=${CMGEOM_DATA_DIR:-$here/../../../shared/data}
quick=()
[[ "${2:-}" == "--quick" ]] && quick=(--quick)
. "$here/../common/describe_run.sh"
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
{
  echo "# Cage_deformation benchmark results"
  echo
  echo "Programs \`benchmark/Cage_deformation/bench_cage_deformation.cpp\` and \`bench_cage_system.cpp\`,"
  echo "run by \`bash benchmark/Cage_deformation/run.sh <build> ${2:-}\`. No peer: CMGeom's own coordinates only."
  echo
  describe_run --threads "1 and 2 (per column)"
  echo
  echo "## Coordinates: binding and deformation"
  echo
  "$build/bin/bench_Cage_deformation" "${quick[@]}" "$data"
  echo
  echo "## *Cages against one cage"
  echo
  "$build/bin/bench_Cage_system" "${quick[@]}" "$data"
} > "$tmp"
mv "$tmp" "$here/RESULTS.md"

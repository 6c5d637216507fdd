#!/usr/bin/env bash
# Writes benchmark/Metrics/RESULTS.md: Metro-style error against CGAL's Hausdorff distance at
# equal sample counts (1 and 2 threads) and the renderer's speed.
#   bash benchmark/Metrics/run.sh <build-dir> [--quick]     (called by benchmark/run.sh)
set -euo pipefail
build=${1:?usage: run.sh <build-dir> [--quick]}
here=$(cd "$(dirname "$0")" && pwd)
data=${CMGEOM_DATA_DIR:-$here/../../../shared/data}
reps=5
[[ "${2:-}" == "--quick" ]] && reps=2
. "$here/../common/describe_run.sh"
line=$(describe_run --threads "1 and 2 (per column)" cgal)
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
"$build/bin/bench_Metrics" "$data" "$reps" > "$tmp"
{
  echo "# Metrics and Rendering benchmark results"
  echo
  echo "Program \`benchmark/Metrics/bench_metrics.cpp\`, run by \`bash benchmark/Metrics/run.sh <build> ${2:-}\`"
  echo "($reps runs of each measurement: \"min / median\"). Both directions of the error,"
  echo "AABB-tree construction included, the same vertex/edge/face sample counts for CMGeom and CGAL."
  echo
  echo "$line"
  echo
  cat "$tmp"
} > "$here/RESULTS.md.tmp"
mv "$here/RESULTS.md.tmp" "$here/RESULTS.md"

#!/usr/bin/env bash
# Writes benchmark/Deformable_compact_model/RESULTS.md (thesis Tables 6.1-6.3 style): memory and
# time per deformation of the original mesh, the simplified base, the CM reconstructed then
# deformed, and the deformable CM, with their Metro error against the deformed original.
#   bash benchmark/Deformable_compact_model/run.sh <build-dir> [--quick]   (called by benchmark/run.sh)
set -euo pipefail
build=${1:?usage: run.sh <build-dir> [--quick]}
here=$(cd "$(dirname "$0")" && pwd)
data=${CMGEOM_DATA_DIR:-$here/../../../shared/data}
models=()
[[ "${2:-}" == "--quick" ]] && models=(camel.off:1000)
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
"$build/bin/bench_deformable_compact_model" "$data" "${models[@]}" > "$tmp"
{
  echo "# Deformable_compact_model benchmark results"
  echo
  echo "Program \`benchmark/Deformable_compact_model/bench_deformable_compact_model.cpp\`, run by"
  echo "\`bash benchmark/Deformable_compact_model/run.sh <build> ${2:-}\` on $(date -u +%Y-%m-%d) ($(nproc) cores)."
  echo
  cat "$here/NOTES.md"
  echo
  cat "$tmp"
} > "$here/RESULTS.md.tmp"
mv "$here/RESULTS.md.tmp" "$here/RESULTS.md"

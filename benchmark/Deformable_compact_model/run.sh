#!/usr/bin/env bash
# Writes benchmark/Deformable_compact_model/RESULTS.md (thesis Tables 6.1-6.3 style): memory and
# time per deformation of the original mesh, the simplified base, the CM reconstructed then
# deformed, and the deformable CM, with their Metro error against the deformed original; then
# (without --quick) the same at scale: igea subdivided once (1,074,744 faces, made here by
# benchmark/Scale/subdivide.py, never committed), CM of 4,000 base faces at level 4 (512 k points),
# lattice cage with Green and mean value coordinates.
#   bash benchmark/Deformable_compact_model/run.sh <build-dir> [--quick]   (called by benchmark/run.sh)
set -euo pipefail
build=${1:?usage: run.sh <build-dir> [--quick]}
here=$(cd "$(dirname "$0")" && pwd)
data=${CMGEOM_DATA_DIR:-$here/../../../shared/data}
models=()
[[ "${2:-}" == "--quick" ]] && models=(camel.off:1000)
. "$here/../common/describe_run.sh"
line=$(describe_run)
tmp=$(mktemp)
scale_dir=$(mktemp -d)
trap 'rm -rf "$tmp" "$scale_dir"' EXIT
"$build/bin/bench_deformable_compact_model" "$data" "${models[@]}" > "$tmp"
: > "$scale_dir/scale.md"
if [[ "${2:-}" != "--quick" && -f "$data/classic/igea.ply.gz" ]]; then
  gzip -dc "$data/classic/igea.ply.gz" > "$scale_dir/igea.ply"
  python3 "$here/../Scale/subdivide.py" "$scale_dir/igea.ply" "$scale_dir/igea_subdivided.ply" > /dev/null
  "$build/bin/bench_deformable_compact_model" --scale "$scale_dir/igea_subdivided.ply:4000:4" > "$scale_dir/scale.md"
fi
{
  echo "# Deformable_compact_model benchmark results"
  echo
  echo "Program \`benchmark/Deformable_compact_model/bench_deformable_compact_model.cpp\`, run by"
  echo "\`bash benchmark/Deformable_compact_model/run.sh <build> ${2:-}\`. No peer: every row is CMGeom."
  echo
  echo "$line"
  echo
  cat "$here/NOTES.md"
  echo
  cat "$tmp"
  if [[ -s "$scale_dir/scale.md" ]]; then
    echo
    echo "## At scale"
    echo
    echo "\`bench_deformable_compact_model --scale <igea subdivided once>:4000:4\`: the full mesh deformed"
    echo "directly (a) against the deformable CM whose points and normals are reconstructed along N every pose (d:"
    echo "a \`CM::Regular_reconstructor\` made at binding, the output's triangles written once)"
    echo "and with its rest reconstruction kept (e), posed by the 4 x 4 x 4 lattice cage (98 vertices)."
    echo "\`memory MB\`: (a) mesh + coordinates of every vertex + posed points; (d) CM file + base coordinates + local-map"
    echo "data + the reconstructor (topology, frames, tables) + the output; (e) CM file + base coordinates + local-map data + the output + the kept rest reconstruction (points, normals, triangles) and the tables of its blend."
    echo "Errors: Metro with 2 M face samples per direction and every vertex (no edge samples)."
    echo
    cat "$scale_dir/scale.md"
  fi
} > "$here/RESULTS.md.tmp"
mv "$here/RESULTS.md.tmp" "$here/RESULTS.md"

#!/bin/sh
# Regenerates the figure of doc/Deformable_compact_model/README.md (thesis Fig. 6.4) with the
# cmgeom tool itself: the same cage deformation applied to the original camel, to the simplified
# base, to the CM reconstructed then deformed, and by the deformable CM (cm deform); each one
# measured against the deformed original with `cmgeom error` and drawn with `cmgeom render`.
# Usage: make_figures.sh <path/to/cmgeom> [shared data dir]   (writes into images/ next to this file)
set -e
B=${1:?path to the cmgeom executable}
D=${2:-$(dirname "$0")/../../../shared/data}/classic
HERE=$(cd "$(dirname "$0")" && pwd)
OUT=$HERE/images
S=$HERE/cages/camel_grid_system.json
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
mkdir -p "$OUT"
V="--view 30,20 --size 360x360"

"$B" cm build "$D/camel.off" -o "$T/camel.cm" --faces 1000 --json > "$OUT/camel_build.json"
# (1) the original mesh deformed directly (coordinates of its 9 770 vertices)
"$B" deform "$D/camel.off" --cages "$S" -o "$T/original.off" --json > "$OUT/original_deform.json"
# (2) the simplified base (level 0 of the CM) deformed directly
"$B" cm reconstruct "$T/camel.cm" -o "$T/base.off" --level 0
"$B" deform "$T/base.off" --cages "$S" -o "$T/simplified.off" --json > "$OUT/simplified_deform.json"
# (3) the CM reconstructed at level 2, then deformed directly
"$B" cm reconstruct "$T/camel.cm" -o "$T/reconstructed.off" --level 2
"$B" deform "$T/reconstructed.off" --cages "$S" -o "$T/cm_reconstruction.off" --json > "$OUT/cm_reconstruction_deform.json"
# (4) the deformable CM: base deformed, local maps, deformed reconstruction at level 2
"$B" cm deform "$T/camel.cm" --cages "$S" -o "$T/cm_deformation.off" --level 2 --json > "$OUT/cm_deformation.json"

for m in original simplified cm_reconstruction cm_deformation; do
  if [ $m != original ]; then
    "$B" error "$T/original.off" "$T/$m.off" --json > "$OUT/${m}_error.json"
  fi
  w=; [ $m = simplified ] && w=--wireframe
  "$B" render "$T/$m.off" -o "$OUT/camel_$m.png" $V $w --caption "$m"
done
"$B" render "$D/camel.off" -o "$OUT/camel_rest.png" $V --caption "rest"

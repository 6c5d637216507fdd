#!/bin/sh
# Regenerates the *Cages pictures of README.md with the tools themselves: the twisted prism of
# thesis Fig. 5.6 (single union cage vs *Cages vs piecewise, mean value and Green coordinates)
# and influence maps (Fig. 5.2-5.3) of grid cage systems on the bundled Spot model.
# Usage: make_stars_figures.sh <build dir>   (needs bench_Cage_system, i.e. a build configured
# with -DCMGEOM_BUILD_BENCHMARKS=ON, the cmgeom tool with its renderer, and oiiotool)
set -eu
BUILD=${1:?usage: make_stars_figures.sh <build dir>}
CMGEOM=$BUILD/bin/cmgeom
HERE=$(cd "$(dirname "$0")" && pwd)
SPOT=$HERE/../../data/spot/spot.obj
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
# Prism (4,610 vertices) in 4 stacked box cages, twisted by pi/2 from bottom to top; the single
# cage is the union of the 4 cages (same 20 surface vertices). h = 0.5.
"$BUILD/bin/bench_Cage_system" --write-prism "$TMP"
V="--view 20,25 --size 640x280"
"$CMGEOM" render "$TMP/prism.obj" -o "$TMP/rest.png" $V --caption rest
for c in mean_value green; do
  "$CMGEOM" deform "$TMP/prism.obj" --cages "$TMP/prism_single_$c.json" -o "$TMP/single_$c.obj" --json > "$HERE/images/prism_single_$c.json"
  "$CMGEOM" deform "$TMP/prism.obj" --cages "$TMP/prism_stars_$c.json" -o "$TMP/stars_$c.obj" --json > "$HERE/images/prism_stars_$c.json"
  "$CMGEOM" deform "$TMP/prism.obj" --cages "$TMP/prism_stars_$c.json" --piecewise -o "$TMP/piecewise_$c.obj"
  "$CMGEOM" render "$TMP/single_$c.obj" -o "$TMP/single_$c.png" $V --caption "single cage, $c"
  "$CMGEOM" render "$TMP/stars_$c.obj" -o "$TMP/stars_$c.png" $V --caption "*Cages, $c"
  "$CMGEOM" render "$TMP/piecewise_$c.obj" -o "$TMP/piecewise_$c.png" $V --caption "piecewise, $c"
done
"$CMGEOM" influence "$TMP/prism.obj" --cages "$TMP/prism_stars_mean_value.json" -o "$TMP/prism_influence.png" $V --caption "influence d, h = 0.5"
oiiotool "$TMP/rest.png" "$TMP/prism_influence.png" \
  "$TMP/single_mean_value.png" "$TMP/single_green.png" \
  "$TMP/stars_mean_value.png" "$TMP/stars_green.png" \
  "$TMP/piecewise_mean_value.png" "$TMP/piecewise_green.png" --mosaic 2x4 -o "$HERE/images/prism_twist.png"
# Influence maps of grid systems on Spot: d_i for h = 1 and 0.3 (2x2x1), and 3x3x3 with h = 0.2.
for g in "2,2,1 1" "2,2,1 0.3" "3,3,3 0.2"; do
  set -- $g
  name=$(echo "$1" | tr , x)_h$2
  "$CMGEOM" influence "$SPOT" --grid "$1" --h "$2" -o "$TMP/spot_$name.png" --view front --size 400x400 \
    --caption "grid $1, h = $2" --json > "$HERE/images/spot_influence_$name.json"
done
oiiotool "$TMP/spot_2x2x1_h1.png" "$TMP/spot_2x2x1_h0.3.png" "$TMP/spot_3x3x3_h0.2.png" --mosaic 3x1 \
  -o "$HERE/images/spot_influence.png"

#!/bin/sh
# Regenerates the pictures of doc/Metrics and doc/Rendering with the cmgeom tool itself.
#   sh doc/Metrics/fig/make_figures.sh <path/to/cmgeom> <path/to/shared/data>
set -e
CMGEOM=${1:-cmgeom}
DATA=${2:-../shared/data}
HERE=$(cd "$(dirname "$0")" && pwd)
DOC=$(dirname "$(dirname "$HERE")")
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
export MESA_SHADER_CACHE_DIR="$TMP/mesa"

# Metrics: the bunny coloured by the distance of each vertex to a 25 % simplification.
"$CMGEOM" simplify "$DATA/classic/bunny.off" -o "$TMP/bunny_25.obj" --ratio 0.25
"$CMGEOM" error "$DATA/classic/bunny.off" "$TMP/bunny_25.obj" --field "$TMP/err.ply" --field-on reference
"$CMGEOM" render "$DATA/classic/bunny.off" --field "$TMP/err.ply" -o "$DOC/Metrics/fig/bunny_error_map.png" \
  --size 640x480 --view front --label distance --caption "bunny: distance to its 25% simplification"
# Metrics: image-space comparison grid (reference / approximation / difference, 6 axis views).
"$CMGEOM" compare "$DATA/classic/bunny.off" "$TMP/bunny_25.obj" --size 128 -o "$DOC/Metrics/fig/bunny_compare.png"

# Rendering: spot with its texture and chart boundaries, and its UV atlas.
"$CMGEOM" render "$DATA/textured/spot/spot.obj" --texture "$DATA/textured/spot/spot_texture.png" --charts \
  -o "$DOC/Rendering/fig/spot_charts.png" --size 512x512 --view 150,15 --atlas "$DOC/Rendering/fig/spot_atlas.png"

#!/bin/sh
# Regenerates the texture-part pictures of doc/Textured_simplification/README.md with the cmgeom
# tool: renders with chart boundaries in red and UV atlases, before and after `cmgeom simplify
# --keep-charts` (the thesis' chart-preserving method).
#   make_texture_figures.sh <path to cmgeom> <shared data dir>
set -eu
cmgeom=${1:?usage: make_texture_figures.sh <cmgeom> <data dir>}
data=${2:?usage: make_texture_figures.sh <cmgeom> <data dir>}
fig=$(cd "$(dirname "$0")" && pwd)/fig
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$fig"
# bunny10k_textured (190 charts) to 20 %, spot (13 charts) to 5 %
bunny="$data/textured/bunny10k_textured/bunny10k_textured.obj"
"$cmgeom" render "$bunny" -o "$fig/tex_bunny_orig.png" --views 'front;left' --size 320x320 --charts \
  --atlas "$fig/tex_bunny_atlas_orig.png" --caption "9999 faces, 190 charts"
"$cmgeom" simplify "$bunny" -o "$tmp/bunny.obj" --ratio 0.2 --keep-charts --json > "$tmp/bunny.json"
faces=$(sed -n 's/.*"faces_out": \([0-9]*\).*/\1/p' "$tmp/bunny.json")
charts=$(sed -n 's/.*"charts_out": \([0-9]*\).*/\1/p' "$tmp/bunny.json")
"$cmgeom" render "$tmp/bunny.obj" -o "$fig/tex_bunny_simpl.png" --views 'front;left' --size 320x320 --charts \
  --atlas "$fig/tex_bunny_atlas_simpl.png" --caption "$faces faces, $charts charts"
spot="$data/textured/spot/spot.obj"
spot_tex="$data/textured/spot/spot_texture.png"
"$cmgeom" render "$spot" --texture "$spot_tex" -o "$fig/tex_spot_orig.png" --views 'left;iso' --size 320x320 --charts \
  --atlas "$fig/tex_spot_atlas_orig.png" --caption "5856 faces, 13 charts"
"$cmgeom" simplify "$spot" --texture "$spot_tex" -o "$tmp/spot.obj" --ratio 0.05 --keep-charts --json > "$tmp/spot.json"
faces=$(sed -n 's/.*"faces_out": \([0-9]*\).*/\1/p' "$tmp/spot.json")
charts=$(sed -n 's/.*"charts_out": \([0-9]*\).*/\1/p' "$tmp/spot.json")
"$cmgeom" render "$tmp/spot.obj" -o "$fig/tex_spot_simpl.png" --views 'left;iso' --size 320x320 --charts \
  --atlas "$fig/tex_spot_atlas_simpl.png" --caption "$faces faces, $charts charts"
# the same target with chart boundaries frozen (what other simplifiers do)
"$cmgeom" simplify "$spot" --texture "$spot_tex" -o "$tmp/spot_frozen.obj" --ratio 0.05 --keep-charts --freeze-seams --json > "$tmp/spotf.json"
faces=$(sed -n 's/.*"faces_out": \([0-9]*\).*/\1/p' "$tmp/spotf.json")
"$cmgeom" render "$tmp/spot_frozen.obj" -o "$fig/tex_spot_frozen.png" --views 'left;iso' --size 320x320 --charts \
  --caption "$faces faces, boundaries frozen"

#!/bin/sh
# Regenerates the pictures of doc/Textured_simplification/README.md with the cmgeom tool.
#   make_figures.sh <path to cmgeom> <shared data dir>
set -eu
cmgeom=${1:?usage: make_figures.sh <cmgeom> <data dir>}
data=${2:?usage: make_figures.sh <cmgeom> <data dir>}
fig=$(cd "$(dirname "$0")" && pwd)/fig
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$fig"
gunzip -c "$data/classic/armadillo.obj.gz" > "$tmp/armadillo.obj"
"$cmgeom" render "$data/classic/cow.obj" -o "$fig/cow_orig.png" --views 'right;iso' --size 320x320 --flat --caption "cow 5804 faces"
"$cmgeom" render "$tmp/armadillo.obj" -o "$fig/arma_orig.png" --views 'front;back' --size 320x320 --caption "armadillo 86482 faces"
for policy in weighted plain; do
  "$cmgeom" simplify "$data/classic/cow.obj" --repair -o "$tmp/cow_$policy.obj" --faces 300 --policy $policy
  "$cmgeom" render "$tmp/cow_$policy.obj" -o "$fig/cow_$policy.png" --views 'right;iso' --size 320x320 --flat --wireframe \
    --caption "cow 300 faces, $policy"
  "$cmgeom" simplify "$tmp/armadillo.obj" -o "$tmp/arma_$policy.obj" --faces 500 --policy $policy
  "$cmgeom" render "$tmp/arma_$policy.obj" -o "$fig/arma_$policy.png" --views 'front;back' --size 320x320 --flat \
    --caption "armadillo 500 faces, $policy"
done

#!/usr/bin/env bash
# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
#
# Regenerates the "before / after at 2 %" pictures of doc/Textured_simplification/README.md with
# the cmgeom tool: each model as it is, simplified to 2 % of its faces by `cmgeom simplify`
# (default: new atlas), and by meshoptimizer at the same face count (0.18 seam-aware, and 1.3.0
# Permissive without seam protection, which reaches any count), rendered by `cmgeom render`.
#   make_peer_figures.sh <build-dir> <shared data dir> [<peer build-dir>]
# The build dir holds bin/cmgeom; the peer build dir (default: the build dir), configured with
# -DCMGEOM_BUILD_BENCHMARKS=ON, holds bin/meshopt018_simplify; meshoptimizer 1.3.0 comes from npm
# (run_textured_peers.sh installs it in benchmark/Textured_simplification/peers).
set -euo pipefail
build="$(cd "${1:?usage: make_peer_figures.sh <build-dir> <data dir>}" && pwd)"
data="$(cd "${2:?usage: make_peer_figures.sh <build-dir> <data dir>}" && pwd)"
peer_build="$(cd "${3:-$build}" && pwd)"
here="$(cd "$(dirname "$0")" && pwd)"
fig="$here/fig"
peers="$here/../../benchmark/Textured_simplification/peers"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$fig"
cmgeom="$build/bin/cmgeom"
views='left;iso'
size=256x256
for spec in "DamagedHelmet/DamagedHelmet.obj:helmet" "spot/spot.obj:spot" "bob/bob_tri.obj:bob"; do
  in="$data/textured/${spec%%:*}"
  name="${spec##*:}"
  tex=()
  mtl=()
  if [ "$name" = spot ]; then  # its OBJ names no texture
    tex=(--texture "$data/textured/spot/spot_texture.png")
    printf 'newmtl spot\nKd 1 1 1\nmap_Kd %s\n' "$data/textured/spot/spot_texture.png" > "$tmp/spot.mtl"
    mtl=(--mtl "$tmp/spot.mtl")
  fi
  faces_in=$(grep -c '^f ' "$in")
  "$cmgeom" render "$in" "${tex[@]}" -o "$fig/peers_${name}_orig.png" --views "$views" --size "$size" \
    --caption "input, $faces_in faces"
  "$cmgeom" simplify "$in" "${tex[@]}" -o "$tmp/$name.obj" --ratio 0.02 --json > "$tmp/$name.json"
  faces=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["faces_out"])' "$tmp/$name.json")
  "$cmgeom" render "$tmp/$name.obj" -o "$fig/peers_${name}_ours.png" --views "$views" --size "$size" \
    --caption "CMGeom, $faces faces"
  "$peer_build/bin/meshopt018_simplify" "$in" "$tmp/${name}_mo018.obj" --faces "$faces" "${mtl[@]}" > "$tmp/mo018.json"
  f018=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["faces_out"])' "$tmp/mo018.json")
  "$cmgeom" render "$tmp/${name}_mo018.obj" -o "$fig/peers_${name}_meshopt018.png" --views "$views" --size "$size" \
    --caption "meshopt 0.18, $f018 faces"
  node "$peers/meshopt_simplify.mjs" "$in" "$tmp/${name}_mo13.obj" --faces "$faces" --variant permissive "${mtl[@]}" \
    > "$tmp/mo13.json"
  f13=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["faces_out"])' "$tmp/mo13.json")
  "$cmgeom" render "$tmp/${name}_mo13.obj" -o "$fig/peers_${name}_meshopt13.png" --views "$views" --size "$size" \
    --caption "meshopt 1.3 Permissive, $f13 faces"
done
echo "wrote $fig/peers_*.png"

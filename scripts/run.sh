#!/usr/bin/env bash
# Installs the dependencies, builds the cmgeom tool and runs the main job on the bundled
# default model (Spot), writing its results to ./cmgeom-out (or the directory given).
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-cmgeom-out}"
bash scripts/install-deps.sh
export MESA_SHADER_CACHE_DIR="${MESA_SHADER_CACHE_DIR:-$(pwd)/build/mesa-shader-cache}"
mkdir -p "$MESA_SHADER_CACHE_DIR"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$(nproc)" --target cmgeom
mkdir -p "$out"
build/bin/cmgeom info data/spot/spot.obj
build/bin/cmgeom info --json data/spot/spot.obj > "$out/spot_info.json"
echo "results in $out/"

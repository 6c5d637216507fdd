#!/usr/bin/env bash
# The README's main job: installs the dependencies, builds the cmgeom tool and runs
# `cmgeom pipeline` on the bundled default model (Spot): every stage of the framework, writing
# meshes, PNG pictures, report.md and report.html into ./cmgeom-out (or the directory given).
# Extra arguments go to `cmgeom pipeline` (see `cmgeom pipeline --help`), e.g.
#   bash scripts/run.sh out --model my_scan.obj
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-cmgeom-out}"
shift || true
bash scripts/install-deps.sh
export MESA_SHADER_CACHE_DIR="${MESA_SHADER_CACHE_DIR:-$(pwd)/build/mesa-shader-cache}"
mkdir -p "$MESA_SHADER_CACHE_DIR"
if [[ -z "${CMGEOM_EXE:-}" ]]; then  # CMGEOM_EXE: use an already built tool instead
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build -j "$(nproc)" --target cmgeom
fi
cmgeom=${CMGEOM_EXE:-build/bin/cmgeom}
"$cmgeom" pipeline -o "$out" "$@"
echo "results in $out/: report.md, report.html, meshes and pictures"

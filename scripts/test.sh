#!/usr/bin/env bash
# Installs the dependencies, builds CMGeom with its tests and examples (-O2), runs them with
# CTest, then builds and runs the test suite again under AddressSanitizer + UndefinedBehaviorSanitizer.
# Usage: bash scripts/test.sh [--no-sanitizers]
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
bash scripts/install-deps.sh
jobs=$(nproc)
export MESA_SHADER_CACHE_DIR="${MESA_SHADER_CACHE_DIR:-$root/build/mesa-shader-cache}"
mkdir -p "$MESA_SHADER_CACHE_DIR"

echo "== build (Release, -O2) =="
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMGEOM_BUILD_TESTS=ON -DCMGEOM_BUILD_EXAMPLES=ON
cmake --build build -j "$jobs"
echo "== tests =="
ctest --test-dir build --output-on-failure -j "$jobs"

if [[ "${1:-}" != "--no-sanitizers" ]]; then
  echo "== build (ASan + UBSan) =="
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMGEOM_SANITIZE=address,undefined \
        -DCMGEOM_BUILD_TESTS=ON -DCMGEOM_BUILD_EXAMPLES=OFF
  cmake --build build-asan -j "$jobs"
  echo "== tests under ASan + UBSan =="
  # Leak checking is off: OpenImageIO and OSMesa keep process-lifetime caches that LSan reports.
  ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs"
fi

#!/usr/bin/env bash
# Coverage-guided fuzzing of the mesh readers with libFuzzer (clang), ASan and UBSan.
# Usage: bash scripts/fuzz.sh [seconds per target, default 600]
# Findings (crash-*, leak-*, timeout-* files) are written to build-fuzz/findings/; each one must
# become a regression test (add the file to test/Mesh_IO/fuzz_corpus/ and fix the reader).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-600}"
bash scripts/install-deps.sh
command -v clang++ >/dev/null || { apt-get install -y -qq clang libclang-rt-dev >/dev/null; }
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMGEOM_LIBFUZZER=ON -DCMGEOM_SANITIZE=address,undefined,fuzzer-no-link \
  -DCMGEOM_BUILD_TOOLS=OFF -DCMGEOM_BUILD_EXAMPLES=OFF -DCMGEOM_USE_PCH=OFF
cmake --build build-fuzz --target fuzz_readers_libfuzzer
mkdir -p build-fuzz/corpus build-fuzz/findings
# Seeds: the committed corpus (format byte prefixed) and small shared models.
python3 - <<'PY'
import os, pathlib
fmts = ['.obj', '.off', '.ply', '.gltf', '.glb']
srcs = ['test/Mesh_IO/fuzz_corpus', '../shared/data/textured/fuze', '../shared/data/textured/Duck', '../shared/data/classic']
for d in srcs:
    if not os.path.isdir(d): continue
    for p in sorted(pathlib.Path(d).iterdir()):
        if p.suffix in fmts and p.stat().st_size < 300000:
            (pathlib.Path('build-fuzz/corpus') / (p.name + '.seed')).write_bytes(bytes([fmts.index(p.suffix)]) + p.read_bytes())
PY
ASAN_OPTIONS=detect_leaks=0 build-fuzz/bin/fuzz_readers_libfuzzer build-fuzz/corpus \
  -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 -artifact_prefix=build-fuzz/findings/ -print_final_stats=1

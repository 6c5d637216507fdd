#!/usr/bin/env bash
# Coverage-guided fuzzing of the CMGeom readers with libFuzzer (clang), ASan and UBSan.
# Usage: bash scripts/fuzz.sh [seconds per target, default 600] [target...]
#   targets: readers (OBJ+MTL, OFF, PLY, glTF, GLB; test/Mesh_IO/fuzz_readers.cpp)
#            models  (CM file and cage-system JSON; test/Reliability/fuzz_model_readers.cpp)
#   default: both, one after the other.
# Findings (crash-*, leak-*, timeout-*, oom-* files) are written to build-fuzz/findings/<target>/;
# each one must become a regression test (the input goes into the target's committed corpus,
# test/Mesh_IO/fuzz_corpus/ or test/Reliability/fuzz_corpus/, and the reader gets fixed).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-600}"
shift || true
targets=("$@")
((${#targets[@]})) || targets=(readers models)
bash scripts/install-deps.sh
command -v clang++ >/dev/null || { apt-get install -y -qq clang libclang-rt-dev >/dev/null; }
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMGEOM_LIBFUZZER=ON -DCMGEOM_SANITIZE=address,undefined,fuzzer-no-link \
  -DCMGEOM_BUILD_TOOLS=OFF -DCMGEOM_BUILD_EXAMPLES=OFF -DCMGEOM_USE_PCH=OFF

for target in "${targets[@]}"; do
  corpus="build-fuzz/corpus/$target"
  findings="build-fuzz/findings/$target"
  mkdir -p "$corpus" "$findings"
  case "$target" in
    readers)
      cmake --build build-fuzz --target fuzz_readers_libfuzzer
      binary=build-fuzz/bin/fuzz_readers_libfuzzer
      # Seeds: the committed corpus and small shared models, each prefixed by its format byte.
      python3 - "$corpus" <<'PY'
import os, pathlib, sys
fmts = ['.obj', '.off', '.ply', '.gltf', '.glb']
srcs = ['test/Mesh_IO/fuzz_corpus', '../shared/data/textured/fuze', '../shared/data/textured/Duck', '../shared/data/classic']
for d in srcs:
    if not os.path.isdir(d): continue
    for p in sorted(pathlib.Path(d).iterdir()):
        if p.suffix in fmts and p.stat().st_size < 300000:
            (pathlib.Path(sys.argv[1]) / (p.name + '.seed')).write_bytes(bytes([fmts.index(p.suffix)]) + p.read_bytes())
PY
      ;;
    models)
      cmake --build build-fuzz --target fuzz_model_readers_libfuzzer
      binary=build-fuzz/bin/fuzz_model_readers_libfuzzer
      # Seeds: CM files as given (byte 0) and with their checksum recomputed after mutation
      # (byte 1), cage-system JSON files (byte 2).
      python3 - "$corpus" <<'PY'
import pathlib, sys
for p in sorted(pathlib.Path('test/Reliability/fuzz_corpus').iterdir()):
    modes = [0, 1] if p.suffix == '.cm' else [2] if p.suffix == '.json' else []
    for m in modes:
        (pathlib.Path(sys.argv[1]) / f'{p.name}.{m}.seed').write_bytes(bytes([m]) + p.read_bytes())
PY
      ;;
    *) echo "unknown fuzz target '$target' (readers or models)" >&2; exit 2 ;;
  esac
  echo "== fuzzing $target for $seconds s =="
  ASAN_OPTIONS=detect_leaks=0 "$binary" "$corpus" \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 -artifact_prefix="$findings/" -print_final_stats=1
done

#!/usr/bin/env bash
# Builds every benchmark and regenerates benchmark/RESULTS.md: each package's benchmark writes its
# own benchmark/<Package>/RESULTS.md (through benchmark/<Package>/run.sh <build-dir> [--quick]),
# then collect_results.sh gathers them under one header giving the machine, compiler, flags and
# thread count of this run.
#   bash benchmark/run.sh [--quick] [--build-dir DIR] [--only Package[,Package...]]
# --quick: fewer models and repetitions (a few minutes); the default is the full run.
# Needs ../shared/data (or -DCMGEOM_DATA_DIR); the peers (CGAL, meshoptimizer, OpenMesh, Draco, zstd)
# are the Debian packages that scripts/install-deps.sh installs, and meshoptimizer from npm. Their
# versions, the machine and the thread counts are read at run time (common/describe_run.sh): no
# RESULTS file is edited by hand after a run.
set -euo pipefail
cd "$(dirname "$0")/.."
quick=""
build=build-bench
only=""
while (($#)); do
  case "$1" in
    --quick) quick=--quick ;;
    --build-dir) build=$2; shift ;;
    --only) only=$2; shift ;;
    *) echo "benchmark/run.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
bash scripts/install-deps.sh
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMGEOM_BUILD_BENCHMARKS=ON \
      -DCMGEOM_BUILD_TESTS=OFF -DCMGEOM_BUILD_EXAMPLES=OFF >/dev/null
cmake --build "$build" -j "$(nproc)"
build=$(cd "$build" && pwd)

start=$(date +%s)
failed=()
for script in benchmark/*/run.sh; do
  pkg=$(basename "$(dirname "$script")")
  if [[ -n "$only" && ",$only," != *",$pkg,"* ]]; then continue; fi
  echo "== benchmark $pkg ==" >&2
  t0=$(date +%s)
  if bash "$script" "$build" $quick; then
    echo "== $pkg: $(( $(date +%s) - t0 )) s ==" >&2
  else
    echo "== $pkg: FAILED (its RESULTS.md is left as it was) ==" >&2
    failed+=("$pkg")
  fi
done

compiler=$(c++ --version | head -1)
flags=$(sed -n 's/^CMAKE_CXX_FLAGS_RELEASE:[A-Z]*=//p' "$build/CMakeCache.txt" | head -1)
. benchmark/common/describe_run.sh
bash benchmark/collect_results.sh \
  "Machine: $(machine_description); $(. /etc/os-release && echo "$PRETTY_NAME"); ${compiler}; flags \`${flags:-?}\` (CMake Release); run of $(date -u +%Y-%m-%d) with \`bash benchmark/run.sh $quick\` in $(( $(date +%s) - start )) s."
if ((${#failed[@]})); then
  echo "benchmarks that failed: ${failed[*]}" >&2
  exit 1
fi

#!/usr/bin/env bash
# Builds every benchmark and regenerates benchmark/RESULTS.md: each package's benchmark writes its
# own benchmark/<Package>/RESULTS.md (through benchmark/<Package>/run.sh <build-dir> [--quick]),
# then collect_results.sh gathers them under one header giving the machine, compiler, flags and
# thread count of this run.
#   bash benchmark/run.sh [--quick] [--build-dir DIR] [--only Package[,Package...]]
# --quick: fewer models and repetitions (a few minutes); the default is the full run.
# Needs ../shared/data (or -DCMGEOM_DATA_DIR); the peers (CGAL, meshoptimizer, OpenMesh) are the
# Debian packages that scripts/install-deps.sh installs.
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
cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')
bash benchmark/collect_results.sh \
  "Machine: ${cpu:-unknown CPU}, $(nproc) cores, $(free -g | awk '/Mem:/{print $2}') GiB; $(. /etc/os-release && echo "$PRETTY_NAME"); ${compiler}; flags \`-O2\` (CMake Release); run of $(date -u +%Y-%m-%d) with \`bash benchmark/run.sh $quick\` in $(( $(date +%s) - start )) s."
if ((${#failed[@]})); then
  echo "benchmarks that failed: ${failed[*]}" >&2
  exit 1
fi

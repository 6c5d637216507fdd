#!/usr/bin/env bash
# Writes benchmark/Textured_simplification/RESULTS.md: the geometry part (run_bench.sh: our engine
# and policies against CGAL, meshoptimizer and OpenMesh) and the texture part
# (run_textured_bench.sh: chart-aware simplification against meshoptimizer and CGAL with frozen
# seams, image RMSE over 26 views); RESULTS-peers.md (run_textured_peers.sh: the default textured
# simplification, new atlas, against meshoptimizer 0.18 and 1.3.0 at equal face counts) and
# RESULTS-scale.md (run_textured_scale.sh: a 989k-face textured mesh, time against geometry only
# and one thread against two), RESULTS-policy.md (run_policy_comparison.sh: weighted against plain
# quadrics on the textured models) and RESULTS-memory.md (run_memory_comparison.sh: geometry-only
# simplification with and without the memoryful cost against CGAL and meshoptimizer),
# RESULTS-other-models.md (run_other_models.sh: the same on the shared meshes no target names), RESULTS-lod.md
# (run_lod.py: level-of-detail chains against meshoptimizer-style LODs), RESULTS-lod-scale.md
# (run_lod_scale.py: the chains of that 989k-face textured mesh), RESULTS-paint.md (run_paint.py:
# the new atlas painted from the input or looked up texel by texel) and RESULTS-max-error.md
# (run_max_error_bench.sh: the guaranteed error bound's face counts against the peers' at equal
# measured error; RESULTS-max-error-large.md the same on the 2M-face ogre-sub2),
# RESULTS-max-error-sweep.md (run_max_error_sweep.sh: --max-error on every model of the shared data,
# each output's Hausdorff distance measured independently against its bound),
# RESULTS-topology-sweep.md (run_topology_sweep.py: the topology cmgeom simplify keeps on every model
# of the shared data at 10, 5 and 1 %) and
# RESULTS-fit-by-ratio.md (run_fit_by_ratio.sh: the final fit against none by the share of faces kept,
# what its points-per-face threshold is chosen from). Each script writes its whole
# file (machine, threads and peer versions from common/describe_run.sh); none is edited by hand.
#   bash benchmark/Textured_simplification/run.sh <build-dir> [--quick]   (called by benchmark/run.sh)
set -euo pipefail
build=${1:?usage: run.sh <build-dir> [--quick]}
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../common/describe_run.sh"
describe=$(describe_run "meshoptimizer-npm=$here/peers" node)
if [[ "${2:-}" == "--quick" ]]; then
  sh "$here/run_bench.sh" "$build" --models bunny,max-planck
  sh "$here/run_textured_bench.sh" "$build" --models spot,bob --fractions 0.1
  bash "$here/run_textured_peers.sh" "$build" --quick
  bash "$here/run_textured_scale.sh" "$build" --repeat 1
  python3 "$here/run_lod.py" --build "$build" --models spot --reps 2 --min-seconds 0 --prune --geometry-models horse.ply \
    --out "$here/RESULTS-lod.md" --describe "$describe"
  python3 "$here/run_paint.py" --build "$build" --models spot,Duck --reps 1 --out "$here/RESULTS-paint.md" \
    --describe "$(describe_run)"
  bash "$here/run_max_error_bench.sh" "$build" --quick
else
  sh "$here/run_bench.sh" "$build" --repeat 3
  sh "$here/run_textured_bench.sh" "$build"
  bash "$here/run_textured_peers.sh" "$build"
  bash "$here/run_textured_scale.sh" "$build"
  bash "$here/run_policy_comparison.sh" "$build"
  bash "$here/run_memory_comparison.sh" "$build"
  bash "$here/run_other_models.sh" "$build"
  python3 "$here/run_lod.py" --build "$build" --reps 5 --prune --out "$here/RESULTS-lod.md" --describe "$describe"
  python3 "$here/run_lod_scale.py" --build "$build" --out "$here/RESULTS-lod-scale.md" --describe "$(describe_run)"
  python3 "$here/run_paint.py" --build "$build" --out "$here/RESULTS-paint.md" --describe "$(describe_run)"
  bash "$here/run_max_error_bench.sh" "$build"
  bash "$here/run_max_error_bench.sh" "$build" --large
  bash "$here/run_max_error_sweep.sh" "$build" ||
    echo "run_max_error_sweep.sh: a measured distance above its bound, or a failed run: see RESULTS-max-error-sweep.md" >&2
  python3 "$here/run_topology_sweep.py" --build "$build" ||
    echo "run_topology_sweep.py: an output whose topology changed, or a failed run: see RESULTS-topology-sweep.md" >&2
  bash "$here/run_fit_by_ratio.sh" "$build"
fi

#!/usr/bin/env bash
# Writes benchmark/Compact_model/RESULTS.md (thesis Table 4.1 style): CM build, bytes,
# reconstruction speed at levels 1-3 and Metro error, beside PN triangles on the same base and
# the plain mesh of equal bytes, then regular against adaptive reconstructions at equal vertex
# counts; RESULTS-reconstruction-speed.md (bench_reconstruction_speed); then run_rate_distortion.py
# (RESULTS-rate-distortion.md). Every line is written here: prose in the echo lines, figures and the
# machine / peer line from the run.
#   bash benchmark/Compact_model/run.sh <build-dir> [--quick]     (called by benchmark/run.sh)
#   bash benchmark/Compact_model/run.sh <build-dir> --speed       (RESULTS-reconstruction-speed.md only)
#   bash benchmark/Compact_model/run.sh <build-dir> --adaptive    (RESULTS-adaptive.md only)
set -euo pipefail
build=${1:?usage: run.sh <build-dir> [--quick | --speed | --adaptive]}
speed_only=0
adaptive_only=0
[[ "${2:-}" == "--speed" ]] && speed_only=1
[[ "${2:-}" == "--adaptive" ]] && adaptive_only=1
here=$(cd "$(dirname "$0")" && pwd)
data=${CMGEOM_DATA_DIR:-$here/../../../shared/data}
. "$here/../common/describe_run.sh"
models=()
adaptive_models=(textured/spot/spot.obj:1000 classic/fandisk.obj:250 classic/trim-star.off:1000 classic/camel.off:1000
                 classic/horse.ply:1000 classic/decimated-max.obj:1000 classic/bunny.off:1000 classic/igea.ply.gz:2000)
if [[ "${2:-}" == "--quick" ]]; then
  models=(classic/fandisk.obj:250 classic/camel.off:1000)
  adaptive_models=(classic/fandisk.obj:250)
fi
tmp=$(mktemp)
adaptive=$(mktemp)
huge_new=$(mktemp)
trap 'rm -f "$tmp" "$adaptive" "$huge_new"' EXIT
# Regular against adaptive reconstructions at equal vertex counts: RESULTS-adaptive.md.
if [[ $speed_only == 0 ]]; then
line=$(describe_run)
"$build/bin/bench_compact_model" --adaptive "$data" "${adaptive_models[@]}" > "$adaptive"
{
  echo "# Regular against adaptive reconstructions at equal vertex counts"
  echo
  echo "Program \`benchmark/Compact_model/bench_compact_model.cpp\` (\`--adaptive\`), run by"
  echo "\`bash benchmark/Compact_model/run.sh <build> ${2:-}\`. No peer: every column is a reconstruction of the"
  echo "same Compact Model (default \`Build_options\`: the thesis' fits), measured against the input."
  echo
  echo "$line"
  echo
  echo "\`bench_compact_model --adaptive <data> ${adaptive_models[*]}\`: for regular levels 2-4, three"
  echo "adaptive outputs within the regular level's vertex count: \`Chord_error_criterion\` with the tolerance"
  echo "\`reconstruct_to_vertex_budget\` chose (at most 3 more halvings; the error against the CM surface Phi),"
  echo "the length criterion of §4.5.2 bisected to the count, and the levels per base face chosen from the"
  echo "model's level error table (\`measure_level_errors\`, depth 5, then \`reconstruct_to_vertex_budget\`"
  echo "on the model carrying it: the error against the input, measured at build time). Closest-point"
  echo "projection; Metro errors (every vertex and 10 x F random samples per side, Hausdorff = max, RMS"
  echo "pooled) and the tolerance in % of the diagonal; \`table s\` the time of \`measure_level_errors\`,"
  echo "\`table bytes\` what the table adds to a version 2 file and its stream in a version 3 file."
  echo
  cat "$adaptive"
} > "$here/RESULTS-adaptive.md.tmp"
mv "$here/RESULTS-adaptive.md.tmp" "$here/RESULTS-adaptive.md"
fi
if [[ $adaptive_only == 1 ]]; then exit 0; fi

if [[ $speed_only == 0 ]]; then
"$build/bin/bench_compact_model" "$data" "${models[@]}" > "$tmp"
{
  echo "# Compact_model benchmark results"
  echo
  echo "Program \`benchmark/Compact_model/bench_compact_model.cpp\`, run by"
  echo "\`bash benchmark/Compact_model/run.sh <build> ${2:-}\`. No peer: PN triangles and the plain mesh"
  echo "are computed by CMGeom on the same base."
  echo
  echo "$line"
  echo
  echo "Columns: base V/F of the CM; \`sharp\` sharp edges and \`cones\` cone-type vertices found; \`build s\`"
  echo "CM build time (simplification + gathering + fitting; min / median of 3 builds); \`CM bytes\` size of the CM file (float32);"
  echo "\`rec s\` reconstruction time at the level (\"min / median\" of 5 runs), along N and closest point"
  echo "(Newton); \`Mvert/s\` output vertices per second along N (of the fastest / the median run); errors are Metro-style (every vertex plus 10 x F"
  echo "random area-uniform samples of each mesh measured against the other, Hausdorff = max, RMS pooled)"
  echo "in % of the original's bounding-box diagonal, for the CM reconstruction (closest point), for PN"
  echo "triangles on the same base at the same level, and for the plain simplified mesh (same"
  echo "weighted-quadric simplifier) with the same number of bytes (12 V + 12 F, F = bytes / 18)."
  echo "\`fit\`: \`thesis\` the thesis' independent fits (the library's default), \`joint\` the joint refit, \`joint+cubic+ec\`"
  echo "the joint refit with cubic surfaces and error control (bound 0.3 % of the diagonal, level 3, 4 rounds),"
  echo "\`selected: <candidate>\` build_selected_compact_model() with its default candidates measured at level 3, as"
  echo "\`cmgeom cm build\` does by default (its build time includes the three builds and measures)."
  echo
  cat "$tmp"
  echo
  echo "Regular against adaptive reconstructions at equal vertex counts: the section that follows"
  echo "(RESULTS-adaptive.md)."
} > "$here/RESULTS.md.tmp"
mv "$here/RESULTS.md.tmp" "$here/RESULTS.md"
fi

# Reconstruction throughput (levels with >= 0.5 M output vertices, along N, 1 and 2 threads, fresh and
# reused output): RESULTS-reconstruction-speed.md.
speed_models=(classic/horse.ply:1000 classic/igea.ply.gz:2000)
[[ "${2:-}" == "--quick" ]] && speed_models=(classic/horse.ply:1000)
line=$(describe_run --threads "1 and 2 (per row)")
"$build/bin/bench_reconstruction_speed" "$data" "${speed_models[@]}" --levels 5-6 --along-n --runs 5 > "$tmp"
"$build/bin/bench_reconstruction_speed_huge_new" "$data" "${speed_models[@]}" --levels 5-6 --along-n --runs 5 > "$huge_new"
{
  echo "# Compact Model reconstruction throughput"
  echo
  echo "Program \`benchmark/Compact_model/bench_reconstruction_speed.cpp\`, run by"
  echo "\`bash benchmark/Compact_model/run.sh <build> ${2:-}\`. No peer."
  echo
  echo "$line"
  echo
  echo "Library call alone (no file IO), regular reconstruction along N, \"min / median\" of 5 runs (rates:"
  echo "of the fastest / the median run); \`fresh\` = a new Reconstruction per call (allocation and first touch of the"
  echo "output included), \`reused\` = into the previous call's output (what a per-frame or deformable"
  echo "CM call pays). Target of the Compact_model chapter: >= 30 M output vertices/s on one thread and"
  echo ">= 50 M on two at levels with >= 1 M output vertices."
  echo
  echo "### The standard operator new (\`bench_reconstruction_speed\`)"
  echo
  cat "$tmp"
  echo
  echo "### A program whose operator new is CMGeom/huge_page_new.h, as the \`cmgeom\` tool's (\`bench_reconstruction_speed_huge_new\`)"
  echo
  echo "The same source built with the header included once: blocks of 8 MB and more are aligned to 2 MB"
  echo "and advised for transparent huge pages before their first touch, so that a fresh output faults in"
  echo "2 MB pages instead of 4 kB ones (this machine's kernel gives huge pages on request only)."
  echo
  cat "$huge_new"
} > "$here/RESULTS-reconstruction-speed.md.tmp"
mv "$here/RESULTS-reconstruction-speed.md.tmp" "$here/RESULTS-reconstruction-speed.md"
[[ $speed_only == 1 ]] && exit 0

# Rate-distortion of the compact CM file against Draco, meshoptimizer + zstd and gzipped OBJ
# (RESULTS-rate-distortion.md, its CSV, and the plot doc/Compact_model/rate_distortion.png; the plot
# needs Debian's python3-matplotlib, installed here when missing and possible).
if ! /usr/bin/python3 -c "import matplotlib" 2>/dev/null && [ "$(id -u)" = 0 ]; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends python3-matplotlib >/dev/null 2>&1 || true
fi
# The meshoptimizer peer is installed before the run is described, so that the description names
# the version the run uses (run_rate_distortion.py installs it too when run alone).
if command -v node >/dev/null && command -v npm >/dev/null && [ ! -d "$here/peers/node_modules/meshoptimizer" ]; then
  npm ci --silent --prefix "$here/peers" || true
fi
python3 "$here/run_rate_distortion.py" --build "$build" ${2:+"$2"} \
  --describe "$(describe_run draco zstd "meshoptimizer-npm=$here/peers" node)"

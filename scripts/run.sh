#!/usr/bin/env bash
# Installs the dependencies, builds the cmgeom tool and runs the main job on the bundled default
# model (Spot): simplification (weighted vs plain quadric), Metro error, a Compact Model and its
# reconstruction, pictures of each, and report.md. Output: ./cmgeom-out (or the directory given).
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-cmgeom-out}"
bash scripts/install-deps.sh
export MESA_SHADER_CACHE_DIR="${MESA_SHADER_CACHE_DIR:-$(pwd)/build/mesa-shader-cache}"
mkdir -p "$MESA_SHADER_CACHE_DIR"
if [[ -z "${CMGEOM_EXE:-}" ]]; then  # CMGEOM_EXE: use an already built tool instead
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build -j "$(nproc)" --target cmgeom
fi
cmgeom=${CMGEOM_EXE:-build/bin/cmgeom}
model=data/spot/spot.obj
mkdir -p "$out"
rm -f "$out/report.md"
stage() { echo "== $*" >&2; }
json() { printf '\n```json\n%s\n```\n' "$(cat "$1")" >> "$out/report.md"; }

stage "1/6 model facts"
$cmgeom info --json "$model" > "$out/info.json"
{ echo "# CMGeom on the bundled model (Spot)"; echo; echo "## Input"; } >> "$out/report.md"
json "$out/info.json"
$cmgeom render "$model" -o "$out/spot.png" --charts --size 768x768 --caption "Spot: charts in red"
echo '![input](spot.png)' >> "$out/report.md"

stage "2/6 simplification to 10 %: area-weighted quadric (thesis 3.4) and plain Garland-Heckbert"
for policy in weighted plain; do
  $cmgeom simplify "$model" -o "$out/spot_$policy.obj" --ratio 0.1 --policy "$policy" --json > "$out/simplify_$policy.json"
  $cmgeom error "$model" "$out/spot_$policy.obj" --json > "$out/error_$policy.json"
  $cmgeom render "$out/spot_$policy.obj" -o "$out/spot_$policy.png" --wireframe --size 768x768 --caption "$policy quadric, 10 %"
  { echo; echo "## Simplification, $policy quadric"; } >> "$out/report.md"
  json "$out/simplify_$policy.json"; json "$out/error_$policy.json"
  echo "![$policy](spot_$policy.png)" >> "$out/report.md"
done

stage "3/6 Compact Model (thesis ch. 4)"
$cmgeom cm build "$model" -o "$out/spot.cm" --ratio 0.05 --json > "$out/cm_build.json"
{ echo; echo "## Compact Model"; } >> "$out/report.md"
json "$out/cm_build.json"

stage "4/6 Compact Model reconstruction, level 2"
$cmgeom cm reconstruct "$out/spot.cm" -o "$out/spot_cm_level2.obj" --level 2 --json > "$out/cm_reconstruct.json"
$cmgeom error "$model" "$out/spot_cm_level2.obj" --json > "$out/error_cm_level2.json"
json "$out/cm_reconstruct.json"; json "$out/error_cm_level2.json"

stage "5/6 pictures of the reconstruction"
$cmgeom render "$out/spot_cm_level2.obj" -o "$out/spot_cm_level2.png" --size 768x768 --caption "CM reconstruction, level 2"
echo '![cm](spot_cm_level2.png)' >> "$out/report.md"

stage "6/6 done"
echo "results in $out/ (report.md, meshes, pictures)"

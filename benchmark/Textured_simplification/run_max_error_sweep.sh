#!/usr/bin/env bash
# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
#
# The guarantee of `cmgeom simplify --max-error E` (and of `cmgeom lod --max-errors`, whose levels
# the same bound makes) on every model of the shared data, checked by an independent measurement: for each mesh of shared/data/classic and each textured model of
# shared/data/textured (its OBJ; spot with its texture named by --texture), and each bound E, the
# command's output is measured against the input by `cmgeom error` (Metro-style: dense area samples
# of both surfaces and every vertex, both ways) and the measured Hausdorff distance is set against E;
# then one chain per model, `cmgeom lod --max-errors 0,E...`, each level measured the same way.
# Inputs the reader refuses as they are are run with the option its message names
# (--allow-degenerate for the ogre's zero-area faces). Writes
# benchmark/Textured_simplification/RESULTS-max-error-sweep.md whole (or --out FILE; machine and
# date from common/describe_run.sh), progress on stderr; exits 1 when any measured distance exceeds
# its bound or a run fails (the file is written either way, the failures in it).
#   run_max_error_sweep.sh <build-dir> [--data DIR] [--bounds 0.02,0.005] [--out FILE]
set -euo pipefail
build=$(cd "${1:?usage: run_max_error_sweep.sh <build-dir> [--data DIR] [--bounds 0.02,0.005] [--out FILE]}" && pwd)
shift
here=$(cd "$(dirname "$0")" && pwd)
data="$here/../../../shared/data"
bounds=0.02,0.005
out="$here/RESULTS-max-error-sweep.md"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --data) data="$2"; shift 2 ;;
    --bounds) bounds="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    *) echo "run_max_error_sweep.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
cmgeom="$build/bin/cmgeom"
[[ -x "$cmgeom" ]] || { echo "run_max_error_sweep.sh: $cmgeom not found (build the cmgeom target)" >&2; exit 2; }
if [[ ! -d "$data/classic" || ! -d "$data/textured" ]]; then
  echo "run_max_error_sweep.sh: skipped: shared data not found at $data (pass --data DIR); $out left as it was" >&2
  exit 0
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
. "$here/../common/describe_run.sh"
described=$(describe_run)  # (the load average at the start)

# the models and the options each needs
models=()
options=()
for m in "$data"/classic/*; do
  case "$m" in *.off | *.obj | *.ply | *.obj.gz | *.ply.gz | *.stl) ;; *) continue ;; esac
  models+=("$m")
  case "$(basename "$m")" in ogre.obj.gz) options+=("--allow-degenerate") ;; *) options+=("") ;; esac
done
for d in "$data"/textured/*/; do
  [[ -d "$d" ]] || continue
  obj=$(ls "$d"*.obj 2>/dev/null | head -1 || true)
  [[ -n "$obj" ]] || continue
  models+=("$obj")
  if [[ "$(basename "$obj")" == spot.obj && -f "$d/spot_texture.png" ]]; then
    options+=("--texture $d/spot_texture.png")
  else
    options+=("")
  fi
done

table="$work/table.md"
{
  echo "| model | E | faces | measured Hausdorff | measured / E |"
  echo "|---|---:|---:|---:|---:|"
} > "$table"
runs=0
over=0
failed=0
worst=0
# measure_row INPUT OUTPUT E FACES TABLE: the output's Hausdorff distance to the input (cmgeom error)
# against E, as a row of TABLE; counts what exceeds E (over), the largest share of E (worst) and a
# failed measurement (failed)
measure_row() {
  local measured ratio is_over
  if ! measured=$("$cmgeom" --quiet error "$1" "$2" --json 2> "$work/err" |
    python3 -c 'import json,sys; print(json.load(sys.stdin)["hausdorff"])'); then
    failed=$((failed + 1))
    echo "| $(basename "$1") | $3 | $4 | measure failed: $(tail -1 "$work/err" | tr '|' '/') | |" >> "$5"
    return
  fi
  read -r ratio is_over < <(python3 -c "r = $measured / $3; print('%.4f' % r, int(r > 1))")
  over=$((over + is_over))
  worst=$(python3 -c "print(max($worst, $ratio))")
  printf '| %s | %s | %s | %.6g | %s |\n' "$(basename "$1")" "$3" "$4" "$measured" "$ratio" >> "$5"
}
IFS=, read -r -a bound_list <<< "$bounds"
for i in "${!models[@]}"; do
  m="${models[$i]}"
  name=$(basename "$m")
  for e in "${bound_list[@]}"; do
    echo "  $name, E = $e" >&2
    runs=$((runs + 1))
    # (options word-split on purpose: a flag and its value)
    # shellcheck disable=SC2086
    if ! report=$("$cmgeom" --quiet simplify "$m" ${options[$i]} -o "$work/out.obj" --max-error "$e" --json 2> "$work/err"); then
      failed=$((failed + 1))
      echo "| $name | $e | failed: $(tail -1 "$work/err" | tr '|' '/') | | |" >> "$table"
      continue
    fi
    faces=$(python3 -c 'import json,sys; print(json.loads(sys.stdin.read())["faces_out"])' <<< "$report")
    measure_row "$m" "$work/out.obj" "$e" "$faces" "$table"
  done
done

# the chains by error bound: `cmgeom lod IN --max-errors 0,E...` (the bounds increasing), each level
# written as OBJ (--obj-prefix) and measured as the simplified meshes are
chain_bounds=$(printf '%s\n' "${bound_list[@]}" | sort -g | paste -sd, -)
chain_table="$work/chain.md"
{
  echo "| model | level bound E | faces | measured Hausdorff | measured / E |"
  echo "|---|---:|---:|---:|---:|"
} > "$chain_table"
chain_levels=0
IFS=, read -r -a chain_list <<< "$chain_bounds"
for i in "${!models[@]}"; do
  m="${models[$i]}"
  name=$(basename "$m")
  echo "  $name, lod --max-errors 0,$chain_bounds" >&2
  rm -f "$work"/L_*
  # shellcheck disable=SC2086
  if ! report=$("$cmgeom" --quiet lod "$m" ${options[$i]} -o "$work/chain.glb" --max-errors "0,$chain_bounds" \
    --obj-prefix "$work/L" --json 2> "$work/err"); then
    failed=$((failed + 1))
    echo "| $name | | failed: $(tail -1 "$work/err" | tr '|' '/') | | |" >> "$chain_table"
    continue
  fi
  for k in "${!chain_list[@]}"; do
    e="${chain_list[$k]}"
    level=$((k + 1))
    chain_levels=$((chain_levels + 1))
    faces=$(python3 -c 'import json,sys; print(json.loads(sys.stdin.read())["levels"]['"$level"']["faces"])' <<< "$report")
    measure_row "$m" "$work/L_$level.obj" "$e" "$faces" "$chain_table"
  done
done

result="$work/result.md"
{
  echo "## The --max-error guarantee on every model of the shared data"
  echo
  echo "Generated by \`benchmark/Textured_simplification/run_max_error_sweep.sh <build-dir>\`:" \
    "\`cmgeom simplify IN -o OUT.obj --max-error E\` on every mesh of shared/data/classic and every textured model," \
    "then \`cmgeom error IN OUT.obj\` (its \`hausdorff\`: both ways, dense area samples and every vertex," \
    "a fraction of the input's bounding-box diagonal, as E is)."
  echo
  echo "$described"
  echo
  cat "$table"
  echo
  echo "The chains by error bound of the same models: \`cmgeom lod IN -o OUT.glb --max-errors 0,$chain_bounds" \
    "--obj-prefix L\` (one run per model, each level going on from the last), each level's OBJ measured the same way."
  echo
  cat "$chain_table"
  echo
  echo "- $runs runs of simplify and $chain_levels levels of chains; measured Hausdorff above E: $over; failed runs:" \
    "$failed; largest measured / E: $worst."
} > "$result"
cp "$result" "$out"
echo "wrote $out" >&2
[[ $over -eq 0 && $failed -eq 0 ]]

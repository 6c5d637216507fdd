#!/usr/bin/env bash
# Scale benchmark (doc/Reliability.md): every pipeline stage of the cmgeom tool on igea (268,686
# faces) and on igea subdivided once (1,074,744 faces), each under GNU time, reporting wall time
# and peak resident memory. The 1M-face mesh is made at run time in a temporary directory and never
# committed. Targets: < 2 GB peak per stage; time growing linearly (about x4 from the first
# column to the second; quadratic would be x16).
#
# Usage: bash benchmark/Scale/run.sh [build-dir] [--quick]   (benchmark/run.sh calls it so)
#   build-dir: where bin/cmgeom is (default: build); --quick: the 1M-face mesh only (no time ratio),
#   one run per stage (3 otherwise: times are "min / median", peak RSS the largest of the runs).
#   Writes benchmark/Scale/RESULTS.md.
# Needs: /usr/bin/time (Debian package time), python3, the shared models (../shared/data).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${1:-$root/build}"
quick="${2:-}"
cmgeom="$(realpath "$build/bin/cmgeom")"
results="$here/RESULTS.md"
data="${CMGEOM_DATA_DIR:-$root/../shared/data}"
[[ -x "$cmgeom" ]] || { echo "error: $cmgeom not found (build the cmgeom target first)" >&2; exit 1; }
[[ -f "$data/classic/igea.ply.gz" ]] || { echo "error: $data/classic/igea.ply.gz not found (set CMGEOM_DATA_DIR)" >&2; exit 1; }
[[ -x /usr/bin/time ]] || { echo "error: /usr/bin/time not found (apt-get install time)" >&2; exit 1; }

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
gunzip -c "$data/classic/igea.ply.gz" > "$work/igea250k.ply"
python3 "$here/subdivide.py" "$work/igea250k.ply" "$work/igea1m.ply"

# A box cage 10% larger than the model's bounding box, and the same box sheared along x.
python3 - "$work/igea250k.ply" "$work" <<'PY'
import struct, sys
data = open(sys.argv[1], 'rb').read()
end = data.index(b'end_header\n') + 11
nv = int([l for l in data[:end].decode().splitlines() if l.startswith('element vertex')][0].split()[2])
lo, hi = [1e300] * 3, [-1e300] * 3
for p in struct.iter_unpack('<3f', data[end:end + 12 * nv]):
    for k in range(3):
        lo[k], hi[k] = min(lo[k], p[k]), max(hi[k], p[k])
pad = [0.1 * (hi[k] - lo[k]) for k in range(3)]
lo = [lo[k] - pad[k] for k in range(3)]
hi = [hi[k] + pad[k] for k in range(3)]
faces = 'f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n'
def box(shear):
    out = ''
    for z in (lo[2], hi[2]):
        for x, y in ((lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])):
            t = (y - lo[1]) / (hi[1] - lo[1])
            out += f'v {x + shear * t * (hi[0] - lo[0]):.9g} {y:.9g} {z:.9g}\n'
    return out + faces
open(sys.argv[2] + '/rest.obj', 'w').write(box(0.0))
open(sys.argv[2] + '/deformed.obj', 'w').write(box(0.3))
open(sys.argv[2] + '/cages.json', 'w').write(
    '{"cages": [{"rest": "rest.obj", "deformed": "deformed.obj", "coordinates": "mean_value"}]}\n')
PY

# stage name | arguments ({in} = input mesh, {out} = output directory)
stages=(
  "simplify (10%)|simplify {in} -o {out}/s.ply --ratio 0.1"
  "error (Metro, default sampling)|error {in} {out}/s.ply"
  "render 1024x1024|render {in} -o {out}/r.png --size 1024x1024"
  "cm build (2% base)|cm build {in} -o {out}/m.cm --ratio 0.02"
  "cm reconstruct (level 2)|cm reconstruct {out}/m.cm -o {out}/rec.ply --level 2"
  "deform (box cage, mean value)|deform {in} --cages $work/cages.json -o {out}/d.ply"
  "cm deform (box cage, level 2)|cm deform {out}/m.cm --cages $work/cages.json -o {out}/cd.ply --level 2"
)

. "$here/../common/describe_run.sh"
line=$(describe_run)
declare -A secs rss
sizes=(250k 1m)
runs=3
[[ "$quick" == --quick ]] && sizes=(1m) && runs=1
# minmed "t1 t2 ...": "min / median" of the numbers (2 decimals)
minmed() { tr ' ' '\n' <<< "$1" | grep . | sort -g | awk '{ v[NR] = $1 } END { m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2; printf "%.2f / %.2f", v[1], m }'; }
# med "t1 t2 ...": the median alone
med() { tr ' ' '\n' <<< "$1" | grep . | sort -g | awk '{ v[NR] = $1 } END { print NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
for size in "${sizes[@]}"; do
  out="$work/out_$size"
  mkdir -p "$out"
  for s in "${stages[@]}"; do
    name="${s%%|*}"
    args="${s#*|}"
    args="${args//\{in\}/$work/igea$size.ply}"
    args="${args//\{out\}/$out}"
    echo "== $size: cmgeom $args"
    secs["$name,$size"]=""
    rss["$name,$size"]=0
    for ((r = 0; r < runs; ++r)); do
      # shellcheck disable=SC2086
      if /usr/bin/time -f '%e %M' -o "$work/time.txt" "$cmgeom" $args > "$work/stdout.txt" 2> "$work/stderr.txt"; then
        read -r e m < "$work/time.txt"
        secs["$name,$size"]+=" $e"
        ((m > rss["$name,$size"])) && rss["$name,$size"]=$m
        echo "   $e s, $((m / 1024)) MB"
      else
        echo "   failed: $(tail -1 "$work/stderr.txt")"
        secs["$name,$size"]=failed
        rss["$name,$size"]=0
        break
      fi
    done
  done
done

{
  echo "# Scale: the pipeline stages on a 1M-face mesh"
  echo
  echo "\`bash benchmark/Scale/run.sh $(basename "$build") $quick\`; default threads, no peer."
  echo
  echo "$line"
  echo
  echo "Inputs: igea (134,345 vertices, 268,686 faces) and igea subdivided once (1-to-4 midpoint, 537,374 vertices,"
  echo "1,074,744 faces), made at run time. Wall time (\"min / median\" of $runs runs) and peak resident set size (the largest"
  echo "of the runs) from GNU time; the time ratio is of the medians. Target: < 2 GB per"
  echo "stage; linear stages take about 4x longer on the larger mesh (quadratic ones would take 16x)."
  echo
  echo "| stage | 268k faces: time min / median (s) | peak RSS (MB) | 1.07M faces: time min / median (s) | peak RSS (MB) | time ratio |"
  echo "| --- | ---: | ---: | ---: | ---: | ---: |"
  for s in "${stages[@]}"; do
    name="${s%%|*}"
    a="${secs[$name,250k]:--}"; b="${secs[$name,1m]:--}"
    ma=-; mb=-; ta=$a; tb=$b
    [[ "$a" != - && "$a" != failed ]] && ma=$(med "$a") && ta=$(minmed "$a")
    [[ "$b" != - && "$b" != failed ]] && mb=$(med "$b") && tb=$(minmed "$b")
    ratio=$(python3 -c "a,b='$ma','$mb'; print(f'{float(b)/float(a):.1f}' if a not in ('-','0','0.00') and b != '-' else '-')")
    echo "| $name | $ta | $(( ${rss[$name,250k]:-0} / 1024 )) | $tb | $(( ${rss[$name,1m]:-0} / 1024 )) | $ratio |"
  done
} > "$results"
echo "wrote $results"
cat "$results"

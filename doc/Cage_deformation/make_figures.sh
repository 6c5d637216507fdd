#!/bin/sh
# Regenerates the pictures of README.md with the cmgeom tool itself (deform + render).
# Usage: make_figures.sh <path/to/cmgeom> [shared data dir]   (needs gzip and oiiotool)
set -eu
CMGEOM=${1:?usage: make_figures.sh <path/to/cmgeom> [data dir]}
for tool in gzip oiiotool; do
  command -v "$tool" >/dev/null 2>&1 || {
    echo "make_figures.sh: needs $tool (Debian: apt-get install $([ "$tool" = oiiotool ] && echo openimageio-tools || echo gzip))" >&2
    exit 1
  }
done
HERE=$(cd "$(dirname "$0")" && pwd)
DATA=${2:-$HERE/../../../shared/data}
Q=$DATA/cages/qmvc
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
gzip -dc "$Q/FireHydrant.obj.gz" > "$TMP/FireHydrant.obj"
"$CMGEOM" render "$TMP/FireHydrant.obj" -o "$TMP/rest.png" --view front --size 400x400 --caption rest
for c in mean_value green harmonic; do
  # the cage-system file; paths are relative to it
  cp "$Q/FireHydrant_Cage.obj" "$Q/FireHydrant_Cage_Deformed.obj" "$TMP/"
  printf '{"cages": [{"rest": "FireHydrant_Cage.obj", "deformed": "FireHydrant_Cage_Deformed.obj", "coordinates": "%s"}]}\n' "$c" > "$TMP/$c.json"
  "$CMGEOM" deform "$TMP/FireHydrant.obj" --cages "$TMP/$c.json" -o "$TMP/$c.obj" --json > "$HERE/images/firehydrant_$c.json"
  "$CMGEOM" render "$TMP/$c.obj" -o "$TMP/$c.png" --view front --size 400x400 --caption "$c"
done
oiiotool "$TMP/rest.png" "$TMP/mean_value.png" "$TMP/green.png" "$TMP/harmonic.png" --mosaic 4x1 \
  -o "$HERE/images/firehydrant_deform.png"
# Ogre: the artist's pose moves vertices outside the cage; Green coordinates continue them
# through their exit face (status "extended"), mean value coordinates are defined everywhere, and
# harmonic coordinates, undefined there, take the cage's mean value coordinates when asked.
for c in mean_value green harmonic; do
  cp "$Q/Ogre_Cage.obj" "$Q/Ogre_Cage_Deformed.obj" "$TMP/"
  extra=""
  caption=$c
  if [ "$c" = harmonic ]; then
    extra=', "harmonic": {"outside": "mean_value"}'
    caption="harmonic, MVC outside"
  fi
  printf '{"cages": [{"rest": "Ogre_Cage.obj", "deformed": "Ogre_Cage_Deformed.obj", "coordinates": "%s"%s}]}\n' "$c" "$extra" > "$TMP/ogre_$c.json"
  "$CMGEOM" deform "$Q/Ogre.obj" --cages "$TMP/ogre_$c.json" -o "$TMP/ogre_$c.obj" --json > "$HERE/images/ogre_$c.json"
  "$CMGEOM" render "$TMP/ogre_$c.obj" -o "$TMP/ogre_$c.png" --view front --size 400x400 --caption "$caption"
done
"$CMGEOM" render "$Q/Ogre.obj" -o "$TMP/ogre_rest.png" --view front --size 400x400 --caption rest
oiiotool "$TMP/ogre_rest.png" "$TMP/ogre_mean_value.png" "$TMP/ogre_green.png" "$TMP/ogre_harmonic.png" --mosaic 4x1 \
  -o "$HERE/images/ogre_deform.png"

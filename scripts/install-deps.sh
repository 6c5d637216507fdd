#!/usr/bin/env bash
# Installs CMGeom's build and test dependencies from Debian 12 packages (run as root).
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config git ca-certificates
  libcgal-dev libeigen3-dev libboost-dev libgmp-dev libmpfr-dev libtbb-dev
  libosmesa6-dev libopenimageio-dev libpng-dev libjpeg-dev libzstd-dev
  libcli11-dev nlohmann-json3-dev libtinyobjloader-dev libtinygltf-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libmeshoptimizer-dev libopenmesh-dev draco libdraco-dev time python3
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
echo "dependencies: all ${#packages[@]} packages present"
# Node.js and npm run the Khronos glTF validator in the glTF writer's tests (test/Mesh_IO/gltf_validator);
# optional: without them those tests skip and say so. Looked for as commands, since a Node.js installed
# from elsewhere (e.g. NodeSource, which bundles npm) conflicts with Debian's npm package.
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  echo "installing: nodejs npm (optional)"
  export DEBIAN_FRONTEND=noninteractive
  if ! apt-get install -y -qq --no-install-recommends nodejs npm >/dev/null 2>&1; then
    echo "install-deps.sh: nodejs/npm could not be installed: the glTF validator tests will skip"
  fi
fi

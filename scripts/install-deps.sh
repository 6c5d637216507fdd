#!/usr/bin/env bash
# Installs CMGeom's build and test dependencies from Debian 12 packages (run as root).
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config git ca-certificates
  libcgal-dev libeigen3-dev libboost-dev libgmp-dev libmpfr-dev libtbb-dev
  libosmesa6-dev libopenimageio-dev
  libcli11-dev nlohmann-json3-dev libtinyobjloader-dev libtinygltf-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libmeshoptimizer-dev libopenmesh-dev time python3
  nodejs npm  # the Khronos glTF validator of the glTF writer's tests (test/Mesh_IO/gltf_validator)
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

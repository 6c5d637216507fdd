# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
#
# Shell functions shared by the benchmark scripts (source this file from bash):
#   describe_run [--threads T] [PEER ...]
#       one Markdown line giving the machine (CPU, cores, RAM), the thread count, the versions of
#       the peers named (read from the system now, never written by hand), the load average and
#       the date of the run;
#   peer_version PEER
#       the version of one peer: the Debian package's version (dpkg-query) for cgal, meshoptimizer,
#       openmesh, draco, zstd, tbb; for meshoptimizer-npm[=DIR] the version in
#       DIR/node_modules/meshoptimizer/package.json (DIR: a package's peers/ folder); for node the
#       Node.js version. "not installed" when missing.
#   machine_description
#       "CPU, N cores, M GiB RAM" of this machine.

# deb_version PACKAGE: the Debian package's version, or "not installed".
deb_version() {
  local v
  v=$(dpkg-query -W -f='${db:Status-Status} ${Version}' "$1" 2>/dev/null || true)
  case "$v" in
    installed\ *) echo "${v#installed }" ;;
    *) echo "not installed" ;;
  esac
}

peer_version() {
  local peer=$1 dir v
  case "$peer" in
    cgal) echo "CGAL $(deb_version libcgal-dev) (libcgal-dev)" ;;
    meshoptimizer) echo "meshoptimizer $(deb_version libmeshoptimizer-dev) (libmeshoptimizer-dev)" ;;
    openmesh) echo "OpenMesh $(deb_version libopenmesh-dev) (libopenmesh-dev)" ;;
    draco) echo "Draco $(deb_version draco) (draco)" ;;
    zstd) echo "zstd $(deb_version zstd) (zstd)" ;;
    tbb) echo "oneTBB $(deb_version libtbb-dev) (libtbb-dev)" ;;
    osmesa) echo "OSMesa $(deb_version libosmesa6-dev) (libosmesa6-dev)" ;;
    node) echo "Node.js $(node --version 2>/dev/null || echo 'not installed')" ;;
    meshoptimizer-npm*)
      dir=${peer#meshoptimizer-npm}
      dir=${dir#=}
      v=$(sed -n 's/^[[:space:]]*"version":[[:space:]]*"\([^"]*\)".*/\1/p' "$dir/node_modules/meshoptimizer/package.json" 2>/dev/null | head -1)
      echo "meshoptimizer ${v:-not installed} (npm)" ;;
    *) echo "$peer (unknown peer)" ;;
  esac
}

machine_description() {
  local cpu ram
  cpu=$(sed -n 's/^model name[[:space:]]*: *//p' /proc/cpuinfo | head -1)
  ram=$(awk '/^MemTotal:/ { printf "%.0f", $2 / 1048576 }' /proc/meminfo)
  echo "${cpu:-unknown CPU}, $(nproc) cores, ${ram} GiB RAM"
}

describe_run() {
  local threads peers=() p
  threads=$(nproc)
  if [[ "${1:-}" == --threads ]]; then
    threads=$2
    shift 2
  fi
  for p in "$@"; do peers+=("$(peer_version "$p")"); done
  local peer_text="none"
  if ((${#peers[@]})); then
    peer_text=$(printf '%s, ' "${peers[@]}")
    peer_text=${peer_text%, }
  fi
  echo "Machine: $(machine_description); threads: ${threads}; peers: ${peer_text}; load average at the start $(cut -d' ' -f1-3 /proc/loadavg); run of $(date -u '+%Y-%m-%d %H:%M UTC')."
}

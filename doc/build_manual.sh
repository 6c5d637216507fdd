#!/usr/bin/env bash
# Builds the manual (doc/*.md) into a static HTML site in build/manual with MkDocs (Debian package
# `mkdocs`, installed here when missing; run as root on a fresh machine). Open build/manual/index.html.
# The command-line reference doc/CLI.md is regenerated first when a built cmgeom is given:
#   bash doc/build_manual.sh [path/to/cmgeom]
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v mkdocs >/dev/null; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq && apt-get install -y -qq --no-install-recommends mkdocs >/dev/null
fi
if [[ -n "${1:-}" ]]; then bash doc/make_cli_reference.sh "$1"; fi
mkdocs build --quiet --config-file mkdocs.yml
echo "manual: build/manual/index.html"

#!/usr/bin/env bash
# Gathers the per-package benchmark tables (benchmark/<Package>/RESULTS.md, each written by its
# package's benchmark program or script) into benchmark/RESULTS.md.
set -euo pipefail
cd "$(dirname "$0")"
{
  echo "# CMGeom benchmark results"
  echo
  echo "Each section below is written by the benchmark of its package (see the section for the exact"
  echo "command). Machine of the committed figures: 2-vCPU AMD EPYC VM, 24 GiB, Debian 12, g++ 12.2,"
  echo "\`-O2\` unless a section says otherwise. The machine is shared: trust ratios measured within one run"
  echo "more than absolute seconds."
  for f in */RESULTS.md; do
    echo
    echo "---"
    echo
    sed 's/^# /## /' "$f"
  done
} > RESULTS.md
echo "wrote benchmark/RESULTS.md from: $(ls */RESULTS.md | tr '\n' ' ')"

#!/usr/bin/env bash
# Gathers the per-package benchmark tables (benchmark/<Package>/RESULTS.md, each written by its
# package's benchmark program or script) into benchmark/RESULTS.md. benchmark/run.sh calls it
# with a line describing the machine and the run; without it a generic description is used.
#   collect_results.sh ["machine and run description"]
set -euo pipefail
cd "$(dirname "$0")"
{
  echo "# CMGeom benchmark results"
  echo
  echo "Each section below is written by the benchmark of its package (\`benchmark/<Package>/run.sh\`, see"
  echo "the section for the exact command); \`bash benchmark/run.sh\` rebuilds and reruns them all. Peers"
  echo "(CGAL 5.5.1, meshoptimizer 0.18, OpenMesh 9) run in the same process or the same run as ours."
  echo "Trust ratios measured within one run more than absolute seconds."
  echo
  echo "${1:-Machine of the committed figures: 2-vCPU AMD EPYC VM, 24 GiB, Debian 12, g++ 12.2, \`-O2\` unless a section says otherwise.}"
  for f in */RESULTS.md; do
    echo
    echo "---"
    echo
    sed 's/^# /## /' "$f"
    # further sections of the same package, written by its other scripts (RESULTS-<part>.md)
    for g in "$(dirname "$f")"/RESULTS-*.md; do
      [ -f "$g" ] || continue
      echo
      sed 's/^# /## /' "$g"
    done
  done
} > RESULTS.md
echo "wrote benchmark/RESULTS.md from: $(ls */RESULTS.md */RESULTS-*.md 2>/dev/null | tr '\n' ' ')"

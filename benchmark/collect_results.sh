#!/usr/bin/env bash
# Gathers the per-package benchmark tables (benchmark/<Package>/RESULTS.md, each written by its
# package's benchmark program or script) into benchmark/RESULTS.md. benchmark/run.sh calls it
# with a line describing the machine and the run; without it a generic description is used.
#   collect_results.sh ["machine and run description"]
# Peer versions are read from the system now (common/describe_run.sh), never written by hand.
set -euo pipefail
cd "$(dirname "$0")"
. common/describe_run.sh
peers=$(for p in cgal meshoptimizer openmesh draco zstd meshoptimizer-npm=Compact_model/peers \
                 meshoptimizer-npm=Textured_simplification/peers node; do peer_version "$p"; done |
        sort -u | paste -sd ';' | sed 's/;/, /g')
{
  echo "# CMGeom benchmark results"
  echo
  echo "Each section below is written by the benchmark of its package (\`benchmark/<Package>/run.sh\`, see"
  echo "the section for the exact command); \`bash benchmark/run.sh\` rebuilds and reruns them all, and"
  echo "nothing in this file or in the per-package RESULTS files is edited by hand. Peers run in the same"
  echo "process or the same run as ours; installed now: ${peers}."
  echo "Timings are \"min / median\" of repeated runs unless a table says otherwise. Trust ratios measured"
  echo "within one run more than absolute seconds."
  echo
  echo "${1:-Machine: $(machine_description) (collect_results.sh run alone: the sections below give their own runs).}"
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

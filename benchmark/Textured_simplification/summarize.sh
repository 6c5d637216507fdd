#!/bin/sh
# Appends per-tool medians of the ratios to GH (time, Hausdorff, RMS) to a RESULTS.md table.
#   summarize.sh RESULTS.md
set -eu
f=${1:?usage: summarize.sh RESULTS.md}
summary=$(awk -F'|' '
  /^\| [a-z]/ && $4 !~ /tool/ {
    tool=$4; gsub(/ /, "", tool); model=$2; gsub(/ \(.*/, "", model); gsub(/ /, "", model)
    n[tool]++; t[tool, n[tool]]=$10+0; h[tool, n[tool]]=$11+0; r[tool, n[tool]]=$12+0
    tp[tool, n[tool]]=$7+0; ps[tool, n[tool]]=$13+0
  }
  function median(a, tool, k,   i, j, x, v, m) {
    m=0; for (i=1; i<=k; i++) v[++m]=a[tool, i]
    for (i=1; i<=m; i++) for (j=i+1; j<=m; j++) if (v[j] < v[i]) { x=v[i]; v[i]=v[j]; v[j]=x }
    return (m % 2) ? v[(m+1)/2] : (v[m/2] + v[m/2+1]) / 2
  }
  function minv(a, tool, k,   i, x) { x=a[tool,1]; for (i=2; i<=k; i++) if (a[tool,i] < x) x=a[tool,i]; return x }
  function maxv(a, tool, k,   i, x) { x=a[tool,1]; for (i=2; i<=k; i++) if (a[tool,i] > x) x=a[tool,i]; return x }
  END {
    print "| tool | configs | time / GH median [min-max] | GH time / tool time (speed-up) median | paired speed-up median [min-max] | Hausdorff / GH median [min-max] | RMS / GH median [min-max] | M input tri/s median |"
    print "|---|---:|---|---:|---|---|---|---:|"
    for (tool in n) {
      k=n[tool]
      printf "| %s | %d | %.3g [%.3g-%.3g] | %.3g | %.3g [%.3g-%.3g] | %.3g [%.3g-%.3g] | %.3g [%.3g-%.3g] | %.3g |\n", tool, k,
        median(t, tool, k), minv(t, tool, k), maxv(t, tool, k), 1 / median(t, tool, k),
        median(ps, tool, k), minv(ps, tool, k), maxv(ps, tool, k),
        median(h, tool, k), minv(h, tool, k), maxv(h, tool, k),
        median(r, tool, k), minv(r, tool, k), maxv(r, tool, k), median(tp, tool, k)
    }
  }' "$f" | sort)
{
  echo
  echo "## Summary over all models and targets (ratios to cgal-gh in the same configuration)"
  echo
  echo "$summary" | grep '^| tool'
  echo "$summary" | grep '^|---'
  echo "$summary" | grep -v '^| tool' | grep -v '^|---'
} >> "$f"

#!/usr/bin/env python3
"""Survey of Compact Model build configurations over the shared classic models: the evidence behind
the default candidates of build_selected_compact_model() (`cmgeom cm build --fit auto`).

Every case is a model of ../shared/data/classic with a base of 2 % of its faces (at least 8) and,
for the models of 10,000 faces or more, bases of 250 and 1000 faces. Each configuration is built with
`cmgeom cm build --fit thesis|joint ...`, reconstructed at level 3 (`cm reconstruct`, closest point)
and measured with `cmgeom error` (Metro-style, 10 x the faces' samples per direction; Hausdorff and
RMS in % of the input's bounding-box diagonal). Then, for every set made of the thesis' build and
one to three other configurations, the per-case best (lowest Hausdorff, then RMS) is compared with
the thesis' build: the median ratios, and the build time of the whole set relative to the thesis'.

    python3 benchmark/Compact_model/run_fit_survey.py --build build [--jobs 2] [--out FILE]

Writes benchmark/Compact_model/RESULTS-fit-survey.md (or FILE). Models `cmgeom` cannot read as they
are (beetle, cow, ogre, teapot) are built with --repair --allow-degenerate; a case that fails is left
out, and named with the reason.
"""
import argparse
import concurrent.futures as cf
import itertools
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

CONFIGS = [
    # (tag, description, cm build options)
    ("A", "thesis: base on input vertices, independent quadric fits", ["--fit", "thesis"]),
    ("B", "joint refit, base on input vertices", ["--fit", "joint"]),
    ("C", "joint refit, optimal placement, cubic", ["--fit", "joint", "--optimal-placement", "--cubic"]),
    ("D", "joint refit, optimal placement", ["--fit", "joint", "--optimal-placement"]),
    ("E", "thesis fits, optimal placement", ["--fit", "thesis", "--optimal-placement"]),
    ("F", "joint refit, optimal placement, cubic, sharp 25", ["--fit", "joint", "--optimal-placement", "--cubic",
                                                               "--sharp-angle", "25"]),
    ("G", "joint refit, optimal placement, cubic, sharp 30", ["--fit", "joint", "--optimal-placement", "--cubic",
                                                               "--sharp-angle", "30"]),
    ("H", "joint refit, optimal placement, sharp 25", ["--fit", "joint", "--optimal-placement", "--sharp-angle",
                                                        "25"]),
]
REPAIR = ("beetle", "cow", "ogre", "teapot")


def faces_of(cmgeom, path):
    out = subprocess.run([cmgeom, "info", path, "--json"], capture_output=True, text=True)
    if out.returncode != 0:
        return None
    return json.loads(out.stdout).get("faces")


def one(cmgeom, path, faces, tag, opts, repair):
    with tempfile.TemporaryDirectory(prefix="cmgeom-survey-") as d:
        cm, rec = os.path.join(d, "m.cm"), os.path.join(d, "r.ply")
        t0 = time.monotonic()
        b = subprocess.run([cmgeom, "--quiet", "cm", "build", path, "-o", cm, "--faces", str(faces)] + opts +
                           (["--repair", "--allow-degenerate"] if repair else []), capture_output=True, text=True)
        seconds = time.monotonic() - t0
        if b.returncode != 0:
            return None, b.stderr.strip().splitlines()[-1:] or ["failed"]
        subprocess.run([cmgeom, "--quiet", "cm", "reconstruct", cm, "-o", rec, "--level", "3"], check=True,
                       capture_output=True)
        e = subprocess.run([cmgeom, "error", path, rec, "--json"], capture_output=True, text=True)
        if e.returncode != 0:
            return None, e.stderr.strip().splitlines()[-1:] or ["error failed"]
        j = json.loads(e.stdout)
        return (100 * j["hausdorff"], 100 * j["rms"], seconds), None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out")
    ap.add_argument("--describe", default="")
    a = ap.parse_args()
    here = os.path.dirname(os.path.abspath(__file__))
    data = os.environ.get("CMGEOM_DATA_DIR", os.path.join(here, "..", "..", "..", "shared", "data"))
    classic = os.path.join(data, "classic")
    if not os.path.isdir(classic):
        print(f"run_fit_survey: {classic} not found: nothing measured", file=sys.stderr)
        return 1
    cmgeom = os.path.join(os.path.abspath(a.build), "bin", "cmgeom")
    cases = []
    for name in sorted(os.listdir(classic)):
        if name.endswith((".md", ".txt")):
            continue
        path = os.path.join(classic, name)
        repair = name.startswith(REPAIR)
        f = faces_of(cmgeom, path)
        if not f:
            continue
        bases = [max(8, round(0.02 * f))] + ([250, 1000] if f >= 10000 else [])
        cases += [(name, path, repair, nb) for nb in bases]
    results, skipped = {}, {}
    with cf.ThreadPoolExecutor(a.jobs) as pool:
        futures = {pool.submit(one, cmgeom, path, nb, tag, opts, repair): (name, nb, tag)
                   for (name, path, repair, nb) in cases for (tag, _, opts) in CONFIGS}
        for fu in cf.as_completed(futures):
            name, nb, tag = futures[fu]
            r, why = fu.result()
            if r is None:
                skipped[(name, nb)] = why[0].replace(classic + os.sep, "")
            else:
                results.setdefault((name, nb), {})[tag] = r
    keys = sorted(k for k in results if k not in skipped and len(results[k]) == len(CONFIGS))
    tags = [c[0] for c in CONFIGS]

    L = ["# Compact Model build configurations over the shared classic models", "",
         "Generated by `python3 benchmark/Compact_model/run_fit_survey.py --build <build>`: the evidence behind the default "
         "candidates of `build_selected_compact_model()` (`cmgeom cm build --fit auto`).", ""]
    if a.describe:
        L += [a.describe, ""]
    L += ["Cases: every model of shared/data/classic at a base of 2 % of its faces (at least 8), and the models of "
          "10,000 faces or more at 250 and 1000 base faces; `cm build --faces N` with the options below, `cm reconstruct "
          "--level 3` (closest point), `cmgeom error` (Metro-style, 10 x F samples per direction): Hausdorff % / RMS % "
          "of the diagonal.", "",
          "| tag | configuration | `cm build` options |", "|---|---|---|"]
    for tag, desc, opts in CONFIGS:
        L.append(f"| {tag} | {desc} | `{' '.join(opts)}` |")
    L += ["", "| model | base faces | " + " | ".join(tags) + " |", "|---|---:|" + "---:|" * len(tags)]
    for k in keys:
        L.append(f"| {k[0]} | {k[1]} | " + " | ".join("%.3f / %.4f" % results[k][t][:2] for t in tags) + " |")
    if skipped:
        L += ["", "Left out: " + "; ".join(f"{n} at {nb} ({why})" for (n, nb), why in sorted(skipped.items()))]

    def best_of(cand):
        hr, rr, tr = [], [], []
        for k in keys:
            v = results[k]
            h, r, _ = min((v[t][0], v[t][1], t) for t in cand)
            hr.append(h / v["A"][0])
            rr.append(r / v["A"][1])
            tr.append(sum(v[t][2] for t in cand) / v["A"][2])
        return statistics.median(hr), statistics.median(rr), max(hr), statistics.median(tr)

    rows = []
    for n in (1, 2, 3):
        for comb in itertools.combinations(tags[1:], n):
            cand = "A" + "".join(comb)
            rows.append((best_of(cand), cand))
    rows.sort(key=lambda r: (round(r[0][0], 3), round(r[0][1], 3), len(r[1])))
    L += ["", f"Sets of candidates (the thesis' build A and one to three others), {len(keys)} cases: per case the "
          "candidate of lowest Hausdorff distance (then RMS), against A alone. The 15 best by median Hausdorff ratio, "
          "then median RMS ratio, and every set of A and one other:", "",
          "| set | Hausdorff / A, median | RMS / A, median | Hausdorff / A, worst | command seconds / A's, median |",
          "|---|---:|---:|---:|---:|"]
    shown = rows[:15] + [r for r in rows[15:] if len(r[1]) == 2]
    for (h, r, w, t), cand in shown:
        L.append(f"| {cand} | {h:.3f} | {r:.3f} | {w:.3f} | {t:.1f} |")
    singles = []
    for t in tags[1:]:
        hr = [results[k][t][0] / results[k]["A"][0] for k in keys]
        worse = sum(1 for x in hr if x > 1.1)
        singles.append(f"{t} {statistics.median(hr):.3f} (more than 10 % above A in {worse})")
    L += ["", "Each configuration alone, median Hausdorff ratio to A: " + "; ".join(singles) + "."]
    out = a.out or os.path.join(here, "RESULTS-fit-survey.md")
    with open(out + ".tmp", "w") as f:
        f.write("\n".join(L) + "\n")
    os.replace(out + ".tmp", out)
    print(f"run_fit_survey: {len(keys)} cases, written {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
"""Level-of-detail chains of a large textured mesh: DamagedHelmet subdivided three times
(subdivide_textured.py: 988,928 faces, its 2048² texture), side by side in interleaved rounds:

  simplify    cmgeom simplify IN --ratio <smallest> --prune        (the smallest level alone)
  per-level   cmgeom lod IN --ratios R --no-error --prune          (an atlas for every level)
  shared      cmgeom lod IN --ratios R --no-error --prune --shared-texture

Wall seconds of each whole command (reading the OBJ, writing the GLB or OBJ + PNG) and its peak
resident memory (GNU time), "min / median" of the rounds; the chains' parts (`lod --json`: the parts
the collapses down to the first level ran in, 0 = on the whole). Then, once, each level's image RMSE
against the input (`cmgeom compare IN LEVEL.obj --json --size N`: 26 views, 8-bit units), for both
chains and for `cmgeom simplify IN --faces <the level's faces>` alone. Target of the chains (issue:
one run costs <= 1.2 x the smallest level alone).

Usage: run_lod_scale.py --build DIR [--ratios 1,0.25,0.05,0.01] [--reps 3] [--size 256] [--out FILE]
                        [--describe LINE]
Needs shared/data (CMGEOM_DATA_DIR, else ../shared/data beside the repository): skipped with a
message when DamagedHelmet is not there. Writes one Markdown section (stdout, or --out FILE);
progress on stderr.
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
from run_lod import last_json, log  # noqa: E402  (the chains' benchmark on the shared models)


def timed(cmd):
    """Runs cmd under GNU time: (stdout, wall seconds, peak resident MB); raises on failure."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as tf:
        t0 = time.monotonic()
        p = subprocess.run(["/usr/bin/time", "-f", "%M", "-o", tf.name] + cmd, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
        dt = time.monotonic() - t0
        if p.returncode != 0:
            raise RuntimeError("%s failed (%d): %s" % (" ".join(cmd[:3]), p.returncode,
                                                        (p.stderr.strip().splitlines() or [""])[-1]))
        kb = int(tf.read().split()[-1])
    return p.stdout, dt, kb / 1024.0


def rmse(cmgeom, reference, mesh, size):
    out, _, _ = timed([cmgeom, "compare", reference, mesh, "--json", "--size", str(size)])
    return last_json(out)["rmse"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", required=True)
    ap.add_argument("--ratios", default="1,0.25,0.05,0.01")
    ap.add_argument("--reps", type=int, default=3, help="interleaved timing rounds")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--out")
    ap.add_argument("--describe", help="a line on the machine")
    a = ap.parse_args()
    if a.describe is not None and not a.describe.strip():
        ap.error("--describe is empty (benchmark/common/describe_run.sh needs bash)")
    cmgeom = os.path.join(os.path.abspath(a.build), "bin", "cmgeom")
    data = os.environ.get("CMGEOM_DATA_DIR", os.path.join(REPO, "..", "shared", "data"))
    source = os.path.join(data, "textured", "DamagedHelmet", "DamagedHelmet.obj")
    if not os.path.isfile(source):
        log("run_lod_scale.py: %s not found (set CMGEOM_DATA_DIR): skipped" % source)
        return 0
    smallest = a.ratios.split(",")[-1]
    work = tempfile.mkdtemp(prefix="cmgeom-lod-scale-")
    try:
        big = os.path.join(work, "big.obj")
        subprocess.run([sys.executable, os.path.join(HERE, "subdivide_textured.py"), source, big, "--times", "3"],
                       check=True, stdout=subprocess.DEVNULL)
        runs = {"simplify": [], "per-level": [], "shared": []}
        info = {}
        commands = {
            "simplify": ["simplify", big, "-o", os.path.join(work, "s.obj"), "--ratio", smallest, "--prune"],
            "per-level": ["lod", big, "-o", os.path.join(work, "p.glb"), "--ratios", a.ratios, "--no-error",
                          "--prune", "--json"],
            "shared": ["lod", big, "-o", os.path.join(work, "h.glb"), "--ratios", a.ratios, "--no-error", "--prune",
                       "--shared-texture", "--json"],
        }
        for k in range(a.reps):  # interleaved, so that drift of the machine hits all alike
            for name, cmd in commands.items():
                log("lod scale: round %d, %s" % (k + 1, name))
                out, dt, mb = timed([cmgeom] + cmd)
                runs[name].append((dt, mb))
                if name != "simplify":
                    info[name] = last_json(out)
        # image errors of each level, once: the chains' levels as OBJ, and each level's count alone
        errors = {}
        for name, extra in (("per-level", []), ("shared", ["--shared-texture"])):
            prefix = os.path.join(work, name)
            timed([cmgeom, "lod", big, "-o", prefix + ".glb", "--ratios", a.ratios, "--no-error", "--prune",
                   "--obj-prefix", prefix] + extra)
            errors[name] = [rmse(cmgeom, big, "%s_%d.obj" % (prefix, i), a.size)
                            for i in range(1, len(a.ratios.split(",")))]
        faces = [lv["faces"] for lv in info["per-level"]["levels"]]
        errors["alone"] = []
        for i, f in enumerate(faces[1:], 1):
            out = os.path.join(work, "alone_%d.obj" % i)
            timed([cmgeom, "simplify", big, "-o", out, "--faces", str(f), "--prune"])
            errors["alone"].append(rmse(cmgeom, big, out, a.size))
    finally:
        shutil.rmtree(work, ignore_errors=True)

    med = {n: statistics.median(dt for dt, _ in r) for n, r in runs.items()}
    L = ["## Level-of-detail chains of a large textured mesh", ""]
    L.append("Generated by `python3 benchmark/Textured_simplification/run_lod_scale.py --build <build-dir>` "
             "(ratios %s, %d interleaved rounds, compare size %d)." % (a.ratios, a.reps, a.size))
    L.append("")
    if a.describe:
        L.append(a.describe)
        L.append("")
    L.append("Input: DamagedHelmet subdivided three times (`subdivide_textured.py`, %d faces, its 2048² texture). "
             "Wall seconds of the whole command (reading the OBJ, writing the GLB, or OBJ + MTL + PNG for the "
             "smallest level alone) and peak resident memory (GNU time), \"min / median\"; ratios of the medians; "
             "*parts*: the parts the chain's collapses down to its first level ran in (`lod --json`; 0: on the "
             "whole; a shared texture's chain goes on as one run on the whole after them, its collapse history "
             "started on the mesh they leave)." % info["per-level"]["faces_in"])
    L.append("")
    L.append("| run | parts (runs in parts) | wall (s) | / smallest level alone | peak memory (MB) |")
    L.append("|---|---:|---:|---:|---:|")
    label = {"simplify": "`simplify --ratio %s` (the smallest level alone)" % smallest,
             "per-level": "`lod`, an atlas per level", "shared": "`lod --shared-texture`"}
    for n in ("simplify", "per-level", "shared"):
        r = runs[n]
        parts = "-" if n == "simplify" else "%d (%d)" % (info[n].get("parts", 0), info[n].get("runs_in_parts", 0))
        L.append("| %s | %s | %.2f / %.2f | %.2f | %.0f / %.0f |" % (
            label[n], parts, min(dt for dt, _ in r), med[n], med[n] / med["simplify"], min(mb for _, mb in r),
            statistics.median(mb for _, mb in r)))
    L.append("")
    L.append("Image RMSE of each simplified level against the input (8-bit units, 26 views), and of `cmgeom simplify "
             "--faces <the level's faces>` alone:")
    L.append("")
    L.append("| level | faces | atlas per level | shared texture | simplify alone |")
    L.append("|---:|---:|---:|---:|---:|")
    for i, f in enumerate(faces[1:], 1):
        L.append("| %d | %d | %.2f | %.2f | %.2f |" % (i, f, errors["per-level"][i - 1], errors["shared"][i - 1],
                                                       errors["alone"][i - 1]))
    text = "\n".join(L) + "\n"
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
"""The topology `cmgeom simplify` keeps, on every model of the shared data.

For each mesh of shared/data/classic and each textured model of shared/data/textured (its OBJ;
spot with its texture named by --texture; inputs the reader refuses as they are run with the option
its message names, --allow-degenerate for the ogre), at each ratio (default 0.1, 0.05, 0.01),
`cmgeom simplify IN -o OUT.obj --ratio R` with default options, then `cmgeom info --json` of the
input as `simplify` reads it (with its repairs: non-manifold edges split, non-manifold vertices
duplicated, orientation fixed; `cmgeom info --repair`) and of the output. Checked:
the output is manifold and consistently oriented when the input is, and has the input's genus,
components, boundary loops and Euler characteristic. (The collapses' own test, that no collapse
turns a face by more than 90 degrees, is made collapse by collapse in the unit tests: Checking_visitor.)

Usage: run_topology_sweep.py --build DIR [--data DIR] [--ratios 0.1,0.05,0.01] [--out FILE]
Writes benchmark/Textured_simplification/RESULTS-topology-sweep.md whole (or --out FILE), progress on
stderr; exit status 1 when any output breaks a check or a run fails (the file is written either way).
Skipped with a message (exit 0, the file left as it was) when the shared data is missing.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
KEYS = ("genus", "components", "boundary_loops", "euler_characteristic")


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def must(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        raise RuntimeError((p.stderr.strip().splitlines() or ["no message"])[-1])
    return p.stdout


def info(cmgeom, path):
    return json.loads(must([cmgeom, "--quiet", "info", path, "--json"]))


def info_as_read(cmgeom, path, extra):
    """The topology of `path` as simplify reads it, repaired as its reader repairs (`cmgeom info --repair`)."""
    return json.loads(must([cmgeom, "--quiet", "info", path, "--json", "--repair"] + extra))["repaired"]


def models(data):
    out = []
    for name in sorted(os.listdir(os.path.join(data, "classic"))):
        if name.endswith((".off", ".obj", ".ply", ".obj.gz", ".ply.gz", ".stl")):
            extra = ["--allow-degenerate"] if name == "ogre.obj.gz" else []
            out.append((os.path.join(data, "classic", name), extra, []))
    tex = os.path.join(data, "textured")
    for d in sorted(os.listdir(tex)):
        objs = sorted(f for f in os.listdir(os.path.join(tex, d)) if f.endswith(".obj"))
        if not objs:
            continue
        path = os.path.join(tex, d, objs[0])
        texture = os.path.join(tex, d, "spot_texture.png")
        simplify_extra = ["--texture", texture] if objs[0] == "spot.obj" and os.path.exists(texture) else []
        out.append((path, [], simplify_extra))
    return out


def describe():
    here = os.path.join(HERE, "..", "common", "describe_run.sh")
    p = subprocess.run(["bash", "-c", '. "$0"; describe_run', here], stdout=subprocess.PIPE, text=True)
    return p.stdout.strip()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--data", default=os.path.normpath(os.path.join(HERE, "..", "..", "..", "shared", "data")))
    ap.add_argument("--ratios", default="0.1,0.05,0.01")
    ap.add_argument("--out", default=os.path.join(HERE, "RESULTS-topology-sweep.md"))
    a = ap.parse_args()
    cmgeom = os.path.join(os.path.abspath(a.build), "bin", "cmgeom")
    if not os.access(cmgeom, os.X_OK):
        log("run_topology_sweep.py: %s not found (build the cmgeom target)" % cmgeom)
        return 2
    if not (os.path.isdir(os.path.join(a.data, "classic")) and os.path.isdir(os.path.join(a.data, "textured"))):
        log("run_topology_sweep.py: skipped: shared data not found at %s (pass --data DIR); %s left as it was"
            % (a.data, a.out))
        return 0
    described = describe()
    ratios = [float(r) for r in a.ratios.split(",")]
    rows, broken, failed, runs = [], 0, 0, 0
    with tempfile.TemporaryDirectory(prefix="cmgeom-topology-") as work:
        out_path = os.path.join(work, "out.obj")
        for path, read_extra, simplify_extra in models(a.data):
            name = os.path.basename(path)
            try:
                before = info_as_read(cmgeom, path, read_extra)
            except RuntimeError as e:
                failed += 1
                rows.append("| %s | | reading failed: %s | | | |" % (name, str(e).replace("|", "/")))
                continue
            for r in ratios:
                runs += 1
                log("  %s, ratio %g" % (name, r))
                p = subprocess.run([cmgeom, "--quiet", "simplify", path, "-o", out_path, "--ratio", str(r), "--json"]
                                   + read_extra + simplify_extra, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                   text=True)
                if p.returncode != 0:
                    failed += 1
                    msg = (p.stderr.strip().splitlines() or ["no message"])[-1].replace("|", "/")
                    rows.append("| %s | %g | failed: %s | | | |" % (name, r, msg))
                    continue
                after = info(cmgeom, out_path)
                problems = [k for k in KEYS if after[k] != before[k]]
                for k in ("manifold", "oriented"):
                    if before[k] and not after[k]:
                        problems.append("not " + k)
                broken += bool(problems)
                rows.append("| %s | %g | %d -> %d | %s | %s | %s |" % (
                    name, r, before["faces"], after["faces"],
                    " / ".join(str(before[k]) for k in KEYS),
                    ("manifold" if after["manifold"] else "NOT manifold") + ", " +
                    ("oriented" if after["oriented"] else "NOT oriented"),
                    ", ".join(problems) if problems else "kept"))
    lines = ["## The topology `cmgeom simplify` keeps, on every model of the shared data", "",
             "Generated by `python3 benchmark/Textured_simplification/run_topology_sweep.py --build <build-dir>`: "
             "`cmgeom simplify IN -o OUT.obj --ratio R` (default options) on every mesh of shared/data/classic and "
             "every textured model, then `cmgeom info --json` of the input as `simplify` reads it (repaired as its reader "
             "repairs: `cmgeom info --repair`) and of the output.", "",
             described, "",
             "| model | ratio | faces | genus / components / boundary loops / Euler characteristic of the input "
             "| output | topology |",
             "|---|---:|---:|---|---|---|"] + rows + [
             "", "- %d runs; outputs whose genus, components, boundary loops, Euler characteristic, manifoldness or "
             "orientation differ from the input's: %d; failed runs: %d." % (runs, broken, failed)]
    with open(a.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    log("wrote " + a.out)
    return 1 if broken or failed else 0


if __name__ == "__main__":
    sys.exit(main())

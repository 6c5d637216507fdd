#!/usr/bin/env python3
# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
"""Level-of-detail chains of `cmgeom lod` on every textured model, side by side:

  per-level   cmgeom lod IN --ratios R              (an atlas baked for every level)
  shared      cmgeom lod IN --ratios R --shared-texture   (one atlas for every level)
  mo13        meshoptimizer 1.3.0 (npm) at each level's face count, Permissive with the UV-seam
              vertices protected, and where that stops above the target the sloppy simplifier
              down to it, as gltfpack -sa does: kept vertices keep their UVs, every level wears
              the original texture (peers/meshopt_simplify.mjs --variant permissive-protected
              --aggressive)

For every level: image RMSE against the input (`cmgeom compare IN LEVEL.obj --json --size N`: 26
views, 8-bit units; each mesh wears its own texture). Level 0, the input itself, is also compared
with its own re-baked atlas (`cmgeom simplify IN --faces <its faces>`: no collapse, new charts, the
texture baked as each simplified level's atlas is), beside the input's own texture. Targets: shared <= 1.25 x per-level and
shared < mo13 at every simplified level. Timing (wall clock, min / median of interleaved rounds: at least --reps, more while the smallest
level alone has taken less than --min-seconds in all, at most --max-reps):
`cmgeom lod --no-error` (the chain written as GLB) against `cmgeom simplify --ratio <smallest>`
(that level alone, OBJ + PNG); target: lod <= 1.2 x simplify. Every GLB is run through the Khronos
validator when it is installed (test/Mesh_IO/gltf_validator).

Usage: run_lod.py --build DIR [--ratios 1,0.25,0.05,0.01] [--size 256] [--reps 3 (run.sh: 5)] [--min-seconds 4]
                  [--max-reps 30] [--out FILE]
                  [--models a,b] [--describe LINE] [--prune (run.sh: on)] [--geometry-models a,b]
The chains of untextured meshes (--geometry-models, shared/data/classic; '' for none) are timed the
same way, without --prune; `igea-sub` stands for igea subdivided once (1,074,744 faces, made at run
time by benchmark/Scale/subdivide.py), whose 25 % level is itself cut into parts again.
--prune runs every chain and the smallest level alone with `--prune` (whole connected components may
go when that costs less than the next collapse). meshoptimizer runs without its Prune flag either way:
with the unlimited error these runs give it, Prune removes every component (DamagedHelmet at 1 %
came out empty); its sloppy stage drops small parts anyway.
Writes one Markdown section (stdout, or --out FILE); progress on stderr.
"""
import argparse
import gzip
import json
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
import run_textured_peers as P  # noqa: E402  (model discovery, meshoptimizer status, helpers)

VALIDATOR = os.path.join(REPO, "test", "Mesh_IO", "gltf_validator", "validate.js")


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def run(cmd):
    t0 = time.monotonic()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return p.returncode, p.stdout, p.stderr, time.monotonic() - t0


def must(cmd):
    rc, so, se, dt = run(cmd)
    if rc != 0:
        raise RuntimeError("%s failed (%d): %s" % (" ".join(cmd[:3]), rc, se.strip().splitlines()[-1:] or ""))
    return so, dt


def last_json(text):
    return json.loads(text[text.index("{"):])


def machine():
    cpu = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return "%s, %d cores" % (cpu, os.cpu_count() or 0)


# untextured meshes (shared/data/classic) whose chains are timed beside the textured ones: the
# classic scans, igea large enough for its first level to be simplified in parts, and igea
# subdivided once (1M faces: its 25 % level is large enough to be cut again)
GEOMETRY_MODELS = ["stanford-bunny.obj.gz", "armadillo.obj.gz", "nefertiti.obj.gz", "horse.ply", "igea.ply.gz",
                   "igea-sub"]


def more_rounds(a, t_simp):
    """Whether to time another interleaved round: at least --reps rounds, more (up to --max-reps) while
    the smallest level alone has taken less than --min-seconds in all (a run of a tenth of a second
    varies by a third from one run to the next on a shared machine: short runs get more rounds)."""
    k = len(t_simp)
    return k < a.reps or (k < a.max_reps and sum(t_simp) < a.min_seconds)


def validate(glb):
    if not shutil.which("node") or not os.path.isdir(os.path.join(os.path.dirname(VALIDATOR), "node_modules")):
        return "n/a"
    rc, so, se, _ = run(["node", VALIDATOR, glb])
    if rc != 0:
        return "failed: " + se.strip()
    return so.splitlines()[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", required=True)
    ap.add_argument("--ratios", default="1,0.25,0.05,0.01")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--reps", type=int, default=3, help="timing rounds at least (interleaved)")
    ap.add_argument("--min-seconds", type=float, default=4.0,
                    help="more rounds until the smallest level alone has taken this long in all")
    ap.add_argument("--max-reps", type=int, default=30, help="timing rounds at most")
    ap.add_argument("--out")
    ap.add_argument("--describe", help="a line on the machine and the peers' versions")
    ap.add_argument("--models", help="comma-separated subset of the model names")
    ap.add_argument("--prune", action="store_true",
                    help="chains and the smallest level alone with --prune (whole components may go)")
    ap.add_argument("--geometry-models", default=",".join(GEOMETRY_MODELS),
                    help="untextured meshes of shared/data/classic whose chains are timed too ('' for none)")
    a = ap.parse_args()
    if a.describe is not None and not a.describe.strip():
        # what `--describe "$(describe_run ...)"` gives when describe_run.sh was sourced by a
        # shell other than bash: refuse rather than write results without their machine
        ap.error("--describe is empty (benchmark/common/describe_run.sh needs bash)")
    cmgeom = os.path.join(os.path.abspath(a.build), "bin", "cmgeom")
    root, _ = P.data_dir()
    models = P.find_models(root)
    if a.models:
        models = {k: v for k, v in models.items() if k in a.models.split(",")}
    mo_ok, mo_desc = P.node_status()
    ratios = [float(r) for r in a.ratios.split(",")]
    prune = ["--prune"] if a.prune else []
    work = tempfile.mkdtemp(prefix="cmgeom-lod-")
    rows, times, checks, hidden, sizes, geometry_times = [], [], [], [], [], []
    try:
        for name, m in models.items():
            log("lod: %s" % name)
            d = os.path.join(work, name)
            os.makedirs(d)
            tex = ["--texture", m["texture"]] if m["texture"] else []
            chains = {}
            for mode, extra in (("per", []), ("shared", ["--shared-texture"])):
                so, _ = must([cmgeom, "lod", m["obj"], "-o", os.path.join(d, mode + ".glb"), "--ratios", a.ratios,
                              "--obj-prefix", os.path.join(d, mode), "--json"] + extra + prune + tex)
                chains[mode] = last_json(so)
                checks.append((name, mode, validate(os.path.join(d, mode + ".glb"))))
            hidden.append((name, chains["shared"].get("shared_texture_hidden")))
            # texels: every simplified level's own atlas, against the one atlas the shared levels address
            per_texels = sum(lv.get("texture_width", 0) * lv.get("texture_height", 0)
                             for lv in chains["per"]["levels"] if not lv["is_input"])
            sh = chains["shared"]["levels"][-1]
            sizes.append((name, per_texels, sh.get("texture_width", 0) * sh.get("texture_height", 0),
                          chains["shared"].get("shared_texture_relocated"),
                          chains["shared"].get("shared_texture_overflow")))
            levels = chains["per"]["levels"]
            for i, lv in enumerate(levels):
                row = {"model": name, "level": i, "ratio": ratios[i], "faces": lv["faces"],
                       "faces_shared": chains["shared"]["levels"][i]["faces"]}
                for mode in ("per", "shared"):
                    out = os.path.join(d, "%s_%d.obj" % (mode, i))
                    so, _ = must([cmgeom, "compare", m["obj"], out, "--json", "--size", str(a.size)] + tex)
                    row[mode] = float(last_json(so)["rmse"])
                    row[mode + "_h"] = chains[mode]["levels"][i].get("hausdorff")
                if lv["is_input"]:
                    # level 0's own re-baked atlas: the input through the pipeline that bakes every
                    # simplified level's atlas, with no collapse (its charts rebuilt, its texture
                    # resampled), beside the input's own texture above
                    out = os.path.join(d, "rebaked_%d.obj" % i)
                    must([cmgeom, "simplify", m["obj"], "-o", out, "--faces", str(lv["faces"])] + prune + tex)
                    so, _ = must([cmgeom, "compare", m["obj"], out, "--json", "--size", str(a.size)] + tex)
                    row["rebaked"] = float(last_json(so)["rmse"])
                row["mo13"] = None
                if mo_ok and not lv["is_input"]:
                    out = os.path.join(d, "mo13_%d.obj" % i)
                    rc, so, se, _ = run(["node", P.NODE_SCRIPT, m["obj"], out, "--faces", str(lv["faces"]),
                                         "--variant", "permissive-protected", "--aggressive"])
                    if rc == 0:
                        cmp = [cmgeom, "compare", m["obj"], out, "--json", "--size", str(a.size)] + tex
                        so, _ = must(cmp)
                        row["mo13"] = float(last_json(so)["rmse"])
                        rc2, so2, _, _ = run(["python3", "-c", "import sys;print(sum(1 for l in open(sys.argv[1]) if l.startswith('f ')))", out])
                        row["mo13_faces"] = int(so2.strip()) if rc2 == 0 else None
                    else:
                        row["mo13_error"] = se.strip()
                rows.append(row)
            # timing: the chain against its smallest level alone, interleaved
            t_lod, t_lod_shared, t_simp = [], [], []
            while more_rounds(a, t_simp):
                _, dt = must([cmgeom, "lod", m["obj"], "-o", os.path.join(d, "t.glb"), "--ratios", a.ratios, "--no-error"] + prune + tex)
                t_lod.append(dt)
                _, dt = must([cmgeom, "lod", m["obj"], "-o", os.path.join(d, "ts.glb"), "--ratios", a.ratios, "--no-error",
                              "--shared-texture"] + prune + tex)
                t_lod_shared.append(dt)
                _, dt = must([cmgeom, "simplify", m["obj"], "-o", os.path.join(d, "t.obj"), "--ratio", str(ratios[-1])] + prune + tex)
                t_simp.append(dt)
            times.append((name, (min(t_simp), statistics.median(t_simp)), (min(t_lod), statistics.median(t_lod)),
                          (min(t_lod_shared), statistics.median(t_lod_shared)), len(t_simp)))
        # untextured chains: the collapses alone (and the GLB), against the smallest level alone
        classic = os.path.join(os.path.dirname(root), "classic")
        for g in [x for x in a.geometry_models.split(",") if x]:
            path = os.path.join(classic, g)
            if g == "igea-sub" and os.path.isfile(os.path.join(classic, "igea.ply.gz")):
                path = os.path.join(work, "igea-sub.ply")
                with gzip.open(os.path.join(classic, "igea.ply.gz"), "rb") as fi, \
                        open(os.path.join(work, "igea.ply"), "wb") as fo:
                    shutil.copyfileobj(fi, fo)
                must([sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Scale",
                                                   "subdivide.py"), os.path.join(work, "igea.ply"), path])
            if not os.path.isfile(path):
                log("lod: %s missing, skipped" % path)
                continue
            log("lod (geometry): %s" % g)
            so, _ = must([cmgeom, "lod", path, "-o", os.path.join(work, "g.glb"), "--ratios", a.ratios, "--no-error",
                          "--json"])
            info = last_json(so)
            t_lod, t_simp = [], []
            while more_rounds(a, t_simp):
                _, dt = must([cmgeom, "lod", path, "-o", os.path.join(work, "g.glb"), "--ratios", a.ratios, "--no-error"])
                t_lod.append(dt)
                _, dt = must([cmgeom, "simplify", path, "-o", os.path.join(work, "g.obj"), "--ratio", str(ratios[-1])])
                t_simp.append(dt)
            geometry_times.append((g, info["faces_in"], (info.get("parts", 0), info.get("runs_in_parts", 0)),
                                   (min(t_simp), statistics.median(t_simp)), (min(t_lod), statistics.median(t_lod)),
                                   len(t_simp)))
    finally:
        shutil.rmtree(work, ignore_errors=True)

    L = []
    L.append("## Level-of-detail chains: per-level atlases, one shared texture, meshoptimizer-style LODs")
    L.append("")
    L.append("Generated by `python3 benchmark/Textured_simplification/run_lod.py --build <build-dir>` "
             "(ratios %s, compare size %d, %d timing runs%s). Machine: %s. meshoptimizer: %s." %
             (a.ratios, a.size, a.reps,
              ", --prune: every `cmgeom lod` and `cmgeom simplify` run with --prune (whole components may go when "
              "cheaper than the next collapse); meshoptimizer without its Prune flag, which with the unlimited "
              "error of this comparison removes every component (DamagedHelmet at 1 % came out empty)"
              if a.prune else "",
              machine(), mo_desc))
    L.append("")
    if a.describe:
        L.append(a.describe)
        L.append("")
    L.append("Image RMSE (8-bit units, 26 views) of each level against the input; *shared/per* is the price of one "
             "texture for all levels (target <= 1.25); *mo13*: meshoptimizer 1.3.0 at the level's face count, "
             "kept vertices keep their UVs, original texture, the sloppy simplifier where the other stops above "
             "the target as gltfpack -sa does (target: shared below it).")
    L.append("")
    L.append("| model | level | faces | per-level atlas | shared texture | shared/per | mo13 (faces) | shared < mo13 |")
    L.append("|---|---:|---:|---:|---:|---:|---:|:---:|")
    price, wins, n_cmp, n_mo = [], 0, 0, 0
    for r in rows:
        ratio = r["shared"] / r["per"] if r["per"] > 0 else float("nan")
        simplified = r["level"] > 0 or r["ratio"] < 1
        mo = "n/a" if r["mo13"] is None else "%.2f (%s)" % (r["mo13"], r.get("mo13_faces"))
        win = ""
        if r["mo13"] is not None:
            n_mo += 1
            win = "yes" if r["shared"] < r["mo13"] else "**no**"
            wins += r["shared"] < r["mo13"]
        if simplified and r["per"] > 0:
            price.append(ratio)
            n_cmp += 1
        L.append("| %s | %d | %d | %.2f | %.2f | %s | %s | %s |" % (
            r["model"], r["level"], r["faces"], r["per"], r["shared"],
            ("%.2f" % ratio) if r["per"] > 0 else "-", mo, win))
    L.append("")
    within = sum(1 for x in price if x <= 1.25)
    L.append("- shared/per <= 1.25 at %d of %d simplified levels (median %.2f, worst %.2f)." % (
        within, len(price), statistics.median(price) if price else float("nan"), max(price) if price else float("nan")))
    full = [r for r in rows if not (r["level"] > 0 or r["ratio"] < 1)]
    if full:
        L.append("- level 0, the input itself: with the shared atlas its image RMSE is %.2f-%.2f, where the input's "
                 "own texture (the per-level chain's level 0) gives %.2f-%.2f: the price of one texture for all "
                 "levels, not counted above; the target as written (\"at each level\") is missed there on %d of %d "
                 "models." % (min(r["shared"] for r in full), max(r["shared"] for r in full),
                              min(r["per"] for r in full), max(r["per"] for r in full),
                              sum(1 for r in full if r["shared"] > 1.25 * r["per"]), len(full)))
        rb = [r for r in full if "rebaked" in r and r["rebaked"] > 0]
        if rb:
            q = [r["shared"] / r["rebaked"] for r in rb]
            L.append("- level 0 against its own re-baked atlas (`cmgeom simplify IN --faces <its faces>`: no collapse, "
                     "the input's charts rebuilt and its texture baked into a new atlas, as every simplified level's "
                     "is): re-baked RMSE %.2f-%.2f; shared / re-baked median %.2f, worst %.2f (%s), within 1.25 on "
                     "%d of %d models (%s)." % (
                         min(r["rebaked"] for r in rb), max(r["rebaked"] for r in rb), statistics.median(q), max(q),
                         rb[q.index(max(q))]["model"], sum(1 for x in q if x <= 1.25), len(q),
                         ", ".join("%s %.2f / %.2f" % (r["model"], r["shared"], r["rebaked"]) for r in rb)))
    L.append("- shared texture below meshoptimizer-style LODs at %d of %d levels." % (wins, n_mo))
    L.append("- share of the input's texture the shared atlas hides (parts folding onto one place of the coarsest "
             "level; `cmgeom lod` warns above 5 %): " + ", ".join(
                 "%s %.1f %%" % (n, 100 * h) for n, h in hidden if h is not None) + ".")
    L.append("- texture of the chain, megatexels, per-level atlases / shared atlas (its strip of overflow charts, "
             "as a share of the atlas; the share of the input's area given those charts): " + ", ".join(
                 "%s %.1f / %.1f (%.0f %%; %.0f %%)" % (n, p / 1e6, s_ / 1e6, 100 * (ov or 0), 100 * (rel or 0))
                 for n, p, s_, rel, ov in sizes) + ".")
    L.append("")
    L.append("Wall seconds, \"min / median\" of *runs* interleaved rounds (at least %d, more until the smallest "
             "level alone has taken %.0f s in all, at most %d); ratios of the medians." % (a.reps, a.min_seconds, a.max_reps))
    L.append("")
    L.append("| model | runs | simplify to the smallest level (s) | lod, atlas per level (s) | ratio | lod, shared texture (s) | ratio |")
    L.append("|---|---:|---:|---:|---:|---:|---:|")
    for name, s, l, ls, k in times:
        L.append("| %s | %d | %.2f / %.2f | %.2f / %.2f | %.2f | %.2f / %.2f | %.2f |" % (
            name, k, s[0], s[1], l[0], l[1], l[1] / s[1], ls[0], ls[1], ls[1] / s[1]))
    if times:
        L.append("")
        L.append("- chain / smallest level alone, median: atlas per level %.2f, shared texture %.2f (target <= 1.2)." % (
            statistics.median([l[1] / s[1] for _, s, l, _, _ in times]),
            statistics.median([ls[1] / s[1] for _, s, _, ls, _ in times])))
    if geometry_times:
        L.append("")
        L.append("Untextured meshes (shared/data/classic), the same ratios: `cmgeom lod IN -o OUT.glb --no-error` against "
                 "`cmgeom simplify IN --ratio <smallest>` (OBJ), wall seconds, \"min / median\" of *runs* interleaved "
                 "rounds (as above); *parts*: the parts the collapses down to the first level ran in (`lod --json`; 0: on "
                 "the whole), and how many of the chain's runs began in parts (a level large enough is cut again "
                 "on the way down to the next).")
        L.append("")
        L.append("| model | faces | runs | simplify to the smallest level (s) | lod (s) | ratio | parts (runs in parts) |")
        L.append("|---|---:|---:|---:|---:|---:|---:|")
        for g, faces, parts, s_, l, k in geometry_times:
            L.append("| %s | %d | %d | %.2f / %.2f | %.2f / %.2f | %.2f | %d (%d) |" % (
                g, faces, k, s_[0], s_[1], l[0], l[1], l[1] / s_[1], parts[0], parts[1]))
        gr = [l[1] / s_[1] for _, _, _, s_, l, _ in geometry_times]
        L.append("")
        L.append("- untextured chain / smallest level alone: median %.2f, worst %.2f, within 1.2 on %d of %d (target <= 1.2)." % (
            statistics.median(gr), max(gr), sum(1 for x in gr if x <= 1.2), len(gr)))
    L.append("")
    L.append("Validator (Khronos glTF validator on each chain's GLB): " + "; ".join(
        "%s %s: %s" % c for c in checks))
    text = "\n".join(L) + "\n"
    if a.out:
        tmp = a.out + ".tmp"
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, a.out)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())

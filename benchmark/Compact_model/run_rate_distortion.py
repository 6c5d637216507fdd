#!/usr/bin/env python3
# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
"""Rate-distortion of the compact CM file against compressed plain meshes.

  python3 benchmark/Compact_model/run_rate_distortion.py --build BUILD [--data DIR] [--quick]
          [--out benchmark/Compact_model/RESULTS-rate-distortion.md] [--plot doc/Compact_model/rate_distortion.png]

For every model, everything through the `cmgeom` command of BUILD (so what is measured is what a
user gets):
  * CM: `cmgeom cm build --faces N --compact` (format version 3, default tolerance) for several base
    sizes N, with the default build (fits chosen by measurement among three configurations,
    `--fit auto`) and with --joint-fit; reconstructed at level 3 (`cm reconstruct
    --level 3`, closest-point projection, the default).
  * plain meshes: `cmgeom simplify --faces F` (the default engine) for F = 250 ... 16000 (at most the
    input's faces), each shipped as
      - OBJ + gzip -9 (Python's gzip module, no file name or time stamp in the header),
      - Draco (`draco_encoder -cl 10 -qp Q`, Q in 8 ... 14: the quantization that minimises the error
        at a given size is whichever point lies on the lower envelope), decoded by `draco_decoder`,
      - meshoptimizer 1.3 codec + zstd -19 (peers/meshopt_encode.mjs, B = 10, 12, 14 bits per axis), when node is
        present.
  * errors: `cmgeom error ORIGINAL DECODED --json --samples S` (Metro-style: vertices, edges and S
    random area samples of each mesh against the other, S = max(100000, 2 x input faces);
    Hausdorff = max, RMS pooled), in % of the original's bounding-box diagonal.
Equal bytes: for each CM point, each codec's best plain mesh within the CM's bytes (lowest RMS, and
separately lowest Hausdorff, over every plain point of that codec not larger than the CM file). The
CM wins against a codec when both its RMS and its Hausdorff are lower; a model counts as won when one
of its CM points wins against all three codecs.
Writes the Markdown table (--out), the raw points as CSV beside it, and the plot (--plot; needs
matplotlib, Debian python3-matplotlib: skipped with a message when missing).
"""
import argparse
import csv
import gzip
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
MODELS = ["bunny.off", "armadillo.obj.gz", "nefertiti.obj.gz", "fandisk.obj", "horse.ply", "igea.ply.gz"]
QUICK = ["fandisk.obj", "bunny.off"]
PLAIN_FACES = [250, 500, 1000, 2000, 4000, 8000, 16000]
CM_FACES = [125, 250, 500, 1000, 2000, 4000]
DRACO_QP = [8, 10, 12, 14]
MESHOPT_BITS = [10, 12, 14]


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        sys.exit(f"run_rate_distortion.py: command failed ({r.returncode}): {' '.join(cmd)}\n{r.stderr}")
    return r.stdout


def error(cmgeom, ref, app, samples):
    j = json.loads(run([cmgeom, "--quiet", "error", ref, app, "--json", "--samples", str(samples)]))
    return 100 * j["hausdorff"], 100 * j["rms"]


def best_within(points, bytes_, key):
    c = [p for p in points if p["bytes"] <= bytes_]
    return min(c, key=lambda p: p[key]) if c else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", required=True)
    ap.add_argument("--data", default=os.environ.get("CMGEOM_DATA_DIR", os.path.join(HERE, "../../../shared/data")))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--describe", default="", help="a line on the machine and the peers' versions, written under the title")
    ap.add_argument("--out", default=os.path.join(HERE, "RESULTS-rate-distortion.md"))
    ap.add_argument("--plot", default=os.path.join(HERE, "../../doc/Compact_model/rate_distortion.png"))
    a = ap.parse_args()
    cmgeom = os.path.join(a.build, "bin", "cmgeom")
    if not os.path.exists(cmgeom):
        sys.exit(f"run_rate_distortion.py: no {cmgeom}; build it first (cmake --build {a.build} --target cmgeom)")
    for tool in ("draco_encoder", "draco_decoder"):
        if not shutil.which(tool):
            sys.exit(f"run_rate_distortion.py: {tool} not found (Debian package draco; scripts/install-deps.sh installs it)")
    node = shutil.which("node")
    meshopt = os.path.join(HERE, "peers", "meshopt_encode.mjs")
    if node and not os.path.isdir(os.path.join(HERE, "peers", "node_modules", "meshoptimizer")):
        if shutil.which("npm"):
            subprocess.run(["npm", "ci", "--silent", "--prefix", os.path.join(HERE, "peers")], check=False)
    if not node or not os.path.isdir(os.path.join(HERE, "peers", "node_modules", "meshoptimizer")):
        print("run_rate_distortion.py: node or the meshoptimizer npm package missing: the meshopt+zstd column is skipped",
              file=sys.stderr)
        meshopt = None
    classic = os.path.join(a.data, "classic")
    if not os.path.isdir(classic):
        sys.exit(f"run_rate_distortion.py: no data directory {classic}")

    rows = []  # dict(model, method, param, faces, bytes, hausdorff, rms)
    t_start = time.time()
    with tempfile.TemporaryDirectory() as tmp:
        for name in (QUICK if a.quick else MODELS):
            src = os.path.join(classic, name)
            if not os.path.exists(src):
                print(f"run_rate_distortion.py: {src} missing, skipped", file=sys.stderr)
                continue
            if name.endswith(".gz"):
                path = os.path.join(tmp, name[:-3])
                with gzip.open(src, "rb") as f, open(path, "wb") as g:
                    shutil.copyfileobj(f, g)
            else:
                path = src
            info = json.loads(run([cmgeom, "--quiet", "info", path, "--json"]))
            n_in = info["faces"]
            samples = max(100000, 2 * n_in)
            model = name.split(".")[0]
            print(f"{model}: {n_in} faces", file=sys.stderr)
            for fit in ("default", "joint"):
                for nb in CM_FACES:
                    if nb > n_in // 4:
                        continue
                    cm = os.path.join(tmp, "m.cm")
                    cmd = [cmgeom, "--quiet", "cm", "build", path, "-o", cm, "--faces", str(nb), "--compact", "--json"]
                    if fit == "joint":
                        cmd.append("--joint-fit")
                    j = json.loads(run(cmd))
                    rec = os.path.join(tmp, "rec.obj")
                    run([cmgeom, "--quiet", "cm", "reconstruct", cm, "-o", rec, "--level", "3"])
                    h, r = error(cmgeom, path, rec, samples)
                    rows.append(dict(model=model, method="CM" if fit == "default" else "CM joint fit", param=f"base {nb}",
                                     faces=j["base_faces"], bytes=j["bytes"], hausdorff=h, rms=r))
            for nf in PLAIN_FACES:
                if nf > n_in:
                    continue
                plain = os.path.join(tmp, "plain.obj")
                run([cmgeom, "--quiet", "simplify", path, "-o", plain, "--faces", str(nf)])
                with open(plain, "rb") as f:
                    gz = len(gzip.compress(f.read(), compresslevel=9, mtime=0))
                h, r = error(cmgeom, path, plain, samples)
                rows.append(dict(model=model, method="OBJ gzip", param="", faces=nf, bytes=gz, hausdorff=h, rms=r))
                for qp in DRACO_QP:
                    drc, dec = os.path.join(tmp, "p.drc"), os.path.join(tmp, "p_draco.obj")
                    run(["draco_encoder", "-i", plain, "-o", drc, "-qp", str(qp), "-cl", "10"])
                    run(["draco_decoder", "-i", drc, "-o", dec])
                    h, r = error(cmgeom, path, dec, samples)
                    rows.append(dict(model=model, method="Draco", param=f"qp {qp}", faces=nf, bytes=os.path.getsize(drc),
                                     hausdorff=h, rms=r))
                if meshopt:
                    for bits in MESHOPT_BITS:
                        dec = os.path.join(tmp, "p_meshopt.obj")
                        j = json.loads(run([node, meshopt, plain, dec, "--bits", str(bits)]))
                        h, r = error(cmgeom, path, dec, samples)
                        rows.append(dict(model=model, method="meshopt+zstd", param=f"{bits} bits", faces=nf,
                                         bytes=j["bytes"], hausdorff=h, rms=r))
            print(f"  done ({time.time() - t_start:.0f} s so far)", file=sys.stderr)

    csv_path = os.path.splitext(a.out)[0] + ".csv"
    with open(csv_path + ".tmp", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["model", "method", "param", "faces", "bytes", "hausdorff", "rms"])
        w.writeheader()
        for r in rows:
            w.writerow({**r, "hausdorff": f"{r['hausdorff']:.5f}", "rms": f"{r['rms']:.6f}"})
    os.replace(csv_path + ".tmp", csv_path)

    codecs = ["OBJ gzip", "Draco"] + (["meshopt+zstd"] if meshopt else [])
    models = list(dict.fromkeys(r["model"] for r in rows))
    lines = []
    won = []
    for model in models:
        mr = [r for r in rows if r["model"] == model]
        model_won = False
        for cmr in [r for r in mr if r["method"].startswith("CM")]:
            cells, all_win = [], True
            for c in codecs:
                pts = [r for r in mr if r["method"] == c]
                br, bh = best_within(pts, cmr["bytes"], "rms"), best_within(pts, cmr["bytes"], "hausdorff")
                if br is None:
                    cells.append("none this small | - | -")
                    continue
                win = cmr["rms"] < br["rms"] and cmr["hausdorff"] < bh["hausdorff"]
                all_win = all_win and win
                cells.append(f"{br['rms']:.4f} ({br['faces']} F, {br['param'] or 'obj'}) | {bh['hausdorff']:.3f} | "
                             f"{'CM' if win else 'plain'}")
            model_won = model_won or all_win
            lines.append(f"| {model} | {cmr['method']} | {cmr['param']} | {cmr['bytes']} | {cmr['hausdorff']:.3f} | "
                         f"{cmr['rms']:.4f} | " + " | ".join(cells) + " |")
        if model_won:
            won.append(model)

    with open(a.out + ".tmp", "w") as f:
        f.write("# Compact Models against compressed plain meshes: rate and distortion\n\n")
        f.write(f"Program `benchmark/Compact_model/run_rate_distortion.py`, run by `python3 "
                f"benchmark/Compact_model/run_rate_distortion.py --build <build>{' --quick' if a.quick else ''}` "
                f"on {time.strftime('%Y-%m-%d', time.gmtime())} ({os.cpu_count()} cores, {time.time() - t_start:.0f} s); "
                f"raw points in `{os.path.basename(csv_path)}`, curves in `doc/Compact_model/rate_distortion.png`.\n\n")
        if a.describe:
            f.write(a.describe + "\n\n")
        f.write(__doc__.split("\n", 4)[4].replace("\n\n", "\n") + "\n")
        f.write(f"**Models where a CM point beats every codec at equal bytes: {len(won)} of {len(models)}"
                f"{' (' + ', '.join(won) + ')' if won else ''}.**\n\n")
        head = "| model | CM | base | CM bytes | CM Hausdorff % | CM RMS % | " + " | ".join(
            f"{c}: best RMS % within bytes | {c}: best Hausdorff % | winner" for c in codecs) + " |\n"
        f.write(head)
        f.write("|" + "---|" * (6 + 3 * len(codecs)) + "\n")
        f.write("\n".join(lines) + "\n")
    os.replace(a.out + ".tmp", a.out)
    print(f"wrote {a.out} and {csv_path}", file=sys.stderr)

    # The plot, through Debian's python3 (matplotlib) when this interpreter lacks it.
    plot_script = os.path.join(HERE, "plot_rate_distortion.py")
    for py in (sys.executable, "/usr/bin/python3"):
        if subprocess.run([py, "-c", "import matplotlib"], capture_output=True).returncode == 0:
            subprocess.run([py, plot_script, csv_path, a.plot], check=True)
            print(f"wrote {a.plot}", file=sys.stderr)
            break
    else:
        print("run_rate_distortion.py: matplotlib missing (Debian python3-matplotlib): no plot written", file=sys.stderr)


if __name__ == "__main__":
    main()

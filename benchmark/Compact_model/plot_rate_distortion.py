#!/usr/bin/env python3
# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
"""Plots the rate-distortion points of run_rate_distortion.py.

  python3 plot_rate_distortion.py POINTS.csv OUT.png

One panel per model: RMS error (% of the bounding-box diagonal, log scale) against bytes (log
scale); the CM points as markers joined by base size, each plain-mesh codec as its lower envelope
(best error reached within a number of bytes over every simplification level and quantization).
Written atomically.
"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {
    "CM": dict(color="tab:red", marker="o", linestyle="-"),
    "CM joint fit": dict(color="tab:orange", marker="s", linestyle="-"),
    "Draco": dict(color="tab:blue", marker="", linestyle="-"),
    "meshopt+zstd": dict(color="tab:green", marker="", linestyle="--"),
    "OBJ gzip": dict(color="tab:gray", marker="", linestyle=":"),
}


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: plot_rate_distortion.py POINTS.csv OUT.png")
    with open(sys.argv[1]) as f:
        rows = [dict(r, bytes=int(r["bytes"]), rms=float(r["rms"])) for r in csv.DictReader(f)]
    models = list(dict.fromkeys(r["model"] for r in rows))
    cols = min(3, len(models))
    nrows = math.ceil(len(models) / cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(4.2 * cols, 3.4 * nrows), squeeze=False)
    for i, model in enumerate(models):
        ax = axes[i // cols][i % cols]
        for method, style in STYLE.items():
            pts = sorted((r for r in rows if r["model"] == model and r["method"] == method), key=lambda r: r["bytes"])
            if not pts:
                continue
            if not method.startswith("CM"):
                env, best = [], None
                for p in pts:
                    if best is None or p["rms"] < best:
                        best = p["rms"]
                        env.append(p)
                pts = env
            ax.plot([p["bytes"] for p in pts], [p["rms"] for p in pts], label=method, markersize=4, **style)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(model)
        ax.set_xlabel("bytes")
        ax.set_ylabel("RMS error, % of diagonal")
        ax.grid(True, which="both", alpha=0.3)
    for j in range(len(models), nrows * cols):
        axes[j // cols][j % cols].axis("off")
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    tmp = sys.argv[2] + ".tmp.png"
    fig.savefig(tmp, dpi=90)
    os.replace(tmp, sys.argv[2])


if __name__ == "__main__":
    main()

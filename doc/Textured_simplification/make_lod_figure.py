#!/usr/bin/env python3
# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
"""Renders the levels of `cmgeom lod` side by side: one row per texture mode (an atlas per level,
one shared texture), one column per level, the same camera for all, captions with the face counts.

Usage: make_lod_figure.py --cmgeom BIN --model MESH [--texture IMG] [--ratios 1,0.25,0.05,0.01]
                          [--view iso] [--size 256] -o FIGURE.png
The pictures come from `cmgeom render` (one PNG per level); this script only puts them in a grid
(its own small PNG reader/writer, so that it needs nothing beyond Python's standard library).
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile
import zlib


def read_png(path):
    """(width, height, rows of RGB bytes) of an 8-bit, non-interlaced RGB or RGBA PNG."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(path + ": not a PNG")
    pos, idat, w = 8, b"", 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or colour not in (2, 6) or interlace:
                raise ValueError(path + ": only 8-bit RGB/RGBA non-interlaced PNGs are read here")
            bpp = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = w * bpp
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line) if bpp == 3 else bytes(v for i, v in enumerate(line) if i % 4 != 3))
        prev = line
    return w, h, rows


def write_png(path, w, h, rows):
    raw = b"".join(b"\x00" + r for r in rows)
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) + \
        chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(png)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cmgeom", required=True)
    ap.add_argument("--model", required=True)
    ap.add_argument("--texture")
    ap.add_argument("--ratios", default="1,0.25,0.05,0.01")
    ap.add_argument("--view", default="iso")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("-o", "--output", required=True)
    a = ap.parse_args()
    tex = ["--texture", a.texture] if a.texture else []
    grid = []
    with tempfile.TemporaryDirectory() as d:
        for mode, extra in (("atlas per level", []), ("shared texture", ["--shared-texture"])):
            prefix = os.path.join(d, "shared" if extra else "per")
            out = subprocess.run([a.cmgeom, "--quiet", "lod", a.model, "-o", prefix + ".glb", "--ratios", a.ratios,
                                  "--obj-prefix", prefix, "--json", "--no-error"] + extra + tex,
                                 check=True, stdout=subprocess.PIPE, text=True).stdout
            levels = json.loads(out[out.index("{"):])["levels"]
            row = []
            for i, lv in enumerate(levels):
                png = "%s_%d.png" % (prefix, i)
                caption = "%s: %d faces" % (mode, lv["faces"])
                subprocess.run([a.cmgeom, "--quiet", "render", "%s_%d.obj" % (prefix, i), "-o", png, "--view", a.view,
                                "--size", "%dx%d" % (a.size, a.size), "--caption", caption], check=True)
                row.append(read_png(png))
            grid.append(row)
    w = sum(p[0] for p in grid[0])
    h = sum(row[0][1] for row in grid)
    rows = []
    for row in grid:
        for y in range(row[0][1]):
            rows.append(b"".join(p[2][y] for p in row))
    write_png(a.output, w, h, rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
"""1-to-4 midpoint subdivision of a textured triangle OBJ, repeated --times times: a large textured
mesh for the speed benchmark of the textured simplification (DamagedHelmet, 15,452 faces, three
times: 988,928 faces). Edge midpoints are shared by the two faces of an edge (the surface stays as
closed and manifold as the input); UV midpoints are shared by the corners that share both UVs, so
seams stay seams. The output names the input's MTL by absolute path. Standard library only.
Usage: subdivide_textured.py IN.obj OUT.obj [--times N]
"""
import os
import sys


def read_obj(path):
    v, vt, faces, mtllib, usemtl = [], [], [], None, []
    current = None
    with open(path) as f:
        for number, line in enumerate(f, 1):
            w = line.split()
            if not w:
                continue
            if w[0] == 'v':
                v.append(tuple(float(x) for x in w[1:4]))
            elif w[0] == 'vt':
                vt.append(tuple(float(x) for x in w[1:3]))
            elif w[0] == 'f':
                corners = []
                for c in w[1:]:
                    parts = c.split('/')
                    if len(parts) < 2 or not parts[1]:
                        sys.exit(f'{path}:{number}: a face corner without a texture coordinate')
                    a, b = int(parts[0]), int(parts[1])
                    corners.append((a - 1 if a > 0 else len(v) + a, b - 1 if b > 0 else len(vt) + b))
                for k in range(1, len(corners) - 1):  # fan
                    faces.append((corners[0], corners[k], corners[k + 1]))
                    usemtl.append(current)
            elif w[0] == 'mtllib':
                mtllib = os.path.abspath(os.path.join(os.path.dirname(path), line.split(None, 1)[1].strip()))
            elif w[0] == 'usemtl':
                current = line.split(None, 1)[1].strip()
    return v, vt, faces, mtllib, usemtl


def subdivide(v, vt, faces):
    v, vt = list(v), list(vt)
    mid_v, mid_t, out = {}, {}, []

    def mid(table, pts, a, b):
        key = (a, b) if a < b else (b, a)
        i = table.get(key)
        if i is None:
            i = len(pts)
            pts.append(tuple(0.5 * (x + y) for x, y in zip(pts[a], pts[b])))
            table[key] = i
        return i

    for (a, b, c) in faces:
        ab = (mid(mid_v, v, a[0], b[0]), mid(mid_t, vt, a[1], b[1]))
        bc = (mid(mid_v, v, b[0], c[0]), mid(mid_t, vt, b[1], c[1]))
        ca = (mid(mid_v, v, c[0], a[0]), mid(mid_t, vt, c[1], a[1]))
        out += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    return v, vt, out


def main():
    args = sys.argv[1:]
    times = 1
    if '--times' in args:
        i = args.index('--times')
        times = int(args[i + 1])
        del args[i:i + 2]
    if len(args) != 2 or times < 1:
        sys.exit(__doc__)
    v, vt, faces, mtllib, usemtl = read_obj(args[0])
    materials = usemtl
    for _ in range(times):
        v, vt, faces = subdivide(v, vt, faces)
        materials = [m for m in materials for _ in range(4)]
    tmp = args[1] + '.part'
    with open(tmp, 'w') as f:
        if mtllib:
            f.write(f'mtllib {mtllib}\n')
        f.write(''.join(f'v {x:.9g} {y:.9g} {z:.9g}\n' for x, y, z in v))
        f.write(''.join(f'vt {s:.9g} {t:.9g}\n' for s, t in vt))
        current = None
        for face, m in zip(faces, materials):
            if m != current and m is not None:
                f.write(f'usemtl {m}\n')
                current = m
            f.write('f ' + ' '.join(f'{p + 1}/{t + 1}' for p, t in face) + '\n')
    os.replace(tmp, args[1])
    print(f'{args[1]}: {len(faces)} faces, {len(v)} vertices')


if __name__ == '__main__':
    main()

#!/usr/bin/env python3
# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
"""One 1-to-4 midpoint subdivision of a binary little-endian triangle PLY (float x y z vertices,
uchar/int face lists), written as a binary PLY. Used by run_scale.sh to make a >= 1M-face mesh
from igea (268,686 faces -> 1,074,744) at run time; the result is never committed.

Midpoints are shared between the two faces of an edge, so the output is as closed and manifold
as the input. Standard library only. Usage: subdivide.py in.ply out.ply
"""
import struct
import sys


def read_ply(path):
    with open(path, 'rb') as f:
        data = f.read()
    end = data.index(b'end_header\n') + len(b'end_header\n')
    header = data[:end].decode('ascii').splitlines()
    if 'format binary_little_endian 1.0' not in header:
        sys.exit(f'{path}: only binary little-endian PLY is supported')
    nv = nf = 0
    for line in header:
        w = line.split()
        if w[:2] == ['element', 'vertex']:
            nv = int(w[2])
        elif w[:2] == ['element', 'face']:
            nf = int(w[2])
    vertex_props = [l.split()[1:] for l in header if l.startswith('property') and 'list' not in l]
    if vertex_props != [['float', 'x'], ['float', 'y'], ['float', 'z']]:
        sys.exit(f'{path}: vertices must be exactly float x, y, z')
    verts = list(struct.iter_unpack('<3f', data[end:end + 12 * nv]))
    faces = []
    pos = end + 12 * nv
    for _ in range(nf):
        n = data[pos]
        if n != 3:
            sys.exit(f'{path}: face with {n} vertices (triangles only)')
        faces.append(struct.unpack_from('<3i', data, pos + 1))
        pos += 13
    return verts, faces


def subdivide(verts, faces):
    verts = list(verts)
    mid = {}

    def midpoint(a, b):
        key = (a, b) if a < b else (b, a)
        m = mid.get(key)
        if m is None:
            pa, pb = verts[a], verts[b]
            m = len(verts)
            verts.append(((pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2, (pa[2] + pb[2]) / 2))
            mid[key] = m
        return m

    out = []
    for a, b, c in faces:
        ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
        out += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    return verts, out


def write_ply(path, verts, faces):
    with open(path, 'wb') as f:
        f.write((f'ply\nformat binary_little_endian 1.0\nelement vertex {len(verts)}\n'
                 'property float x\nproperty float y\nproperty float z\n'
                 f'element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n').encode('ascii'))
        f.write(b''.join(struct.pack('<3f', *v) for v in verts))
        f.write(b''.join(struct.pack('<B3i', 3, *t) for t in faces))


if __name__ == '__main__':
    if len(sys.argv) != 3:
        sys.exit('usage: subdivide.py in.ply out.ply')
    v, f = read_ply(sys.argv[1])
    v, f = subdivide(v, f)
    write_ply(sys.argv[2], v, f)
    print(f'{sys.argv[2]}: {len(v)} vertices, {len(f)} faces')

// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Grid cage systems: a lattice of box cages around a box or around a point set, as a
// Cage_system_description (Cage_system_description.h) with deformed = rest, ready for
// Cage_system (Cage_system.h), for write_cage_system() (Cage_system_io.h) or for editing. It lets
// the *Cages deformation of thesis §5.3 run on any model without authored cages (`cmgeom deform
// --grid`, `cmgeom influence --grid`). See "*Cages" in doc/Cage_deformation/README.md.
//
// Complexity: O(nx · ny · nz) cages of 8 vertices and 12 triangles; O(N) for the bounding box of
// N points.
#ifndef CMGEOM_CAGE_DEFORMATION_GRID_CAGE_SYSTEM_H
#define CMGEOM_CAGE_DEFORMATION_GRID_CAGE_SYSTEM_H

#include <CMGeom/Cage_deformation/Cage_system_description.h>
#include <CMGeom/Cage_deformation/Triangle_cage.h>
#include <CMGeom/Error.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <string>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {

/// A lattice of nx × ny × nz box cages around [lo, hi] (thesis §5.3 on any model, no authored
/// cages): shared faces are split along the diagonal through their lowest-numbered lattice
/// vertex, identically in both cells, so neighbours share triangles. Deformed = rest.
inline Cage_system_description make_grid_cage_system(const Vec3& lo, const Vec3& hi, int nx, int ny, int nz,
                                                     Coordinate_type type = Coordinate_type::mean_value,
                                                     double h = 1.0) {
  if (nx < 1 || ny < 1 || nz < 1 || nx * ny * nz > 4096)
    throw Invalid_input("grid cage system: cell counts must be >= 1 and at most 4096 cells in all");
  for (int a = 0; a < 3; ++a)
    if (!(hi[a] > lo[a]) || !std::isfinite(lo[a]) || !std::isfinite(hi[a]))
      throw Invalid_input("grid cage system: the box must have a positive, finite size along each axis");
  const int n[3] = {nx, ny, nz};
  auto id = [&](int i, int j, int k) { return std::uint32_t((k * (ny + 1) + j) * (nx + 1) + i); };
  auto pos = [&](int i, int j, int k) {
    const int q[3] = {i, j, k};
    Vec3 p;
    for (int a = 0; a < 3; ++a) p[a] = q[a] == n[a] ? hi[a] : lo[a] + (hi[a] - lo[a]) * q[a] / n[a];
    return p;
  };
  Cage_system_description d;
  d.source = "grid";
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        Cage_description c;
        c.name = "cell_" + std::to_string(i) + "_" + std::to_string(j) + "_" + std::to_string(k);
        c.rest_source = "grid";
        std::vector<std::uint32_t> gid;
        for (int c3 = 0; c3 < 8; ++c3) {
          const int di = c3 & 1, dj = (c3 >> 1) & 1, dk = (c3 >> 2) & 1;
          c.rest.vertices.push_back(pos(i + di, j + dj, k + dk));
          gid.push_back(id(i + di, j + dj, k + dk));
        }
        // Outward quads (local corner bits x = 1, y = 2, z = 4), counter-clockwise from outside.
        const std::array<std::array<std::uint32_t, 4>, 6> quads{
            {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}}};
        for (const auto& q : quads) {
          int s = 0;  // start the fan at the corner with the smallest lattice id
          for (int r = 1; r < 4; ++r)
            if (gid[q[r]] < gid[q[s]]) s = r;
          const std::uint32_t a = q[s], b = q[(s + 1) % 4], cc = q[(s + 2) % 4], e = q[(s + 3) % 4];
          c.rest.triangles.push_back({a, b, cc});
          c.rest.triangles.push_back({a, cc, e});
        }
        validate_cage(c.rest, c.name, Cage_orientation::require_outward);
        c.deformed = c.rest.vertices;
        c.coordinates = type;
        c.h = h;
        d.cages.push_back(std::move(c));
      }
  return d;
}

/// The grid of box cages around the bounding box of `points` (a range of CGAL points or
/// 3-arrays), enlarged on every side by `margin` times its diagonal (a flat model still gets
/// cages of positive thickness).
template <class PointRange>
Cage_system_description make_grid_cage_system(const PointRange& points, int nx, int ny, int nz, double margin = 0.05,
                                              Coordinate_type type = Coordinate_type::mean_value, double h = 1.0) {
  if (std::begin(points) == std::end(points)) throw Invalid_input("grid cage system: no points");
  if (!(margin >= 0 && margin <= 10)) throw Invalid_input("grid cage system: the margin must be in [0, 10]");
  Vec3 lo = internal::to_vec3(*std::begin(points)), hi = lo;
  for (const auto& q : points) {
    const Vec3 p = internal::to_vec3(q);
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  }
  double diag = internal::norm(internal::sub(hi, lo));
  if (!(diag > 0) || !std::isfinite(diag)) throw Invalid_input("grid cage system: the points have no extent");
  const double e = std::max(margin * diag, 1e-6 * diag);
  for (int a = 0; a < 3; ++a) {
    lo[a] -= e;
    hi[a] += e;
  }
  return make_grid_cage_system(lo, hi, nx, ny, nz, type, h);
}

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_GRID_CAGE_SYSTEM_H

// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Conversion of a Reconstruction (thesis §4.5) into a CMGeom::Surface_mesh or a
// CMGeom::Textured_mesh (per-corner uvs of §4.5.4 when the model is textured). The mesh shares
// vertices exactly as the reconstruction does (no duplicated seam points). Throws Invalid_input if
// a triangle cannot be added (a non-manifold configuration).
//
// Complexity: O(points + triangles).
#ifndef CMGEOM_COMPACT_MODEL_RECONSTRUCTION_TO_MESH_H
#define CMGEOM_COMPACT_MODEL_RECONSTRUCTION_TO_MESH_H

#include <CMGeom/Compact_model/reconstruct.h>
#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>

#include <vector>

namespace CMGeom {
namespace CM {

/// Fills `out` (cleared first) with the reconstruction; uvs and the texture path as a material
/// when the reconstruction has corner uvs and `texture` is not empty.
inline void to_textured_mesh(const Reconstruction& r, Textured_mesh& out, const std::string& texture = "") {
  out.clear();
  Surface_mesh& m = out.mesh();
  m.reserve(r.points.size(), 3 * r.triangles.size() / 2 + 16, r.triangles.size());
  std::vector<Surface_mesh::Vertex_index> vs(r.points.size());
  for (std::size_t i = 0; i < r.points.size(); ++i)
    vs[i] = m.add_vertex(Point_3(r.points[i].x, r.points[i].y, r.points[i].z));
  const bool uv = r.corner_uvs.size() == 3 * r.triangles.size() && !r.triangles.empty();
  for (std::size_t t = 0; t < r.triangles.size(); ++t) {
    const auto& T = r.triangles[t];
    const auto f = m.add_face(vs[T[0]], vs[T[1]], vs[T[2]]);
    if (f == Surface_mesh::null_face())
      throw Invalid_input("reconstruction triangle " + std::to_string(t) + " cannot be added (non-manifold)");
    if (uv) {
      auto h = m.halfedge(f);
      for (int c = 0; c < 3; ++c, h = m.next(h)) {
        // target(halfedge(f)) is T[2] for a face added as (T0, T1, T2); find the corner by vertex.
        const auto v = m.target(h);
        const int k = v == vs[T[0]] ? 0 : (v == vs[T[1]] ? 1 : 2);
        out.set_uv(h, Point_2(r.corner_uvs[3 * t + k][0], r.corner_uvs[3 * t + k][1]));
      }
    }
  }
  if (uv) {
    out.set_has_uvs(true);
    if (!texture.empty()) {
      Material mat;
      mat.name = "cm_texture";
      mat.diffuse_texture = texture;
      out.materials().push_back(mat);
    }
  }
}

/// Geometry only.
inline Surface_mesh to_surface_mesh(const Reconstruction& r) {
  Textured_mesh t;
  to_textured_mesh(r, t);
  return t.mesh();
}

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_RECONSTRUCTION_TO_MESH_H

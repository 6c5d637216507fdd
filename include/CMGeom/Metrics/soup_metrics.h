// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// approximation_error() and texture_deviation() on polygon soups (Mesh_IO/Polygon_soup.h), i.e.
// directly on the content of a file, without building a halfedge mesh. The Metro measure
// (thesis §2.3.2.2) is defined on any set of triangles, so non-manifold, non-oriented or
// multi-component meshes — which a halfedge structure refuses or has to repair — are measured as
// they are. Polygons are split into the fans the readers make (polygon_fan_starts()) for face
// sampling;
// edge samples lie on the polygon sides (each undirected side once); vertices used by no face are
// not sampled. Vertex fields follow the order of `soup.positions` (the file's vertex order).
//
// Complexity: as approximation_error(), plus O(C log C) to collect the C polygon sides.
#ifndef CMGEOM_METRICS_SOUP_METRICS_H
#define CMGEOM_METRICS_SOUP_METRICS_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Polygon_soup.h>
#include <CMGeom/Metrics/approximation_error.h>
#include <CMGeom/Metrics/texture_deviation.h>

#include <algorithm>
#include <string>
#include <vector>

namespace CMGeom {
namespace Metrics {
namespace internal {

/// The soup's triangles, its polygons split as `fan_start` (polygon_fan_starts(s)) says.
inline Flat_mesh make_flat_mesh(const Polygon_soup& s, const std::string& what,
                                const std::vector<std::uint32_t>& fan_start) {
  Flat_mesh m;
  m.points = s.positions;
  m.used.assign(m.points.size(), 0);
  std::vector<std::array<std::uint32_t, 2>> sides;
  for (std::size_t f = 0; f < s.number_of_faces(); ++f) {
    const std::uint32_t b = s.face_start[f], n = std::uint32_t(s.face_size(f));
    if (n < 3) continue;
    for (std::uint32_t k = 0; k < n; ++k) {
      const std::uint32_t u = s.corner_vertex[b + k], v = s.corner_vertex[b + (k + 1) % n];
      if (u >= m.points.size() || v >= m.points.size()) throw Invalid_input(what + ": vertex index out of range");
      m.used[u] = 1;
      if (u != v) sides.push_back({{std::min(u, v), std::max(u, v)}});
    }
    const std::uint32_t c = fan_start.empty() ? 0 : fan_start[f];
    for (std::uint32_t k = 1; k + 1 < n; ++k)
      m.triangles.push_back(
          {{s.corner_vertex[b + c], s.corner_vertex[b + (c + k) % n], s.corner_vertex[b + (c + k + 1) % n]}});
  }
  std::sort(sides.begin(), sides.end());
  sides.erase(std::unique(sides.begin(), sides.end()), sides.end());
  m.edges = std::move(sides);
  for (char u : m.used) m.used_vertices += std::size_t(u);
  if (m.triangles.empty()) throw Invalid_input(what + ": the mesh has no face");
  for (const auto& p : m.points)
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw Invalid_input(what + ": a vertex has a non-finite coordinate");
  return m;
}

inline Flat_mesh make_flat_mesh(const Polygon_soup& s, const std::string& what) {
  return make_flat_mesh(s, what, polygon_fan_starts(s));
}

/// The triangles of the faces that carry a UV on every corner.
inline UV_flat_mesh make_uv_flat_mesh(const Polygon_soup& s, const std::string& what) {
  Polygon_soup t;  // the textured faces only, with their UVs
  t.positions = s.positions;
  t.uvs = s.uvs;
  UV_flat_mesh m;
  for (std::size_t f = 0; f < s.number_of_faces(); ++f) {
    const std::uint32_t b = s.face_start[f], n = std::uint32_t(s.face_size(f));
    bool ok = n >= 3 && !s.corner_uv.empty();
    for (std::uint32_t k = 0; ok && k < n; ++k) ok = s.corner_uv[b + k] < s.uvs.size();
    if (!ok) continue;
    for (std::uint32_t k = 0; k < n; ++k) {
      t.corner_vertex.push_back(s.corner_vertex[b + k]);
      t.corner_uv.push_back(s.corner_uv[b + k]);
    }
    t.face_start.push_back(std::uint32_t(t.corner_vertex.size()));
  }
  // (the fans of the geometry below, corner for corner)
  const std::vector<std::uint32_t> fan_start = polygon_fan_starts(t);
  for (std::size_t f = 0; f < t.number_of_faces(); ++f) {
    const std::uint32_t b = t.face_start[f], n = std::uint32_t(t.face_size(f)),
                        c = fan_start.empty() ? 0 : fan_start[f];
    for (std::uint32_t k = 1; k + 1 < n; ++k)
      m.uvs.push_back(
          {{t.uvs[t.corner_uv[b + c]], t.uvs[t.corner_uv[b + (c + k) % n]], t.uvs[t.corner_uv[b + (c + k + 1) % n]]}});
  }
  m.geometry = make_flat_mesh(t, what + " (textured faces)", fan_start);
  return m;
}

}  // namespace internal

/// approximation_error() of two soups (see the file comment).
inline Approximation_error approximation_error(const Polygon_soup& reference, const Polygon_soup& approximation,
                                               const Error_options& options = Error_options()) {
  return internal::approximation_error_flat(internal::make_flat_mesh(reference, "reference mesh"),
                                            internal::make_flat_mesh(approximation, "approximation mesh"), options);
}

/// texture_deviation() of two soups with texture coordinates (faces without UVs are ignored).
inline Texture_deviation texture_deviation(const Polygon_soup& reference, const Polygon_soup& approximation,
                                           const Error_options& options = Error_options()) {
  return internal::texture_deviation_flat(internal::make_uv_flat_mesh(reference, "reference mesh"),
                                          internal::make_uv_flat_mesh(approximation, "approximation mesh"), options);
}

}  // namespace Metrics
}  // namespace CMGeom

#endif  // CMGEOM_METRICS_SOUP_METRICS_H

// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// make_render_mesh(): turns a CGAL face graph (optionally with per-corner UVs, a per-vertex
// scalar field and per-face textures) into the flat Render_mesh a renderer draws, and
// seam_edges(): the chart boundaries of a UV atlas (thesis §3.2 and Figure 3.14, "chart
// boundaries (in red)").
//
// A chart boundary is an edge whose two incident faces give different UVs to one of its end
// points: the atlas is cut there. Border edges (one incident face) are NOT chart boundaries by
// this definition — they bound the surface, not a cut between two charts — and are only drawn as
// part of the wireframe. Polygonal faces are drawn as the fans the readers make (polygon_fan_starts()).
//
// Complexity: O(V + F) time and memory.
#ifndef CMGEOM_RENDERING_MAKE_RENDER_MESH_H
#define CMGEOM_RENDERING_MAKE_RENDER_MESH_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Polygon_soup.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>
#include <CMGeom/Mesh_IO/charts.h>
#include <CMGeom/Rendering/Render_mesh.h>

#include <CGAL/boost/graph/helpers.h>
#include <CGAL/boost/graph/iterator.h>
#include <CGAL/boost/graph/properties.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <type_traits>
#include <vector>

namespace CMGeom {
namespace Rendering {

/// The edges of `tm` whose two incident faces disagree on the UV of an end point (the seams of
/// CMGeom::is_seam_edge(), charts.h), in the order of edges(tm).
/// `uv`: readable map halfedge -> 2D point, the UV of target(h) as seen from face(h).
template <class FaceGraph, class UVMap>
std::vector<typename boost::graph_traits<FaceGraph>::edge_descriptor> seam_edges(const FaceGraph& tm, UVMap uv) {
  std::vector<typename boost::graph_traits<FaceGraph>::edge_descriptor> out;
  for (auto e : edges(tm))
    if (CMGeom::is_seam_edge(e, tm, uv)) out.push_back(e);
  return out;
}

namespace internal {
struct No_uv_map {};
}  // namespace internal

/// Inputs of make_render_mesh() beyond the mesh: all optional.
template <class UVMap = internal::No_uv_map>
struct Render_mesh_inputs {
  const UVMap* uv = nullptr;                   ///< per-corner UVs (enables textures and charts)
  const std::vector<double>* field = nullptr;  ///< one value per vertex, order of vertices(tm)
  /// Texture of a face: `texture_of(face index in faces(tm) order)`; null = none.
  std::function<const Image*(std::size_t)> texture_of;
};

/// Flattens `tm` through the vertex point map `vpm` (see the file comment).
template <class FaceGraph, class VertexPointMap, class UVMap>
Render_mesh make_render_mesh(const FaceGraph& tm, VertexPointMap vpm, const Render_mesh_inputs<UVMap>& in) {
  Render_mesh rm;
  auto index = get(CGAL::dynamic_vertex_property_t<std::size_t>(), tm);
  std::vector<std::array<double, 3>> p;
  for (auto v : vertices(tm)) {
    put(index, v, p.size());
    const auto& q = get(vpm, v);
    p.push_back({{CGAL::to_double(q.x()), CGAL::to_double(q.y()), CGAL::to_double(q.z())}});
  }
  if (in.field && in.field->size() != p.size())
    throw Invalid_input("scalar field has " + std::to_string(in.field->size()) + " values but the mesh has " +
                        std::to_string(p.size()) + " vertices");
  // Area-weighted vertex normals (the cross product's length is twice the area).
  std::vector<std::array<double, 3>> n(p.size(), {{0., 0., 0.}});
  struct Corner_tri {
    std::size_t v[3];
    typename boost::graph_traits<FaceGraph>::halfedge_descriptor h[3];
    const Image* tex;
  };
  std::vector<Corner_tri> tris;
  std::size_t fi = 0;
  for (auto f : faces(tm)) {
    std::vector<typename boost::graph_traits<FaceGraph>::halfedge_descriptor> hs;
    for (auto h : CGAL::halfedges_around_face(halfedge(f, tm), tm)) hs.push_back(h);
    const Image* tex = in.texture_of ? in.texture_of(fi) : nullptr;
    ++fi;
    for (std::size_t k = 1; k + 1 < hs.size(); ++k) {
      Corner_tri t{{get(index, target(hs[0], tm)), get(index, target(hs[k], tm)), get(index, target(hs[k + 1], tm))},
                   {hs[0], hs[k], hs[k + 1]},
                   tex};
      const auto &a = p[t.v[0]], &b = p[t.v[1]], &c = p[t.v[2]];
      const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const double cr[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      for (int j = 0; j < 3; ++j)
        for (int d = 0; d < 3; ++d) n[t.v[j]][d] += cr[d];
      tris.push_back(t);
    }
  }
  // Group triangles by texture so that each range is one draw call; stable, so the order of
  // faces within a texture is kept.
  std::stable_sort(tris.begin(), tris.end(),
                   [](const Corner_tri& a, const Corner_tri& b) { return std::less<const Image*>()(a.tex, b.tex); });
  const bool with_uv = in.uv != nullptr;
  rm.positions.reserve(tris.size() * 9);
  rm.normals.reserve(tris.size() * 9);
  if (with_uv) rm.uvs.reserve(tris.size() * 6);
  double smin = HUGE_VAL, smax = -HUGE_VAL;
  for (std::size_t i = 0; i < tris.size(); ++i) {
    const Corner_tri& t = tris[i];
    if (rm.ranges.empty() || rm.ranges.back().texture != t.tex) rm.ranges.push_back({i, 0, t.tex});
    ++rm.ranges.back().count;
    for (int j = 0; j < 3; ++j) {
      const auto& q = p[t.v[j]];
      const auto& m = n[t.v[j]];
      const double l = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
      for (int d = 0; d < 3; ++d) {
        rm.positions.push_back(float(q[d]));
        rm.normals.push_back(l > 0. ? float(m[d] / l) : 0.f);
      }
      if constexpr (!std::is_same<UVMap, internal::No_uv_map>::value) {
        if (with_uv) {
          const auto& uv = get(*in.uv, t.h[j]);
          rm.uvs.push_back(float(CGAL::to_double(uv.x())));
          rm.uvs.push_back(float(CGAL::to_double(uv.y())));
        }
      }
      if (in.field) {
        const double s = (*in.field)[t.v[j]];
        rm.scalars.push_back(float(s));
        if (std::isfinite(s)) {
          smin = std::min(smin, s);
          smax = std::max(smax, s);
        }
      }
    }
  }
  if (in.field) {
    rm.scalar_min = smin <= smax ? smin : 0.;
    rm.scalar_max = smin <= smax ? smax : 0.;
  }
  auto push_line = [&](std::vector<float>& out, std::size_t a, std::size_t b) {
    for (std::size_t v : {a, b})
      for (int d = 0; d < 3; ++d) out.push_back(float(p[v][d]));
  };
  rm.bbox = {{HUGE_VAL, HUGE_VAL, HUGE_VAL, -HUGE_VAL, -HUGE_VAL, -HUGE_VAL}};
  for (const Corner_tri& t : tris)
    for (std::size_t v : t.v)
      for (int d = 0; d < 3; ++d) {
        rm.bbox[d] = std::min(rm.bbox[d], p[v][d]);
        rm.bbox[d + 3] = std::max(rm.bbox[d + 3], p[v][d]);
      }
  if (tris.empty()) throw Invalid_input("cannot render a mesh without faces");
  for (auto e : edges(tm)) push_line(rm.wire_lines, get(index, source(e, tm)), get(index, target(e, tm)));
  if constexpr (!std::is_same<UVMap, internal::No_uv_map>::value) {
    if (with_uv) {
      for (auto e : seam_edges(tm, *in.uv))
        push_line(rm.chart_lines, get(index, source(e, tm)), get(index, target(e, tm)));
      // UV layout: every face side once per face (seams appear on both of their charts).
      for (auto f : faces(tm))
        for (auto h : CGAL::halfedges_around_face(halfedge(f, tm), tm)) {
          const auto& a = get(*in.uv, prev(h, tm));
          const auto& b = get(*in.uv, h);
          rm.uv_lines.insert(rm.uv_lines.end(), {float(CGAL::to_double(a.x())), float(CGAL::to_double(a.y())),
                                                 float(CGAL::to_double(b.x())), float(CGAL::to_double(b.y()))});
        }
    }
  }
  return rm;
}

/// make_render_mesh() of a plain face graph with its internal vertex points, optionally with a
/// per-vertex field (order of vertices(tm)).
template <class FaceGraph>
Render_mesh make_render_mesh(const FaceGraph& tm, const std::vector<double>* field = nullptr) {
  Render_mesh_inputs<internal::No_uv_map> in;
  in.field = field;
  return make_render_mesh(tm, get(CGAL::vertex_point, tm), in);
}

/// make_render_mesh() of a Textured_mesh: its UVs (when it has some) and, per face, the decoded
/// diffuse image of the face's material (when loaded). The images must outlive the result.
inline Render_mesh make_render_mesh(const Textured_mesh& tm, const std::vector<double>* field = nullptr) {
  const auto& mesh = tm.mesh();
  if (!tm.has_uvs()) return make_render_mesh(mesh, field);
  Render_mesh_inputs<Textured_mesh::UV_map> in;
  const Textured_mesh::UV_map uv = tm.uv_map();
  in.uv = &uv;
  in.field = field;
  std::vector<const Image*> by_face;
  for (auto f : mesh.faces()) {
    const int m = tm.material(f);
    const Image* img = nullptr;
    if (m >= 0 && std::size_t(m) < tm.materials().size() && !tm.materials()[m].diffuse_image.empty())
      img = &tm.materials()[m].diffuse_image;
    by_face.push_back(img);
  }
  in.texture_of = [&by_face](std::size_t f) { return by_face[f]; };
  return make_render_mesh(mesh, mesh.points(), in);
}

/// make_render_mesh() of a polygon soup (the content of a file, Mesh_IO/Polygon_soup.h), without
/// building a halfedge mesh: non-manifold or non-oriented input is drawn as it is. Polygons are
/// fan-triangulated; a polygon side is a chart boundary when the faces that share it (two or
/// more) do not all give the same UV values to its end points. `field`: one value per position,
/// file order. Textures: the decoded diffuse image of each face's material, when loaded.
inline Render_mesh make_render_mesh(const Polygon_soup& s, const std::vector<double>* field = nullptr) {
  const std::size_t nv = s.positions.size();
  if (field && field->size() != nv)
    throw Invalid_input("scalar field has " + std::to_string(field->size()) + " values but the mesh has " +
                        std::to_string(nv) + " vertices");
  struct Tri {
    std::uint32_t v[3];
    std::uint32_t uv[3];
    const Image* tex;
  };
  struct Side {
    std::uint32_t a, b, ua, ub;  // ua / ub: UV index at a / b, or no_index
  };
  const std::uint32_t none = Polygon_soup::no_index;
  std::vector<Tri> tris;
  std::vector<Side> sides;
  std::vector<std::array<double, 3>> n(nv, {{0., 0., 0.}});
  Render_mesh rm;
  const std::vector<std::uint32_t> fan_start = polygon_fan_starts(s);  // the readers' fans
  for (std::size_t f = 0; f < s.number_of_faces(); ++f) {
    const std::uint32_t b = s.face_start[f], k = std::uint32_t(s.face_size(f));
    if (k < 3) continue;
    bool has_uv = !s.corner_uv.empty();
    for (std::uint32_t i = 0; has_uv && i < k; ++i) has_uv = s.corner_uv[b + i] < s.uvs.size();
    auto uv_of = [&](std::uint32_t c) { return has_uv ? s.corner_uv[c] : none; };
    const Image* tex = nullptr;
    const int m = f < s.face_material.size() ? s.face_material[f] : 0;
    if (has_uv && m >= 0 && std::size_t(m) < s.materials.size() && !s.materials[m].diffuse_image.empty())
      tex = &s.materials[m].diffuse_image;
    for (std::uint32_t i = 0; i < k; ++i) {
      const std::uint32_t c0 = b + i, c1 = b + (i + 1) % k;
      std::uint32_t va = s.corner_vertex[c0], vb = s.corner_vertex[c1], ua = uv_of(c0), ub = uv_of(c1);
      if (va >= nv || vb >= nv) throw Invalid_input(s.source + ": vertex index out of range");
      if (va == vb) continue;
      if (va > vb) {
        std::swap(va, vb);
        std::swap(ua, ub);
      }
      sides.push_back({va, vb, ua, ub});
      if (has_uv) {
        const auto& p = s.uvs[uv_of(c0)];
        const auto& q = s.uvs[uv_of(c1)];
        rm.uv_lines.insert(rm.uv_lines.end(), {float(p[0]), float(p[1]), float(q[0]), float(q[1])});
      }
    }
    const std::uint32_t c = fan_start.empty() ? 0 : fan_start[f];
    for (std::uint32_t i = 1; i + 1 < k; ++i) {
      const std::uint32_t c0 = b + c, c1 = b + (c + i) % k, c2 = b + (c + i + 1) % k;
      Tri t{{s.corner_vertex[c0], s.corner_vertex[c1], s.corner_vertex[c2]}, {uv_of(c0), uv_of(c1), uv_of(c2)}, tex};
      const auto &a = s.positions[t.v[0]], &q = s.positions[t.v[1]], &c = s.positions[t.v[2]];
      const double u[3] = {q[0] - a[0], q[1] - a[1], q[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const double cr[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      for (int j = 0; j < 3; ++j)
        for (int d = 0; d < 3; ++d) n[t.v[j]][d] += cr[d];
      tris.push_back(t);
    }
  }
  if (tris.empty()) throw Invalid_input("cannot render a mesh without faces");
  std::stable_sort(tris.begin(), tris.end(),
                   [](const Tri& a, const Tri& b) { return std::less<const Image*>()(a.tex, b.tex); });
  const bool with_uv = s.has_uvs() && !s.corner_uv.empty();
  double smin = HUGE_VAL, smax = -HUGE_VAL;
  rm.bbox = {{HUGE_VAL, HUGE_VAL, HUGE_VAL, -HUGE_VAL, -HUGE_VAL, -HUGE_VAL}};
  for (std::size_t i = 0; i < tris.size(); ++i) {
    const Tri& t = tris[i];
    if (rm.ranges.empty() || rm.ranges.back().texture != t.tex) rm.ranges.push_back({i, 0, t.tex});
    ++rm.ranges.back().count;
    for (int j = 0; j < 3; ++j) {
      const auto& q = s.positions[t.v[j]];
      const auto& m = n[t.v[j]];
      const double l = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
      for (int d = 0; d < 3; ++d) {
        rm.positions.push_back(float(q[d]));
        rm.normals.push_back(l > 0. ? float(m[d] / l) : 0.f);
        rm.bbox[d] = std::min(rm.bbox[d], q[d]);
        rm.bbox[d + 3] = std::max(rm.bbox[d + 3], q[d]);
      }
      if (with_uv) {
        const bool ok = t.uv[j] != none;
        rm.uvs.push_back(ok ? float(s.uvs[t.uv[j]][0]) : 0.f);
        rm.uvs.push_back(ok ? float(s.uvs[t.uv[j]][1]) : 0.f);
      }
      if (field) {
        const double v = (*field)[t.v[j]];
        rm.scalars.push_back(float(v));
        if (std::isfinite(v)) {
          smin = std::min(smin, v);
          smax = std::max(smax, v);
        }
      }
    }
  }
  if (field) {
    rm.scalar_min = smin <= smax ? smin : 0.;
    rm.scalar_max = smin <= smax ? smax : 0.;
  }
  // Sides: sorted by end points, each undirected side once in the wireframe; a chart boundary
  // when its textured faces disagree on the UV values at its ends.
  std::sort(sides.begin(), sides.end(),
            [](const Side& x, const Side& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
  auto push_line = [&](std::vector<float>& out, std::uint32_t a, std::uint32_t b) {
    for (std::uint32_t v : {a, b})
      for (int d = 0; d < 3; ++d) out.push_back(float(s.positions[v][d]));
  };
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i;
    bool seam = false;
    const Side* first = nullptr;
    std::size_t textured = 0;
    for (; j < sides.size() && sides[j].a == sides[i].a && sides[j].b == sides[i].b; ++j) {
      if (sides[j].ua == none || sides[j].ub == none) continue;
      ++textured;
      if (!first)
        first = &sides[j];
      else if (s.uvs[first->ua] != s.uvs[sides[j].ua] || s.uvs[first->ub] != s.uvs[sides[j].ub])
        seam = true;
    }
    push_line(rm.wire_lines, sides[i].a, sides[i].b);
    if (seam && textured >= 2) push_line(rm.chart_lines, sides[i].a, sides[i].b);
    i = j;
  }
  return rm;
}

}  // namespace Rendering
}  // namespace CMGeom

#endif  // CMGEOM_RENDERING_MAKE_RENDER_MESH_H

// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Metro-style surface sampling (thesis §2.3.2.2, eqs. 2.7-2.8: the sample sets should at least
// contain all the vertices): a triangle mesh is copied once into flat arrays and sampled on its
// vertices, on the interior of its edges and on its faces by similar-triangle sampling, as Metro
// does. For N samples the linear density s solves A s^2 + L s + V = N, so edges and faces get the
// same spacing; per-face counts are drawn from a hash of (seed, face index), so the samples depend
// on the seed only, never on threads. Complexity: O(V + E + F + N) time and memory.
//
// Manual: doc/Metrics/README.md, "Geometric error in the Metro convention".
#ifndef CMGEOM_METRICS_INTERNAL_SURFACE_SAMPLING_H
#define CMGEOM_METRICS_INTERNAL_SURFACE_SAMPLING_H

#include <CMGeom/Error.h>

#include <CGAL/boost/graph/helpers.h>
#include <CGAL/boost/graph/iterator.h>
#include <CGAL/boost/graph/properties.h>
#include <CGAL/property_map.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace CMGeom {
namespace Metrics {
namespace internal {

/// A triangle mesh copied into flat arrays, in the order of vertices(tm) / faces(tm) / edges(tm).
struct Flat_mesh {
  std::vector<std::array<double, 3>> points;            ///< one per vertex of vertices(tm)
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< one per face of faces(tm)
  std::vector<std::array<std::uint32_t, 2>> edges;      ///< one per edge of edges(tm)
  std::vector<char> used;                               ///< vertex is incident to a face
  std::size_t used_vertices = 0;

  std::array<double, 6> bbox() const {  // xmin ymin zmin xmax ymax zmax of the used vertices
    std::array<double, 6> b{{HUGE_VAL, HUGE_VAL, HUGE_VAL, -HUGE_VAL, -HUGE_VAL, -HUGE_VAL}};
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!used[i]) continue;
      for (int k = 0; k < 3; ++k) {
        b[k] = std::min(b[k], points[i][k]);
        b[k + 3] = std::max(b[k + 3], points[i][k]);
      }
    }
    return b;
  }
  double diagonal() const {
    const auto b = bbox();
    if (b[0] > b[3]) return 0.;
    return std::sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) + (b[5] - b[2]) * (b[5] - b[2]));
  }
};

/// Copies `tm` (a FaceListGraph of triangles) through the vertex point map `vpm`.
/// Throws Invalid_input naming `what` when a face is not a triangle or the mesh has no face.
template <class TriangleMesh, class VertexPointMap>
Flat_mesh make_flat_mesh(const TriangleMesh& tm, VertexPointMap vpm, const std::string& what) {
  using vertex_descriptor = typename boost::graph_traits<TriangleMesh>::vertex_descriptor;
  Flat_mesh m;
  auto index = get(CGAL::dynamic_vertex_property_t<std::uint32_t>(), tm);
  std::uint32_t n = 0;
  for (vertex_descriptor v : vertices(tm)) {
    put(index, v, n++);
    const auto& p = get(vpm, v);
    m.points.push_back({{CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())}});
  }
  m.used.assign(m.points.size(), 0);
  for (auto f : faces(tm)) {
    std::array<std::uint32_t, 3> t{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(halfedge(f, tm), tm)) {
      if (k == 3) throw Invalid_input(what + ": a face has more than 3 vertices; triangulate first");
      t[k++] = get(index, v);
    }
    if (k != 3) throw Invalid_input(what + ": a face has fewer than 3 vertices");
    for (auto i : t) m.used[i] = 1;
    m.triangles.push_back(t);
  }
  for (auto e : edges(tm)) m.edges.push_back({{get(index, source(e, tm)), get(index, target(e, tm))}});
  for (char u : m.used) m.used_vertices += std::size_t(u);
  if (m.triangles.empty()) throw Invalid_input(what + ": the mesh has no face");
  for (const auto& p : m.points)
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw Invalid_input(what + ": a vertex has a non-finite coordinate");
  return m;
}

/// splitmix64: a tiny, well-mixed hash used to draw per-face random numbers from (seed, index).
inline std::uint64_t mix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}
inline double uniform01(std::uint64_t seed, std::uint64_t index) {
  return double(mix64(mix64(seed) ^ index) >> 11) * (1.0 / 9007199254740992.0);
}

inline double triangle_area(const std::array<double, 3>& a, const std::array<double, 3>& b,
                            const std::array<double, 3>& c) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double x = u[1] * w[2] - u[2] * w[1], y = u[2] * w[0] - u[0] * w[2], z = u[0] * w[1] - u[1] * w[0];
  return 0.5 * std::sqrt(x * x + y * y + z * z);
}
inline double distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/// Which parts of the surface are sampled and how densely.
struct Sampling_plan {
  double linear_density = 0.;  ///< samples per unit length on edges (s)
  double areal_density = 0.;   ///< samples per unit area on faces (s^2)
  bool vertices = true, edges = true, faces = true;
};

/// The plan that spends about `target` samples on `m` (see the file comment).
inline Sampling_plan metro_plan(const Flat_mesh& m, std::size_t target, bool sample_vertices = true,
                                bool sample_edges = true, bool sample_faces = true) {
  Sampling_plan plan;
  plan.vertices = sample_vertices;
  plan.edges = sample_edges;
  plan.faces = sample_faces;
  double A = 0., L = 0.;
  if (sample_faces)
    for (const auto& t : m.triangles) A += triangle_area(m.points[t[0]], m.points[t[1]], m.points[t[2]]);
  if (sample_edges)
    for (const auto& e : m.edges) L += distance(m.points[e[0]], m.points[e[1]]);
  const double rest = double(target) - (sample_vertices ? double(m.used_vertices) : 0.);
  if (rest <= 0.) return plan;
  double s = 0.;
  if (A > 0.)
    s = (-L + std::sqrt(L * L + 4. * A * rest)) / (2. * A);
  else if (L > 0.)
    s = rest / L;
  plan.linear_density = s;
  plan.areal_density = s * s;
  return plan;
}

/// Number of n x n similar-triangle subdivisions of face `f` of area `area` under `plan`.
inline std::uint32_t face_subdivision(const Sampling_plan& plan, double area, std::uint64_t seed, std::size_t f) {
  const double c = plan.areal_density * area;
  const double r = std::sqrt(c);
  std::uint32_t n = std::uint32_t(r);
  // Choose n or n+1 with the probability that makes E[n^2] = c.
  const double p = (c - double(n) * n) / (2. * n + 1.);
  if (uniform01(seed, f) < p) ++n;
  return n;
}

/// Calls `vertex(i)` for every used vertex, `point(p)` for every edge and face sample, in a fixed
/// order (vertices, edges, faces) that only depends on the mesh, the plan and the seed.
/// `face_sample(f, b0, b1, b2)` receives the face index and barycentric coordinates as well.
template <class VertexFn, class FaceFn, class EdgeFn>
void sample_surface(const Flat_mesh& m, const Sampling_plan& plan, std::uint64_t seed, VertexFn vertex,
                    EdgeFn edge_sample, FaceFn face_sample) {
  if (plan.vertices)
    for (std::size_t i = 0; i < m.points.size(); ++i)
      if (m.used[i]) vertex(i);
  if (plan.edges && plan.linear_density > 0.) {
    double carry = 0.;
    for (std::size_t e = 0; e < m.edges.size(); ++e) {
      const auto& a = m.points[m.edges[e][0]];
      const auto& b = m.points[m.edges[e][1]];
      const double want = distance(a, b) * plan.linear_density + carry;
      const std::size_t k = std::size_t(want);
      carry = want - double(k);
      for (std::size_t i = 1; i <= k; ++i) {
        const double t = double(i) / double(k + 1);
        edge_sample(e, t);
      }
    }
  }
  if (plan.faces && plan.areal_density > 0.) {
    for (std::size_t f = 0; f < m.triangles.size(); ++f) {
      const auto& t = m.triangles[f];
      const double area = triangle_area(m.points[t[0]], m.points[t[1]], m.points[t[2]]);
      const std::uint32_t n = face_subdivision(plan, area, seed, f);
      if (n == 0) continue;
      const double inv = 1.0 / double(n);
      // Upright sub-triangles (i, j), i + j <= n - 1, barycentre at ((i+1/3)/n, (j+1/3)/n);
      // inverted ones (i, j), i + j <= n - 2, barycentre at ((i+2/3)/n, (j+2/3)/n).
      for (std::uint32_t i = 0; i < n; ++i)
        for (std::uint32_t j = 0; i + j < n; ++j) {
          const double b1 = (i + 1. / 3.) * inv, b2 = (j + 1. / 3.) * inv;
          face_sample(f, 1. - b1 - b2, b1, b2);
          if (i + j + 2 <= n) {
            const double c1 = (i + 2. / 3.) * inv, c2 = (j + 2. / 3.) * inv;
            face_sample(f, 1. - c1 - c2, c1, c2);
          }
        }
    }
  }
}

}  // namespace internal
}  // namespace Metrics
}  // namespace CMGeom

#endif  // CMGEOM_METRICS_INTERNAL_SURFACE_SAMPLING_H

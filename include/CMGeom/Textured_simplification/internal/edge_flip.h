// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The edge-flip test of thesis §3.5.1: the criterion of Jiao et al. 2006 (the quadric of each
// vertex restricted to the tangent plane is a local metric) with the modified Delaunay test of
// Bossen & Heckbert 1996, plus non-overlap checks. Key choices: one tangent plane per edge; a
// tolerance that prevents flip cycles on co-circular configurations; a feature guard refusing
// flips across edges whose two triangles' normals differ by more than about 11 degrees; policies
// without `quadric(v)` get the Euclidean Delaunay test. O(deg) per test, O(1) geometry.
//
// Manual: doc/Textured_simplification/README.md, "Choices where the thesis is silent or ambiguous".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_EDGE_FLIP_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_EDGE_FLIP_H

#include <CMGeom/Textured_simplification/internal/Symmetric_quadric.h>
#include <CMGeom/Textured_simplification/internal/collapse_checks.h>

#include <type_traits>
#include <utility>

namespace CMGeom {
namespace Textured_simplification {
namespace internal {

template <class P, class V, class = void>
struct has_vertex_quadric : std::false_type {};
template <class P, class V>
struct has_vertex_quadric<P, V, std::void_t<decltype(std::declval<const P&>().quadric(std::declval<V>()))>>
    : std::true_type {};

template <class Policy, class V>
void add_restricted_metric(const Policy& policy, V v, const Vec3& t1, const Vec3& t2, double m[3], double& tr) {
  if constexpr (has_vertex_quadric<Policy, V>::value) {
    const Symmetric_quadric& q = policy.quadric(v);
    const Vec3 At1 = q.A_times(t1), At2 = q.A_times(t2);
    m[0] += dot(t1, At1);
    m[1] += dot(t1, At2);
    m[2] += dot(t2, At2);
    tr += q.trace();
  } else {
    (void)policy;
    (void)v;
    (void)t1;
    (void)t2;
    (void)m;
    (void)tr;
  }
}

/// True when the edge of interior halfedge `h` should be flipped (see the file comment).
template <class TriangleMesh, class VertexPointMap, class Policy, class VertexIndexMap, class MarkVector>
bool should_flip(const TriangleMesh& tm, const VertexPointMap& vpm,
                 typename boost::graph_traits<TriangleMesh>::halfedge_descriptor h, const Policy& policy,
                 const VertexIndexMap& vim, MarkVector& mark, unsigned& stamp) {
  const auto o = opposite(h, tm);
  if (is_border(h, tm) || is_border(o, tm)) return false;
  const auto va = source(h, tm), vb = target(h, tm);
  const auto vc = target(next(h, tm), tm), vd = target(next(o, tm), tm);
  if (vc == vd) return false;
  const Vec3 a = to_vec3(get(vpm, va)), b = to_vec3(get(vpm, vb)), c = to_vec3(get(vpm, vc)), d = to_vec3(get(vpm, vd));
  // feature guard and plane
  const Vec3 nL = cross(sub(b, a), sub(c, a));  // triangle (a, b, c)
  const Vec3 nR = cross(sub(a, b), sub(d, b));  // triangle (b, a, d)
  const double lL = norm(nL), lR = norm(nR);
  if (!(lL > 0) || !(lR > 0)) return false;
  if (dot(nL, nR) < 0.98 * lL * lR) return false;
  // non-overlap: new triangles (c, a, d) and (d, b, c)
  const Vec3 n1 = cross(sub(a, c), sub(d, c));
  const Vec3 n2 = cross(sub(b, d), sub(c, d));
  const Vec3 n = add(scale(nL, 1 / lL), scale(nR, 1 / lR));
  if (!(dot(n1, n) > 0) || !(dot(n2, n) > 0) || !(dot(n1, nL) > 0) || !(dot(n1, nR) > 0) || !(dot(n2, nL) > 0) ||
      !(dot(n2, nR) > 0))
    return false;

  // tangent-plane basis
  const double nl = norm(n);
  const Vec3 nn = scale(n, 1 / nl);
  const Vec3 e = sub(b, a);
  Vec3 t1 = sub(e, scale(nn, dot(e, nn)));
  const double t1l = norm(t1);
  if (!(t1l > 0)) return false;
  t1 = scale(t1, 1 / t1l);
  const Vec3 t2 = cross(nn, t1);
  double m[3] = {0, 0, 0};
  double tr = 0;
  add_restricted_metric(policy, va, t1, t2, m, tr);
  add_restricted_metric(policy, vb, t1, t2, m, tr);
  add_restricted_metric(policy, vc, t1, t2, m, tr);
  add_restricted_metric(policy, vd, t1, t2, m, tr);
  if (tr > 0) {
    m[0] /= tr;
    m[1] /= tr;
    m[2] /= tr;
  }
  m[0] += 0.01;
  m[2] += 0.01;
  // metric inner products of 2-D vectors: <x, y>_M = x^T M y; |x × y|_M = sqrt(det M) |x × y|
  auto proj = [&](const Vec3& p) {
    const Vec3 q = sub(p, a);
    return std::pair<double, double>(dot(q, t1), dot(q, t2));
  };
  const auto A2 = proj(a), B2 = proj(b), C2 = proj(c), D2 = proj(d);
  const double sdet = std::sqrt((std::max)(m[0] * m[2] - m[1] * m[1], 1e-300));
  auto cot = [&](const std::pair<double, double>& apex, const std::pair<double, double>& p,
                 const std::pair<double, double>& q) {
    const double ux = p.first - apex.first, uy = p.second - apex.second;
    const double vx = q.first - apex.first, vy = q.second - apex.second;
    const double ip = ux * (m[0] * vx + m[1] * vy) + uy * (m[1] * vx + m[2] * vy);
    const double cr = std::abs(ux * vy - uy * vx) * sdet;
    return cr > 0 ? ip / cr : 0.0;
  };
  if (!(cot(C2, A2, B2) + cot(D2, A2, B2) < -0.05)) return false;

  // topology: the new edge (c, d) must not exist, a and b keep >= 3 neighbours
  std::size_t deg_a = 0, deg_b = 0;
  for (auto hh : CGAL::halfedges_around_target(va, tm)) {
    (void)hh;
    ++deg_a;
  }
  for (auto hh : CGAL::halfedges_around_target(vb, tm)) {
    (void)hh;
    ++deg_b;
  }
  if (deg_a <= 3 || deg_b <= 3) return false;
  (void)vim;
  (void)mark;
  (void)stamp;
  for (auto hh : CGAL::halfedges_around_target(vc, tm))
    if (source(hh, tm) == vd) return false;
  return true;
}

}  // namespace internal
}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_EDGE_FLIP_H

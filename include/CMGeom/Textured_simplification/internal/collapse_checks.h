// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Local validity tests of one edge collapse, shared by CMGeom's engine and the filters that run
// under CGAL's engine: the link condition (topology) and the fold-over test (geometry).
// Both are O(deg(v0) + deg(v1)) and allocate nothing.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_COLLAPSE_CHECKS_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_COLLAPSE_CHECKS_H

#include <CMGeom/Textured_simplification/internal/Symmetric_quadric.h>

#include <CGAL/boost/graph/helpers.h>
#include <CGAL/number_utils.h>
#include <boost/graph/graph_traits.hpp>

#include <limits>

namespace CMGeom {
namespace Textured_simplification {
namespace internal {

template <class Point>
inline Vec3 to_vec3(const Point& p) {
  return {CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())};
}

/// True when moving the endpoints of halfedge `h_v0v1` to `x` flips (or flattens to zero area)
/// some triangle of the star of v0 or v1 that survives the collapse. A flip is a non-positive dot
/// product between the triangle's normal before and after the move (§3.4.2: "fold-overs" are
/// rejected; the thesis does not fix a threshold, we use the sign, as CGAL's
/// Bounded_normal_change_filter does).
/// If `star_normal` is not null and the answer is false, it receives the sum of the new normals of
/// the triangles tested (each twice the triangle's area long): they are the star of the kept vertex
/// once it sits at `x`, so this is the area-weighted normal of the kept vertex after the collapse,
/// the same sum as over its star then, up to the order of the additions.
template <class TriangleMesh, class VertexPointMap>
bool collapse_flips_a_face(const TriangleMesh& tm, const VertexPointMap& vpm,
                           typename boost::graph_traits<TriangleMesh>::halfedge_descriptor h_v0v1, const Vec3& x,
                           Vec3* star_normal = nullptr) {
  using halfedge_descriptor = typename boost::graph_traits<TriangleMesh>::halfedge_descriptor;
  using face_descriptor = typename boost::graph_traits<TriangleMesh>::face_descriptor;
  const auto v0 = source(h_v0v1, tm);
  const auto v1 = target(h_v0v1, tm);
  const face_descriptor fL = face(h_v0v1, tm);
  const face_descriptor fR = face(opposite(h_v0v1, tm), tm);
  Vec3 sum{0, 0, 0};
  for (int side = 0; side < 2; ++side) {
    const auto v = side == 0 ? v0 : v1;
    const Vec3 pv = to_vec3(get(vpm, v));
    for (halfedge_descriptor h : CGAL::halfedges_around_target(v, tm)) {
      if (is_border(h, tm)) continue;
      const face_descriptor f = face(h, tm);
      if (f == fL || f == fR) continue;
      // h = (a -> v); the triangle is (v, b, a) with b = target(next(h)).
      const Vec3 a = to_vec3(get(vpm, source(h, tm)));
      const Vec3 b = to_vec3(get(vpm, target(next(h, tm), tm)));
      const Vec3 n_old = cross(sub(b, pv), sub(a, pv));
      const Vec3 n_new = cross(sub(b, x), sub(a, x));
      const double d = dot(n_old, n_new);
      const double nn = dot(n_new, n_new);
      if (!(d > 0) || !(nn > 1e-24 * dot(n_old, n_old))) return true;
      sum = add(sum, n_new);
    }
  }
  if (star_normal) *star_normal = sum;
  return false;
}

/// Walks the faces a collapse of halfedge `h_v0v1` changes: `removed(f)` for each face of the
/// edge (none, one or two), then `surviving(f, g)` for every other face around v0, then around v1,
/// `g` the halfedge of f that ends at v0 or v1, so that with the kept vertex at x the face becomes
/// the triangle (x, target(next(g)), source(g)). (collapse_flips_a_face walks the same faces with
/// an early exit of its own.)
template <class TriangleMesh, class Removed, class Surviving>
void for_each_face_of_collapse(const TriangleMesh& tm,
                               typename boost::graph_traits<TriangleMesh>::halfedge_descriptor h_v0v1, Removed removed,
                               Surviving surviving) {
  using GT = boost::graph_traits<TriangleMesh>;
  const typename GT::face_descriptor fl = is_border(h_v0v1, tm) ? GT::null_face() : face(h_v0v1, tm);
  const typename GT::halfedge_descriptor o = opposite(h_v0v1, tm);
  const typename GT::face_descriptor fr = is_border(o, tm) ? GT::null_face() : face(o, tm);
  if (fl != GT::null_face()) removed(fl);
  if (fr != GT::null_face()) removed(fr);
  for (int side = 0; side < 2; ++side)
    for (typename GT::halfedge_descriptor g :
         CGAL::halfedges_around_target(side == 0 ? source(h_v0v1, tm) : target(h_v0v1, tm), tm)) {
      if (is_border(g, tm)) continue;
      const typename GT::face_descriptor f = face(g, tm);
      if (f != fl && f != fr) surviving(f, g);
    }
}

/// How many border halfedges end at v: 0 inside, 1 on a boundary, more at a pinch (fans of faces
/// meeting at one vertex), where Euler::collapse_edge, which assumes a 2-manifold vertex, can leave
/// a fan behind at the vertex's old place. The count stops at `limit`.
template <class TriangleMesh>
int border_passes(const TriangleMesh& tm, typename boost::graph_traits<TriangleMesh>::vertex_descriptor v,
                  int limit = std::numeric_limits<int>::max()) {
  int borders = 0;
  for (auto g : CGAL::halfedges_around_target(v, tm))
    if (is_border(g, tm) && ++borders >= limit) break;
  return borders;
}

/// The default `on_neighbour` of is_collapse_topologically_valid(): does nothing.
struct Ignore_neighbour {
  template <class V>
  void operator()(const V&) const {}
};

/// Link condition of Dey et al. / Hoppe et al. for collapsing halfedge `h_v0v1` of a manifold
/// triangle mesh, plus the cases where the result would be degenerate although the link condition
/// holds (a tetrahedron, an isolated triangle, a kept vertex with fewer than three neighbours, an
/// interior edge between two boundary vertices, the edge's two faces on the same three vertices, an
/// endpoint the border passes more than once). A second edge joining v0 and v1 (a valid
/// CGAL::Surface_mesh may hold one, e.g. after triangulating quads whose diagonals meet an existing
/// edge) fails the link condition: the apexes of its faces are neighbours of both that are not
/// apexes of this edge. `mark`/`stamp` are caller-owned scratch (a vertex-indexed array and a
/// counter, used for vertices of degree > 64) so the test allocates nothing. `on_neighbour(v)` is
/// called for every neighbour of v0 and of v1 met while the test walks their stars (an engine uses
/// it to prefetch their data); it must not modify the mesh. If `warm` is not null, the stars of its
/// endpoints are walked too, read only, alongside the test's own walks and never longer: an engine
/// passes the edge it will most likely test next, whose halfedge records then come into the cache
/// while this test waits for its own (walking a star is a chain of dependent memory accesses;
/// independent chains overlap). The verdict does not depend on `warm`.
template <class TriangleMesh, class VertexIndexMap, class MarkVector, class OnNeighbour = Ignore_neighbour>
bool is_collapse_topologically_valid(const TriangleMesh& tm, const VertexIndexMap& vim,
                                     typename boost::graph_traits<TriangleMesh>::halfedge_descriptor h,
                                     MarkVector& mark, unsigned& stamp, const OnNeighbour& on_neighbour = OnNeighbour(),
                                     typename boost::graph_traits<TriangleMesh>::halfedge_descriptor warm =
                                         boost::graph_traits<TriangleMesh>::null_halfedge()) {
  using halfedge_descriptor = typename boost::graph_traits<TriangleMesh>::halfedge_descriptor;
  using vertex_descriptor = typename boost::graph_traits<TriangleMesh>::vertex_descriptor;
  const halfedge_descriptor o = opposite(h, tm);
  const bool left = !is_border(h, tm), right = !is_border(o, tm);
  if (!left && !right) return false;
  const vertex_descriptor v0 = source(h, tm), v1 = target(h, tm);
  vertex_descriptor vL = boost::graph_traits<TriangleMesh>::null_vertex();
  vertex_descriptor vR = vL;
  if (left) {
    vL = target(next(h, tm), tm);
    // an isolated triangle (both other edges on the border) would vanish to a segment
    if (is_border(opposite(next(h, tm), tm), tm) && is_border(opposite(prev(h, tm), tm), tm)) return false;
  }
  if (right) {
    vR = target(next(o, tm), tm);
    if (is_border(opposite(next(o, tm), tm), tm) && is_border(opposite(prev(o, tm), tm), tm)) return false;
  }
  // the edge's two faces on the same three vertices (a pocket: the triangle twice, back to back)
  // would collapse to a dangling pair of edges
  if (left && right && vL == vR) return false;

  // The neighbours of v0 and of v1 go to small local arrays (no random access into a
  // vertex-indexed array: this test runs once per popped edge); vertex-indexed marks only past 64
  // neighbours. The two stars are walked side by side: each step of a walk waits for the previous
  // one's memory access, but the two walks are independent, so their cache misses overlap.
  constexpr std::size_t local_max = 64;
  vertex_descriptor ring0[local_max], ring1[local_max];
  bool v0_border = false, v1_border = false;
  std::size_t deg0 = 0, deg1 = 0;
  int border_in0 = 0, border_in1 = 0;  // border halfedges ending at v0 / v1
  {
    const halfedge_descriptor s0 = halfedge(v0, tm), s1 = halfedge(v1, tm);
    halfedge_descriptor h0 = s0, h1 = s1;
    bool done0 = false, done1 = false;
    const bool warm_on = warm != boost::graph_traits<TriangleMesh>::null_halfedge();
    const halfedge_descriptor ws0 = warm_on ? halfedge(source(warm, tm), tm) : h0;
    const halfedge_descriptor ws1 = warm_on ? halfedge(target(warm, tm), tm) : h1;
    halfedge_descriptor w0 = ws0, w1 = ws1;
    bool wdone0 = !warm_on, wdone1 = !warm_on;
    while (!done0 || !done1) {
      if (!wdone0) {
        w0 = opposite(next(w0, tm), tm);
        wdone0 = w0 == ws0;
      }
      if (!wdone1) {
        w1 = opposite(next(w1, tm), tm);
        wdone1 = w1 == ws1;
      }
      if (!done0) {
        const vertex_descriptor k = source(h0, tm);
        on_neighbour(k);
        if (deg0 < local_max) ring0[deg0] = k;
        border_in0 += int(is_border(h0, tm));
        v0_border = v0_border || is_border(h0, tm) || is_border(opposite(h0, tm), tm);
        ++deg0;
        h0 = opposite(next(h0, tm), tm);
        done0 = h0 == s0;
      }
      if (!done1) {
        const vertex_descriptor k = source(h1, tm);
        on_neighbour(k);
        if (deg1 < local_max) ring1[deg1] = k;
        border_in1 += int(is_border(h1, tm));
        v1_border = v1_border || is_border(h1, tm) || is_border(opposite(h1, tm), tm);
        ++deg1;
        h1 = opposite(next(h1, tm), tm);
        done1 = h1 == s1;
      }
    }
  }
  // A vertex the border passes more than once (a pinch: fans of faces that meet at one vertex,
  // which a halfedge structure can hold) is not a 2-manifold vertex, which Euler::collapse_edge
  // assumes: with a fan on the edge's border side it removes that fan's face and takes the vertex
  // for gone while its other fans still hold it, so they keep its old place and one of them can
  // come off as a new component. Such a vertex is never collapsed (its other edges are).
  if (border_in0 > 1 || border_in1 > 1) return false;
  const bool use_marks = deg0 > local_max;
  if (use_marks) {
    if (++stamp == 0) {  // counter wrapped: reset the marks once every 2^32 tests
      std::fill(mark.begin(), mark.end(), 0u);
      stamp = 1;
    }
    for (halfedge_descriptor hh : CGAL::halfedges_around_target(v0, tm)) mark[get(vim, source(hh, tm))] = stamp;
  }
  // a neighbour shared by v0 and v1 must be an apex of the edge's faces
  auto shared_ok = [&](vertex_descriptor k, std::size_t& common) {
    bool shared = false;
    if (use_marks) {
      shared = mark[get(vim, k)] == stamp;
    } else {
      for (std::size_t j = 0; j < deg0; ++j)
        if (ring0[j] == k) {
          shared = true;
          break;
        }
    }
    if (!shared) return true;
    if ((left && k == vL) || (right && k == vR)) {
      ++common;
      return true;
    }
    return false;  // k, v0, v1 is not a face: collapsing would pinch the surface
  };
  std::size_t common = 0;
  if (deg1 <= local_max) {
    for (std::size_t j = 0; j < deg1; ++j)
      if (!shared_ok(ring1[j], common)) return false;
  } else {
    for (halfedge_descriptor hh : CGAL::halfedges_around_target(v1, tm))
      if (!shared_ok(source(hh, tm), common)) return false;
  }
  if (common != std::size_t(left) + std::size_t(right)) return false;
  // an interior edge joining two boundary vertices would pinch the boundary
  if (left && right && v0_border && v1_border) return false;
  // The kept vertex must keep at least three neighbours. The apexes need no test of their own:
  // an interior apex of degree 3 passes the link condition only when its third neighbour is the
  // other apex, i.e. the component is a tetrahedron, which this test rejects (3 + 3 - 2 - 2 < 3);
  // a border apex of degree 2 is an isolated triangle, rejected above.
  const std::size_t removed = std::size_t(left) + std::size_t(right);
  if (deg0 + deg1 - 2 - removed < 3) return false;
  return true;
}

}  // namespace internal
}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_COLLAPSE_CHECKS_H

// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Hausdorff_bound, Hausdorff_bound_filter, Hausdorff_bound_visitor: a guaranteed bound E on the
// two-sided Hausdorff distance between a mesh being simplified and its input. The input's faces
// are kept as triangles ("pieces"), each attached to a current face it lies within E of (the
// thesis' point gathering, §4.3, with whole triangles). A collapse or a flip is allowed only when
// every piece of the faces it changes lies within E of one face of the new star or of a face next
// to it, and every point of every new face lies within E of one of the pieces near it. Both tests
// are exact on triangles: the distance to a triangle is convex, so a triangle is within E of
// another when its three corners are; one that fits in no single triangle is cut in four, down to
// a depth limit. The input's flat regions are also grouped into convex planar patches, so that a new
// face across many small flat triangles is tested against their union at once, and a new face is
// first tested whole against the input's faces projected onto its plane (covered_by_projection()),
// which most often spares the cuts; before that, against the faces it replaces, each carrying a
// bound on its own distance to the input (covered_by_old_faces()), which spares the input's faces.
// An input face cut in parts becomes one piece again when a change moves all its parts to one face
// (commit()): its points are theirs, so it lies within E of that face too.
// A collapse at a vertex the border passes more than once (a pinch, which Euler::collapse_edge does
// not handle as a 2-manifold vertex) is refused.
// Conservative: an allowed change is always within E, a refused one may have been.
// Complexity: O(F) set-up; a test O(k m + g), k pieces near the edge, m parts a new face is cut in,
// g input faces gathered for the projections.
//
// Manual: doc/Textured_simplification/README.md, "A guaranteed error bound: `max_error`".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_HAUSDORFF_BOUND_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_HAUSDORFF_BOUND_H

#include <CMGeom/Compact_model/internal/Vec3.h>
#include <CMGeom/Textured_simplification/Edge_collapse_visitor_base.h>
#include <CMGeom/Textured_simplification/No_normal_flip_filter.h>
#include <CMGeom/Textured_simplification/internal/collapse_checks.h>

#include <CGAL/boost/graph/helpers.h>
#include <CGAL/boost/graph/iterator.h>
#include <CGAL/number_utils.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {

/// Options of Hausdorff_bound.
struct Hausdorff_bound_options {
  /// A triangle that lies within E of no single triangle is cut in four, at most this many times
  /// over (the cuts follow the edges it straddles: a few pieces per cut, not 4^depth).
  int max_depth = 8;
  /// At most this many point-triangle distances per test; a change that needs more is refused.
  std::size_t max_work = std::size_t(1) << 18;
};

/// Throws std::invalid_argument when `options` are out of range (max_depth outside [0, 16]);
/// `max_depth_name` names that option in the message (e.g. "Hausdorff_bound: max_depth").
inline void check_bound_options(const Hausdorff_bound_options& options, const std::string& max_depth_name) {
  if (options.max_depth < 0 || options.max_depth > 16)
    throw std::invalid_argument(max_depth_name + " must be in [0, 16]");
}

/// The bound's state on a mesh being simplified (see the file comment).
/// \tparam TriangleMesh `CGAL::Surface_mesh` (face indices must stay valid while faces are
///   removed, as they do until `collect_garbage()`)
/// \tparam VertexPointMap the mesh's point map
template <class TriangleMesh, class VertexPointMap>
class Hausdorff_bound {
  using GT = boost::graph_traits<TriangleMesh>;
  using vertex_descriptor = typename GT::vertex_descriptor;
  using halfedge_descriptor = typename GT::halfedge_descriptor;
  using face_descriptor = typename GT::face_descriptor;
  using V3 = CM::internal::Vec3;
  static constexpr std::uint32_t nil = 0xffffffffu;

public:
  /// Takes every face of `tm` as a piece attached to itself. `max_error` is the bound E in the
  /// mesh's units (> 0 and finite, else std::invalid_argument).
  Hausdorff_bound(const TriangleMesh& tm, const VertexPointMap& vpm, double max_error,
                  const Hausdorff_bound_options& options = Hausdorff_bound_options())
      : vpm_(vpm), options_(options), e_(max_error) {
    if (!(max_error > 0.0) || !std::isfinite(max_error))
      throw std::invalid_argument("Hausdorff_bound: max_error must be finite and > 0, got " +
                                  std::to_string(max_error));
    check_bound_options(options, "Hausdorff_bound: max_depth");
    set_bound(max_error);
    std::size_t nf = 0;
    for (face_descriptor f : faces(tm)) nf = (std::max)(nf, std::size_t(f) + 1);
    head_.assign(nf, nil);
    const std::vector<std::uint32_t> face_patch = make_patches(tm, nf);
    input_.assign(nf, Input_face());
    for (face_descriptor f : faces(tm)) {
      const halfedge_descriptor h = halfedge(f, tm);
      Input_face& in = input_[std::size_t(f)];
      halfedge_descriptor g = h;
      for (int k = 0; k < 3; ++k, g = next(g, tm)) {  // corner k = source of side k
        in.corner[k] = point(source(g, tm));
        const halfedge_descriptor o = opposite(g, tm);
        in.across[k] = is_border(o, tm) ? nil : std::uint32_t(std::size_t(face(o, tm)));
      }
      Piece p;
      p.t = input_tri(in);
      p.patch = face_patch[std::size_t(f)];
      p.origin = std::uint32_t(std::size_t(f));
      p.next = head_[std::size_t(f)];
      head_[std::size_t(f)] = std::uint32_t(pieces_.size());
      pieces_.push_back(p);
    }
    live_pieces_ = pieces_.size();
    fragments_.assign(nf, 1);
    merge_.assign(nf, Merge());
    seen_.assign(nf, 0);
    face_bound_.assign(nf, 0.);
  }

  /// E, in the mesh's units.
  double max_error() const { return e_; }
  /// Raises the bound to `max_error` (>= the current one) for the collapses that follow: what the
  /// earlier ones were allowed stays within it (a level-of-detail chain by error bounds runs on
  /// with each larger bound).
  void raise_max_error(double max_error) {
    if (!(max_error >= e_) || !std::isfinite(max_error))
      throw std::invalid_argument("Hausdorff_bound: raise_max_error needs a finite bound >= the current one, got " +
                                  std::to_string(max_error));
    set_bound(max_error);
  }
  /// The largest distance any accepted test found (<= E): a bound on the Hausdorff distance
  /// between the current mesh and the input.
  double bound() const { return bound_; }
  /// Number of pieces of the input (the input's faces, and the pieces of those that were cut).
  std::size_t number_of_pieces() const { return live_pieces_; }
  /// How many times an input face cut in parts became one piece again (all its parts moved to
  /// one face by the same change).
  std::size_t made_whole() const { return made_whole_; }
  /// Number of collapses and flips refused because they would have broken the bound.
  std::size_t refused() const { return refused_; }
  /// Number of flat patches: convex planar polygons, each the union of two or more adjacent
  /// input faces (see make_patches()).
  std::size_t number_of_patches() const { return patches_.size(); }
  /// Number of new faces the second test found covered by the input's faces projected onto them
  /// whole (see covered_by_projection()), and the number it tested that way (the parts of faces
  /// cut after failing it are tried that way too, and not counted).
  std::size_t projected() const { return projected_; }
  std::size_t projection_tests() const { return projection_tests_; }
  /// A bound on the distance from any point of face `f` of the mesh to the input (0 for a face
  /// of the input; then what the test that made or last changed the face found).
  double face_bound(face_descriptor f) const { return face_bound_[std::size_t(f)]; }
  /// Number of new faces the second test found within E through the faces they replace
  /// (covered_by_old_faces()), without looking at the input.
  std::size_t covered_by_old_faces() const { return covered_by_old_; }

  /// Calls `fn(face, a, b, c)` for every piece, `face` the current face it is attached to and
  /// a, b, c its corners (CM::internal::Vec3).
  template <class Fn>
  void for_each_piece(Fn fn) const {
    for (std::size_t f = 0; f < head_.size(); ++f)
      for (std::uint32_t i = head_[f]; i != nil; i = pieces_[i].next)
        fn(face_descriptor(typename face_descriptor::size_type(f)), pieces_[i].t.a, pieces_[i].t.b, pieces_[i].t.c);
  }

  /// Whether the collapse of halfedge `h` (v0 -> v1) with the kept vertex at `x` keeps the
  /// bound. If it does, the pieces' new faces are remembered for collapsed().
  bool allows_collapse(const TriangleMesh& tm, halfedge_descriptor h, const V3& x) {
    start_test();
    // Euler::collapse_edge assumes 2-manifold endpoints: at a vertex the border passes twice it
    // can leave a fan behind, where the faces walked here would not be the faces it changes
    if (internal::border_passes(tm, source(h, tm), 2) > 1 || internal::border_passes(tm, target(h, tm), 2) > 1) {
      ++refused_;
      return false;
    }
    internal::for_each_face_of_collapse(
        tm, h, [&](face_descriptor f) { olds_.push_back(f); },
        [&](face_descriptor f, halfedge_descriptor g) {
          olds_.push_back(f);
          news_.push_back(make_tri(x, point(target(next(g, tm), tm)), point(source(g, tm))));
          homes_.push_back(f);
        });
    plan_.x = x;
    return decide(tm, h, false);
  }

  /// Call after the collapse allowed last by allows_collapse(), `kept` the vertex kept at its
  /// new place: the pieces move to their new faces. Does nothing for any other collapse.
  void collapsed(const TriangleMesh& tm, halfedge_descriptor h, vertex_descriptor kept) {
    if (!plan_.valid || plan_.flip || plan_.h != h || point(kept) != plan_.x) return;
    commit();
  }

  /// Whether flipping the edge of halfedge `h` keeps the bound (remembered for flipped()).
  bool allows_flip(const TriangleMesh& tm, halfedge_descriptor h) {
    start_test();
    const halfedge_descriptor o = opposite(h, tm);
    if (is_border(h, tm) || is_border(o, tm)) return false;
    // faces (a, b, c) and (b, a, d) become (b, c, d) and (c, a, d)
    const vertex_descriptor a = source(h, tm), b = target(h, tm), c = target(next(h, tm), tm),
                            d = target(next(o, tm), tm);
    olds_.push_back(face(h, tm));
    olds_.push_back(face(o, tm));
    news_.push_back(make_tri(point(b), point(c), point(d)));
    news_.push_back(make_tri(point(c), point(a), point(d)));
    homes_.push_back(GT::null_face());  // resolved in flipped()
    homes_.push_back(GT::null_face());
    flip_b_ = b;
    return decide(tm, h, true);
  }

  /// Call after flipping the edge allowed last by allows_flip(); `h` is the new edge.
  void flipped(const TriangleMesh& tm, halfedge_descriptor h) {
    if (!plan_.valid || !plan_.flip || plan_.h != h) return;
    // the new triangle (b, c, d) is the face of the new edge's halfedges that holds b
    const face_descriptor f0 = face(h, tm), f1 = face(opposite(h, tm), tm);
    bool f0_has_b = false;
    for (vertex_descriptor v : CGAL::vertices_around_face(halfedge(f0, tm), tm)) f0_has_b |= v == flip_b_;
    homes_[0] = f0_has_b ? f0 : f1;
    homes_[1] = f0_has_b ? f1 : f0;
    commit();
  }

private:
  struct Tri {
    V3 a, b, c;
    V3 centre;  // centroid, and radius: the largest distance from it to a corner
    double radius;
  };
  struct Piece {
    Tri t;
    std::uint32_t patch = nil;   // the flat patch of the input face it comes from, if any
    std::uint32_t origin = nil;  // that input face
    std::uint32_t next = nil;
  };
  struct Part;  // (below)
  /// An input face: its corners (corner k is the source of side k, in the order of
  /// halfedges_around_face from halfedge(f)) and the face across each side (nil: a border).
  struct Input_face {
    V3 corner[3];
    std::uint32_t across[3] = {nil, nil, nil};
  };
  /// A face a change replaces, as it is before the change: its corners (corner k the source of
  /// side k), the index in olds_ of the changed face across each side (-1: none, a side of the
  /// changed region's border), and its bound (face_bound_).
  struct Old_face {
    V3 corner[3];
    int across[3];
    double bound;
  };
  /// A convex planar polygon that is the union of adjacent input faces, each within tau of its
  /// plane (origin o, orthonormal u, v, normal n); corners_[begin, end) are its corners in (u, v),
  /// counterclockwise about n.
  struct Patch {
    V3 o, u, v, n;
    double slack;  // every point of the patch lies within it of an input face
    std::uint32_t begin, end;
  };
  struct Placed {         // a piece of a moving piece (whole or cut) and the index of its new face in homes_
    std::uint32_t piece;  // the moving piece it comes from
    std::uint32_t home;
    bool whole;
    Tri t;
  };
  struct Plan {
    bool valid = false, flip = false;
    halfedge_descriptor h;
    V3 x;
  };

  static Tri make_tri(const V3& a, const V3& b, const V3& c) {
    const CM::internal::Centroid_sphere sphere = CM::internal::centroid_sphere(a, b, c);
    return Tri{a, b, c, sphere.centre, sphere.radius};
  }
  /// An input face's triangle, as its piece starts (and as commit() makes it whole again).
  static Tri input_tri(const Input_face& in) { return make_tri(in.corner[0], in.corner[1], in.corner[2]); }
  static double dist2(const V3& q, const Tri& t) {
    return CM::internal::squared_length(q - CM::internal::closest_on_triangle(q, t.a, t.b, t.c));
  }
  /// The largest squared distance from the corners of `t` to triangle `q` when none is above
  /// `limit2`, else the first one found above it (the corners after it are not measured: the
  /// caller only compares the result with `limit2`). `known[k]`, when not negative, is the squared
  /// distance from corner k to `q`, found already.
  static double corners_dist2(const Tri& t, const Tri& q, double limit2, const double (&known)[3]) {
    const V3* corner[3] = {&t.a, &t.b, &t.c};
    double m = 0.;
    for (int k = 0; k < 3; ++k) {
      const double d = known[k] >= 0. ? known[k] : dist2(*corner[k], q);
      if (d > limit2) return d;
      m = (std::max)(m, d);
    }
    return m;
  }
  /// Whether two triangles' bounding spheres are more than E apart (then no point of one is
  /// within E of the other).
  bool apart(const Tri& s, const Tri& t) const { return apart(s, t.centre, t.radius); }
  bool apart(const Tri& s, const V3& centre, double radius) const {
    const double reach = s.radius + radius + e_test_;
    return CM::internal::squared_length(s.centre - centre) > reach * reach;
  }

  V3 point(vertex_descriptor v) const {
    const auto& q = get(vpm_, v);
    return V3(CGAL::to_double(q.x()), CGAL::to_double(q.y()), CGAL::to_double(q.z()));
  }

  /// Groups the input's faces into flat patches, for the new-face test: a new face that lies
  /// across several small input triangles of one flat region is within E of the region (a
  /// convex set, so its corners decide) although no single triangle holds it. Greedy growth
  /// from each face not yet taken, in face order, across edges: a neighbour joins when its
  /// third corner lies within tau = E / 100 of the seed's plane, on the far side of the
  /// shared edge, and the polygon stays convex up to round-off (at most 64 corners).
  /// The patch is then the polygon's convex hull, with a slack: the largest distance of a
  /// corner to the plane plus the deepest dent. Every point of a patch lies within its slack
  /// of an input face, so the distance to the input is at most the distance to the patch plus
  /// the slack. Returns each face's patch (nil: alone).
  std::vector<std::uint32_t> make_patches(const TriangleMesh& tm, std::size_t nf) {
    using CM::internal::cross;
    using CM::internal::dot;
    const double tau = 0.01 * e_;
    const double dent_tolerance = 1e-7 * e_;
    std::vector<std::uint32_t> face_patch(nf, nil);
    std::vector<char> taken(nf, 0);
    std::vector<vertex_descriptor> poly;    // the growing patch's corners (mesh vertices)
    std::vector<std::array<double, 2>> uv;  // and their coordinates in its plane
    std::vector<face_descriptor> members, queue;
    auto dist2d = [](const std::array<double, 2>& a, const std::array<double, 2>& b) {
      return std::hypot(b[0] - a[0], b[1] - a[1]);
    };
    for (face_descriptor f : faces(tm)) {
      if (taken[std::size_t(f)]) continue;
      taken[std::size_t(f)] = 1;
      const halfedge_descriptor h = halfedge(f, tm);
      const vertex_descriptor va = source(h, tm), vb = target(h, tm), vc = target(next(h, tm), tm);
      const V3 a = point(va), b = point(vb), c = point(vc);
      const V3 nn = cross(b - a, c - a);
      const double area2 = CM::internal::length(nn);
      if (!(area2 > 0.) || !std::isfinite(area2)) continue;
      Patch pa;
      pa.o = a;
      pa.n = (1. / area2) * nn;
      pa.u = CM::internal::normalized(b - a);
      pa.v = cross(pa.n, pa.u);
      auto in_plane = [&](const V3& q) -> std::array<double, 2> { return {dot(q - pa.o, pa.u), dot(q - pa.o, pa.v)}; };
      poly = {va, vb, vc};
      uv = {in_plane(a), in_plane(b), in_plane(c)};
      members = {f};
      queue = {f};
      for (std::size_t q = 0; q < queue.size(); ++q) {  // breadth first: rounder patches
        const face_descriptor g = queue[q];
        for (halfedge_descriptor hh : CGAL::halfedges_around_face(halfedge(g, tm), tm)) {
          const halfedge_descriptor oh = opposite(hh, tm);
          if (is_border(oh, tm) || poly.size() >= 64) continue;
          const face_descriptor k = face(oh, tm);
          if (taken[std::size_t(k)]) continue;
          // the shared edge must be a side of the polygon, traversed the same way
          const std::size_t m = poly.size();
          std::size_t i = 0;
          while (i < m && !(poly[i] == source(hh, tm) && poly[(i + 1) % m] == target(hh, tm))) ++i;
          if (i == m) continue;
          const vertex_descriptor wv = target(next(oh, tm), tm);
          const V3 w = point(wv);
          if (!(std::abs(dot(w - pa.o, pa.n)) <= tau)) continue;
          const std::array<double, 2> w2 = in_plane(w);
          const std::array<double, 2>&e0 = uv[i], &e1 = uv[(i + 1) % m], &before = uv[(i + m - 1) % m],
                                   &after = uv[(i + 2) % m];
          // w beyond the shared side; the corners at its ends convex, up to round-off (a straight
          // side is not refused for a dent of 1e-7 E; the dents are measured below)
          if (!(orient(e0, e1, w2) < 0.) || orient(before, e0, w2) < -dent_tolerance * dist2d(before, w2) ||
              orient(w2, e1, after) < -dent_tolerance * dist2d(w2, after))
            continue;
          poly.insert(poly.begin() + std::ptrdiff_t(i + 1), wv);
          uv.insert(uv.begin() + std::ptrdiff_t(i + 1), w2);
          taken[std::size_t(k)] = 1;
          members.push_back(k);
          queue.push_back(k);
        }
      }
      if (members.size() < 2) continue;
      // the patch is the convex hull of the polygon: its corners with the dents removed, and a
      // slack for the dents' depth and the corners' distance to the plane (the hull lies within
      // the slack of the input faces)
      const std::size_t m = uv.size();
      std::vector<char> keep(m, 1);
      // the kept corners before and after corner i
      auto kept_around = [&](std::size_t i) {
        std::size_t a = (i + m - 1) % m, c = (i + 1) % m;
        while (!keep[a]) a = (a + m - 1) % m;
        while (!keep[c]) c = (c + 1) % m;
        return std::make_pair(a, c);
      };
      for (bool changed = true; changed;) {
        changed = false;
        for (std::size_t i = 0; i < m; ++i) {
          if (!keep[i]) continue;
          const auto [a, c] = kept_around(i);
          if (orient(uv[a], uv[i], uv[c]) < 0.) keep[i] = 0, changed = true;
        }
      }
      // Each dent lies between the hull's side (a, c) and the parallel at its depth, over the
      // side itself (else the patch is dropped): every point of the hull outside the polygon is
      // then within the depth of the polygon.
      double dent = 0., off_plane = 0.;
      bool dents_over_sides = true;
      for (std::size_t i = 0; i < m; ++i) {
        off_plane = (std::max)(off_plane, std::abs(dot(point(poly[i]) - pa.o, pa.n)));
        if (keep[i]) continue;
        const auto [a, c] = kept_around(i);
        const double l = dist2d(uv[a], uv[c]);
        const double along =
            (uv[i][0] - uv[a][0]) * (uv[c][0] - uv[a][0]) + (uv[i][1] - uv[a][1]) * (uv[c][1] - uv[a][1]);
        const double depth = l > 0. ? orient(uv[a], uv[c], uv[i]) / l : -1.;
        dents_over_sides = dents_over_sides && depth >= 0. && along >= 0. && along <= l * l;
        dent = (std::max)(dent, depth);
      }
      if (!dents_over_sides) continue;
      pa.slack = off_plane + dent;
      pa.begin = std::uint32_t(corners_.size());
      for (std::size_t i = 0; i < m; ++i)
        if (keep[i]) corners_.push_back(uv[i]);
      pa.end = std::uint32_t(corners_.size());
      for (face_descriptor g : members) face_patch[std::size_t(g)] = std::uint32_t(patches_.size());
      patches_.push_back(pa);
    }
    return face_patch;
  }

  /// Squared distance from q to patch `pi` (a convex polygon in its plane).
  double patch_dist2(const V3& q, std::uint32_t pi) const {
    const Patch& pa = patches_[pi];
    const V3 d = q - pa.o;
    const double h = CM::internal::dot(d, pa.n), x = CM::internal::dot(d, pa.u), y = CM::internal::dot(d, pa.v);
    bool inside = true;
    double best = std::numeric_limits<double>::infinity();
    for (std::uint32_t i = pa.begin; i < pa.end; ++i) {
      const std::array<double, 2>& p0 = corners_[i];
      const std::array<double, 2>& p1 = corners_[i + 1 < pa.end ? i + 1 : pa.begin];
      const double ex = p1[0] - p0[0], ey = p1[1] - p0[1], qx = x - p0[0], qy = y - p0[1];
      if (ex * qy - ey * qx >= 0.) continue;  // on the inner side of this side
      inside = false;
      const double l2 = ex * ex + ey * ey;
      const double s = l2 > 0. ? std::clamp((qx * ex + qy * ey) / l2, 0., 1.) : 0.;
      const double dx = qx - s * ex, dy = qy - s * ey;
      best = (std::min)(best, dx * dx + dy * dy);
    }
    return h * h + (inside ? 0. : best);
  }

  /// E and its test thresholds: the tests compare squared distances computed in double precision
  /// against a threshold a millionth below E, so that round-off cannot carry an accepted distance
  /// over E.
  void set_bound(double e) {
    e_ = e;
    e_test_ = e_ * (1.0 - 1e-6);
    e2_ = e_test_ * e_test_;
  }

  /// Forgets the last test's plan and faces.
  void start_test() {
    plan_.valid = false;
    olds_.clear();
    news_.clear();
    homes_.clear();
  }

  /// Completes olds_ / news_ / homes_ with the ring, runs both tests and remembers the plan of an
  /// allowed change of `h` (a flip or, with plan_.x set, a collapse).
  bool decide(const TriangleMesh& tm, halfedge_descriptor h, bool flip) {
    add_ring(tm);
    if (!test()) {
      ++refused_;
      return false;
    }
    plan_.valid = true;
    plan_.flip = flip;
    plan_.h = h;
    return true;
  }

  /// The faces across the outer edges of the changed faces: unchanged, they may take pieces too.
  /// Also the changed faces as they are before the change (old_tris_), in the same walk.
  void add_ring(const TriangleMesh& tm) {
    old_tris_.clear();
    ring_begin_ = homes_.size();
    for (face_descriptor f : olds_) {
      Old_face o;
      halfedge_descriptor g = halfedge(f, tm);
      for (int k = 0; k < 3; ++k, g = next(g, tm)) {
        o.corner[k] = point(source(g, tm));
        o.across[k] = -1;
        const halfedge_descriptor og = opposite(g, tm);
        if (is_border(og, tm)) continue;
        const face_descriptor r = face(og, tm);
        const auto at = std::find(olds_.begin(), olds_.end(), r);
        if (at != olds_.end())
          o.across[k] = int(at - olds_.begin());
        else if (std::find(homes_.begin() + std::ptrdiff_t(ring_begin_), homes_.end(), r) == homes_.end())
          homes_.push_back(r);
      }
      o.bound = face_bound_[std::size_t(f)];
      old_tris_.push_back(o);
    }
    ring_.clear();
    for (std::size_t k = ring_begin_; k < homes_.size(); ++k) {
      const halfedge_descriptor g = halfedge(homes_[k], tm);
      ring_.push_back(make_tri(point(source(g, tm)), point(target(g, tm)), point(target(next(g, tm), tm))));
    }
  }

  /// The triangle of homes_ index k (a new triangle or a ring face's).
  const Tri& home_tri(std::size_t k) const { return k < ring_begin_ ? news_[k] : ring_[k - ring_begin_]; }

  /// Both tests on olds_ -> news_ (homes_, ring_ set); fills placed_.
  bool test() {
    work_ = 0;
    placed_.clear();
    cand_.clear();
    double worst = 0.;
    // 1. every piece of the changed faces lies within E of one new or ring face
    for (std::size_t j = 0; j < olds_.size(); ++j) {
      // a surviving face's own new triangle is tried first
      const std::size_t hint = j < olds_.size() - news_.size() ? 0 : j - (olds_.size() - news_.size());
      for (std::uint32_t i = head_[std::size_t(olds_[j])]; i != nil; i = pieces_[i].next) {
        cand_.push_back(i);
        if (!place(i, pieces_[i].t, hint, 0, true, worst)) return false;
      }
    }
    // the ring faces' pieces are input surface too: candidates for the second test
    for (std::size_t k = ring_begin_; k < homes_.size(); ++k)
      for (std::uint32_t i = head_[std::size_t(homes_[k])]; i != nil; i = pieces_[i].next) cand_.push_back(i);
    // 2. every point of every new face lies within E of a piece
    parts_.clear();
    near_.clear();
    new_bound_.assign(news_.size(), -1.);
    for (std::size_t j = 0; j < news_.size(); ++j) {
      const Tri& t = news_[j];
      // first against the faces it replaces, then against the input's faces
      double b = 0.;
      if (covered_by_old_faces(t, b) && b <= e_test_) {
        ++covered_by_old_;
        new_bound_[j] = b;
        worst = (std::max)(worst, b * b);
        continue;
      }
      double h2 = 0.;
      if (covered_by_projection(t, h2)) {
        new_bound_[j] = std::sqrt(h2);
        worst = (std::max)(worst, h2);
        continue;
      }
      Part part;
      part.t = t;
      part.begin = near_.size();
      for (std::uint32_t i : cand_)
        if (!apart(t, pieces_[i].t)) near_.push_back(Nearby{pieces_[i].t.centre, pieces_[i].t.radius, i});
      part.end = near_.size();
      for (int k = 0; k < 3; ++k) part.corner[k] = nearest(k == 0 ? t.a : k == 1 ? t.b : t.c, part, nil);
      parts_.push_back(part);
    }
    if (!covered(worst)) return false;
    pending_worst_ = worst;
    return true;
  }

  /// Triangle t seen in its own plane, what both projection tests set up: unit normal n and
  /// in-plane axes u (along t's first side) and v; t's corners there (a at the origin, b on the u
  /// axis, c above it), its sides' lengths, the margin (a billionth of its perimeter) by which t'
  /// is t shrunk, and its centroid. `valid` is false for a t without area.
  struct Plane_view {
    using P2 = std::array<double, 2>;
    bool valid = false;
    V3 origin, n, u, v;
    std::array<P2, 3> tri;
    std::array<double, 3> lengths;
    double margin = 0.;
    P2 m;

    explicit Plane_view(const Tri& t) : origin(t.a) {
      using CM::internal::cross;
      using CM::internal::dot;
      const V3 ab = t.b - t.a, ac = t.c - t.a;
      const V3 nn = cross(ab, ac);
      const double area2 = CM::internal::length(nn), lab = CM::internal::length(ab);
      if (!(area2 > 0.) || !(lab > 0.) || !std::isfinite(area2)) return;
      n = (1. / area2) * nn;
      u = (1. / lab) * ab;
      v = cross(n, u);
      const P2 A{0., 0.}, B{lab, 0.}, C{dot(ac, u), dot(ac, v)};
      margin = 1e-9 * (lab + CM::internal::length(ac) + CM::internal::length(t.c - t.b));
      tri = {A, B, C};
      lengths = {lab, std::sqrt(squared_distance_2(B, C)), std::sqrt(squared_distance_2(C, A))};
      m = P2{(A[0] + B[0] + C[0]) / 3., (A[1] + B[1] + C[1]) / 3.};
      valid = true;
    }
    /// `p` in the plane's coordinates; `height` receives the larger of itself and |p's height|.
    P2 project(const V3& p, double& height) const {
      using CM::internal::dot;
      const V3 d = p - origin;
      height = (std::max)(height, std::abs(dot(d, n)));
      return P2{dot(d, u), dot(d, v)};
    }
    /// Whether projected triangle `q` faces t's way (counterclockwise in the plane) by more than
    /// the projection's round-off.
    static bool faces_its_way(const std::array<P2, 3>& q) {
      const double sides2 =
          squared_distance_2(q[0], q[1]) + squared_distance_2(q[1], q[2]) + squared_distance_2(q[2], q[0]);
      return orient(q[0], q[1], q[2]) > 1e-12 * sides2;
    }
    /// Whether the centroid lies inside t' by the margin.
    bool centroid_inside() const {
      for (std::size_t k = 0; k < 3; ++k)
        if (!(orient(tri[k], tri[(k + 1) % 3], m) > 2. * margin * lengths[k])) return false;
      return true;
    }
    /// The distance within which every point of t lies of t': margin / sin(a / 2), a t's smallest
    /// angle (infinite for a t with an angle of 0).
    double shrink_reach() const {
      double sine = 1.;
      for (std::size_t k = 0; k < 3; ++k) {
        const P2& o = tri[k];
        const P2& p = tri[(k + 1) % 3];
        const P2& r = tri[(k + 2) % 3];
        const double c =
            ((p[0] - o[0]) * (r[0] - o[0]) + (p[1] - o[1]) * (r[1] - o[1])) / (lengths[k] * lengths[(k + 2) % 3]);
        sine = (std::min)(sine, std::sqrt((std::max)(0., 0.5 * (1. - c))));
      }
      return sine > 0. ? margin / sine : std::numeric_limits<double>::infinity();
    }
    /// Whether projected triangle `p` holds `x` beyond the margin.
    bool holds(const std::array<P2, 3>& p, const P2& x) const {
      for (int k = 0; k < 3; ++k) {
        const P2& p0 = p[std::size_t(k)];
        const P2& p1 = p[std::size_t((k + 1) % 3)];
        const double o = orient(p0, p1, x);
        if (!(o > 0. && o * o > margin * margin * squared_distance_2(p0, p1))) return false;
      }
      return true;
    }
  };

  /// The second test for a new face `t`, first against the faces the change replaces (old_tris_)
  /// instead of the input's faces under it. Every face keeps a bound on the distance from its
  /// points to the input (face_bound_: 0 for the input's own faces, then what the test that made
  /// the face found). The old faces that face t's way once projected onto its plane are "good";
  /// when their projections cover t (no side of their union's border meeting t shrunk by the
  /// margin, and t's centroid, or a point halfway from it to a corner, inside one of them: the
  /// argument of covered_by_projection(), with the old faces for the input's), every point of t
  /// lies within `reach` (the good faces' largest height over the plane, plus the margin's share)
  /// of a point of a good old face, and so within reach plus that face's bound of the input. `b`
  /// receives reach plus the largest bound of the good faces. O(old faces), where
  /// covered_by_projection() gathers every input face under t; the bounds add up collapse after
  /// collapse, and a face whose sum passes E goes to the input's faces, which give it a fresh one.
  bool covered_by_old_faces(const Tri& t, double& b) {
    using P2 = std::array<double, 2>;
    const Plane_view pv(t);
    if (!pv.valid || !pv.centroid_inside()) return false;
    // the old faces facing t's way once projected ("good"); R, the union of their projections,
    // is bounded by their sides with no good face across
    double hmax = 0., bmax = 0.;
    bool point_inside = false;
    proj_old_.resize(old_tris_.size());
    good_old_.assign(old_tris_.size(), 0);
    for (std::size_t i = 0; i < old_tris_.size(); ++i) {
      const Old_face& o = old_tris_[i];
      std::array<P2, 3>& p = proj_old_[i];
      double h = 0.;
      for (int k = 0; k < 3; ++k) p[std::size_t(k)] = pv.project(o.corner[k], h);
      if (!Plane_view::faces_its_way(p)) continue;
      good_old_[i] = 1;
      hmax = (std::max)(hmax, h);
      bmax = (std::max)(bmax, o.bound);
    }
    for (std::size_t i = 0; i < old_tris_.size(); ++i) {
      if (!good_old_[i]) continue;
      const std::array<P2, 3>& p = proj_old_[i];
      for (int k = 0; k < 3; ++k) {
        const int across = old_tris_[i].across[k];
        if ((across < 0 || !good_old_[std::size_t(across)]) &&
            segment_meets_triangle(p[std::size_t(k)], p[std::size_t((k + 1) % 3)], pv.tri, pv.lengths, pv.margin))
          return false;
      }
      // a point of t' inside one of them: the centroid, or a point halfway from it to a corner
      // (both inside t' by the test above; on a regular grid the centroid often lies on an old side)
      for (std::size_t c = 0; c < 4 && !point_inside; ++c) {
        const P2& m = pv.m;
        const P2 x = c == 0 ? m : P2{0.5 * (m[0] + pv.tri[c - 1][0]), 0.5 * (m[1] + pv.tri[c - 1][1])};
        point_inside = pv.holds(p, x);
      }
    }
    if (!point_inside) return false;
    b = hmax + pv.shrink_reach() + bmax;
    return std::isfinite(b);
  }

  /// The second test for a whole new face `t`, at once: whether the input's faces, projected
  /// orthogonally onto its plane, cover it while lying within E of that plane. A point q' of the
  /// plane that is the projection of a point p of such a face is within |p - q'|, p's height over
  /// the plane, of the input, and a face's heights are at most those of its corners. The faces
  /// kept ("good") are those facing the way t does (positive area once projected) with their three
  /// corners within E of the plane; they are gathered from the candidate pieces' input faces
  /// across the input's sides, as far as their projections reach t's bounding box. Let R be the
  /// union of their projections and t' the triangle t with its sides moved inwards by a margin (a
  /// billionth of its perimeter). R's boundary is made of sides of good faces with no good face
  /// across (or on the input's border): across any other side the two good faces lie on either
  /// side of it once projected, the input being oriented, and the good faces around a corner with
  /// no such side wind around it. So when (1) none of those sides meets t' and (2) t's centroid
  /// lies in t' and inside a good face's projection, t' (convex, off R's boundary) lies inside R,
  /// and every point of t, within margin / sin(a / 2) of t' (a: t's smallest angle), is within that
  /// plus the largest height of the good faces near t of the input. A side lying along one of t's
  /// own sides (a crease of the input under an edge of the new face) does not meet t'. The tests
  /// lean towards "meets" and "outside" by round-off: a refusal only sends t to the test by
  /// parts. `h2` receives the square of the bound found. With `part` (a part of a new face cut by
  /// covered(), t its triangle), the gathering starts from the pieces of its list.
  bool covered_by_projection(const Tri& t, double& h2, const Part* part = nullptr) {
    using P2 = std::array<double, 2>;
    const Plane_view pv(t);
    if (!pv.valid) return false;
    if (!part) ++projection_tests_;         // (new faces whole only)
    const std::array<P2, 3>& tri = pv.tri;  // t in its plane: (0, 0), (|ab|, 0), the third above
    const std::array<double, 3>& lengths = pv.lengths;
    const double margin = pv.margin, lab = tri[1][0];
    const P2& C = tri[2];
    const double box_lo[2] = {(std::min)(0., C[0]) - margin, -margin},
                 box_hi[2] = {(std::max)(lab, C[0]) + margin, C[1] + margin};
    // marks of this test (above every mark of an earlier one): evaluated and not good; good, its
    // projection off t's box; good, within reach (its sides are looked at)
    if (stamp_ > 0xfffffff0u) {  // (before the marks wrap around)
      std::fill(seen_.begin(), seen_.end(), 0u);
      stamp_ = 0;
    }
    const std::uint32_t bad = ++stamp_, good_off = ++stamp_, good_near = ++stamp_;
    double worst = 0.;
    std::array<P2, 3> q;
    // evaluates input face f once: its mark, and its projected corners in q when it is near
    auto evaluate = [&](std::uint32_t f) {
      const Input_face& in = input_[f];
      double hmax = 0.;
      for (int k = 0; k < 3; ++k) q[std::size_t(k)] = pv.project(in.corner[k], hmax);
      if (!(hmax <= e_test_) || !Plane_view::faces_its_way(q)) return seen_[f] = bad;
      for (int a = 0; a < 2; ++a) {
        const double lo = (std::min)({q[0][std::size_t(a)], q[1][std::size_t(a)], q[2][std::size_t(a)]});
        const double hi = (std::max)({q[0][std::size_t(a)], q[1][std::size_t(a)], q[2][std::size_t(a)]});
        if (hi < box_lo[a] || lo > box_hi[a]) return seen_[f] = good_off;
      }
      worst = (std::max)(worst, hmax * hmax);
      faces_.push_back(f);
      proj_.push_back(q);
      return seen_[f] = good_near;
    };
    faces_.clear();
    proj_.clear();
    auto seed = [&](std::uint32_t i) {
      const std::uint32_t f = pieces_[i].origin;
      if (f != nil && seen_[f] < bad) evaluate(f);
    };
    if (part)
      for (std::size_t k = part->begin; k < part->end; ++k) seed(near_[k].piece);
    else
      for (std::uint32_t i : cand_) seed(i);
    if (faces_.empty()) return false;
    // (1) across the sides of the good faces within reach: more such faces, or a side of R's
    // boundary, which must not meet t' (the sides of good faces off t's box cannot)
    for (std::size_t j = 0; j < faces_.size(); ++j) {
      const std::uint32_t f = faces_[j];
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t g = input_[f].across[k];
        const std::uint32_t mark = g == nil ? bad : seen_[g] >= bad ? seen_[g] : evaluate(g);
        if (faces_.size() > options_.max_work) return false;  // (the gathering's budget)
        if (mark != bad) continue;
        if (segment_meets_triangle(proj_[j][std::size_t(k)], proj_[j][std::size_t((k + 1) % 3)], tri, lengths, margin))
          return false;
      }
    }
    // (2) the centroid inside t', and inside a good face's projection by the margin; every point
    // of t lies within margin / sin(a / 2) of t', a its smallest angle
    if (!pv.centroid_inside()) return false;
    const double reach = std::sqrt(worst) + pv.shrink_reach();
    if (!(reach <= e_test_)) return false;
    for (const auto& p : proj_) {
      if (pv.holds(p, pv.m)) {
        h2 = reach * reach;
        if (!part) ++projected_;
        return true;
      }
    }
    return false;
  }

  /// Twice the signed area of triangle (p, q, r) in the plane.
  static double orient(const std::array<double, 2>& p, const std::array<double, 2>& q, const std::array<double, 2>& r) {
    return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
  }

  static double squared_distance_2(const std::array<double, 2>& p, const std::array<double, 2>& q) {
    return (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]);
  }

  /// Whether segment pq may meet t', triangle `tri` (counterclockwise, side k from corner k to
  /// corner k + 1 of length lengths[k]) with its sides moved inwards by `margin`: false only when
  /// pq lies wholly less than margin / 2 inside the line of a side of `tri` (outside t' by more
  /// than the round-off, and so a side lying along one of t's sides does not meet t'), or when
  /// pq's line leaves the three corners of `tri` on one side by more than the margin.
  static bool segment_meets_triangle(const std::array<double, 2>& p, const std::array<double, 2>& q,
                                     const std::array<std::array<double, 2>, 3>& tri,
                                     const std::array<double, 3>& lengths, double margin) {
    for (std::size_t k = 0; k < 3; ++k) {  // the segment wholly outside t' across one side
      const double lim = 0.5 * margin * lengths[k];
      const auto& s0 = tri[k];
      const auto& s1 = tri[(k + 1) % 3];
      if (orient(s0, s1, p) < lim && orient(s0, s1, q) < lim) return false;
    }
    const double len = std::sqrt(squared_distance_2(p, q));
    if (!(len > 0.)) return true;  // (a point side: taken as meeting)
    const double oa = orient(p, q, tri[0]), ob = orient(p, q, tri[1]), oc = orient(p, q, tri[2]);
    const double lim = margin * len;
    if ((oa > lim && ob > lim && oc > lim) || (oa < -lim && ob < -lim && oc < -lim)) return false;
    return true;
  }

  /// Finds a home within E for triangle `t` (piece `i` or a part of it), cutting it if needed.
  bool place(std::uint32_t i, const Tri& t, std::size_t hint, int depth, bool whole, double& worst) {
    const std::size_t n = homes_.size();
    for (std::size_t s = 0; s < n; ++s) {
      const std::size_t k = s == 0 ? hint : (s == hint ? 0 : s);
      const Tri& h = home_tri(k);
      if (apart(t, h)) continue;
      work_ += 3;  // (the budget counts three distances per test, however many corners it measures)
      const double d = corners_dist2(t, h, e2_, {-1., -1., -1.});
      if (d <= e2_) {
        worst = (std::max)(worst, d);
        placed_.push_back(Placed{i, std::uint32_t(k), whole, t});
        return true;
      }
    }
    if (depth >= options_.max_depth || work_ > options_.max_work) return false;
    const V3 ab = 0.5 * (t.a + t.b), bc = 0.5 * (t.b + t.c), ca = 0.5 * (t.c + t.a);
    return place(i, make_tri(t.a, ab, ca), hint, depth + 1, false, worst) &&
           place(i, make_tri(ab, t.b, bc), hint, depth + 1, false, worst) &&
           place(i, make_tri(ca, bc, t.c), hint, depth + 1, false, worst) &&
           place(i, make_tri(ab, bc, ca), hint, depth + 1, false, worst);
  }

  using Near = std::pair<double, std::uint32_t>;  // (squared distance, piece), nil: none
  /// A piece in a part's list, with its bounding sphere: the lists are scanned for every nearest
  /// point, and the spheres, read in list order, spare most of those scans a visit to the
  /// pieces' records (scattered in memory).
  struct Nearby {
    V3 centre;
    double radius;
    std::uint32_t piece;
  };
  /// A new face, or a part of one cut for the new-face test: near_[begin, end) are the pieces
  /// near it, corner[k] the nearest of them to its corner k.
  struct Part {
    Tri t;
    std::size_t begin = 0, end = 0;
    Near corner[3];
  };

  /// The piece of `part`'s list nearest to q, starting from `seed` (a piece tried first); pieces whose
  /// bounding sphere is farther than the best so far are skipped (an exact minimum).
  Near nearest(const V3& q, const Part& part, std::uint32_t seed) {
    double best = std::numeric_limits<double>::infinity();
    std::uint32_t best_i = nil;
    auto consider = [&](std::uint32_t i) {
      ++work_;
      const double d = dist2(q, pieces_[i].t);
      if (d < best) {
        best = d;
        best_i = i;
      }
    };
    if (seed != nil) consider(seed);
    double sb = std::sqrt(best);
    for (std::size_t n = part.begin; n < part.end; ++n) {
      const Nearby& p = near_[n];
      const std::uint32_t i = p.piece;
      if (i == seed) continue;
      // skip when |q - centre| >= radius + sqrt(best): every point of the piece is farther
      const double lim = p.radius + sb;
      if (CM::internal::squared_length(q - p.centre) >= lim * lim) continue;
      const std::uint32_t before = best_i;
      consider(i);
      if (best_i != before) sb = std::sqrt(best);
    }
    return {best, best_i};
  }

  /// Whether every point of every part of parts_ lies within E of a piece of its list (pieces
  /// near it; a piece left out is farther than E from all of the part). Level by level (all
  /// parts, then their cuts), so that a point farther than E is found before fine cuts are
  /// made elsewhere. A part is covered by one of two sufficient conditions: (a) its three
  /// corners lie within E of one piece (the distance to a triangle is convex), tried with the
  /// pieces nearest to the centroid and to each corner; (b) the distance to the input is
  /// 1-Lipschitz, so every point of the part is within d(p) + (its distance from p) for the
  /// centroid or a corner p. Otherwise it is cut in four. A corner, a centroid or a midpoint
  /// farther than E from every piece ends the test at once: no cut can cover that point.
  bool covered(double& worst) {
    for (int depth = 0; !parts_.empty(); ++depth) {
      // the centroids' nearest pieces, and the points found outside (a part covered by projection
      // gets no piece, nil: a part whose centroid has none ends the test here)
      mids_.clear();
      for (std::size_t j = 0; j < parts_.size(); ++j) {
        const Part& p = parts_[j];
        // a cut part is tried by projection first, as its whole face was (covered_by_projection())
        double h2 = 0.;
        if (depth > 0 && covered_by_projection(p.t, h2, &p)) {
          worst = (std::max)(worst, h2);
          mids_.push_back(Near{0., nil});
          continue;
        }
        const Near mid = nearest(p.t.centre, p, p.corner[0].second);
        if (mid.second == nil || mid.first > e2_ || p.corner[0].first > e2_ || p.corner[1].first > e2_ ||
            p.corner[2].first > e2_)
          return false;
        mids_.push_back(mid);
      }
      next_parts_.clear();
      next_near_.clear();
      for (std::size_t j = 0; j < parts_.size(); ++j) {
        const Near& mid = mids_[j];
        if (mid.second == nil) continue;  // (covered by projection)
        const Part& p = parts_[j];
        const Tri& t = p.t;
        const std::uint32_t tried[4] = {mid.second, p.corner[0].second, p.corner[1].second, p.corner[2].second};
        bool done = false;
        for (int k = 0; k < 4 && !done; ++k) {
          if (tried[k] == nil || std::find(tried, tried + k, tried[k]) != tried + k) continue;
          const Tri& q = pieces_[tried[k]].t;
          work_ += 3;
          // (a corner whose nearest piece this is has its distance to it already)
          double known[3];
          for (int c = 0; c < 3; ++c) known[c] = p.corner[c].second == tried[k] ? p.corner[c].first : -1.;
          const double m = corners_dist2(t, q, e2_, known);
          if (m <= e2_) {  // (a)
            worst = (std::max)(worst, m);
            done = true;
          }
        }
        // (a) with the flat patches of those pieces: within E when the corners are within E - slack
        for (int k = 0; k < 4 && !done; ++k) {
          const std::uint32_t pk = tried[k] == nil ? nil : pieces_[tried[k]].patch;
          bool seen = pk == nil;
          for (int l = 0; l < k && !seen; ++l) seen = tried[l] != nil && pieces_[tried[l]].patch == pk;
          if (seen) continue;
          work_ += 3;
          const double m = std::sqrt((std::max)({patch_dist2(t.a, pk), patch_dist2(t.b, pk), patch_dist2(t.c, pk)})) +
                           patches_[pk].slack;
          if (m <= e_test_) {
            worst = (std::max)(worst, m * m);
            done = true;
          }
        }
        if (done) continue;
        double reach = std::sqrt(mid.first) + t.radius;  // (b)
        const V3* pts[3] = {&t.a, &t.b, &t.c};
        for (int k = 0; k < 3; ++k) {
          const double spread = std::sqrt(
              (std::max)({CM::internal::squared_length(t.a - *pts[k]), CM::internal::squared_length(t.b - *pts[k]),
                          CM::internal::squared_length(t.c - *pts[k])}));
          reach = (std::min)(reach, std::sqrt(p.corner[k].first) + spread);
        }
        if (reach <= e_test_) {
          worst = (std::max)(worst, reach * reach);
          continue;
        }
        if (depth >= options_.max_depth || work_ > options_.max_work) return false;
        const V3 ab = 0.5 * (t.a + t.b), bc = 0.5 * (t.b + t.c), ca = 0.5 * (t.c + t.a);
        // the midpoints' nearest pieces, shared by the parts that have them as corners
        const Near n_ab = nearest(ab, p, p.corner[0].second), n_bc = nearest(bc, p, p.corner[1].second),
                   n_ca = nearest(ca, p, p.corner[2].second);
        if (n_ab.first > e2_ || n_bc.first > e2_ || n_ca.first > e2_) return false;
        const Tri cuts[4] = {make_tri(t.a, ab, ca), make_tri(ab, t.b, bc), make_tri(ca, bc, t.c), make_tri(ab, bc, ca)};
        const Near cut_corners[4][3] = {
            {p.corner[0], n_ab, n_ca}, {n_ab, p.corner[1], n_bc}, {n_ca, n_bc, p.corner[2]}, {n_ab, n_bc, n_ca}};
        for (int k = 0; k < 4; ++k) {
          Part c;
          c.t = cuts[k];
          c.begin = next_near_.size();
          for (std::size_t n = p.begin; n < p.end; ++n)
            if (!apart(cuts[k], near_[n].centre, near_[n].radius)) next_near_.push_back(near_[n]);
          c.end = next_near_.size();
          std::copy(cut_corners[k], cut_corners[k] + 3, c.corner);
          next_parts_.push_back(c);
        }
      }
      parts_.swap(next_parts_);
      near_.swap(next_near_);
    }
    return true;
  }

  /// Applies the last accepted test: the pieces of olds_ move to their homes (cut ones replaced).
  /// An input face whose pieces all moved, and all to one home, becomes one piece again (its
  /// triangle as the constructor made it): every point of it lies in one of those pieces, each
  /// within E of that home, so it is within E of it too (its corners are corners of the pieces,
  /// and the distance to a triangle is convex). Without this an input face cut once stays in
  /// parts for the rest of the run, and every later change that moves it moves each part.
  void commit() {
    plan_.valid = false;
    for (face_descriptor f : olds_) head_[std::size_t(f)] = nil;
    // the input faces whose pieces all go to one home
    touched_.clear();
    for (const Placed& p : placed_) {
      const std::uint32_t o = pieces_[p.piece].origin;
      Merge& m = merge_[o];
      if (m.entries == 0) {
        touched_.push_back(o);
        m.home = p.home;
      }
      m.mixed = m.mixed || p.home != m.home;
      ++m.entries;
      if (p.piece != m.last) {  // (the parts of one moving piece are consecutive in placed_)
        ++m.moving;
        m.last = p.piece;
      }
    }
    for (const std::uint32_t o : touched_) {
      Merge& m = merge_[o];
      m.whole = !m.mixed && m.entries > 1 && m.moving == fragments_[o];
      m.last = nil;
    }
    // a cut piece's record is reused for its first part; the other parts get free records
    std::uint32_t last_cut = nil;
    for (const Placed& p : placed_) {
      const std::uint32_t o = pieces_[p.piece].origin;
      Merge& m = merge_[o];
      std::uint32_t r = p.piece;
      if (m.whole) {
        if (m.kept != nil) {
          if (p.piece != m.kept && p.piece != m.last) {  // (each other moving piece's record once)
            m.last = p.piece;
            free_.push_back(p.piece);
            --live_pieces_;
          }
          continue;
        }
        m.kept = p.piece;  // the input face whole, in the first moving piece's record
        ++made_whole_;
        pieces_[r].t = input_tri(input_[o]);
      } else if (!p.whole) {
        if (last_cut == p.piece) {
          if (!free_.empty()) {
            r = free_.back();
            free_.pop_back();
          } else {
            r = std::uint32_t(pieces_.size());
            pieces_.emplace_back();
          }
          ++live_pieces_;
          ++fragments_[o];
        }
        last_cut = p.piece;
        pieces_[r].t = p.t;
        pieces_[r].patch = pieces_[p.piece].patch;
        pieces_[r].origin = pieces_[p.piece].origin;
      }
      std::uint32_t& head = head_[std::size_t(homes_[p.home])];
      pieces_[r].next = head;
      head = r;
    }
    for (const std::uint32_t o : touched_) {
      if (merge_[o].whole) fragments_[o] = 1;
      merge_[o] = Merge();
    }
    bound_ = (std::max)(bound_, std::sqrt(pending_worst_));
    // (a new face tested by parts gets the test's worst: every distance the test found is at most that)
    for (std::size_t j = 0; j < news_.size(); ++j)
      face_bound_[std::size_t(homes_[j])] = new_bound_[j] >= 0. ? new_bound_[j] : std::sqrt(pending_worst_);
  }

  VertexPointMap vpm_;
  Hausdorff_bound_options options_;
  double e_, e_test_ = 0., e2_ = 0., bound_ = 0., pending_worst_ = 0.;
  std::vector<Piece> pieces_;
  std::vector<Patch> patches_;
  std::vector<std::array<double, 2>> corners_;  // the patches' corners
  std::vector<std::uint32_t> head_;             // per face: its first piece, or nil
  std::vector<std::uint32_t> free_;             // records of no piece
  std::vector<std::uint32_t> fragments_;        // per input face: its pieces (1, or the parts it is cut in)
  /// commit()'s count, per input face, of the entries of placed_ that come from it
  struct Merge {
    std::uint32_t home = nil, entries = 0, moving = 0;  // its one home, its parts, its moving pieces
    std::uint32_t last = nil, kept = nil;               // (the moving piece last counted or freed; the record kept)
    bool mixed = false, whole = false;                  // parts in several homes; made whole again
  };
  std::vector<Merge> merge_;
  std::vector<std::uint32_t> touched_;  // the input faces with entries in placed_
  std::size_t live_pieces_ = 0, refused_ = 0, work_ = 0, made_whole_ = 0;
  // the test in progress
  std::vector<face_descriptor> olds_;   // the changed faces, the removed ones first
  std::vector<Tri> news_;               // the new triangles (news_[k] is homes_[k]'s new shape)
  std::vector<face_descriptor> homes_;  // faces that may take pieces: news_'s, then the ring's
  std::vector<Tri> ring_;
  std::size_t ring_begin_ = 0;
  std::vector<Old_face> old_tris_;                              // olds_' triangles as they are before the change
  std::vector<std::array<std::array<double, 2>, 3>> proj_old_;  // their corners in a new face's plane
  std::vector<char> good_old_;      // and whether each faces its way (covered_by_old_faces())
  std::vector<double> face_bound_;  // per face: every point of it lies within this of the input
  std::vector<double> new_bound_;   // per new triangle of the test: its bound (-1: the test's worst)
  std::vector<std::uint32_t> cand_;
  std::vector<Part> parts_, next_parts_;  // the new-face test's parts, level by level
  std::vector<Input_face> input_;         // the input's faces, by face index
  std::vector<std::uint32_t> seen_;       // per input face: the projection test's marks
  std::uint32_t stamp_ = 0;
  std::vector<std::uint32_t> faces_;                        // the projection test's input faces
  std::vector<std::array<std::array<double, 2>, 3>> proj_;  // and their corners in t's plane
  std::size_t projected_ = 0, projection_tests_ = 0, covered_by_old_ = 0;
  std::vector<Nearby> near_, next_near_;  // their lists of nearby pieces
  std::vector<Near> mids_;
  std::vector<Placed> placed_;
  vertex_descriptor flip_b_;
  Plan plan_;
};

/// A model of CGAL's `PlacementFilter` that refuses the collapses a Hausdorff_bound refuses,
/// after `BaseFilter` (e.g. No_normal_flip_filter on CGAL's engine). CMGeom's engine also asks it
/// before each edge flip (allows_flip / flipped). Pair it with Hausdorff_bound_visitor. A null
/// `bound` refuses nothing (one instantiation serves runs with and without a bound).
template <class Bound, class BaseFilter = Identity_filter>
struct Hausdorff_bound_filter {
  Bound* bound;
  BaseFilter base = BaseFilter();

  template <class Profile, class Placement>
  Placement operator()(const Profile& profile, const Placement& placement) const {
    Placement p = base(profile, placement);
    if (!p || !bound) return p;
    const CM::internal::Vec3 x(CGAL::to_double(p->x()), CGAL::to_double(p->y()), CGAL::to_double(p->z()));
    return bound->allows_collapse(profile.surface_mesh(), profile.v0_v1(), x) ? p : Placement();
  }
  template <class TM, class H>
  bool allows_flip(const TM& tm, H h) const {
    return !bound || bound->allows_flip(tm, h);
  }
  template <class TM, class H>
  void flipped(const TM& tm, H h) const {
    if (bound) bound->flipped(tm, h);
  }
};

/// A visitor that tells a Hausdorff_bound about each collapse, then forwards every event to
/// `Visitor` (a model of CGAL's `EdgeCollapseSimplificationVisitor`); with a null `bound`, only
/// forwards.
template <class Bound, class Visitor = Edge_collapse_visitor_base>
struct Hausdorff_bound_visitor : Visitor {
  Bound* bound;
  Hausdorff_bound_visitor(Bound* b, const Visitor& v = Visitor()) : Visitor(v), bound(b) {}
  template <class Profile, class V>
  void OnCollapsed(const Profile& profile, const V& kept) {
    if (bound) bound->collapsed(profile.surface_mesh(), profile.v0_v1(), kept);
    Visitor::OnCollapsed(profile, kept);
  }
};

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_HAUSDORFF_BOUND_H

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
// a depth limit. Conservative: an allowed change is always within E, a refused one may have been.
// Complexity: O(F) set-up; a test O(k m), k pieces near the edge, m pieces a new face is cut in.
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
    if (options.max_depth < 0 || options.max_depth > 16)
      throw std::invalid_argument("Hausdorff_bound: max_depth must be in [0, 16]");
    // the tests compare squared distances computed in double precision against a threshold a
    // millionth below E, so that round-off cannot carry an accepted distance over E
    e_test_ = e_ * (1.0 - 1e-6);
    e2_ = e_test_ * e_test_;
    std::size_t nf = 0;
    for (face_descriptor f : faces(tm)) nf = (std::max)(nf, std::size_t(f) + 1);
    head_.assign(nf, nil);
    for (face_descriptor f : faces(tm)) {
      const halfedge_descriptor h = halfedge(f, tm);
      Piece p;
      p.t = make_tri(point(source(h, tm)), point(target(h, tm)), point(target(next(h, tm), tm)));
      p.next = head_[std::size_t(f)];
      head_[std::size_t(f)] = std::uint32_t(pieces_.size());
      pieces_.push_back(p);
    }
    live_pieces_ = pieces_.size();
  }

  /// E, in the mesh's units.
  double max_error() const { return e_; }
  /// The largest distance any accepted test found (<= E): a bound on the Hausdorff distance
  /// between the current mesh and the input.
  double bound() const { return bound_; }
  /// Number of pieces of the input (the input's faces, and the pieces of those that were cut).
  std::size_t number_of_pieces() const { return live_pieces_; }
  /// Number of collapses and flips refused because they would have broken the bound.
  std::size_t refused() const { return refused_; }

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
    std::uint32_t next = nil;
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
    const V3 g = (1. / 3.) * (a + b + c);
    const double r = std::sqrt((std::max)({CM::internal::squared_length(a - g), CM::internal::squared_length(b - g),
                                           CM::internal::squared_length(c - g)}));
    return Tri{a, b, c, g, r};
  }
  static double dist2(const V3& q, const Tri& t) {
    return CM::internal::squared_length(q - CM::internal::closest_on_triangle(q, t.a, t.b, t.c));
  }
  /// Whether two triangles' bounding spheres are more than E apart (then no point of one is
  /// within E of the other).
  bool apart(const Tri& s, const Tri& t) const {
    const double reach = s.radius + t.radius + e_test_;
    return CM::internal::squared_length(s.centre - t.centre) > reach * reach;
  }

  V3 point(vertex_descriptor v) const {
    const auto& q = get(vpm_, v);
    return V3(CGAL::to_double(q.x()), CGAL::to_double(q.y()), CGAL::to_double(q.z()));
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
  void add_ring(const TriangleMesh& tm) {
    ring_begin_ = homes_.size();
    for (face_descriptor f : olds_)
      for (halfedge_descriptor g : CGAL::halfedges_around_face(halfedge(f, tm), tm)) {
        const halfedge_descriptor og = opposite(g, tm);
        if (is_border(og, tm)) continue;
        const face_descriptor r = face(og, tm);
        if (std::find(olds_.begin(), olds_.end(), r) != olds_.end()) continue;
        if (std::find(homes_.begin() + std::ptrdiff_t(ring_begin_), homes_.end(), r) != homes_.end()) continue;
        homes_.push_back(r);
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
    level_.resize(std::size_t(options_.max_depth) + 1);
    for (const Tri& t : news_) {
      std::vector<std::uint32_t>& first = level_[0];
      first.clear();
      for (std::uint32_t i : cand_)
        if (!apart(t, pieces_[i].t)) first.push_back(i);
      const Near corner[3] = {nearest(t.a, first, nil), nearest(t.b, first, nil), nearest(t.c, first, nil)};
      if (!covered(t, corner, 0, worst)) return false;
    }
    pending_worst_ = worst;
    return true;
  }

  /// Finds a home within E for triangle `t` (piece `i` or a part of it), cutting it if needed.
  bool place(std::uint32_t i, const Tri& t, std::size_t hint, int depth, bool whole, double& worst) {
    const std::size_t n = homes_.size();
    for (std::size_t s = 0; s < n; ++s) {
      const std::size_t k = s == 0 ? hint : (s == hint ? 0 : s);
      const Tri& h = home_tri(k);
      if (apart(t, h)) continue;
      work_ += 3;
      const double d = (std::max)({dist2(t.a, h), dist2(t.b, h), dist2(t.c, h)});
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

  /// The piece of `near` nearest to q, starting from `seed` (a piece tried first); pieces whose
  /// bounding sphere is farther than the best so far are skipped (an exact minimum).
  Near nearest(const V3& q, const std::vector<std::uint32_t>& near, std::uint32_t seed) {
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
    for (std::uint32_t i : near) {
      if (i == seed) continue;
      const Tri& p = pieces_[i].t;
      // skip when |q - centre| >= radius + sqrt(best): every point of the piece is farther
      const double lim = p.radius + sb;
      if (CM::internal::squared_length(q - p.centre) >= lim * lim) continue;
      const std::uint32_t before = best_i;
      consider(i);
      if (best_i != before) sb = std::sqrt(best);
    }
    return {best, best_i};
  }

  /// Whether every point of `t` lies within E of a piece of level_[depth] (pieces near t);
  /// `corner[k]` is the nearest piece to t's corner k. Two sufficient conditions, then a cut in
  /// four: (a) the three corners lie within E of one piece (the distance to a triangle is convex),
  /// tried with the pieces nearest to the centroid and to each corner; (b) the distance to the
  /// input is 1-Lipschitz, so every point of t is within d(p) + (its distance from p) for the
  /// centroid or a corner p.
  bool covered(const Tri& t, const Near (&corner)[3], int depth, double& worst) {
    const std::vector<std::uint32_t>& near = level_[std::size_t(depth)];
    const Near mid = nearest(t.centre, near, corner[0].second);
    if (mid.second == nil) return false;  // no piece near t at all
    const std::uint32_t tried[4] = {mid.second, corner[0].second, corner[1].second, corner[2].second};
    for (int k = 0; k < 4; ++k) {
      if (tried[k] == nil || std::find(tried, tried + k, tried[k]) != tried + k) continue;
      const Tri& p = pieces_[tried[k]].t;
      work_ += 3;
      const double m = (std::max)({dist2(t.a, p), dist2(t.b, p), dist2(t.c, p)});
      if (m <= e2_) {  // (a)
        worst = (std::max)(worst, m);
        return true;
      }
    }
    double reach = std::sqrt(mid.first) + t.radius;  // (b)
    const V3* pts[3] = {&t.a, &t.b, &t.c};
    for (int k = 0; k < 3; ++k) {
      const double spread = std::sqrt(
          (std::max)({CM::internal::squared_length(t.a - *pts[k]), CM::internal::squared_length(t.b - *pts[k]),
                      CM::internal::squared_length(t.c - *pts[k])}));
      reach = (std::min)(reach, std::sqrt(corner[k].first) + spread);
    }
    if (reach <= e_test_) {
      worst = (std::max)(worst, reach * reach);
      return true;
    }
    if (depth >= options_.max_depth || work_ > options_.max_work) return false;
    const V3 ab = 0.5 * (t.a + t.b), bc = 0.5 * (t.b + t.c), ca = 0.5 * (t.c + t.a);
    // the midpoints' nearest pieces, shared by the parts that have them as corners
    const Near n_ab = nearest(ab, near, corner[0].second), n_bc = nearest(bc, near, corner[1].second),
               n_ca = nearest(ca, near, corner[2].second);
    const Tri parts[4] = {make_tri(t.a, ab, ca), make_tri(ab, t.b, bc), make_tri(ca, bc, t.c), make_tri(ab, bc, ca)};
    const Near part_corners[4][3] = {
        {corner[0], n_ab, n_ca}, {n_ab, corner[1], n_bc}, {n_ca, n_bc, corner[2]}, {n_ab, n_bc, n_ca}};
    for (int k = 0; k < 4; ++k) {
      std::vector<std::uint32_t>& sub = level_[std::size_t(depth) + 1];
      sub.clear();
      for (std::uint32_t i : level_[std::size_t(depth)])
        if (!apart(parts[k], pieces_[i].t)) sub.push_back(i);
      if (!covered(parts[k], part_corners[k], depth + 1, worst)) return false;
    }
    return true;
  }

  /// Applies the last accepted test: the pieces of olds_ move to their homes (cut ones replaced).
  void commit() {
    plan_.valid = false;
    for (face_descriptor f : olds_) head_[std::size_t(f)] = nil;
    // a cut piece's record is reused for its first part; the other parts get free records
    std::uint32_t last_cut = nil;
    for (const Placed& p : placed_) {
      std::uint32_t r = p.piece;
      if (!p.whole) {
        if (last_cut == p.piece) {
          if (!free_.empty()) {
            r = free_.back();
            free_.pop_back();
          } else {
            r = std::uint32_t(pieces_.size());
            pieces_.emplace_back();
          }
          ++live_pieces_;
        }
        last_cut = p.piece;
        pieces_[r].t = p.t;
      }
      std::uint32_t& head = head_[std::size_t(homes_[p.home])];
      pieces_[r].next = head;
      head = r;
    }
    bound_ = (std::max)(bound_, std::sqrt(pending_worst_));
  }

  VertexPointMap vpm_;
  Hausdorff_bound_options options_;
  double e_, e_test_ = 0., e2_ = 0., bound_ = 0., pending_worst_ = 0.;
  std::vector<Piece> pieces_;
  std::vector<std::uint32_t> head_;  // per face: its first piece, or nil
  std::vector<std::uint32_t> free_;  // records of no piece
  std::size_t live_pieces_ = 0, refused_ = 0, work_ = 0;
  // the test in progress
  std::vector<face_descriptor> olds_;   // the changed faces, the removed ones first
  std::vector<Tri> news_;               // the new triangles (news_[k] is homes_[k]'s new shape)
  std::vector<face_descriptor> homes_;  // faces that may take pieces: news_'s, then the ring's
  std::vector<Tri> ring_;
  std::size_t ring_begin_ = 0;
  std::vector<std::uint32_t> cand_;
  std::vector<std::vector<std::uint32_t>> level_;
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

// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Surface_memory, Surface_memory_options: a memoryful cost for edge collapses. The input's
// vertices are "points", each attached to one current face and weighted by the area of its input
// star; a collapse is priced by the sum over the points of the faces around the edge of
// area x (distance to the new star)^2, the quadric's own unit, which sees a flattened rim, bump or
// thin part the quadric forgets, plus the other side: the distance from the new vertex to the
// points. It is the thesis' point gathering (§4.3) turned into a cost.
// CMGeom's engine uses it lazily (parameters::surface_memory) behind the quadric cost, and prices
// several collapses at once on all cores (cost() with a Pricing_scratch per thread; a collapse
// that moves hundreds of points finds their new faces on all cores too). A cost, not a bound.
// Complexity: O(V + F) set-up; a cost or an update O(k d).
//
// Manual: doc/Textured_simplification/README.md, "The memoryful cost".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_SURFACE_MEMORY_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_SURFACE_MEMORY_H

#include <CMGeom/Compact_model/internal/Vec3.h>
#include <CMGeom/Textured_simplification/Stop_predicates.h>
#include <CMGeom/Textured_simplification/internal/collapse_checks.h>

#include <CGAL/boost/graph/helpers.h>
#include <CGAL/Iterator_range.h>
#include <CGAL/boost/graph/iterator.h>
#include <CGAL/number_utils.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {

/// Options of Surface_memory::fit_vertices(): the final fit of the simplified mesh's vertices to
/// the points (see there).
struct Surface_fit_options {
  /// Rounds of (re-attach the points, move every vertex once); 0 = no fit.
  int rounds = 3;
  /// A vertex is pulled back towards where it is by this fraction of its star's point area (the
  /// damping of an under-determined vertex, e.g. one whose points all lie near one corner).
  double damping = 0.1;
  /// Weight of the vertex's quadric (the squared distances to the planes of the input faces it
  /// stands for, in the points' unit: area x distance^2), which keeps the vertex on the input's
  /// surface where the points alone would pull it off.
  double quadric_weight = 1.0;
  /// A move that turns a face of the star by more than this (radians) from its normal before the
  /// fit, or makes it degenerate, is not made. In (0, pi].
  double max_turn = 1.0;
  /// The fit is made only when the memory holds at least this many points per face of the mesh
  /// (0: always). With fewer, a vertex's least squares have little more than the points it was
  /// made from and the fit moves it off them (manual, "Fitting the vertices to the points": on the
  /// classic models of the shared data, at 50 % of the faces, about 1 point per face, the fit made
  /// the median Hausdorff and RMS worse; at 25 %, about 2, it traded Hausdorff for RMS; from 15 %,
  /// about 3.3, down it lowers the RMS at an even Hausdorff). Finite, >= 0.
  double min_points_per_face = 3.0;
};

/// Throws std::invalid_argument unless `w` is a valid Surface_memory_options::vertex_gap_weight
/// (finite, >= 0); returns it.
inline double checked_vertex_gap_weight(double w) {
  if (!(w >= 0. && std::isfinite(w)))
    throw std::invalid_argument("Surface_memory_options: vertex_gap_weight must be finite and >= 0");
  return w;
}

/// Options of Surface_memory.
struct Surface_memory_options {
  /// At most this many original points (every k-th vertex of the input, its area counted k
  /// times, when the input has more vertices); 0 = all, the default. A vertex no point stands for
  /// is seen by no distance: on a large scan such a vertex was where the Hausdorff distance came
  /// from (manual, "The memoryful cost").
  std::size_t max_points = 0;
  /// The cost prices collapses once the mesh has at most two faces per point, counting at most
  /// this many points (0 = all of them): the first collapses of a dense mesh are local and the
  /// quadric sees them well, and pricing them would multiply the time on large inputs (the points
  /// are followed down all the same).
  std::size_t pricing_points = 65536;
  /// Weight of the distance from a collapse's new vertex to the points (see Surface_memory::cost());
  /// 0 = the points' distances to the new faces only.
  double vertex_gap_weight = 1.0;
  /// CMGeom's engine prices the collapses the queue gives next on all cores at once (the result
  /// is the same on any number of cores, see Edge_collapse_engine's price_ahead()); off where
  /// the cores are busy already (simplify_mesh()'s parts).
  bool parallel_pricing = true;
  /// The fit of the vertices to the points after the collapses (simplify_mesh() runs it without a
  /// guaranteed error bound).
  Surface_fit_options fit;
};

/// Throws std::invalid_argument unless `o` is valid (rounds >= 0, damping >= 0, quadric_weight >=
/// 0, max_turn in (0, pi], all finite).
inline void check_fit_options(const Surface_fit_options& o) {
  if (o.rounds < 0) throw std::invalid_argument("Surface_fit_options: rounds must be >= 0");
  if (!(o.damping >= 0. && std::isfinite(o.damping)))
    throw std::invalid_argument("Surface_fit_options: damping must be finite and >= 0");
  if (!(o.quadric_weight >= 0. && std::isfinite(o.quadric_weight)))
    throw std::invalid_argument("Surface_fit_options: quadric_weight must be finite and >= 0");
  if (!(o.max_turn > 0. && o.max_turn <= 3.141592653589793))
    throw std::invalid_argument("Surface_fit_options: max_turn must be in (0, pi]");
  if (!(o.min_points_per_face >= 0. && std::isfinite(o.min_points_per_face)))
    throw std::invalid_argument("Surface_fit_options: min_points_per_face must be finite and >= 0");
}

/// Original points attached to the faces of a mesh being simplified (see the file comment).
/// \tparam TriangleMesh `CGAL::Surface_mesh` (face indices must stay valid while faces are
///   removed, as they do until `collect_garbage()`)
/// \tparam VertexPointMap the mesh's point map
template <class TriangleMesh, class VertexPointMap>
class Surface_memory {
  using GT = boost::graph_traits<TriangleMesh>;
  using vertex_descriptor = typename GT::vertex_descriptor;
  using halfedge_descriptor = typename GT::halfedge_descriptor;
  using face_descriptor = typename GT::face_descriptor;
  using V3 = CM::internal::Vec3;
  static constexpr std::uint32_t nil = 0xffffffffu;

public:
  class Pricing_scratch;  // (see below)

  /// Takes the input's vertices (or a subset, see Surface_memory_options) as the original points,
  /// each attached to a face of its star and weighted by its star's area.
  Surface_memory(const TriangleMesh& tm, const VertexPointMap& vpm,
                 const Surface_memory_options& options = Surface_memory_options())
      : vpm_(vpm),
        gap_weight_(checked_vertex_gap_weight(options.vertex_gap_weight)),
        pricing_points_(options.pricing_points),
        parallel_pricing_(options.parallel_pricing) {
    const std::size_t live = set_up(tm);
    const std::size_t cap = options.max_points;
    const std::size_t stride = cap > 0 && live > cap ? (live + cap - 1) / cap : 1;
    items_.reserve(live / stride + 1);
    std::size_t k = 0;
    for (vertex_descriptor v : vertices(tm)) {
      if (k++ % stride != 0) continue;
      Item r;
      r.p = point(v);
      double area = 0.;
      face_descriptor home = GT::null_face();
      for (halfedge_descriptor h : CGAL::halfedges_around_target(v, tm)) {
        if (is_border(h, tm)) continue;
        const V3 a = point(source(h, tm)), b = point(target(next(h, tm), tm));
        area += 0.5 * CM::internal::length(CM::internal::cross(b - r.p, a - r.p));
        if (home == GT::null_face()) home = face(h, tm);
      }
      if (home == GT::null_face()) continue;  // an isolated vertex: no surface to stay close to
      r.area = area * double(stride);
      r.radius = disc_radius(r.area);
      r.next = head_[std::size_t(home)];
      head_[std::size_t(home)] = std::uint32_t(items_.size());
      items_.push_back(r);
    }
  }

  /// Takes the given points instead of the mesh's vertices (of `options`, the weight of the new
  /// vertex's distance to them and the pricing threshold; max_points is not applied): `points` is a range of
  /// (face, point, area) triples, `face` a live face of `tm`, `point` a CM::internal::Vec3, as
  /// for_each_point() gives them (simplify_mesh() gathers the points of the memories of the parts
  /// it simplified separately into one memory of the whole).
  template <class PointRange>
  Surface_memory(const TriangleMesh& tm, const VertexPointMap& vpm, const PointRange& points,
                 const Surface_memory_options& options)
      : vpm_(vpm),
        gap_weight_(checked_vertex_gap_weight(options.vertex_gap_weight)),
        pricing_points_(options.pricing_points),
        parallel_pricing_(options.parallel_pricing) {
    set_up(tm);
    items_.reserve(std::size_t(std::distance(std::begin(points), std::end(points))));
    for (const auto& [f, p, area] : points) add_point(f, p, area);
  }

  /// Number of original points kept.
  std::size_t number_of_points() const { return items_.size(); }

  /// Adds a point attached to the live face `f`; returns its index (the points are numbered in
  /// the order they were added, the constructor's first). Points may be added between collapses:
  /// level_of_detail.h follows the vertices of each level of a chain down to the coarsest one.
  std::uint32_t add_point(face_descriptor f, const V3& p, double area = 0.) {
    const std::uint32_t i = std::uint32_t(items_.size());
    Item r;
    r.p = p;
    r.area = area;
    r.radius = disc_radius(area);
    r.next = head_[std::size_t(f)];
    head_[std::size_t(f)] = i;
    items_.push_back(r);
    return i;
  }

  /// The face each point is attached to, by point index (null_face() for a point a collapse
  /// dropped, which a valid collapse never does).
  std::vector<face_descriptor> faces_of_points() const {
    std::vector<face_descriptor> out(items_.size(), GT::null_face());
    for (std::size_t f = 0; f < head_.size(); ++f)
      for (std::uint32_t i = head_[f]; i != nil; i = items_[i].next)
        out[i] = face_descriptor(typename face_descriptor::size_type(f));
    return out;
  }

  /// Calls `fn(face, point, area)` for every original point, `face` the face it is attached to
  /// (a live face of the mesh, or null_face() for none), `point` a CM::internal::Vec3.
  template <class Fn>
  void for_each_point(Fn fn) const {
    for (std::size_t f = 0; f < head_.size(); ++f)
      for (std::uint32_t i = head_[f]; i != nil; i = items_[i].next)
        fn(face_descriptor(typename face_descriptor::size_type(f)), items_[i].p, items_[i].area);
  }

  /// Whether the engine may call cost() on several threads at once
  /// (Surface_memory_options::parallel_pricing).
  bool parallel_pricing() const { return parallel_pricing_; }

  /// Whether cost() prices collapses yet: once there are at most two faces per point, counting at
  /// most Surface_memory_options::pricing_points points (plus 8, for genus: a closed mesh of genus
  /// g has 2V + 4g - 4 faces), i.e. from the start when every vertex of an input of at most that
  /// many vertices is a point; on a larger input the earlier collapses are local and the quadric
  /// sees them well.
  bool active() const {
    const std::size_t n = pricing_points_ > 0 ? (std::min)(pricing_points_, items_.size()) : items_.size();
    return faces_alive_ <= 2 * n + 8;
  }

  /// The memory cost of collapsing halfedge `h` (v0 -> v1) to `placement`: the sum over the
  /// points of the faces around v0 and v1 of area x squared distance to the new star, plus the
  /// other side: vertex_gap_weight x (area of the new star) / 6 x gap^2, gap the distance from
  /// `placement` to the nearest of those points less the radius of the disc of a third of its
  /// area (the input around a point: its star counts each face three times), when positive. A
  /// vertex placed where no input lies (the quadrics' planes meeting beyond a rim, a hole's edge
  /// or a thin part) is seen by no point's distance to the new faces, which pass near them all; a
  /// sixth is the mean of the square of a distance that falls linearly from the vertex to the far
  /// side of each new face.
  template <class Point>
  double cost(const TriangleMesh& tm, halfedge_descriptor h, const Point& placement) const {
    return cost(tm, h, placement, star_);
  }

  /// The same, with the caller's scratch space: calls with distinct scratches may run at once
  /// (on different threads) as long as nothing changes the mesh or the memory meanwhile.
  template <class Point>
  double cost(const TriangleMesh& tm, halfedge_descriptor h, const Point& placement, Pricing_scratch& s) const {
    if (!active()) return 0.;
    bool any = false;  // most regions of a large input hold no point: nothing to build then
    for (int side = 0; side < 2 && !any; ++side)
      for (halfedge_descriptor g : CGAL::halfedges_around_target(side == 0 ? source(h, tm) : target(h, tm), tm))
        if (!is_border(g, tm) && head_[std::size_t(face(g, tm))] != nil) {
          any = true;
          break;
        }
    if (!any) return 0.;
    star_of_collapse(
        tm, h, V3(CGAL::to_double(placement.x()), CGAL::to_double(placement.y()), CGAL::to_double(placement.z())), s);
    if (s.tris.empty()) return 0.;
    double sum = 0.;
    const V3 x = s.tris.front().a;
    double gap = std::numeric_limits<double>::infinity();  // from x to the nearest point's disc
    for (std::size_t j = 0; j < s.faces.size(); ++j) {
      // a surviving face's own new triangle is the first guess of its points' nearest one
      const std::size_t hint = j < s.removed ? 0 : j - s.removed;
      for (std::uint32_t i = head_[std::size_t(s.faces[j])]; i != nil; i = items_[i].next) {
        const Item& r = items_[i];
        const double d = nearest(s.tris, r.p, hint, floor_sq_).first;
        if (d > floor_sq_) sum += r.area * d;
        gap = (std::min)(gap, CM::internal::length(x - r.p) - double(r.radius));
      }
    }
    if (gap > 0. && std::isfinite(gap) && gap_weight_ > 0.) {
      double area = 0.;
      for (const Tri& t : s.tris) area += 0.5 * CM::internal::length(CM::internal::cross(t.b - t.a, t.c - t.a));
      sum += gap_weight_ * area * gap * gap * (1. / 6.);
    }
    return sum;
  }

  /// Call before the collapse of `h`: detaches the points of the faces around the edge (only of
  /// the two that disappear while the memory is not active yet).
  void before_collapse(const TriangleMesh& tm, halfedge_descriptor h) {
    moving_.clear();
    faces_alive_ -= std::size_t(!is_border(h, tm)) + std::size_t(!is_border(opposite(h, tm), tm));
    if (!active()) {
      for (halfedge_descriptor g : {h, opposite(h, tm)})
        if (!is_border(g, tm)) detach(face(g, tm));
      return;
    }
    for (int side = 0; side < 2; ++side)
      for (halfedge_descriptor g : CGAL::halfedges_around_target(side == 0 ? source(h, tm) : target(h, tm), tm))
        if (!is_border(g, tm)) detach(face(g, tm));
  }

  /// Call after the collapse, `v` the kept vertex at its new place: the detached points join the
  /// nearest face of its star.
  void after_collapse(const TriangleMesh& tm, vertex_descriptor v) {
    if (moving_.empty()) return;
    std::vector<face_descriptor>& star_faces = star_.faces;
    std::vector<Tri>& star_tris = star_.tris;
    star_faces.clear();
    star_tris.clear();
    const V3 x = point(v);
    for (halfedge_descriptor g : CGAL::halfedges_around_target(v, tm)) {
      if (is_border(g, tm)) continue;
      star_faces.push_back(face(g, tm));
      star_tris.push_back(make_tri(x, point(target(next(g, tm), tm)), point(source(g, tm))));
    }
    if (star_faces.empty()) return;  // cannot happen on a valid collapse; the points are dropped
    // a point's first guess: the new triangle of the face it was on (the first for a face the
    // collapse removed)
    auto hint_of = [&](face_descriptor from) {
      const std::size_t k = std::size_t(std::find(star_faces.begin(), star_faces.end(), from) - star_faces.begin());
      return k == star_faces.size() ? std::size_t(0) : k;
    };
    const std::size_t n = moving_.size();
    if (parallel_pricing_ && n >= parallel_attach_points) {
      // many points (late in a long run, faces hold dozens): their nearest faces are found on all
      // cores, then linked in the order of the serial loop below (the same lists)
      nearest_of_moving_.resize(n);
      tbb::this_task_arena::isolate([&] {  // (see Edge_collapse_engine's price_ahead())
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64), [&](const tbb::blocked_range<std::size_t>& r) {
          std::size_t hint = 0;
          face_descriptor hint_face = GT::null_face();
          for (std::size_t k = r.begin(); k != r.end(); ++k) {
            const auto& [i, from] = moving_[k];
            if (from != hint_face) hint = hint_of(hint_face = from);
            nearest_of_moving_[k] = std::uint32_t(nearest(star_tris, items_[i].p, hint).second);
          }
        });
      });
      for (std::size_t k = 0; k < n; ++k) link(moving_[k].first, nearest_of_moving_[k]);
      return;
    }
    std::size_t hint = 0;
    face_descriptor hint_face = GT::null_face();
    for (const auto& [i, from] : moving_) {
      if (from != hint_face) hint = hint_of(hint_face = from);  // (the points come face by face)
      attach(i, hint);
    }
  }

  /// Call before the faces `fs` are removed with no collapse (a whole component pruned, see
  /// parameters::prune_components): their points are dropped (faces_of_points() gives them
  /// null_face()), as the surface they stood for leaves the mesh.
  template <class FaceRange>
  void drop_faces(const FaceRange& fs) {
    for (face_descriptor f : fs) {
      head_[std::size_t(f)] = nil;
      --faces_alive_;
    }
  }

  /// Call after an edge flip, `h` the new edge: the points of its two faces join the nearer one.
  void after_flip(const TriangleMesh& tm, halfedge_descriptor h) {
    moving_.clear();
    std::vector<face_descriptor>& star_faces = star_.faces;
    std::vector<Tri>& star_tris = star_.tris;
    star_faces.clear();
    star_tris.clear();
    for (halfedge_descriptor g : {h, opposite(h, tm)}) {
      if (is_border(g, tm)) continue;
      detach(face(g, tm));
      star_faces.push_back(face(g, tm));
      star_tris.push_back(make_tri(point(source(g, tm)), point(target(g, tm)), point(target(next(g, tm), tm))));
    }
    for (const auto& [i, from] : moving_) attach(i, star_faces.size() > 1 && star_faces[1] == from ? 1 : 0);
    moving_.clear();
  }

  /// Vertex indices per block of the fit's parallel step (fit_vertices(), step 2): large enough
  /// that most vertices of a mesh whose indices follow its surface have their neighbours in their
  /// block, small enough that a mesh of some ten thousand vertices has several.
  static constexpr std::size_t fit_block = 8192;

  /// Fits the vertices of `tm` to the points, after the collapses: a least-squares fit in the
  /// manner of the distance energy of Hoppe et al., "Mesh optimization" (SIGGRAPH 1993). Each of
  /// `options.rounds` rounds (1) re-attaches every point to the nearest face found by walking from
  /// its face to nearer ones (those across its edges and, when its nearest point is a corner, those
  /// around the corner; at most 8 steps), keeping the barycentric coordinates of its nearest point
  /// there (made once before the first round, which then bounds the distances below), then
  /// (2) moves the vertices one after the other (Gauss-Seidel; vertices whose stars are apart move
  /// at once, on all cores, with the same result on any number of them), each to the minimiser of
  ///   sum over the points of its star of area x |point - its nearest point|^2 (coordinates fixed)
  ///   + quadric_weight x quadric_of(v)(x) + damping x (the star's point area) x |x - where v is|^2,
  /// a 3x3 solve; a move that turns a face of the star by more than `max_turn` from its normal
  /// before the fit, or makes it degenerate, or takes a point of the star farther from its face
  /// than the farthest point was from its face before the fit, is not made. So the energy (the
  /// points' part and the quadrics') never grows, and neither does the largest distance from a
  /// point to the mesh. Connectivity is unchanged; the points stay attached (for_each_point() sees
  /// the faces they end on). Returns the number of vertex moves made; O(rounds x (points + vertex
  /// degrees)).
  /// \tparam QuadricOf a callable: `quadric_of(v)` is v's internal::Symmetric_quadric (e.g.
  ///   Area_weighted_quadric_policies::quadric()); one returning a zero quadric fits to points only
  template <class QuadricOf>
  std::size_t fit_vertices(const TriangleMesh& tm, const Surface_fit_options& options, QuadricOf quadric_of) {
    check_fit_options(options);
    if (!fit_applies(tm, options)) return 0;
    std::vector<V3> pos = positions(tm);
    std::vector<std::uint32_t> link = links();
    const std::size_t moves = fit(tm, options, quadric_of, pos, head_, link);
    for (std::size_t i = 0; i < items_.size(); ++i) items_[i].next = link[i];
    using Point = typename boost::property_traits<VertexPointMap>::value_type;
    for (vertex_descriptor v : vertices(tm)) {
      const V3& x = pos[std::size_t(v)];
      const V3 x0 = point(v);
      if (x.x != x0.x || x.y != x0.y || x.z != x0.z) put(vpm_, v, Point(x.x, x.y, x.z));
    }
    return moves;
  }

  /// Whether fit_vertices() and fitted_positions() fit `tm`'s vertices under `options`: rounds
  /// above 0, and at least options.min_points_per_face points per face of `tm` (otherwise they
  /// leave the positions as they are).
  bool fit_applies(const TriangleMesh& tm, const Surface_fit_options& options) const {
    return !items_.empty() && options.rounds > 0 &&
           double(items_.size()) >= options.min_points_per_face * double(internal::live_face_count(tm));
  }

  /// Where fit_vertices() would move the vertices, without moving them and without re-attaching
  /// the points: the memory and `tm` are left as they are, so the collapses can go on (the levels of
  /// a chain, level_of_detail.h, are fitted this way when taken, each as simplify_mesh() fits the
  /// mesh it ends with). The result is indexed by vertex index (std::size_t(v)); entries of
  /// removed vertices are unspecified.
  template <class QuadricOf>
  std::vector<typename boost::property_traits<VertexPointMap>::value_type> fitted_positions(
      const TriangleMesh& tm, const Surface_fit_options& options, QuadricOf quadric_of) const {
    check_fit_options(options);
    std::vector<V3> pos = positions(tm);
    if (fit_applies(tm, options)) {
      std::vector<std::uint32_t> head = head_, link = links();
      fit(tm, options, quadric_of, pos, head, link);
    }
    return as_points(pos);
  }

  /// fitted_positions() to be computed later, on any thread, while the collapses go on: what the
  /// fit reads is copied now (`tm` with its element indices, the vertices' positions and their
  /// quadrics `quadric_of(v)`, the points and which face each lies on), and the callable returned
  /// gives what fitted_positions(tm, options, quadric_of) gives now, bit for bit; it holds no
  /// reference to the memory, `tm` or `quadric_of`, and may be called once. The costs of the copy:
  /// O(tm's elements, removed ones included, + points). Needs a copyable `TriangleMesh`.
  template <class QuadricOf>
  std::function<std::vector<typename boost::property_traits<VertexPointMap>::value_type>()> fitted_positions_later(
      const TriangleMesh& tm, const Surface_fit_options& options, QuadricOf quadric_of) const {
    check_fit_options(options);
    struct State {
      TriangleMesh tm;
      std::vector<V3> pos;
      std::vector<Item> items;
      std::vector<std::uint32_t> head, link;
      std::vector<internal::Symmetric_quadric> quadric;
    };
    auto s = std::make_shared<State>();
    s->pos = positions(tm);
    if (fit_applies(tm, options)) {
      s->tm = tm;
      s->items = items_;
      s->head = head_;
      s->link = links();
      s->quadric.resize(s->pos.size());
      for (vertex_descriptor v : vertices(tm)) s->quadric[std::size_t(v)] = quadric_of(v);
    }
    return [s, options]() {
      if (!s->items.empty())
        fit(
            s->tm, s->items, options, [&](vertex_descriptor v) { return s->quadric[std::size_t(v)]; }, s->pos, s->head,
            s->link);
      return as_points(s->pos);
    };
  }

private:
  struct Item;  // (a point; below)

  /// Each point's successor in its face's list (Item::next), by point index.
  std::vector<std::uint32_t> links() const {
    std::vector<std::uint32_t> link(items_.size());
    for (std::size_t i = 0; i < items_.size(); ++i) link[i] = items_[i].next;
    return link;
  }
  /// `pos` as points of the vertex point map's type.
  static std::vector<typename boost::property_traits<VertexPointMap>::value_type> as_points(
      const std::vector<V3>& pos) {
    std::vector<typename boost::property_traits<VertexPointMap>::value_type> out;
    out.reserve(pos.size());
    for (const V3& x : pos) out.emplace_back(x.x, x.y, x.z);
    return out;
  }

  /// The vertices' positions, indexed by vertex index.
  std::vector<V3> positions(const TriangleMesh& tm) const {
    std::size_t n = 0;
    for (vertex_descriptor v : vertices(tm)) n = (std::max)(n, std::size_t(v) + 1);
    std::vector<V3> pos(n, V3(0., 0., 0.));
    for (vertex_descriptor v : vertices(tm)) pos[std::size_t(v)] = point(v);
    return pos;
  }

  /// fit_vertices()' body, on the positions `pos` (by vertex index) and the per-face lists of the
  /// points `head` and `link` (as head_ and Item::next), which it updates; nothing else changes.
  template <class QuadricOf>
  std::size_t fit(const TriangleMesh& tm, const Surface_fit_options& options, QuadricOf quadric_of,
                  std::vector<V3>& pos, std::vector<std::uint32_t>& head, std::vector<std::uint32_t>& link) const {
    return fit(tm, items_, options, quadric_of, pos, head, link);
  }
  /// (the body, on the points `items`: a copy of items_ for fitted_positions_later())
  ///
  /// The mesh does not change during the fit, and what the steps read of it is laid out once, at
  /// the start: the live faces as rows (corners, faces across the edges, normal before the fit,
  /// and each round the run of their points), numbered in the order a walk of the vertices in index
  /// order first meets them, and each vertex's star as a run of (row, corner) in the order of
  /// halfedges_around_target(). Step 2 then reads rows and runs instead of following the mesh's
  /// halfedges and the points' links, which were most of its time (memory latency); the
  /// arithmetic, and its order, is the same.
  template <class QuadricOf>
  static std::size_t fit(const TriangleMesh& tm, const std::vector<Item>& items, const Surface_fit_options& options,
                         QuadricOf quadric_of, std::vector<V3>& pos, std::vector<std::uint32_t>& head,
                         std::vector<std::uint32_t>& link) {
    const int rounds = options.rounds;
    const double damping = options.damping, mu = options.quadric_weight, max_turn = options.max_turn;
    const std::size_t np = items.size();
    const auto point = [&pos](vertex_descriptor v) -> const V3& { return pos[std::size_t(v)]; };
    struct Row {
      V3 n0;                                    // the face's normal before the fit (not unit)
      std::array<vertex_descriptor, 3> corner;  // in the order of halfedges_around_face(halfedge(f))
      std::array<std::uint32_t, 3> across;      // rows across the edges (nil across a border)
      std::uint32_t first = 0, end = 0;         // the face's points: run[first] to run[end - 1]
      face_descriptor face;
    };
    struct Star_entry {
      std::uint32_t row;
      std::uint32_t k;  // the vertex's corner in the row
    };
    struct Run_point {
      V3 p, w;  // the point and its barycentric coordinates on its face
      double area;
    };
    // rows, in the order the vertex walk meets them
    std::vector<std::uint32_t> row_of(head.size(), nil);
    std::vector<Row> rows;
    std::vector<std::uint32_t> star_first(pos.size() + 1, 0);
    std::vector<Star_entry> star;
    const auto row_of_face = [&](face_descriptor f) {  // (a new row the first time f is met)
      std::uint32_t& r = row_of[std::size_t(f)];
      if (r == nil) {
        r = std::uint32_t(rows.size());
        Row row;
        const halfedge_descriptor g = halfedge(f, tm);
        row.corner = {target(g, tm), target(next(g, tm), tm), source(g, tm)};
        row.face = f;
        rows.push_back(row);
      }
      return r;
    };
    for (vertex_descriptor v : vertices(tm)) {
      for (halfedge_descriptor h : CGAL::halfedges_around_target(v, tm)) {
        if (is_border(h, tm)) continue;
        const std::uint32_t r = row_of_face(face(h, tm));
        const auto& c = rows[r].corner;
        star.push_back({r, c[0] == v ? 0u : (c[1] == v ? 1u : 2u)});
      }
      star_first[std::size_t(v) + 1] = std::uint32_t(star.size());
    }
    for (std::size_t v = 1; v < star_first.size(); ++v) star_first[v] = (std::max)(star_first[v], star_first[v - 1]);
    // (faces no vertex walk meets: none in a valid mesh; numbered after the others all the same)
    for (face_descriptor f : faces(tm)) row_of_face(f);
    const std::size_t nr = rows.size();
    std::vector<std::uint32_t> at(np, nil);  // each point's row
    std::vector<V3> bary(np);
    std::vector<Run_point> run(np);
    const double cos_turn = std::cos(max_turn);
    // each row's neighbours and normal before the fit, and each point's row
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nr, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t j = r.begin(); j != r.end(); ++j) {
        Row& row = rows[j];
        std::size_t k = 0;
        for (halfedge_descriptor g : CGAL::halfedges_around_face(halfedge(row.face, tm), tm))
          row.across[k++] = is_border(opposite(g, tm), tm) ? nil : row_of[std::size_t(face(opposite(g, tm), tm))];
        const auto& c = row.corner;
        const V3 q[3] = {point(c[0]), point(c[1]), point(c[2])};
        row.n0 = CM::internal::cross(q[1] - q[0], q[2] - q[0]);
        for (std::uint32_t i = head[std::size_t(row.face)]; i != nil; i = link[i]) at[i] = std::uint32_t(j);
      }
    });
    // step 1 for point i: the nearest face among its face and the faces next to it, and the
    // coordinates there; repeated from the face found while that is nearer (at most 8 steps), "next
    // to" being the faces across its edges and, when the nearest point of the face is one of its
    // corners, every face around that corner (a point whose nearest face lies across a vertex is
    // otherwise stuck). The collapses leave points on faces of their part of the surface, not
    // always on the nearest one: the kept vertex moves, its star's faces change shape, and the
    // points stay where they were attached. Returns the squared distance to the face found.
    const auto reattach = [&](std::size_t i) -> double {
      const std::uint32_t start = at[i];
      if (start == nil) return 0.;
      double best = std::numeric_limits<double>::infinity();
      const auto consider = [&](std::uint32_t g) {
        const auto& c = rows[g].corner;
        const V3 a = point(c[0]), b = point(c[1]), cc = point(c[2]);
        const V3 w = CM::internal::closest_barycentric_on_triangle(items[i].p, a, b, cc);
        const double d = CM::internal::squared_length(items[i].p - (w.x * a + w.y * b + w.z * cc));
        if (d < best) {
          best = d;
          at[i] = g;
          bary[i] = w;
        }
      };
      consider(start);
      for (int step = 0; step < 8; ++step) {
        const std::uint32_t f = at[i];
        for (const std::uint32_t g : rows[f].across)
          if (g != nil) consider(g);
        if (at[i] == f) {  // no edge neighbour is nearer: the faces around a corner, if nearest there
          const V3& w = bary[i];
          const int k = w.x == 1. ? 0 : (w.y == 1. ? 1 : (w.z == 1. ? 2 : -1));
          if (k < 0) break;
          const vertex_descriptor corner = rows[f].corner[std::size_t(k)];
          for (const Star_entry& e : star_range(star, star_first, corner)) consider(e.row);
          if (at[i] == f) break;
        }
      }
      return best;
    };
    // step 1 for the first round, which also gives the largest squared distance from a point to its
    // face before the fit (a maximum: the same on any number of cores)
    const double worst = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, np, 4096), 0.,
        [&](const tbb::blocked_range<std::size_t>& r, double w) {
          for (std::size_t i = r.begin(); i != r.end(); ++i) w = (std::max)(w, reattach(i));
          return w;
        },
        [](double x, double y) { return (std::max)(x, y); });
    // the move of v (step 2), from its star alone; true when made
    const auto move = [&](vertex_descriptor v) -> bool {
      const V3 x0 = point(v);
      const auto stars = star_range(star, star_first, v);
      double aa = 0., weight = 0.;
      V3 rhs(0., 0., 0.);
      for (const Star_entry& e : stars) {
        const Row& row = rows[e.row];
        if (row.first == row.end) continue;
        const auto& c = row.corner;
        const int k = int(e.k);
        const V3 q[3] = {point(c[0]), point(c[1]), point(c[2])};
        for (std::uint32_t t = row.first; t != row.end; ++t) {
          const Run_point& r = run[t];
          const double w[3] = {r.w.x, r.w.y, r.w.z};
          V3 rest(0., 0., 0.);
          for (int j = 0; j < 3; ++j)
            if (j != k) rest += w[j] * q[j];
          aa += r.area * w[k] * w[k];
          rhs += (r.area * w[k]) * (r.p - rest);
          weight += r.area;
        }
      }
      if (!(aa > 0.)) return false;
      const double lambda = damping * weight;
      internal::Symmetric_quadric q = quadric_of(v);
      q *= mu;
      q.a00 += aa + lambda;
      q.a11 += aa + lambda;
      q.a22 += aa + lambda;
      q.b0 -= rhs.x + lambda * x0.x;
      q.b1 -= rhs.y + lambda * x0.y;
      q.b2 -= rhs.z + lambda * x0.z;
      internal::Vec3 u;
      if (!q.solve(u)) return false;
      const V3 x(u[0], u[1], u[2]);
      // each face of the star: turned by at most max_turn and not degenerate, and none of its
      // points farther from it than the farthest point was from its face before the fit (the
      // star's other corners: a = source(h), b = target(next(h)) for the halfedge h into v)
      bool ok = true;
      for (const Star_entry& e : stars) {
        const Row& row = rows[e.row];
        const auto& c = row.corner;
        const V3 a = point(c[(e.k + 2) % 3]), b = point(c[(e.k + 1) % 3]);
        const V3 n = CM::internal::cross(b - x, a - x);
        const V3& m = row.n0;
        const double nn = CM::internal::squared_length(n), mm = CM::internal::squared_length(m);
        ok = nn > 1e-24 * mm && CM::internal::dot(n, m) > cos_turn * std::sqrt(nn * mm);
        if (!ok) break;
        if (row.first == row.end) continue;
        V3 q[3] = {point(c[0]), point(c[1]), point(c[2])};
        q[e.k] = x;
        for (std::uint32_t t = row.first; t != row.end && ok; ++t) {
          const V3& p = run[t].p;
          const V3& w = run[t].w;
          // the point at its coordinates is at least as far as the face: often enough
          if (CM::internal::squared_length(p - (w.x * q[0] + w.y * q[1] + w.z * q[2])) <= worst) continue;
          ok = CM::internal::squared_length(p - CM::internal::closest_on_triangle(p, q[0], q[1], q[2])) <= worst;
        }
        if (!ok) break;
      }
      if (!ok) return false;
      pos[std::size_t(v)] = x;
      return true;
    };
    // Step 2 is Gauss-Seidel over blocks of fit_block consecutive vertex indices: a vertex whose
    // neighbours are all in its block ("inner") reads and changes only faces whose corners are all
    // there, so the blocks' inner vertices move at once, each block's in index order; the others
    // ("rim") then move one after the other in index order. The same result on any number of cores.
    std::vector<std::vector<vertex_descriptor>> inner;
    std::vector<vertex_descriptor> rim;
    for (vertex_descriptor v : vertices(tm)) {
      const std::size_t b = std::size_t(v) / fit_block;
      bool in = true;
      for (vertex_descriptor w : CGAL::vertices_around_target(v, tm)) in = in && std::size_t(w) / fit_block == b;
      if (!in) {
        rim.push_back(v);
        continue;
      }
      if (inner.size() <= b) inner.resize(b + 1);
      inner[b].push_back(v);
    }
    std::size_t moves = 0;
    for (int round = 0; round < rounds; ++round) {
      // step 1 (made above for the first round: nothing has moved since), each point on its own: on
      // all cores, the same result on any number of them
      if (round > 0)
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, np, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t i = r.begin(); i != r.end(); ++i) reattach(i);
        });
      // each face's list of points (head and link: the fit's output), by increasing index, and
      // the same points in one run per row for step 2
      std::fill(head.begin(), head.end(), nil);
      for (Row& row : rows) row.first = row.end = 0;
      for (std::size_t i = np; i-- > 0;) {
        if (at[i] == nil) continue;
        Row& row = rows[at[i]];
        link[i] = head[std::size_t(row.face)];
        head[std::size_t(row.face)] = std::uint32_t(i);
        ++row.end;
      }
      std::uint32_t next_first = 0;
      for (Row& row : rows) {
        row.first = next_first;
        next_first += row.end;
        row.end = row.first;
      }
      for (std::size_t i = 0; i < np; ++i)
        if (at[i] != nil) run[rows[at[i]].end++] = {items[i].p, bary[i], items[i].area};
      // the inner vertices of the blocks, the blocks at once, then the others in index order
      moves += tbb::parallel_reduce(
          tbb::blocked_range<std::size_t>(0, inner.size(), 1), std::size_t(0),
          [&](const tbb::blocked_range<std::size_t>& r, std::size_t m) {
            for (std::size_t b = r.begin(); b != r.end(); ++b)
              for (vertex_descriptor v : inner[b]) m += move(v) ? 1 : 0;
            return m;
          },
          std::plus<std::size_t>());
      for (vertex_descriptor v : rim) moves += move(v) ? 1 : 0;
    }
    return moves;
  }

  /// The entries of `star` that hold vertex v's star (fit()).
  template <class Entry>
  static CGAL::Iterator_range<const Entry*> star_range(const std::vector<Entry>& star,
                                                       const std::vector<std::uint32_t>& star_first,
                                                       vertex_descriptor v) {
    const Entry* base = star.data();
    return CGAL::make_range(base + star_first[std::size_t(v)], base + star_first[std::size_t(v) + 1]);
  }

  struct Item {
    V3 p;
    double area = 0.;
    std::uint32_t next = nil;
    float radius = 0.f;  // of the disc the point stands for (see cost())
  };

  /// The radius of the disc of a third of `area` (a vertex's star counts each face three times).
  static float disc_radius(double area) { return float(std::sqrt(area * (1. / (3. * 3.141592653589793)))); }

  struct Tri {
    V3 a, b, c, n;  // n: unit normal (zero for a degenerate triangle)
    V3 centre;      // centroid, and radius: the largest distance from it to a corner
    double radius;
  };

public:
  /// Scratch space of cost(): the faces a collapse changes and the new star's triangles.
  class Pricing_scratch {
    friend class Surface_memory;
    std::vector<face_descriptor> faces;
    std::vector<Tri> tris;
    std::size_t removed = 0;
  };

private:
  /// Sizes the per-face lists, counts the faces and sets the distance floor; returns the number
  /// of vertices.
  std::size_t set_up(const TriangleMesh& tm) {
    std::size_t nf = 0;
    for (face_descriptor f : faces(tm)) {
      nf = (std::max)(nf, std::size_t(f) + 1);
      ++faces_alive_;
    }
    head_.assign(nf, nil);
    std::size_t live = 0;
    V3 lo(1e300, 1e300, 1e300), hi(-1e300, -1e300, -1e300);
    for (vertex_descriptor v : vertices(tm)) {
      ++live;
      const V3 p = point(v);
      lo = V3((std::min)(lo.x, p.x), (std::min)(lo.y, p.y), (std::min)(lo.z, p.z));
      hi = V3((std::max)(hi.x, p.x), (std::max)(hi.y, p.y), (std::max)(hi.z, p.z));
    }
    // distances below a millionth of the bounding-box diagonal are round-off, not deviation
    if (live > 0) floor_sq_ = 1e-12 * CM::internal::squared_length(hi - lo);
    return live;
  }

  /// Moves the points of face f to moving_ (with f), leaving f without points.
  void detach(face_descriptor f) {
    std::uint32_t& head = head_[std::size_t(f)];
    for (std::uint32_t i = head; i != nil; i = items_[i].next) moving_.emplace_back(i, f);
    head = nil;
  }

  /// Attaches point i to the face of star_.faces whose triangle in star_.tris is nearest
  /// (star_.tris[hint] first).
  void attach(std::uint32_t i, std::size_t hint) { link(i, nearest(star_.tris, items_[i].p, hint).second); }
  /// Puts point i at the head of the list of star_.faces[k].
  void link(std::uint32_t i, std::size_t k) {
    std::uint32_t& head = head_[std::size_t(star_.faces[k])];
    items_[i].next = head;
    head = i;
  }

  static Tri make_tri(const V3& a, const V3& b, const V3& c) {
    const CM::internal::Centroid_sphere sphere = CM::internal::centroid_sphere(a, b, c);
    return Tri{a, b, c, CM::internal::normalized(CM::internal::cross(b - a, c - a)), sphere.centre, sphere.radius};
  }

  /// (squared distance, index) of the triangle of `tris` nearest to q, starting from tris[hint];
  /// a triangle whose plane, or whose bounding sphere, is already farther than the best so far is
  /// skipped (both are lower bounds of the distance: the result is the exact minimum).
  /// With `enough` >= 0 the search ends at the first triangle within sqrt(enough) (cost() counts
  /// any distance below the floor as zero: which such triangle is nearest does not matter there).
  static std::pair<double, std::size_t> nearest(const std::vector<Tri>& tris, const V3& q, std::size_t hint,
                                                double enough = -1.) {
    auto dist = [&](const Tri& t) {
      return CM::internal::squared_length(q - CM::internal::closest_on_triangle(q, t.a, t.b, t.c));
    };
    double best = dist(tris[hint]);
    std::size_t k_best = hint;
    for (std::size_t k = 0; k < tris.size() && best > enough; ++k) {
      if (k == hint) continue;
      const Tri& t = tris[k];
      const double plane = CM::internal::dot(q - t.a, t.n);
      if (plane * plane >= best) continue;
      const double out = CM::internal::length(q - t.centre) - t.radius;
      if (out > 0 && out * out >= best) continue;
      const double d = dist(t);
      if (d < best) {
        best = d;
        k_best = k;
      }
    }
    return {best, k_best};
  }

  V3 point(vertex_descriptor v) const {
    const auto& q = get(vpm_, v);
    return V3(CGAL::to_double(q.x()), CGAL::to_double(q.y()), CGAL::to_double(q.z()));
  }

  /// s.faces: the faces around v0 or v1, the (up to two) faces of the edge first (s.removed of
  /// them); s.tris: the star of the kept vertex at x, s.tris[k] replacing s.faces[s.removed + k].
  void star_of_collapse(const TriangleMesh& tm, halfedge_descriptor h, const V3& x, Pricing_scratch& s) const {
    s.faces.clear();
    s.tris.clear();
    internal::for_each_face_of_collapse(
        tm, h, [&](face_descriptor f) { s.faces.push_back(f); },
        [&](face_descriptor f, halfedge_descriptor g) {
          s.faces.push_back(f);
          s.tris.push_back(make_tri(x, point(target(next(g, tm), tm)), point(source(g, tm))));
        });
    s.removed = s.faces.size() - s.tris.size();
  }

  VertexPointMap vpm_;
  double gap_weight_ = 1.0;
  std::size_t pricing_points_ = 0;
  bool parallel_pricing_ = true;
  static constexpr std::size_t parallel_attach_points = 256;  // (see after_collapse())
  std::vector<std::uint32_t> nearest_of_moving_;              // after_collapse()'s, on all cores
  double floor_sq_ = 0.;
  std::size_t faces_alive_ = 0;
  std::vector<Item> items_;
  std::vector<std::uint32_t> head_;                                // per face: its first point, or nil
  std::vector<std::pair<std::uint32_t, face_descriptor>> moving_;  // detached points and their former face
  mutable Pricing_scratch star_;  // cost()'s scratch, and after_collapse()'s and after_flip()'s
};

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_SURFACE_MEMORY_H

// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Area_weighted_quadric_policies: the edge-collapse cost and placement of thesis §3.4 (weighted
// quadric error metrics), one object modelling both CGAL's GetCost and GetPlacement as CGAL's
// Garland-Heckbert policies do, so it runs under CGAL::Surface_mesh_simplification::edge_collapse
// and under CMGeom's edge_collapse. Vertex quadrics are area-weighted sums of face quadrics (§3.4),
// border edges adding a boundary quadric; the weight of §3.4.1 is w = (trace(A) - lambda) /
// (trace(A) + lambda); cost and merge follow §3.4.2. Key choices: weights clamped to
// [min_weight, 1] so flat regions never give 0/0; the placement falls back to the segment when A
// is singular; Quadric_merge::sum as an option, and plain Garland-Heckbert (weighted = false)
// sums quadrics. Storage: one 96-byte record per vertex, shared by every copy of the policy.
// Complexity: cost and placement O(1); update_after_collapse() O(deg) at most.
//
// Manual: doc/Textured_simplification/README.md, "Choices where the thesis is silent or ambiguous".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_AREA_WEIGHTED_QUADRIC_POLICIES_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_AREA_WEIGHTED_QUADRIC_POLICIES_H

#include <CMGeom/config.h>
#include <CMGeom/Textured_simplification/internal/Symmetric_quadric.h>
#include <CMGeom/Textured_simplification/internal/collapse_checks.h>

#include <CGAL/Kernel_traits.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/boost/graph/named_params_helper.h>
#include <CGAL/boost/graph/properties.h>
#include <CGAL/tags.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {

/// How the kept vertex's quadric is formed from the two endpoints' quadrics (weighted mode).
enum class Quadric_merge {
  /// (w_i Q_i + w_j Q_j) / (w_i + w_j), thesis §3.4.2.
  weighted_average,
  /// Q_i + Q_j, as Garland-Heckbert; the weights still scale the cost and are recomputed.
  sum
};

/// Options of Area_weighted_quadric_policies.
struct Quadric_options {
  /// true: the thesis' weighted quadrics (§3.4.2); false: plain Garland-Heckbert.
  bool weighted = true;
  /// Lower clamp of the local area distortion weight (flat regions have weight 0); must be in
  /// (0, 1] (the constructor throws std::invalid_argument otherwise).
  double min_weight = 1e-3;
  /// Multiplier of the boundary-preserving quadric of border edges (0 disables it); must be
  /// finite and >= 0.
  double boundary_weight = 100.0;
  /// Merge rule in weighted mode (plain mode always sums).
  Quadric_merge merge = Quadric_merge::weighted_average;
};

/// Cost and placement policies of thesis §3.4 (see the file comment).
/// \tparam TriangleMesh a model of `FaceListGraph` and `HalfedgeListGraph`
/// \tparam GeomTraits a CGAL kernel; its `Point_3` is the placement type
template <class TriangleMesh,
          class GeomTraits = typename CGAL::Kernel_traits<typename boost::property_traits<
              typename boost::property_map<TriangleMesh, CGAL::vertex_point_t>::type>::value_type>::Kernel>
class Area_weighted_quadric_policies {
public:
  using Triangle_mesh = TriangleMesh;
  using Geom_traits = GeomTraits;
  using FT = typename GeomTraits::FT;
  using Point_3 = typename GeomTraits::Point_3;
  using vertex_descriptor = typename boost::graph_traits<TriangleMesh>::vertex_descriptor;
  using halfedge_descriptor = typename boost::graph_traits<TriangleMesh>::halfedge_descriptor;
  using Quadric = internal::Symmetric_quadric;

  using Self = Area_weighted_quadric_policies;
  using Get_cost = Self;
  using Get_placement = Self;
  /// CGAL's engine calls initialize() and update_after_collapse() when this is true.
  using Update_tag = CGAL::Tag_true;
  /// Tells CMGeom's engine that an edge's cost depends only on its two endpoints' data, so only
  /// the edges around the kept vertex need a new cost after a collapse.
  using Cost_depends_on_endpoints_only = CGAL::Tag_true;

  explicit Area_weighted_quadric_policies(TriangleMesh& tm, const Quadric_options& options = Quadric_options())
      : vim_(CGAL::get_initialized_vertex_index_map(tm)),
        data_(std::make_shared<std::vector<Record>>()),
        keep_once_(std::make_shared<bool>(false)),
        options_(options) {
    // Checked here because a bad value does not fail loudly later: min_weight > 1 or NaN is
    // undefined behaviour in std::clamp, min_weight = 0 lets two flat endpoints merge as 0/0.
    if (!(options.min_weight > 0.0 && options.min_weight <= 1.0))
      throw std::invalid_argument("Area_weighted_quadric_policies: min_weight must be in (0, 1], got " +
                                  std::to_string(options.min_weight));
    if (!(options.boundary_weight >= 0.0 && std::isfinite(options.boundary_weight)))
      throw std::invalid_argument("Area_weighted_quadric_policies: boundary_weight must be finite and >= 0, got " +
                                  std::to_string(options.boundary_weight));
    // no records yet: initialize() (or set_vertex_data()) makes them, in the data every copy shares
    // (simplify_mesh() in parts never needs the whole input's, 96 bytes a vertex)
  }

  const Get_cost& get_cost() const { return *this; }
  const Get_placement& get_placement() const { return *this; }
  const Quadric_options& options() const { return options_; }

  /// Unweighted quadric and weight of a vertex (valid after initialize()).
  const Quadric& quadric(vertex_descriptor v) const { return record(v).q; }
  double weight(vertex_descriptor v) const { return record(v).w; }

  /// Asks the processor to start loading v's quadric and weight (a hint for engines that know
  /// which vertices they will evaluate next; no effect on results).
  void prefetch(vertex_descriptor v) const {
#if defined(__GNUC__)
    const char* r = reinterpret_cast<const char*>(&record(v));
    __builtin_prefetch(r);
    __builtin_prefetch(r + sizeof(Record) - 1);
#else
    (void)v;
#endif
  }

  /// True when `other` is this object or a copy of it (same vertex data and options): then its
  /// placement is this object's, and the engine may use cost_at_own_placement().
  bool shares_state_with(const Self& other) const { return data_ == other.data_; }

  /// Sets the quadric and weight of vertex v, for a simplification that continues one done
  /// elsewhere (simplify_mesh() does its first collapses in parts of the mesh, then the rest on
  /// the whole with the parts' quadrics); with keep_vertex_data_once(), the next initialize()
  /// keeps what was set here instead of computing the quadrics from the faces.
  void set_vertex_data(vertex_descriptor v, const Quadric& q, double w) const {
    const std::size_t i = std::size_t(get(vim_, v));
    if (data_->size() <= i) data_->resize(i + 1);
    (*data_)[i].q = q;
    (*data_)[i].w = w;
  }
  /// The next initialize() (only that one) keeps the vertex data set by set_vertex_data().
  void keep_vertex_data_once() const { *keep_once_ = true; }

  /// Recomputes the weight of v from its quadric and its current star (weighted mode; 1 in plain
  /// mode), e.g. after set_vertex_data() for a vertex whose star changed.
  template <class VertexPointMap>
  void recompute_weight(const TriangleMesh& tm, const VertexPointMap& vpm, vertex_descriptor v) const {
    Record& r = record(v);
    r.w = compute_weight(tm, vpm, v, r.q);
  }

  /// The quadric and weight initialize() gives vertex v of tm, from v's star alone: the same
  /// numbers, the faces and border edges being summed in the order of their indices as
  /// initialize() sums them. For a caller that needs a few vertices' data of a large mesh without
  /// the memory of all of them (simplify_mesh() does, for the vertices on the borders of its
  /// parts). TriangleMesh must have index descriptors, as CGAL::Surface_mesh.
  template <class VertexPointMap>
  std::pair<Quadric, double> star_vertex_data(const TriangleMesh& tm, const VertexPointMap& vpm,
                                              vertex_descriptor v) const {
    if (halfedge(v, tm) == boost::graph_traits<TriangleMesh>::null_halfedge()) return {Quadric(), 1.0};  // isolated
    std::vector<halfedge_descriptor> around, borders;  // a face's halfedge(f); the face sides of border edges
    for (halfedge_descriptor h : CGAL::halfedges_around_target(v, tm)) {
      const halfedge_descriptor o = opposite(h, tm);
      if (!is_border(h, tm)) around.push_back(halfedge(face(h, tm), tm));
      if (options_.boundary_weight > 0 && is_border(o, tm) != is_border(h, tm))
        borders.push_back(is_border(o, tm) ? h : o);
    }
    std::sort(around.begin(), around.end(), [&](halfedge_descriptor x, halfedge_descriptor y) {
      return std::size_t(face(x, tm)) < std::size_t(face(y, tm));
    });
    std::sort(borders.begin(), borders.end(),
              [](halfedge_descriptor x, halfedge_descriptor y) { return std::size_t(x) < std::size_t(y); });
    Quadric q;
    internal::Vec3 normal{0, 0, 0};
    for (halfedge_descriptor h : around) {
      const internal::Vec3 a = internal::to_vec3(get(vpm, source(h, tm))),
                           b = internal::to_vec3(get(vpm, target(h, tm))),
                           c = internal::to_vec3(get(vpm, target(next(h, tm), tm)));
      const internal::Vec3 n2 = internal::cross(internal::sub(b, a), internal::sub(c, a));
      normal = internal::add(normal, n2);
      const double len = internal::norm(n2);
      if (len > 0) q += face_plane(n2, len, a);
    }
    for (halfedge_descriptor h : borders)
      if (const auto bq = border_plane(tm, vpm, h)) q += *bq;
    return {q, weight_of(q, normal)};
  }

  /// Builds the vertex quadrics and weights. Called once by the engines before collecting edges.
  template <class VertexPointMap>
  void initialize(const TriangleMesh& tm, const VertexPointMap& vpm, const GeomTraits& = GeomTraits()) const {
    resize(tm);
    if (*keep_once_) {
      *keep_once_ = false;
      return;
    }
    for (vertex_descriptor v : vertices(tm)) record(v) = Record();
    // Weighted mode: the vertex normals (sums of the incident faces' cross products, as
    // compute_weight() forms them) are gathered in the face loop rather than by walking every
    // vertex's star afterwards.
    std::vector<internal::Vec3> normals(options_.weighted ? data_->size() : 0, internal::Vec3{0, 0, 0});
    for (auto f : faces(tm)) {
      const halfedge_descriptor h = halfedge(f, tm);
      const vertex_descriptor va = source(h, tm), vb = target(h, tm), vc = target(next(h, tm), tm);
      const internal::Vec3 a = internal::to_vec3(get(vpm, va)), b = internal::to_vec3(get(vpm, vb)),
                           c = internal::to_vec3(get(vpm, vc));
      const internal::Vec3 n2 = internal::cross(internal::sub(b, a), internal::sub(c, a));
      if (options_.weighted)
        for (vertex_descriptor v : {va, vb, vc}) {
          internal::Vec3& nv = normals[std::size_t(get(vim_, v))];
          nv = internal::add(nv, n2);
        }
      const double len = internal::norm(n2);
      if (!(len > 0)) continue;  // a zero-area face defines no plane and has no area
      const Quadric q = face_plane(n2, len, a);
      for (vertex_descriptor v : {va, vb, vc}) record(v).q += q;
    }
    if (options_.boundary_weight > 0) {
      for (halfedge_descriptor h : halfedges(tm)) {
        if (!is_border(opposite(h, tm), tm) || is_border(h, tm)) continue;
        if (const auto q = border_plane(tm, vpm, h))  // h is the face side of a border edge
          for (vertex_descriptor v : {source(h, tm), target(h, tm)}) record(v).q += *q;
      }
    }
    if (!options_.weighted) return;  // the records' weights are 1
    for (vertex_descriptor v : vertices(tm)) {
      Record& r = record(v);
      r.w = halfedge(v, tm) == boost::graph_traits<TriangleMesh>::null_halfedge()
                ? 1.0  // isolated
                : weight_of(r.q, normals[std::size_t(get(vim_, v))]);
    }
  }

  /// Merges the quadrics of the collapsed edge into `v_kept` (§3.4.2) and recomputes its weight.
  /// Called by the engines right after each collapse, `v_kept` already at its new position.
  template <class Profile>
  void update_after_collapse(const Profile& profile, vertex_descriptor v_kept) const {
    update_after_collapse(profile, v_kept, before_collapse(profile));
  }

  /// The endpoints' record indices, taken before the collapse. CMGeom's engine calls this and
  /// then the overload below: graphs such as Polyhedron_3 with item ids free the removed vertex,
  /// whose index lives in the vertex record. Under CGAL's engine (the overload above) the removed
  /// vertex's index is read after the collapse: fine for Surface_mesh and for graphs whose index
  /// map is not stored in the vertex (e.g. Polyhedron_3 without ids), not for Polyhedron_3 with
  /// item ids.
  struct Collapse_token {
    std::size_t id0, id1;
  };
  template <class Profile>
  Collapse_token before_collapse(const Profile& profile) const {
    return {std::size_t(get(vim_, profile.v0())), std::size_t(get(vim_, profile.v1()))};
  }

  template <class Profile>
  void update_after_collapse(const Profile& profile, vertex_descriptor v_kept, const Collapse_token& t) const {
    Record& kept = merge(v_kept, t);
    kept.w = compute_weight(profile.surface_mesh(), profile.vertex_point_map(), v_kept, kept.q);
  }

  /// As above, with the kept vertex's normal already known: `star_normal` is the sum of the
  /// cross products of the triangles around `v_kept` at its new position (CMGeom's engine has
  /// it from its fold-over test, which visits exactly those triangles; see
  /// internal::collapse_flips_a_face). The weight depends on the normal only through the choice
  /// of the eigenvalue, so a normal summed in another order gives the same weight (but for a
  /// tie between two eigenvectors).
  template <class Profile>
  void update_after_collapse(const Profile&, vertex_descriptor v_kept, const Collapse_token& t,
                             const internal::Vec3& star_normal) const {
    Record& kept = merge(v_kept, t);
    kept.w = weight_of(kept.q, star_normal);
  }

  /// GetPlacement: the minimiser of w0 Q0 + w1 Q1 (singular-safe, see the file comment).
  template <class Profile>
  CMGeom::internal::optional<Point_3> operator()(const Profile& profile) const {
    const Quadric q = edge_quadric(profile.v0(), profile.v1());
    const internal::Vec3 u = q.minimiser_on_edge(internal::to_vec3(profile.p0()), internal::to_vec3(profile.p1()));
    return Point_3(u[0], u[1], u[2]);
  }

  /// GetCost: (w0 Q0 + w1 Q1)(placement); absent placement gives absent cost.
  template <class Profile>
  CMGeom::internal::optional<FT> operator()(const Profile& profile,
                                            const CMGeom::internal::optional<Point_3>& placement) const {
    if (!placement) return CMGeom::internal::optional<FT>();
    const Quadric q = edge_quadric(profile.v0(), profile.v1());
    return FT((std::max)(0.0, q(internal::to_vec3(*placement))));
  }

  /// Cost at this object's own placement, the edge quadric computed once: equal to
  /// (*this)(profile, (*this)(profile)) (CMGeom's engine calls it when the cost and placement
  /// policies share their state, see shares_state_with()).
  template <class Profile>
  CMGeom::internal::optional<FT> cost_at_own_placement(const Profile& profile) const {
    const Quadric q = edge_quadric(profile.v0(), profile.v1());
    const internal::Vec3 u = q.minimiser_on_edge(internal::to_vec3(profile.p0()), internal::to_vec3(profile.p1()));
    return FT((std::max)(0.0, q(u)));
  }

  /// The quadric whose minimum is the collapse cost of edge (v0, v1).
  Quadric edge_quadric(vertex_descriptor v0, vertex_descriptor v1) const {
    const Record& r0 = record(v0);
    const Record& r1 = record(v1);
    return Quadric::combine(r0.q, r0.w, r1.q, r1.w);
  }

private:
  struct alignas(32) Record {
    Quadric q;
    double w = 1.0;
  };
  using Vertex_index_map = typename CGAL::GetInitializedVertexIndexMap<TriangleMesh>::const_type;

  Record& record(vertex_descriptor v) const { return (*data_)[std::size_t(get(vim_, v))]; }
  void resize(const TriangleMesh& tm) const {
    std::size_t n = 0;
    for (vertex_descriptor v : vertices(tm)) n = (std::max)(n, std::size_t(get(vim_, v)) + 1);
    if (data_->size() < n) data_->resize(n);
  }

  /// Stores the merged quadric of the collapsed edge (§3.4.2) in v_kept's record.
  Record& merge(vertex_descriptor v_kept, const Collapse_token& t) const {
    const Record& r0 = (*data_)[t.id0];
    const Record& r1 = (*data_)[t.id1];
    const double w0 = r0.w, w1 = r1.w;
    Quadric q;
    if (options_.weighted && options_.merge == Quadric_merge::weighted_average) {
      q = Quadric::combine(r0.q, w0 / (w0 + w1), r1.q, w1 / (w0 + w1));
    } else {
      q = Quadric::combine(r0.q, 1.0, r1.q, 1.0);
    }
    Record& kept = record(v_kept);
    kept.q = q;
    return kept;
  }

  /// The area-weighted quadric of the plane of a face: n2 its sides' cross product, len its
  /// length (> 0), a a corner.
  static Quadric face_plane(const internal::Vec3& n2, double len, const internal::Vec3& a) {
    const internal::Vec3 n = internal::scale(n2, 1.0 / len);
    return Quadric::plane(n, -internal::dot(n, a), 0.5 * len);
  }

  /// The quadric of border edge h (its face side): the plane through it perpendicular to its
  /// face, weighted by boundary_weight times its squared length; none for a degenerate face.
  template <class VertexPointMap>
  std::optional<Quadric> border_plane(const TriangleMesh& tm, const VertexPointMap& vpm, halfedge_descriptor h) const {
    const internal::Vec3 a = internal::to_vec3(get(vpm, source(h, tm))), b = internal::to_vec3(get(vpm, target(h, tm))),
                         c = internal::to_vec3(get(vpm, target(next(h, tm), tm)));
    const internal::Vec3 e = internal::sub(b, a);
    const internal::Vec3 fn = internal::cross(e, internal::sub(c, a));
    internal::Vec3 m = internal::cross(e, fn);
    const double ml = internal::norm(m);
    if (!(ml > 0)) return std::nullopt;
    m = internal::scale(m, 1.0 / ml);
    return Quadric::plane(m, -internal::dot(m, a), options_.boundary_weight * internal::dot(e, e));
  }

  /// The clamped weight of a vertex with quadric q and (unnormalised) normal n; 1 in plain mode.
  double weight_of(const Quadric& q, const internal::Vec3& n) const {
    if (!options_.weighted) return 1.0;
    return std::clamp(q.area_distortion(n), options_.min_weight, 1.0);
  }

  template <class VertexPointMap>
  double compute_weight(const TriangleMesh& tm, const VertexPointMap& vpm, vertex_descriptor v,
                        const Quadric& q) const {
    if (!options_.weighted) return 1.0;
    if (halfedge(v, tm) == boost::graph_traits<TriangleMesh>::null_halfedge()) return 1.0;  // isolated
    // vertex normal: sum of the (area-weighted) normals of the incident faces
    internal::Vec3 n{0, 0, 0};
    const internal::Vec3 pv = internal::to_vec3(get(vpm, v));
    for (halfedge_descriptor h : CGAL::halfedges_around_target(v, tm)) {
      if (is_border(h, tm)) continue;
      const internal::Vec3 a = internal::to_vec3(get(vpm, source(h, tm)));
      const internal::Vec3 b = internal::to_vec3(get(vpm, target(next(h, tm), tm)));
      n = internal::add(n, internal::cross(internal::sub(b, pv), internal::sub(a, pv)));
    }
    return weight_of(q, n);
  }

  Vertex_index_map vim_;
  std::shared_ptr<std::vector<Record>> data_;
  std::shared_ptr<bool> keep_once_;  // shared, as data_, by the copies the engines make
  Quadric_options options_;
};

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_AREA_WEIGHTED_QUADRIC_POLICIES_H

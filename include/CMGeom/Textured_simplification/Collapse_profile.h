// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Collapse_profile: what CMGeom's edge_collapse hands to cost, placement, filter, stop predicate
// and visitor — the same accessors as CGAL's `Surface_mesh_simplification::Edge_profile`
// (v0, v1, p0, p1, v0_v1, v1_v0, vL, vR, v1_vL, vL_v0, v0_vR, vR_v1, left/right_face_exists,
// is_v0_v1_a_border, is_v1_v0_a_border, surface_mesh, vertex_point_map, geom_traits), so a policy
// written against those (as templates on the profile type) runs under both engines.
//
// Not provided: triangles(), link() and border_edges(). CGAL's profile fills three vectors for
// them on every construction; a profile is built for every cost evaluation, and the quadric
// policies never need them. The endpoints, points and border flags are read at construction, the
// apexes on first use (O(1) either way); the engine loads the apexes before collapsing so the
// profile stays valid after the collapse, as visitors' OnCollapsed expects.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_COLLAPSE_PROFILE_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_COLLAPSE_PROFILE_H

#include <boost/graph/graph_traits.hpp>
#include <boost/property_map/property_map.hpp>

namespace CMGeom {
namespace Textured_simplification {

template <class TriangleMesh, class VertexPointMap, class GeomTraits>
class Collapse_profile {
public:
  using Triangle_mesh = TriangleMesh;
  using TM = TriangleMesh;
  using Vertex_point_map = VertexPointMap;
  using VertexPointMap_ = VertexPointMap;
  using Geom_traits = GeomTraits;
  using FT = typename GeomTraits::FT;
  using Point = typename boost::property_traits<VertexPointMap>::value_type;
  using vertex_descriptor = typename boost::graph_traits<TriangleMesh>::vertex_descriptor;
  using halfedge_descriptor = typename boost::graph_traits<TriangleMesh>::halfedge_descriptor;

  Collapse_profile(halfedge_descriptor h_v0v1, const TriangleMesh& tm, const VertexPointMap& vpm,
                   const GeomTraits& gt)
      : tm_(&tm), vpm_(vpm), gt_(&gt), h_(h_v0v1), o_(opposite(h_v0v1, tm)),
        v0_(source(h_v0v1, tm)), v1_(target(h_v0v1, tm)), p0_(get(vpm, v0_)), p1_(get(vpm, v1_)),
        left_(!is_border(h_, tm)), right_(!is_border(o_, tm)) {}

  /// Reads the apexes and the halfedges of the two incident faces now (they are otherwise read
  /// on first use: cost evaluations rarely need them, and each costs a cache miss). The engine
  /// calls this before collapsing, so the profile stays valid afterwards.
  void load_apexes() const {
    if (apexes_loaded_) return;
    apexes_loaded_ = true;
    if (left_) {
      v1vL_ = next(h_, *tm_);
      vLv0_ = prev(h_, *tm_);
      vL_ = target(v1vL_, *tm_);
    }
    if (right_) {
      v0vR_ = next(o_, *tm_);
      vRv1_ = prev(o_, *tm_);
      vR_ = target(v0vR_, *tm_);
    }
  }

  halfedge_descriptor v0_v1() const { return h_; }
  halfedge_descriptor v1_v0() const { return o_; }
  vertex_descriptor v0() const { return v0_; }
  vertex_descriptor v1() const { return v1_; }
  /// null unless left_face_exists()
  vertex_descriptor vL() const { load_apexes(); return vL_; }
  halfedge_descriptor v1_vL() const { load_apexes(); return v1vL_; }
  halfedge_descriptor vL_v0() const { load_apexes(); return vLv0_; }
  /// null unless right_face_exists()
  vertex_descriptor vR() const { load_apexes(); return vR_; }
  halfedge_descriptor v0_vR() const { load_apexes(); return v0vR_; }
  halfedge_descriptor vR_v1() const { load_apexes(); return vRv1_; }
  const Point& p0() const { return p0_; }
  const Point& p1() const { return p1_; }
  bool left_face_exists() const { return left_; }
  bool right_face_exists() const { return right_; }
  bool is_v0_v1_a_border() const { return !left_; }
  bool is_v1_v0_a_border() const { return !right_; }
  const TriangleMesh& surface_mesh() const { return *tm_; }
  const TriangleMesh& surface() const { return *tm_; }
  const VertexPointMap& vertex_point_map() const { return vpm_; }
  const GeomTraits& geom_traits() const { return *gt_; }

private:
  const TriangleMesh* tm_;
  VertexPointMap vpm_;
  const GeomTraits* gt_;
  halfedge_descriptor h_, o_;
  vertex_descriptor v0_, v1_;
  Point p0_, p1_;
  bool left_, right_;
  mutable bool apexes_loaded_ = false;
  mutable vertex_descriptor vL_ = boost::graph_traits<TriangleMesh>::null_vertex();
  mutable vertex_descriptor vR_ = boost::graph_traits<TriangleMesh>::null_vertex();
  mutable halfedge_descriptor v1vL_ = boost::graph_traits<TriangleMesh>::null_halfedge();
  mutable halfedge_descriptor vLv0_ = boost::graph_traits<TriangleMesh>::null_halfedge();
  mutable halfedge_descriptor v0vR_ = boost::graph_traits<TriangleMesh>::null_halfedge();
  mutable halfedge_descriptor vRv1_ = boost::graph_traits<TriangleMesh>::null_halfedge();
};

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_COLLAPSE_PROFILE_H

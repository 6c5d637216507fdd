// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Collapse_profile: what CMGeom's edge_collapse hands to cost, placement, filter, stop predicate
// and visitor, with the same accessors and types as CGAL's Surface_mesh_simplification::
// Edge_profile, so a policy written against CGAL's EdgeProfile concept (CGAL's Lindstrom-Turk and
// Garland-Heckbert policies included) runs under both engines. Key choice: the endpoints, points
// and border flags are read at construction, the apexes and the vectors of triangles(), link()
// and border_edges() on first use only, since a profile is built for every cost evaluation and the
// quadric policies never need them.
//
// Manual: doc/Textured_simplification/README.md, "Pieces".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_COLLAPSE_PROFILE_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_COLLAPSE_PROFILE_H

#include <boost/graph/graph_traits.hpp>
#include <boost/property_map/property_map.hpp>

#include <algorithm>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {

template <class TriangleMesh, class VPMap, class GeomTraits>
class Collapse_profile {
public:
  using Triangle_mesh = TriangleMesh;
  using TM = TriangleMesh;
  using Vertex_point_map = VPMap;
  using Geom_traits = GeomTraits;
  using FT = typename GeomTraits::FT;
  using Point = typename boost::property_traits<VPMap>::value_type;
  using vertex_descriptor = typename boost::graph_traits<TriangleMesh>::vertex_descriptor;
  using halfedge_descriptor = typename boost::graph_traits<TriangleMesh>::halfedge_descriptor;
  using edge_descriptor = typename boost::graph_traits<TriangleMesh>::edge_descriptor;
  using face_descriptor = typename boost::graph_traits<TriangleMesh>::face_descriptor;
  using VertexPointMap = VPMap;  // the name of CGAL's EdgeProfile concept
  using vertex_descriptor_vector = std::vector<vertex_descriptor>;
  using halfedge_descriptor_vector = std::vector<halfedge_descriptor>;
  struct Triangle {
    Triangle() = default;
    Triangle(vertex_descriptor a, vertex_descriptor b, vertex_descriptor c) : v0(a), v1(b), v2(c) {}
    vertex_descriptor v0, v1, v2;
  };
  using Triangle_vector = std::vector<Triangle>;

  Collapse_profile(halfedge_descriptor h_v0v1, const TriangleMesh& tm, const VertexPointMap& vpm, const GeomTraits& gt)
      : tm_(&tm),
        vpm_(vpm),
        gt_(&gt),
        h_(h_v0v1),
        o_(opposite(h_v0v1, tm)),
        v0_(source(h_v0v1, tm)),
        v1_(target(h_v0v1, tm)),
        p0_(get(vpm, v0_)),
        p1_(get(vpm, v1_)),
        left_(!is_border(h_, tm)),
        right_(!is_border(o_, tm)) {}

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
  vertex_descriptor vL() const {
    load_apexes();
    return vL_;
  }
  halfedge_descriptor v1_vL() const {
    load_apexes();
    return v1vL_;
  }
  halfedge_descriptor vL_v0() const {
    load_apexes();
    return vLv0_;
  }
  /// null unless right_face_exists()
  vertex_descriptor vR() const {
    load_apexes();
    return vR_;
  }
  halfedge_descriptor v0_vR() const {
    load_apexes();
    return v0vR_;
  }
  halfedge_descriptor vR_v1() const {
    load_apexes();
    return vRv1_;
  }
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

  const Triangle_vector& triangles() const {
    load_neighbourhood();
    return triangles_;
  }
  const vertex_descriptor_vector& link() const {
    load_neighbourhood();
    return link_;
  }
  const halfedge_descriptor_vector& border_edges() const {
    load_neighbourhood();
    return border_edges_;
  }

private:
  void load_neighbourhood() const {
    if (neighbourhood_loaded_) return;
    neighbourhood_loaded_ = true;
    load_apexes();
    const TriangleMesh& tm = *tm_;
    if (left_) triangles_.emplace_back(v0_, v1_, vL_);
    if (right_) triangles_.emplace_back(v1_, v0_, vR_);
    auto add_link = [&](vertex_descriptor v) {
      if (v != v0_ && v != v1_ && std::find(link_.begin(), link_.end(), v) == link_.end()) link_.push_back(v);
    };
    for (const vertex_descriptor c : {v0_, v1_}) {
      // Every halfedge pointing to c: its source is a neighbour, its face (when any) an incident face.
      const halfedge_descriptor start = halfedge(c, tm);
      halfedge_descriptor h = start;
      do {
        const halfedge_descriptor o = opposite(h, tm);
        add_link(source(h, tm));
        const bool edge_v0v1 = (h == h_ || h == o_);
        if (!edge_v0v1 || c == v0_) {  // the edge v0v1 once
          if (is_border(h, tm))
            border_edges_.push_back(h);
          else if (is_border(o, tm))
            border_edges_.push_back(o);
        }
        if (!is_border(h, tm)) {  // faces holding both v0 and v1 are the edge's, listed first
          const vertex_descriptor a = source(h, tm), b = target(h, tm), d = target(next(h, tm), tm);
          const vertex_descriptor other = (c == v0_) ? v1_ : v0_;
          if (a != other && d != other) triangles_.emplace_back(a, b, d);
        }
        h = opposite(next(h, tm), tm);
      } while (h != start);
    }
  }

  const TriangleMesh* tm_;
  VertexPointMap vpm_;
  const GeomTraits* gt_;
  halfedge_descriptor h_, o_;
  vertex_descriptor v0_, v1_;
  Point p0_, p1_;
  bool left_, right_;
  mutable bool apexes_loaded_ = false, neighbourhood_loaded_ = false;
  mutable Triangle_vector triangles_;
  mutable vertex_descriptor_vector link_;
  mutable halfedge_descriptor_vector border_edges_;
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

// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Point gathering during simplification (thesis §4.3): Gathered_points and the collapse visitor.
// Every original vertex v_i starts with R_i = {v_i} ∪ 1-ring(v_i); when an edge collapses, the kept
// vertex receives R_i ∪ R_j. Key choice: memory linear in the input, the sets being linked lists
// of V + 2E nodes allocated once, a union an O(1) splice, duplicates removed once at the end. The
// visitor works with CGAL::Surface_mesh_simplification::edge_collapse and with CMGeom's engine.
// Complexity: O(V + E) set-up, O(1) per collapse, O(k log k) to read a set of k entries.
//
// Manual: doc/Compact_model/README.md, "Choices where the thesis is open (and why)".
#ifndef CMGEOM_COMPACT_MODEL_POINT_GATHERING_VISITOR_H
#define CMGEOM_COMPACT_MODEL_POINT_GATHERING_VISITOR_H

#include <CMGeom/Textured_simplification/edge_collapse.h>

#include <CGAL/boost/graph/helpers.h>
#include <CGAL/boost/graph/iterator.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace CMGeom {
namespace CM {

/// The point sets R_i of §4.3, indexed by vertex index (Surface_mesh indices before garbage
/// collection: the ids of the input's vertices).
class Gathered_points {
public:
  static constexpr std::uint32_t nil = 0xffffffffu;

  /// R_i = {v_i} ∪ 1-ring(v_i) for every vertex of `tm` (indices taken from `vim`).
  template <class TriangleMesh, class VertexIndexMap>
  Gathered_points(const TriangleMesh& tm, VertexIndexMap vim) {
    const std::size_t nv = num_vertices(tm);
    head_.assign(nv, nil);
    tail_.assign(nv, nil);
    point_.reserve(nv + 2 * num_edges(tm));
    next_.reserve(nv + 2 * num_edges(tm));
    for (auto v : vertices(tm)) {
      const std::uint32_t i = std::uint32_t(get(vim, v));
      push(i, i);
      for (auto h : CGAL::halfedges_around_target(halfedge(v, tm), tm)) push(i, std::uint32_t(get(vim, source(h, tm))));
    }
  }

  /// R_kept = R_kept ∪ R_removed (splice, O(1)); R_removed becomes empty.
  void merge(std::uint32_t kept, std::uint32_t removed) {
    if (kept == removed || head_[removed] == nil) return;
    if (head_[kept] == nil) {
      head_[kept] = head_[removed];
    } else {
      next_[tail_[kept]] = head_[removed];
    }
    tail_[kept] = tail_[removed];
    head_[removed] = tail_[removed] = nil;
  }

  /// The distinct point ids of R_i, ascending.
  std::vector<std::uint32_t> points_of(std::uint32_t i) const {
    std::vector<std::uint32_t> r;
    for (std::uint32_t n = head_[i]; n != nil; n = next_[n]) r.push_back(point_[n]);
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
    return r;
  }

  /// Number of list nodes (memberships before duplicate removal): V + 2E, constant.
  std::size_t number_of_nodes() const { return point_.size(); }

private:
  void push(std::uint32_t set, std::uint32_t point) {
    const auto n = std::uint32_t(point_.size());
    point_.push_back(point);
    next_.push_back(nil);
    if (head_[set] == nil)
      head_[set] = n;
    else
      next_[tail_[set]] = n;
    tail_[set] = n;
  }
  std::vector<std::uint32_t> point_, next_, head_, tail_;
};

/// Collapse visitor filling a Gathered_points (see the file comment). `VertexIndexMap` maps the
/// simplified mesh's vertices to the indices the Gathered_points was built with.
template <class VertexIndexMap, class Base = Textured_simplification::Edge_collapse_visitor_base>
struct Point_gathering_visitor : Base {
  Gathered_points* points;
  VertexIndexMap vim;
  Point_gathering_visitor(Gathered_points* p, VertexIndexMap m, const Base& base = Base())
      : Base(base), points(p), vim(m) {}

  template <class Profile, class V>
  void OnCollapsed(const Profile& profile, const V& v_kept) const {
    const V removed = (profile.v0() == v_kept) ? profile.v1() : profile.v0();
    points->merge(std::uint32_t(get(vim, v_kept)), std::uint32_t(get(vim, removed)));
    Base::OnCollapsed(profile, v_kept);
  }
};

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_POINT_GATHERING_VISITOR_H

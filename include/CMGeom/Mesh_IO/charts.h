// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Texture charts of a mesh with per-corner UVs (thesis §3.2): two faces sharing an edge belong to
// one chart iff both corners at each end of the edge carry the same UV in the two faces. Seam
// edges are the interior edges where this fails; chart-boundary edges are seams plus mesh-border
// edges. These are the queries the chart constraints of §3.5 are written with.
//
// Generic over any `FaceListGraph` + `HalfedgeListGraph` with a readable halfedge property map
// giving the UV of target(h) in face(h). Complexity: O(1) per edge/vertex query (O(degree) for
// vertex queries), O(F) for compute_chart_ids().
#ifndef CMGEOM_MESH_IO_CHARTS_H
#define CMGEOM_MESH_IO_CHARTS_H

#include <CGAL/boost/graph/helpers.h>
#include <CGAL/boost/graph/iterator.h>

#include <boost/graph/graph_traits.hpp>

#include <cstddef>
#include <vector>

namespace CMGeom {

/// True when `e` is an interior edge whose two faces disagree on the UV of one of its ends.
template <class FaceGraph, class UVMap>
bool is_seam_edge(typename boost::graph_traits<FaceGraph>::edge_descriptor e, const FaceGraph& g, const UVMap& uv) {
  const auto h = halfedge(e, g);
  const auto o = opposite(h, g);
  if (is_border(h, g) || is_border(o, g)) return false;
  // h and o point to opposite ends; the corner of a vertex in a face is the halfedge ending there.
  return get(uv, h) != get(uv, prev(o, g)) || get(uv, o) != get(uv, prev(h, g));
}

/// True for seam edges and mesh-border edges.
template <class FaceGraph, class UVMap>
bool is_chart_boundary_edge(typename boost::graph_traits<FaceGraph>::edge_descriptor e, const FaceGraph& g,
                            const UVMap& uv) {
  return is_border(e, g) || is_seam_edge(e, g, uv);
}

/// Number of chart-boundary edges incident to `v`.
template <class FaceGraph, class UVMap>
std::size_t number_of_chart_boundary_edges(typename boost::graph_traits<FaceGraph>::vertex_descriptor v,
                                           const FaceGraph& g, const UVMap& uv) {
  std::size_t n = 0;
  for (auto h : CGAL::halfedges_around_target(v, g))
    if (is_chart_boundary_edge(edge(h, g), g, uv)) ++n;
  return n;
}

/// Labels each face with its chart id (0, 1, ...; in order of the first face of each chart in
/// `faces(g)`) and returns the number of charts.
template <class FaceGraph, class UVMap, class FaceChartMap>
std::size_t compute_chart_ids(const FaceGraph& g, const UVMap& uv, FaceChartMap chart) {
  using face_descriptor = typename boost::graph_traits<FaceGraph>::face_descriptor;
  for (face_descriptor f : faces(g)) put(chart, f, -1);
  std::size_t n = 0;
  std::vector<face_descriptor> stack;
  for (face_descriptor seed : faces(g)) {
    if (get(chart, seed) >= 0) continue;
    const int id = int(n++);
    put(chart, seed, id);
    stack.push_back(seed);
    while (!stack.empty()) {
      const face_descriptor f = stack.back();
      stack.pop_back();
      for (auto h : CGAL::halfedges_around_face(halfedge(f, g), g)) {
        if (is_border(opposite(h, g), g) || is_seam_edge(edge(h, g), g, uv)) continue;
        const face_descriptor nf = face(opposite(h, g), g);
        if (get(chart, nf) < 0) {
          put(chart, nf, id);
          stack.push_back(nf);
        }
      }
    }
  }
  return n;
}

/// Number of distinct charts among the faces around `v`, given face chart ids.
template <class FaceGraph, class FaceChartMap>
std::size_t number_of_charts_around_vertex(typename boost::graph_traits<FaceGraph>::vertex_descriptor v,
                                           const FaceGraph& g, const FaceChartMap& chart) {
  int seen[16];
  std::size_t n = 0;
  std::vector<int> more;
  for (auto f : CGAL::faces_around_target(halfedge(v, g), g)) {
    if (f == boost::graph_traits<FaceGraph>::null_face()) continue;
    const int c = get(chart, f);
    bool known = false;
    for (std::size_t i = 0; i < n && i < 16; ++i) known |= seen[i] == c;
    for (int m : more) known |= m == c;
    if (known) continue;
    if (n < 16)
      seen[n] = c;
    else
      more.push_back(c);
    ++n;
  }
  return n;
}

}  // namespace CMGeom

#endif  // CMGEOM_MESH_IO_CHARTS_H

// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Internal to simplify_mesh(): cutting a Surface_mesh into 2^k parts (median splits of the face
// centroids, a function of the face count only, so the result does not depend on the number of
// threads) that are simplified at the same time on separate cores, and putting the simplified
// parts back together. A part is built straight from the input's halfedges and is manifold; the
// vertices on a cut are locked, so the parts' borders along the cuts match vertex for vertex at
// the merge, where the locked copies of an input vertex become one vertex again. Sibling parts can
// also be put back together into their group of a coarser level (merge_part_group()): there the
// copies that share a run of that group's faces around their input vertex become one vertex, and
// only those on the group's own cuts stay locked.
//
// Manual: doc/Textured_simplification/README.md, "One call, and large meshes on all cores: `simplify_mesh()`".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_MESH_PARTS_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_MESH_PARTS_H

#include <CGAL/Surface_mesh.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {
namespace internal {

constexpr std::uint32_t no_index = 0xffffffffu;

/// Gives the empty mesh `m` the triangles `corners` (three vertex indices per face, into
/// `points`), whose sides are given: side j of face i, from corner j to corner j + 1, lies on edge
/// `sides[3 i + j]` (< number_of_edges). Every edge must have one side (a border edge) or two of
/// opposite directions, and the faces around every vertex must form one fan (these hold for the
/// parts and merges below by construction). Throws std::logic_error when an edge has no side or
/// more than two, or a border cannot be closed.
template <class Point>
void build_triangle_mesh(CGAL::Surface_mesh<Point>& m, const std::vector<Point>& points,
                         const std::vector<std::uint32_t>& corners, const std::vector<std::uint32_t>& sides,
                         std::size_t number_of_edges) {
  using Mesh = CGAL::Surface_mesh<Point>;
  using V = typename Mesh::Vertex_index;
  using H = typename Mesh::Halfedge_index;
  using F = typename Mesh::Face_index;
  using size_type = typename Mesh::size_type;
  const std::size_t nf = corners.size() / 3;
  m.reserve(size_type(points.size()), size_type(number_of_edges), size_type(nf));
  for (const Point& p : points) m.add_vertex(p);
  for (std::size_t e = 0; e < number_of_edges; ++e) m.add_edge();
  std::vector<std::uint8_t> used(number_of_edges, 0);
  for (std::size_t i = 0; i < nf; ++i) {
    const F f = m.add_face();
    std::array<H, 3> hs;
    for (std::size_t j = 0; j < 3; ++j) {
      const std::size_t e = sides[3 * i + j];
      if (used[e] == 2) throw std::logic_error("build_triangle_mesh: an edge with more than two sides");
      const H h(static_cast<size_type>(2 * e + used[e]++));
      const V v(static_cast<size_type>(corners[3 * i + (j + 1) % 3]));
      m.set_target(h, v);
      m.set_face(h, f);
      m.set_halfedge(v, h);
      hs[j] = h;
    }
    for (std::size_t j = 0; j < 3; ++j) m.set_next(hs[j], hs[(j + 1) % 3]);
    m.set_halfedge(f, hs[0]);
  }
  // the border halfedges: the unused side of one-sided edges, incoming halfedge of their target
  for (std::size_t e = 0; e < number_of_edges; ++e) {
    if (used[e] == 0) throw std::logic_error("build_triangle_mesh: an edge with no side");
    if (used[e] == 2) continue;
    const H h(size_type(2 * e)), b(size_type(2 * e + 1));
    const V s = m.target(m.prev(h));
    m.set_target(b, s);
    m.set_face(b, F());
    m.set_halfedge(s, b);
  }
  // next of a border halfedge b (into v): the border halfedge out of v at the other end of v's fan
  for (std::size_t e = 0; e < number_of_edges; ++e) {
    if (used[e] == 2) continue;
    const H b(size_type(2 * e + 1));
    H x = m.opposite(b);
    for (std::size_t guard = 0;; ++guard) {
      if (guard > m.number_of_halfedges()) throw std::logic_error("build_triangle_mesh: a border that does not close");
      const H y = m.opposite(m.prev(x));
      if (m.is_border(y)) {
        m.set_next(b, y);
        break;
      }
      x = y;
    }
  }
}

/// The most halvings of an input into parts.
constexpr int max_part_levels = 4;

/// A part of a mesh cut for simplification (see the file comment), or the union of two parts
/// put back together along their common cut (a group of a coarser level: merge_part_group()).
template <class Point>
struct Mesh_part {
  CGAL::Surface_mesh<Point> mesh;
  std::vector<std::uint32_t> to_input;  ///< part vertex -> input vertex (for locked vertices)
  std::vector<std::uint8_t> locked;     ///< part vertex on a cut (kept in place)
  /// For a locked vertex, and each coarser level L = 1 .. levels - 1 (entry L - 1): which run of
  /// faces around its input vertex, among the faces of its level-L group, holds its own faces (a
  /// halfedge of the input, the same for every copy in that run: the copies a pairwise merge
  /// glues into one vertex); bit L of `run_cut` is set when that run ends at a face outside the
  /// group (the vertex stays locked in the group).
  std::vector<std::array<std::uint32_t, max_part_levels - 1>> run;
  std::vector<std::uint8_t> run_cut;
  std::size_t input_faces = 0, input_vertices = 0;  ///< of the input, in this part
};

/// The run of faces around the target of `h` that holds face(h), among the faces whose
/// halfedges `in` accepts: a key the same from every halfedge of the run (its first halfedge
/// turning clockwise, or the lowest index when the run closes around the vertex) and whether the
/// run ends at a face `in` refuses (not at the border).
template <class Mesh, class In>
std::pair<std::uint32_t, bool> face_run(const Mesh& m, typename Mesh::Halfedge_index h, In in) {
  using H = typename Mesh::Halfedge_index;
  H x = h;
  std::uint32_t lowest = std::uint32_t(h);
  bool cut = false;
  for (;;) {  // backwards to the run's first halfedge
    const H y = m.opposite(x);
    if (m.is_border(y)) break;
    if (!in(y)) {
      cut = true;
      break;
    }
    x = m.prev(y);
    if (x == h) return {lowest, false};  // closed around the vertex
    lowest = (std::min)(lowest, std::uint32_t(x));
  }
  const H first = x;
  if (!cut)
    for (;;) {  // forwards to its other end
      const H y = m.opposite(m.next(x));
      if (m.is_border(y)) break;
      if (!in(y)) {
        cut = true;
        break;
      }
      x = y;
    }
  return {std::uint32_t(first), cut};
}

/// Labels the live faces of `m` with their part (2^levels parts, median splits along the longest
/// side of the centroids' box); `label` is indexed by face index, `no_index` for removed faces.
/// Returns the faces of each part.
template <class Point>
std::vector<std::vector<std::uint32_t>> split_faces(const CGAL::Surface_mesh<Point>& m, int levels,
                                                    std::vector<std::uint32_t>& label) {
  // left uninitialised (a removed face's is never read): the pages are first touched on all cores
  std::unique_ptr<std::array<double, 3>[]> centre(new std::array<double, 3>[m.num_faces()]);
  std::vector<std::uint32_t> order;
  order.reserve(m.number_of_faces());
  for (auto f : m.faces()) order.push_back(std::uint32_t(f));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 8192),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i < r.end(); ++i) {
                        const typename CGAL::Surface_mesh<Point>::Face_index f(order[i]);
                        std::array<double, 3> c{0, 0, 0};
                        for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) {
                          const Point& p = m.point(v);
                          c[0] += CGAL::to_double(p.x());
                          c[1] += CGAL::to_double(p.y());
                          c[2] += CGAL::to_double(p.z());
                        }
                        centre[order[i]] = c;  // three times the centroid: the order is the same
                      }
                    });
  std::vector<std::pair<std::size_t, std::size_t>> ranges{{0, order.size()}};
  for (int level = 0; level < levels; ++level) {
    std::vector<std::pair<std::size_t, std::size_t>> next(2 * ranges.size());
    // the ranges of a level are disjoint: split at once
    tbb::parallel_for(std::size_t(0), ranges.size(), [&](std::size_t q) {
      const auto [lo, hi] = ranges[q];
      std::array<double, 3> a{1e300, 1e300, 1e300}, b{-1e300, -1e300, -1e300};
      for (std::size_t i = lo; i < hi; ++i)
        for (int k = 0; k < 3; ++k) {
          a[k] = (std::min)(a[k], centre[order[i]][k]);
          b[k] = (std::max)(b[k], centre[order[i]][k]);
        }
      int axis = 0;
      for (int k = 1; k < 3; ++k)
        if (b[k] - a[k] > b[axis] - a[axis]) axis = k;
      const std::size_t mid = lo + (hi - lo) / 2;
      // ties broken by face index: the split is a function of the mesh alone
      std::nth_element(order.begin() + std::ptrdiff_t(lo), order.begin() + std::ptrdiff_t(mid),
                       order.begin() + std::ptrdiff_t(hi), [&](std::uint32_t x, std::uint32_t y) {
                         const double cx = centre[x][axis], cy = centre[y][axis];
                         return cx < cy || (cx == cy && x < y);
                       });
      next[2 * q] = {lo, mid};
      next[2 * q + 1] = {mid, hi};
    });
    ranges.swap(next);
  }
  label.assign(m.num_faces(), no_index);
  tbb::parallel_for(std::size_t(0), ranges.size(), [&](std::size_t k) {  // parts own disjoint labels
    for (std::size_t i = ranges[k].first; i < ranges[k].second; ++i) label[order[i]] = std::uint32_t(k);
  });
  // each part's faces in input order: one scan of the labels per part
  std::vector<std::vector<std::uint32_t>> parts(ranges.size());
  tbb::parallel_for(std::size_t(0), ranges.size(), [&](std::size_t k) {
    parts[k].reserve(ranges[k].second - ranges[k].first);
    for (std::size_t f = 0; f < label.size(); ++f)
      if (label[f] == k) parts[k].push_back(std::uint32_t(f));
  });
  return parts;
}

/// Builds part k of `m` (faces `faces`, labels `label`) of 2^levels parts (`levels` > 0 gives the
/// locked vertices their runs of the coarser levels, for merge_part_group()). `corner_vertex` and
/// `side_edge`, indexed by the input's halfedge index and filled with no_index by the caller, are
/// shared by all parts: part k writes only the entries of halfedges of its own faces, so parts can
/// be built at once.
template <class Point>
Mesh_part<Point> make_part(const CGAL::Surface_mesh<Point>& m, std::uint32_t k, const std::vector<std::uint32_t>& faces,
                           const std::vector<std::uint32_t>& label, std::vector<std::uint32_t>& corner_vertex,
                           std::vector<std::uint32_t>& side_edge, int levels = 0) {
  using Mesh = CGAL::Surface_mesh<Point>;
  using H = typename Mesh::Halfedge_index;
  using F = typename Mesh::Face_index;
  if (levels > max_part_levels) throw std::invalid_argument("make_part: more than max_part_levels levels");
  Mesh_part<Point> part;
  part.input_faces = faces.size();
  std::vector<Point> points;
  auto in_part = [&](H h) { return !m.is_border(h) && label[std::size_t(m.face(h))] == k; };
  // the run of part faces around target(h) that holds face(h) gets one part vertex
  auto add_vertex = [&](H h) {
    const std::uint32_t u = std::uint32_t(points.size());
    const auto v = m.target(h);
    points.push_back(m.point(v));
    part.to_input.push_back(std::uint32_t(v));
    bool cut = false;
    H x = h;
    bool closed = false;
    for (;;) {  // forwards: the next face around v
      corner_vertex[std::size_t(x)] = u;
      const H y = m.opposite(m.next(x));
      if (m.is_border(y)) break;
      if (!in_part(y)) {
        cut = true;
        break;
      }
      if (y == h) {
        closed = true;
        break;
      }
      x = y;
    }
    if (!closed) {
      x = h;
      for (;;) {  // backwards
        const H y = m.opposite(x);
        if (m.is_border(y)) break;
        if (!in_part(y)) {
          cut = true;
          break;
        }
        x = m.prev(y);
        corner_vertex[std::size_t(x)] = u;
      }
    }
    part.locked.push_back(cut ? 1 : 0);
    std::array<std::uint32_t, max_part_levels - 1> run{};
    std::uint8_t run_cut = 0;
    if (cut)
      for (int level = 1; level < levels; ++level) {
        const int shift = levels - level;
        const auto [key, level_cut] = face_run(
            m, h, [&](H y) { return !m.is_border(y) && (label[std::size_t(m.face(y))] >> shift) == (k >> shift); });
        run[std::size_t(level - 1)] = key;
        if (level_cut) run_cut = std::uint8_t(run_cut | (1u << level));
      }
    part.run.push_back(run);
    part.run_cut.push_back(run_cut);
  };
  std::vector<std::uint32_t> corners(3 * faces.size()), sides(3 * faces.size());
  std::uint32_t edges = 0;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const F f(static_cast<typename Mesh::size_type>(faces[i]));
    std::array<H, 3> hs;
    hs[0] = m.halfedge(f);
    hs[1] = m.next(hs[0]);
    hs[2] = m.next(hs[1]);
    for (std::size_t j = 0; j < 3; ++j) {
      const H h = hs[j];
      if (corner_vertex[std::size_t(h)] == no_index) add_vertex(h);
      if (side_edge[std::size_t(h)] == no_index) {
        const H o = m.opposite(h);
        side_edge[std::size_t(h)] =
            in_part(o) && side_edge[std::size_t(o)] != no_index ? side_edge[std::size_t(o)] : edges++;
      }
    }
    for (std::size_t j = 0; j < 3; ++j) {
      corners[3 * i + j] = corner_vertex[std::size_t(hs[(j + 2) % 3])];  // source of side j
      sides[3 * i + j] = side_edge[std::size_t(hs[j])];
    }
  }
  part.input_vertices = points.size();
  build_triangle_mesh(part.mesh, points, corners, sides, edges);
  return part;
}

/// The simplified parts put back together (see the file comment) as one list of triangles for
/// build_triangle_mesh(), with where each part's vertices and faces went.
template <class Point>
struct Merged_parts {
  std::vector<Point> points;
  std::vector<std::uint32_t> corners, sides;
  std::size_t edges = 0;
  std::vector<std::uint32_t> input_vertex;               ///< merged vertex -> input vertex, or no_index
  std::vector<std::vector<std::uint32_t>> vertex, face;  ///< per part: part vertex / face -> merged
};

/// Puts the simplified parts back together. The numbering of vertices, edges and faces is the
/// one a single pass over the parts in order gives (a part's live vertices, then edges, then faces,
/// in index order; a vertex shared by parts numbered where it is first met; the edges along the
/// cuts last, ordered by their end vertices), computed part by part on all cores: each part lists
/// its live elements, one pass over the locked vertices alone finds the part that numbers each
/// shared one, and prefix sums place every part's numbers.
/// The locked vertices are glued by `key(k, u)` (part k's vertex u), in [0, keys): the copies of
/// a vertex have the same key.
template <class Point, class Key>
Merged_parts<Point> merge_parts(const std::vector<const Mesh_part<Point>*>& part_list, std::size_t keys, Key key) {
  using Mesh = CGAL::Surface_mesh<Point>;
  using H = typename Mesh::Halfedge_index;
  using V = typename Mesh::Vertex_index;
  struct Parts {  // parts[k] reads as for a vector of parts
    const std::vector<const Mesh_part<Point>*>& list;
    const Mesh_part<Point>& operator[](std::size_t k) const { return *list[k]; }
  } parts{part_list};
  const std::size_t n = part_list.size();
  Merged_parts<Point> out;
  out.vertex.resize(n);
  out.face.resize(n);
  // each part's live vertices (in order) and which of its locked ones it numbers
  std::vector<std::vector<V>> live(n);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t k) {
    for (auto u : parts[k].mesh.vertices()) live[k].push_back(u);
  });
  std::vector<std::uint32_t> merged_of_input(keys, no_index);  // by key
  std::vector<std::vector<std::uint8_t>> numbers(n);           // per live vertex: 1 if this part numbers it
  std::vector<std::size_t> vertex_start(n + 1, 0);
  for (std::size_t k = 0; k < n; ++k) {
    numbers[k].assign(live[k].size(), 1);
    for (std::size_t i = 0; i < live[k].size(); ++i) {
      const std::size_t u = std::size_t(live[k][i]);
      if (!parts[k].locked[u]) continue;
      std::uint32_t& owner = merged_of_input[key(k, u)];
      if (owner == no_index)
        owner = 0;  // met: numbered here (the number is set below)
      else
        numbers[k][i] = 0;
    }
    vertex_start[k + 1] =
        vertex_start[k] + std::size_t(std::count(numbers[k].begin(), numbers[k].end(), std::uint8_t(1)));
  }
  out.points.resize(vertex_start[n]);
  out.input_vertex.resize(vertex_start[n]);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t k) {
    const auto& part = parts[k];
    auto& vid = out.vertex[k];
    vid.assign(part.mesh.num_vertices(), no_index);
    std::size_t next = vertex_start[k];
    for (std::size_t i = 0; i < live[k].size(); ++i) {
      if (!numbers[k][i]) continue;
      const V u = live[k][i];
      const bool locked = part.locked[std::size_t(u)] != 0;
      vid[std::size_t(u)] = std::uint32_t(next);
      out.points[next] = part.mesh.point(u);
      out.input_vertex[next] = locked ? part.to_input[std::size_t(u)] : no_index;
      if (locked) merged_of_input[key(k, std::size_t(u))] = std::uint32_t(next);  // its own entry
      ++next;
    }
  });
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t k) {  // the shared vertices numbered elsewhere
    for (std::size_t i = 0; i < live[k].size(); ++i)
      if (!numbers[k][i]) out.vertex[k][std::size_t(live[k][i])] = merged_of_input[key(k, std::size_t(live[k][i]))];
  });
  std::vector<std::vector<V>>().swap(live);
  // edges: a border halfedge a -> b between locked vertices waits for b -> a from another part
  struct Waiting {
    std::uint64_t key;
    std::size_t part;
    std::uint32_t edge;
  };
  std::vector<std::vector<std::uint32_t>> edge_of(n), plain(n);
  std::vector<std::vector<Waiting>> waiting_of(n);
  std::vector<std::vector<std::uint32_t>> live_faces(n);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t k) {
    const auto& pm = parts[k].mesh;
    const auto& vid = out.vertex[k];
    edge_of[k].assign(pm.num_edges(), no_index);
    for (auto e : pm.edges()) {
      H h = pm.halfedge(e);
      if (pm.is_border(h)) h = pm.opposite(h);
      const bool border = pm.is_border(pm.opposite(h));
      const auto s = pm.source(h), t = pm.target(h);
      if (border && parts[k].locked[std::size_t(s)] && parts[k].locked[std::size_t(t)])
        waiting_of[k].push_back(
            {(std::uint64_t(vid[std::size_t(s)]) << 32) | vid[std::size_t(t)], k, std::uint32_t(e)});
      else
        plain[k].push_back(std::uint32_t(e));
    }
    for (auto f : pm.faces()) live_faces[k].push_back(std::uint32_t(f));
  });
  std::vector<std::size_t> edge_start(n + 1, 0), face_start(n + 1, 0);
  for (std::size_t k = 0; k < n; ++k) {
    edge_start[k + 1] = edge_start[k] + plain[k].size();
    face_start[k + 1] = face_start[k] + live_faces[k].size();
  }
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t k) {
    for (std::size_t i = 0; i < plain[k].size(); ++i) edge_of[k][plain[k][i]] = std::uint32_t(edge_start[k] + i);
  });
  out.edges = edge_start[n];
  std::vector<Waiting> waiting;
  for (const auto& w : waiting_of) waiting.insert(waiting.end(), w.begin(), w.end());
  // pair a -> b with b -> a: sort by the unordered pair, then by part
  auto unordered = [](std::uint64_t key) {
    const std::uint64_t a = key >> 32, b = key & 0xffffffffu;
    return a < b ? (a << 32) | b : (b << 32) | a;
  };
  std::sort(waiting.begin(), waiting.end(), [&](const Waiting& x, const Waiting& y) {
    const std::uint64_t ux = unordered(x.key), uy = unordered(y.key);
    return ux < uy || (ux == uy && (x.part < y.part || (x.part == y.part && x.edge < y.edge)));
  });
  for (std::size_t i = 0; i < waiting.size();) {
    std::size_t j = i + 1;
    while (j < waiting.size() && unordered(waiting[j].key) == unordered(waiting[i].key)) ++j;
    if (j - i > 2 || (j - i == 2 && (waiting[i].key == waiting[i + 1].key || waiting[i].part == waiting[i + 1].part)))
      throw std::logic_error("merge_parts: the parts' borders do not match");
    const std::uint32_t id = std::uint32_t(out.edges++);
    for (std::size_t q = i; q < j; ++q) edge_of[waiting[q].part][waiting[q].edge] = id;
    i = j;
  }
  out.corners.resize(3 * face_start[n]);
  out.sides.resize(3 * face_start[n]);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t k) {
    const auto& pm = parts[k].mesh;
    const auto& vid = out.vertex[k];
    out.face[k].assign(pm.num_faces(), no_index);
    for (std::size_t i = 0; i < live_faces[k].size(); ++i) {
      const std::size_t id = face_start[k] + i;
      const typename Mesh::Face_index f(static_cast<typename Mesh::size_type>(live_faces[k][i]));
      out.face[k][std::size_t(f)] = std::uint32_t(id);
      H h = pm.halfedge(f);
      for (std::size_t j = 0; j < 3; ++j, h = pm.next(h)) {
        out.corners[3 * id + j] = vid[std::size_t(pm.source(h))];
        out.sides[3 * id + j] = edge_of[k][std::size_t(pm.edge(h))];
      }
    }
  });
  return out;
}

/// merge_parts() of all the parts, gluing the copies of an input vertex (`input_vertices`: the
/// number of the input's vertex slots).
template <class Point>
Merged_parts<Point> merge_parts(const std::vector<Mesh_part<Point>>& parts, std::size_t input_vertices) {
  std::vector<const Mesh_part<Point>*> list;
  for (const auto& part : parts) list.push_back(&part);
  return merge_parts(list, input_vertices, [&](std::size_t k, std::size_t u) { return parts[k].to_input[u]; });
}

/// merge_parts() of the parts `list` of a finer level into their group of level `level` (>= 1),
/// gluing the copies that share their run of that level (Mesh_part::run).
template <class Point>
Merged_parts<Point> merge_part_group(const std::vector<const Mesh_part<Point>*>& list, int level) {
  std::vector<std::uint32_t> keys;  // the runs, numbered in order
  for (const auto* p : list)
    for (auto u : p->mesh.vertices())
      if (p->locked[std::size_t(u)]) keys.push_back(p->run[std::size_t(u)][std::size_t(level - 1)]);
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return merge_parts(list, keys.size(), [&](std::size_t k, std::size_t u) {
    const std::uint32_t run = list[k]->run[u][std::size_t(level - 1)];
    return std::uint32_t(std::lower_bound(keys.begin(), keys.end(), run) - keys.begin());
  });
}

}  // namespace internal
}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_MESH_PARTS_H

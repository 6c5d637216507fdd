// Measurement of polygon soups: topology (edges, components, boundary loops, manifoldness,
// orientation, genus), degeneracies and UV charts, robust to any input.
#include <CMGeom/Mesh_IO/Polygon_soup.h>

#include "io_internal.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

namespace CMGeom {

std::string Polygon_soup::face_location(std::size_t f) const {
  if (f < face_line.size() && face_line[f] > 0) return source + ":" + std::to_string(face_line[f]);
  return source + " (face " + std::to_string(f) + ")";
}

bool Polygon_soup::face_has_uvs(std::size_t f) const {
  return std::all_of(corner_uv.begin() + face_start[f], corner_uv.begin() + face_start[f + 1],
                     [](std::uint32_t u) { return u != no_index; });
}

bool Polygon_soup::faces_have_uvs() const {
  for (std::size_t f = 0; f < number_of_faces(); ++f)
    if (face_has_uvs(f)) return true;
  return false;
}

namespace {

struct Union_find {
  std::vector<std::uint32_t> parent;
  explicit Union_find(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);  // deterministic roots
  }
};

// One face side of an undirected edge: the corners holding its two endpoints.
struct Edge_entry {
  std::uint32_t lo, hi;  // vertex ids, lo < hi
  std::uint32_t face;
  std::uint32_t corner_lo;  // corner of `lo` in `face`
  std::uint32_t corner_hi;
  bool forward;  // face walks lo -> hi
};

// Every face side of every edge, ordered by (lo, hi, face), sides of one face in face order. A
// counting sort on `lo` (the entries are made face by face, so each bucket is already in face
// order), then an insertion sort on `hi` inside each bucket (a vertex's few edges): linear, where
// a comparison sort of the 3.2 M sides of a 1M-face mesh was a third of reading it.
std::vector<Edge_entry> edge_entries(const Polygon_soup& s) {
  std::size_t nv = s.positions.size();  // (or past the largest vertex id, if a soup has a bad one)
  for (std::uint32_t v : s.corner_vertex) nv = std::max(nv, std::size_t(v) + 1);
  auto for_each_side = [&](auto&& f) {
    for (std::uint32_t face = 0; face < s.number_of_faces(); ++face) {
      const std::uint32_t b = s.face_start[face], n = s.face_start[face + 1] - b;
      for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t ca = b + i, cb = b + (i + 1) % n;
        const std::uint32_t va = s.corner_vertex[ca], vb = s.corner_vertex[cb];
        if (va == vb) continue;  // repeated vertex: no edge
        if (va < vb)
          f(Edge_entry{va, vb, face, ca, cb, true});
        else
          f(Edge_entry{vb, va, face, cb, ca, false});
      }
    }
  };
  std::vector<std::uint32_t> start(nv + 1, 0);
  std::size_t count = 0;
  for_each_side([&](const Edge_entry& x) {
    ++start[x.lo + 1];
    ++count;
  });
  for (std::size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<Edge_entry> e(count);
  {
    std::vector<std::uint32_t> next(start.begin(), start.end() - 1);
    for_each_side([&](const Edge_entry& x) { e[next[x.lo]++] = x; });
  }
  for (std::size_t v = 0; v < nv; ++v)
    for (std::uint32_t i = start[v] + 1; i < start[v + 1]; ++i) {  // stable: faces stay in order
      const Edge_entry x = e[i];
      std::uint32_t j = i;
      for (; j > start[v] && e[j - 1].hi > x.hi; --j) e[j] = e[j - 1];
      e[j] = x;
    }
  return e;
}

template <class F>
void for_each_edge_group(const std::vector<Edge_entry>& e, F&& f) {
  for (std::size_t i = 0; i < e.size();) {
    std::size_t j = i + 1;
    while (j < e.size() && e[j].lo == e[i].lo && e[j].hi == e[i].hi) ++j;
    f(i, j);
    i = j;
  }
}

bool same_uv(const Polygon_soup& s, std::uint32_t c1, std::uint32_t c2) {
  const std::uint32_t a = s.corner_uv[c1], b = s.corner_uv[c2];
  if (a == Polygon_soup::no_index || b == Polygon_soup::no_index) return false;
  return a == b || s.uvs[a] == s.uvs[b];
}

}  // namespace

std::size_t count_soup_charts(const Polygon_soup& s, std::vector<int>* face_chart) {
  const std::size_t nf = s.number_of_faces();
  std::vector<bool> textured(nf, false);
  for (std::size_t f = 0; f < nf; ++f) {
    bool all = true;
    for (std::uint32_t c = s.face_start[f]; c < s.face_start[f + 1]; ++c)
      all &= s.corner_uv[c] != Polygon_soup::no_index;
    textured[f] = all && !s.uvs.empty();
  }
  Union_find uf(nf);
  const std::vector<Edge_entry> e = edge_entries(s);
  for_each_edge_group(e, [&](std::size_t i, std::size_t j) {
    for (std::size_t a = i; a < j; ++a)
      for (std::size_t b = a + 1; b < j; ++b) {
        const Edge_entry &x = e[a], &y = e[b];
        if (!textured[x.face] || !textured[y.face]) continue;
        if (same_uv(s, x.corner_lo, y.corner_lo) && same_uv(s, x.corner_hi, y.corner_hi)) uf.unite(x.face, y.face);
      }
  });
  std::vector<int> id(nf, -1);
  std::unordered_map<std::uint32_t, int> root_id;
  for (std::size_t f = 0; f < nf; ++f) {
    if (!textured[f]) continue;
    auto [it, ins] = root_id.emplace(uf.find(std::uint32_t(f)), int(root_id.size()));
    id[f] = it->second;
  }
  if (face_chart) *face_chart = std::move(id);
  return root_id.size();
}

namespace IO {
namespace internal {

bool is_oriented_manifold_soup(const Polygon_soup& s, std::size_t vertices) {
  const std::vector<std::uint32_t>& face_start = s.face_start;
  const std::vector<std::uint32_t>& corner_vertex = s.corner_vertex;
  for (std::size_t f = 0; f + 1 < face_start.size(); ++f)
    for (std::uint32_t i = face_start[f]; i < face_start[f + 1]; ++i)
      for (std::uint32_t j = i + 1; j < face_start[f + 1]; ++j)
        if (corner_vertex[i] == corner_vertex[j]) return false;  // a repeated vertex
  const std::vector<Edge_entry> e = edge_entries(s);
  Union_find corner_uf(corner_vertex.size());
  bool ok = true;
  for_each_edge_group(e, [&](std::size_t i, std::size_t j) {
    if (j - i > 2 || (j - i == 2 && e[i].forward == e[i + 1].forward)) ok = false;
    if (j - i == 2) {
      corner_uf.unite(e[i].corner_lo, e[i + 1].corner_lo);
      corner_uf.unite(e[i].corner_hi, e[i + 1].corner_hi);
    }
  });
  if (!ok) return false;
  // one fan per vertex: all its corners linked through shared edges
  std::vector<std::uint32_t> first_root(vertices, Polygon_soup::no_index);
  for (std::uint32_t c = 0; c < corner_vertex.size(); ++c) {
    const std::uint32_t v = corner_vertex[c], r = corner_uf.find(c);
    if (first_root[v] == Polygon_soup::no_index)
      first_root[v] = r;
    else if (first_root[v] != r)
      return false;
  }
  return true;
}

}  // namespace internal
}  // namespace IO

Mesh_statistics analyze_soup(const Polygon_soup& s) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  Mesh_statistics st;
  const std::size_t nf = s.number_of_faces();
  st.faces = nf;

  std::vector<bool> used(s.positions.size(), false);
  for (std::uint32_t v : s.corner_vertex) used[v] = true;
  st.vertices = std::size_t(std::count(used.begin(), used.end(), true));
  st.unreferenced_vertices = s.positions.size() - st.vertices;
  for (const auto& p : s.positions)
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) ++st.invalid_coordinates;
  for (const auto& t : s.uvs)
    if (!std::isfinite(t[0]) || !std::isfinite(t[1])) ++st.invalid_coordinates;

  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t b = s.face_start[f], n = s.face_start[f + 1] - b;
    bool degenerate = false;
    for (std::uint32_t i = 0; i < n && !degenerate; ++i)
      for (std::uint32_t j = i + 1; j < n; ++j)
        if (s.corner_vertex[b + i] == s.corner_vertex[b + j]) degenerate = true;
    if (!degenerate) {  // zero area: all corners collinear (exact predicate)
      auto P = [&](std::uint32_t c) {
        const auto& p = s.positions[s.corner_vertex[c]];
        return K::Point_3(p[0], p[1], p[2]);
      };
      degenerate = true;
      for (std::uint32_t i = 2; i < n && degenerate; ++i) degenerate = CGAL::collinear(P(b), P(b + 1), P(b + i));
    }
    if (degenerate) {
      if (st.degenerate_faces == 0) st.first_degenerate_face = f;
      ++st.degenerate_faces;
    }
  }

  const std::vector<Edge_entry> e = edge_entries(s);
  Union_find corner_uf(s.corner_vertex.size());
  // Outgoing boundary halfedges (as seen from the hole): for boundary loops.
  std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> boundary_next;
  for_each_edge_group(e, [&](std::size_t i, std::size_t j) {
    ++st.edges;
    const std::size_t k = j - i;
    for (std::size_t a = i + 1; a < j; ++a) {
      corner_uf.unite(e[i].corner_lo, e[a].corner_lo);
      corner_uf.unite(e[i].corner_hi, e[a].corner_hi);
    }
    if (k == 1) {
      ++st.boundary_edges;
      // the face walks from -> to; the hole's loop walks to -> from
      const std::uint32_t from = e[i].forward ? e[i].lo : e[i].hi;
      const std::uint32_t to = e[i].forward ? e[i].hi : e[i].lo;
      boundary_next[to].push_back(from);
    } else if (k == 2) {
      if (e[i].forward == e[i + 1].forward) ++st.inconsistent_edges;
    } else {
      if (st.non_manifold_edges == 0) st.first_non_manifold_edge_face = e[i].face;
      ++st.non_manifold_edges;
    }
  });

  // A vertex is manifold when all its corners are linked through shared edges into one fan.
  {
    std::vector<std::uint32_t> first_root(s.positions.size(), Polygon_soup::no_index);
    std::vector<bool> nm(s.positions.size(), false);
    for (std::uint32_t c = 0; c < s.corner_vertex.size(); ++c) {
      const std::uint32_t v = s.corner_vertex[c];
      const std::uint32_t r = corner_uf.find(c);
      if (first_root[v] == Polygon_soup::no_index)
        first_root[v] = r;
      else if (first_root[v] != r)
        nm[v] = true;
    }
    for (std::size_t v = 0; v < nm.size(); ++v)
      if (nm[v]) {
        if (st.non_manifold_vertices == 0) st.first_non_manifold_vertex = v;
        ++st.non_manifold_vertices;
      }
  }

  {
    // Connected components of the vertex graph (faces touching at a vertex are connected).
    Union_find vuf(s.positions.size());
    for (std::size_t f = 0; f < nf; ++f)
      for (std::uint32_t c = s.face_start[f] + 1; c < s.face_start[f + 1]; ++c)
        vuf.unite(s.corner_vertex[s.face_start[f]], s.corner_vertex[c]);
    std::vector<bool> is_root(s.positions.size(), false);
    for (std::uint32_t v : s.corner_vertex) is_root[vuf.find(v)] = true;
    st.components = std::size_t(std::count(is_root.begin(), is_root.end(), true));
  }

  // Boundary loops: follow the hole's halfedges; each vertex of a manifold boundary has one.
  {
    std::unordered_map<std::uint32_t, std::size_t> cursor;
    std::size_t remaining = st.boundary_edges;
    std::vector<std::uint32_t> starts;
    starts.reserve(boundary_next.size());
    for (const auto& kv : boundary_next) starts.push_back(kv.first);
    std::sort(starts.begin(), starts.end());
    for (std::uint32_t start : starts) {
      while (cursor[start] < boundary_next[start].size()) {
        std::uint32_t v = start;
        ++st.boundary_loops;
        do {
          auto& c = cursor[v];
          auto& outs = boundary_next[v];
          if (c >= outs.size()) break;
          const std::uint32_t w = outs[c++];
          --remaining;
          v = w;
        } while (v != start && remaining > 0);
      }
    }
  }

  st.closed = st.boundary_edges == 0;
  st.manifold = st.non_manifold_edges == 0 && st.non_manifold_vertices == 0;
  st.oriented = st.inconsistent_edges == 0;
  st.euler_characteristic = int(st.vertices) - int(st.edges) + int(nf);
  if (st.manifold && st.oriented) {
    // chi = sum over components of (2 - 2 g_i - b_i)
    const long long twice_g = 2 * (long long)st.components - st.euler_characteristic - (long long)st.boundary_loops;
    st.genus = twice_g >= 0 && twice_g % 2 == 0 ? int(twice_g / 2) : -1;
  }
  st.charts = s.uvs.empty() ? 0 : count_soup_charts(s);
  return st;
}

}  // namespace CMGeom

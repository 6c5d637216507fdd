// Format dispatch, validation and construction of Textured_mesh from a soup, geometry writers.
#include "io_internal.h"

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <numeric>
#include <cctype>
#include <filesystem>

namespace CMGeom {
namespace IO {

namespace fs = std::filesystem;

std::string extension(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return e;
}

Polygon_soup read_polygon_soup(const std::string& path) {
  Polygon_soup soup;
  std::string ext = extension(path);
  if (ext == ".gz") {  // bunny.obj.gz: the readers decompress it (internal::is_gzipped_path)
    ext = extension(path.substr(0, path.size() - 3));
    if (ext != ".obj" && ext != ".off" && ext != ".ply" && ext != ".stl")
      throw IO_error(
          path, "unsupported compressed file type '" + ext + ".gz' (expected .obj.gz, .off.gz, .ply.gz or .stl.gz)");
  }
  if (ext == ".obj")
    internal::read_obj(path, soup);
  else if (ext == ".off")
    internal::read_off(path, soup);
  else if (ext == ".ply")
    internal::read_ply(path, soup);
  else if (ext == ".stl")
    internal::read_stl(path, soup);
  else if (ext == ".gltf" || ext == ".glb")
    internal::read_gltf(path, soup);
  else
    throw IO_error(path,
                   "unsupported file type '" + ext +
                       "' (expected .obj, .off, .ply, .stl, .gltf or .glb, the first four also gzipped: .obj.gz)");
  return soup;
}

namespace {

// Remembers, for every vertex that orient_polygon_soup duplicates, the vertex it copies.
struct Duplication_visitor : CGAL::Polygon_mesh_processing::Default_orientation_visitor {
  std::vector<std::size_t>* original;
  void duplicated_vertex(std::size_t v, std::size_t copy) {
    if (original->size() <= copy) original->resize(copy + 1);
    (*original)[copy] = (*original)[v];
  }
};

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// Links the triangles `tris` (indices of vertices already in `m`, three distinct per triangle)
// into `m`, which has vertices and no edges or faces, directly from the triangles' halfedges: the
// halfedges leaving each vertex are grouped (a counting sort), each finds its opposite among those
// leaving its target, and each vertex's fan is walked once. Returns false, leaving `m` without
// edges or faces, unless the triangles form an oriented 2-manifold (every directed edge once, in
// at most two faces of opposite orientations, every vertex's triangles one fan); the caller then
// adds the faces one by one (CGAL::Euler::add_face), which reports the defect. On success the
// result is the mesh that adding the triangles one by one with add_face builds, numbering and
// all: edges in order of first use, each edge's even halfedge in the face that first used it, a
// face's halfedge the one into its first corner, a border vertex's halfedge the border one into
// it, an interior vertex's the one into it in the last triangle around it (add_face leaves it
// there when that triangle closes the vertex's fan). `halfedge_of[3f + k]` is set to the
// halfedge from corner k to corner k + 1 of triangle f. O(F) time and memory, against add_face's
// searches around vertices.
bool link_oriented_manifold(Surface_mesh& m, const std::vector<std::array<std::uint32_t, 3>>& tris,
                            std::vector<Surface_mesh::Halfedge_index>& halfedge_of) {
  using H = Surface_mesh::Halfedge_index;
  constexpr std::uint32_t nil = 0xffffffffu;
  const std::size_t nv = m.number_of_vertices(), nd = 3 * tris.size();
  if (nd >= nil / 2) return false;
  const auto src = [&](std::uint32_t d) { return tris[d / 3][d % 3]; };
  const auto tgt = [&](std::uint32_t d) { return tris[d / 3][(d % 3 + 1) % 3]; };
  const auto prev_in_face = [](std::uint32_t d) { return d - d % 3 + (d % 3 + 2) % 3; };
  // the directed halfedges leaving each vertex: out_[first[v], first[v + 1])
  std::vector<std::uint32_t> first(nv + 1, 0);
  for (std::uint32_t d = 0; d < nd; ++d) ++first[src(d) + 1];
  for (std::size_t v = 0; v < nv; ++v) first[v + 1] += first[v];
  std::vector<std::uint32_t> out_d(nd), out_t(nd);
  {
    std::vector<std::uint32_t> at(first.begin(), first.end() - 1);
    for (std::uint32_t d = 0; d < nd; ++d) {
      const std::uint32_t k = at[src(d)]++;
      out_d[k] = d;
      out_t[k] = tgt(d);
    }
  }
  // opposites; a directed edge used twice, or an edge with two halfedges one way, is a defect
  std::vector<std::uint32_t> opp(nd, nil), border_out(nv, nil), border_in(nv, nil);
  std::atomic<bool> defect(false);
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(nd), 1u << 14), [&](const auto& r) {
    for (std::uint32_t d = r.begin(); d != r.end(); ++d) {
      const std::uint32_t a = src(d), b = tgt(d);
      int same = 0;
      for (std::uint32_t k = first[a]; k < first[a + 1]; ++k) same += out_t[k] == b;
      int back = 0;
      for (std::uint32_t k = first[b]; k < first[b + 1]; ++k)
        if (out_t[k] == a) {
          ++back;
          opp[d] = out_d[k];
        }
      if (same != 1 || back > 1) defect = true;
    }
  });
  if (defect) return false;
  std::vector<std::uint32_t>().swap(out_t);  // (the memory of a large mesh is freed as it goes)
  for (std::uint32_t d = 0; d < nd; ++d) {
    if (opp[d] != nil) continue;
    // a border edge: at most one leaves and one enters each vertex
    const std::uint32_t a = src(d), b = tgt(d);
    if (border_out[a] != nil || border_in[b] != nil) return false;
    border_out[a] = d;
    border_in[b] = d;
  }
  // each vertex's triangles form one fan: turning from one halfedge leaving it (the border one,
  // if any) to the next visits all of them
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv, 1u << 14), [&](const auto& r) {
    for (std::size_t v = r.begin(); v != r.end(); ++v) {
      const std::uint32_t degree = first[v + 1] - first[v];
      if (degree == 0) continue;
      if ((border_out[v] == nil) != (border_in[v] == nil)) {
        defect = true;
        return;
      }
      const std::uint32_t s = border_out[v] != nil ? border_out[v] : out_d[first[v]];
      std::uint32_t d = s, steps = 1;
      for (;;) {
        const std::uint32_t o = opp[prev_in_face(d)];
        if (o == nil || o == s) break;
        d = o;
        if (++steps > degree) break;
      }
      if (steps != degree) {
        defect = true;
        return;
      }
    }
  });
  if (defect) return false;
  // edges numbered in order of first use, as add_face does
  halfedge_of.assign(nd, H());
  std::uint32_t ne = 0;
  for (std::uint32_t d = 0; d < nd; ++d) {
    if (halfedge_of[d] != H()) continue;
    halfedge_of[d] = H(2 * ne);
    if (opp[d] != nil) halfedge_of[opp[d]] = H(2 * ne + 1);
    ++ne;
  }
  // each vertex's halfedge: the border one into it, or the one into it in its last triangle
  const auto twin = [](H h) { return H(Surface_mesh::size_type(h.idx() ^ 1u)); };
  std::vector<H> vertex_halfedge(nv, H());
  for (std::size_t v = 0; v < nv; ++v)
    if (first[v + 1] != first[v])
      vertex_halfedge[v] =
          border_out[v] != nil ? twin(halfedge_of[border_out[v]]) : halfedge_of[prev_in_face(out_d[first[v + 1] - 1])];
  std::vector<std::uint32_t>().swap(out_d);
  std::vector<std::uint32_t>().swap(first);
  std::vector<std::uint32_t>().swap(border_out);
  m.resize(Surface_mesh::size_type(nv), Surface_mesh::size_type(ne), Surface_mesh::size_type(tris.size()));
  using V = Surface_mesh::Vertex_index;
  using F = Surface_mesh::Face_index;
  // each halfedge's links are written by one task (set_next also sets the next one's prev)
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(nd), 1u << 14), [&](const auto& r) {
    for (std::uint32_t d = r.begin(); d != r.end(); ++d) {
      const H h = halfedge_of[d];
      const F f(Surface_mesh::size_type(d / 3));
      m.set_target(h, V(tgt(d)));
      m.set_face(h, f);
      m.set_next(h, halfedge_of[d - d % 3 + (d % 3 + 1) % 3]);
      if (d % 3 == 2) m.set_halfedge(f, h);
      if (opp[d] == nil) {  // its border twin, into the source, goes on along the border
        const H b = m.opposite(h);
        m.set_target(b, V(src(d)));
        m.set_face(b, m.null_face());
        m.set_next(b, m.opposite(halfedge_of[border_in[src(d)]]));
      }
    }
  });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv, 1u << 14), [&](const auto& r) {
    for (std::size_t v = r.begin(); v != r.end(); ++v)
      if (vertex_halfedge[v] != H()) m.set_halfedge(V(Surface_mesh::size_type(v)), vertex_halfedge[v]);
  });
  return true;
}

// Validates `soup` and builds its mesh (see build_textured_mesh()); with `attributes`, the mesh
// has the "f:material" map of a Textured_mesh and, when the soup has texture coordinates
// (`uv_seen` set on return), its filled "h:uv" map; without, neither map (the UVs are checked all
// the same).
Surface_mesh build_mesh(const Polygon_soup& soup, const Read_options& options, bool attributes, bool& uv_seen) {
  const std::string& src = soup.source.empty() ? std::string("<memory>") : soup.source;
  const std::size_t nf = soup.number_of_faces();
  if (nf == 0) throw IO_error(src, "mesh has no faces");

  // Faces as triangles with their corner UVs; UVs on all faces or on none.
  using Triangle = std::array<std::uint32_t, 3>;
  std::vector<Triangle> tris;
  std::vector<std::array<std::uint32_t, 3>> tri_uv;  // only when the soup has texture coordinates
  std::vector<std::size_t> tri_face;                 // filled once triangle i is not face i
  bool identity = true;                              // triangle i is face i (tri_face unused)
  const auto face_of = [&](std::size_t i) { return identity ? i : tri_face[i]; };
  const bool keep_uv = attributes && soup.has_uvs();
  tris.reserve(nf);
  bool polygons = false;
  uv_seen = false;
  std::size_t first_without_uv = Polygon_soup::no_index;
  // Polygons are split into fans as polygon_fan_starts() says (Polygon_soup.h): from the first
  // corner, or from another where that fan would repeat an edge.
  const std::vector<std::uint32_t> fan_start = polygon_fan_starts(soup);
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t b = soup.face_start[f], n = std::uint32_t(soup.face_size(f));
    if (n < 3) throw IO_error(soup.face_location(f), "face with fewer than 3 corners");
    polygons |= n != 3;
    bool repeated = false;
    for (std::uint32_t i = 0; i < n; ++i) {
      if (soup.corner_vertex[b + i] >= soup.positions.size())
        throw IO_error(soup.face_location(f), "vertex index out of range");
      const std::uint32_t u = soup.corner_uv[b + i];
      if (u != Polygon_soup::no_index && u >= soup.uvs.size())
        throw IO_error(soup.face_location(f), "texture coordinate index out of range");
      for (std::uint32_t j = i + 1; j < n; ++j) repeated |= soup.corner_vertex[b + i] == soup.corner_vertex[b + j];
    }
    const bool face_has_uv = soup.face_has_uvs(f);
    uv_seen |= face_has_uv;
    if (!face_has_uv && first_without_uv == Polygon_soup::no_index) first_without_uv = f;
    if (repeated && !options.drop_repeated_vertex_faces)
      throw IO_error(soup.face_location(f),
                     "face repeats a vertex (degenerate face); the option "
                     "drop_repeated_vertex_faces (--drop-repeated) drops such faces");
    if ((repeated || n != 3) && identity) {  // triangle i is no longer face i from here on
      tri_face.resize(tris.size());
      std::iota(tri_face.begin(), tri_face.end(), std::size_t(0));
      identity = false;
    }
    if (repeated) continue;
    // (c_s, c_s+i, c_s+i+1)
    const std::uint32_t s = fan_start.empty() ? 0 : fan_start[f];
    for (std::uint32_t i = 1; i + 1 < n; ++i) {
      Triangle t;
      std::array<std::uint32_t, 3> u;
      const std::uint32_t idx[3] = {b + s, b + (s + i) % n, b + (s + i + 1) % n};
      for (int k = 0; k < 3; ++k) {
        t[std::size_t(k)] = soup.corner_vertex[idx[k]];
        u[std::size_t(k)] = soup.corner_uv[idx[k]];
      }
      tris.push_back(t);
      if (keep_uv) tri_uv.push_back(u);
      if (!identity) tri_face.push_back(f);
    }
  }
  if (uv_seen && first_without_uv != Polygon_soup::no_index)
    throw IO_error(soup.face_location(first_without_uv),
                   "face has no texture coordinates while other faces have (textured mesh)");
  if (tris.empty()) throw IO_error(src, "mesh has no valid faces");
  for (const auto& p : soup.positions)
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw IO_error(src, "non-finite vertex coordinate");

  const auto point_of = [](const auto& p) { return Point_3(p[0], p[1], p[2]); };
  // Zero-area triangles (the repeated-vertex ones were handled above): their count, the face of
  // the first in `first`; refused unless allowed.
  const auto count_zero_area = [&](std::size_t& first) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < tris.size(); ++i)
      if (CGAL::collinear(point_of(soup.positions[tris[i][0]]), point_of(soup.positions[tris[i][1]]),
                          point_of(soup.positions[tris[i][2]])) &&
          !n++)
        first = face_of(i);
    return n;
  };
  const auto refuse_zero_area = [&](std::size_t n, std::size_t first) {
    if (n)
      throw IO_error(soup.face_location(first),
                     plural(n, "zero-area face", "zero-area faces") +
                         " (first here); the option allow_degenerate_faces (--allow-degenerate) keeps them");
  };
  // Builds the mesh of triangles `ps` over `pts` (UVs `tuv`); with `linked_only`, nothing
  // (std::nullopt) unless they form an oriented manifold (see link_oriented_manifold), else face
  // by face with add_face, which names the first defect. `pts`: the soup's positions, or the
  // points of a repaired soup.
  auto construct = [&](const auto& pts, const std::vector<Triangle>& ps,
                       const std::vector<std::array<std::uint32_t, 3>>& tuv,
                       bool linked_only = false) -> std::optional<Surface_mesh> {
    Surface_mesh m;
    Textured_mesh::UV_map uv;
    Textured_mesh::Material_map mat;
    if (attributes) {
      // (no "h:uv" map without texture coordinates: it would be 16 bytes a halfedge of zeros)
      if (uv_seen) uv = m.add_property_map<Surface_mesh::Halfedge_index, Point_2>("h:uv", Point_2(0, 0)).first;
      mat = m.add_property_map<Surface_mesh::Face_index, int>("f:material", 0).first;
    }
    std::vector<bool> used(pts.size(), !options.remove_unreferenced_vertices);
    if (options.remove_unreferenced_vertices)
      for (const auto& t : ps) used[t[0]] = used[t[1]] = used[t[2]] = true;
    std::vector<Surface_mesh::Vertex_index> vmap(pts.size());
    m.reserve(Surface_mesh::size_type(pts.size()), Surface_mesh::size_type(3 * ps.size() / 2),
              Surface_mesh::size_type(ps.size()));
    Surface_mesh::size_type nv = 0;
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (used[i]) vmap[i] = Surface_mesh::Vertex_index(nv++);
    m.resize(nv, 0, 0);  // the vertices, without their halfedges yet
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pts.size(), 1u << 14), [&](const auto& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i)
        if (used[i]) m.point(vmap[i]) = point_of(pts[i]);
    });
    std::vector<Triangle> renumbered;  // the triangles in m's vertex numbers, when they differ
    if (nv != pts.size()) {
      renumbered.resize(ps.size());
      for (std::size_t i = 0; i < ps.size(); ++i)
        for (std::size_t k = 0; k < 3; ++k) renumbered[i][k] = std::uint32_t(vmap[ps[i][k]]);
    }
    const std::vector<Triangle>& linked = nv != pts.size() ? renumbered : ps;
    std::vector<Surface_mesh::Halfedge_index> halfedge_of;
    if (link_oriented_manifold(m, linked, halfedge_of)) {
      if (attributes)
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ps.size(), 1u << 14), [&](const auto& r) {
          for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Surface_mesh::Face_index f{Surface_mesh::size_type(i)};
            mat[f] = soup.face_material[face_of(i)];
            if (uv_seen)
              for (std::size_t k = 0; k < 3; ++k) {  // the halfedge into corner k comes from corner k - 1
                const auto& q = soup.uvs[tuv[i][k]];
                uv[halfedge_of[3 * i + (k + 2) % 3]] = Point_2(q[0], q[1]);
              }
          }
        });
      CGAL_assertion(m.is_valid(false));
    } else if (linked_only) {
      return std::nullopt;
    } else {
      for (std::size_t i = 0; i < ps.size(); ++i) {
        const auto& t = ps[i];
        const auto f = m.add_face(vmap[t[0]], vmap[t[1]], vmap[t[2]]);
        if (f == Surface_mesh::null_face())
          throw IO_error(soup.face_location(face_of(i)),
                         "face cannot be added to a manifold mesh (non-manifold configuration after "
                         "splitting polygons into triangles); the option repair (--repair) fixes it");
        if (!attributes) continue;
        mat[f] = soup.face_material[face_of(i)];
        if (uv_seen) {
          // halfedge(f) points to the face's first corner? Not necessarily: match by target vertex.
          for (auto h : m.halfedges_around_face(m.halfedge(f)))
            for (int k = 0; k < 3; ++k)
              if (m.target(h) == vmap[t[std::size_t(k)]]) {
                const auto& q = soup.uvs[tuv[i][std::size_t(k)]];
                uv[h] = Point_2(q[0], q[1]);
              }
        }
      }
      // Surface_mesh's own check: CGAL::is_valid_polygon_mesh() also rejects isolated vertices,
      // which are kept on purpose (vertex order survives read -> write).
      if (!m.is_valid(false)) throw IO_error(src, "faces do not form a valid manifold mesh");
    }
    return m;
  };

  // A soup of triangles only, none dropped, is first linked as it is (one pass, see
  // link_oriented_manifold) while another core looks for zero-area faces; a soup that links and
  // has none is the mesh, without the statistics below. Otherwise the topology checks on the soup
  // report defects with counts and the first location, and the repair (if asked) mends them.
  const bool as_read = !polygons && tris.size() == nf;
  if (as_read) {
    std::optional<Surface_mesh> linked;
    std::size_t zero_area = 0, first = Polygon_soup::no_index;
    tbb::parallel_invoke(
        [&] {
          if (!options.allow_degenerate_faces) zero_area = count_zero_area(first);
        },
        [&] { linked = construct(soup.positions, tris, tri_uv, true); });
    refuse_zero_area(zero_area, first);
    if (linked) return std::move(*linked);
  }
  const Mesh_statistics st = analyze_soup(soup);
  if (st.degenerate_faces > 0 && !options.allow_degenerate_faces) {
    std::size_t first = Polygon_soup::no_index;
    const std::size_t zero_area = count_zero_area(first);
    refuse_zero_area(zero_area, first);
  }
  if (!options.repair) {
    if (st.non_manifold_edges)
      throw IO_error(
          soup.face_location(st.first_non_manifold_edge_face),
          plural(st.non_manifold_edges, "non-manifold edge", "non-manifold edges") +
              " (edges with more than two faces; first at this face); the option repair (--repair) splits them");
    if (st.non_manifold_vertices) {
      std::size_t where = 0;
      for (std::size_t f = 0; f < nf; ++f)
        for (std::uint32_t c = soup.face_start[f]; c < soup.face_start[f + 1]; ++c)
          if (soup.corner_vertex[c] == st.first_non_manifold_vertex) {
            where = f;
            f = nf;
            break;
          }
      throw IO_error(soup.face_location(where),
                     plural(st.non_manifold_vertices, "non-manifold vertex", "non-manifold vertices") +
                         " (first: vertex " + std::to_string(st.first_non_manifold_vertex + 1) +
                         ", used by this face); the option repair (--repair) duplicates them");
    }
    if (st.inconsistent_edges)
      throw IO_error(src, plural(st.inconsistent_edges, "edge", "edges") +
                              " with inconsistently oriented faces; the option repair (--repair) re-orients them");
  }

  // Optional repair: CGAL orients the soup and duplicates non-manifold vertices; UVs follow
  // their corners because every triangle keeps its three original vertices.
  std::vector<Point_3> points(soup.positions.size());
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = point_of(soup.positions[i]);
  std::vector<std::size_t> original(points.size());
  std::iota(original.begin(), original.end(), std::size_t(0));
  std::vector<Triangle> polys = tris;
  // The decision is taken on the triangles: splitting a non-convex polygon into a fan can itself
  // create a non-manifold edge even when the polygon mesh is manifold.
  auto is_manifold_triangle_soup = [](const auto& triangles, std::size_t vertices) {
    Polygon_soup t;
    t.face_start.resize(triangles.size() + 1);
    t.corner_vertex.reserve(3 * triangles.size());
    for (std::size_t i = 0; i < triangles.size(); ++i) {
      t.face_start[i + 1] = std::uint32_t(3 * (i + 1));
      for (int k = 0; k < 3; ++k) t.corner_vertex.push_back(std::uint32_t(triangles[i][std::size_t(k)]));
    }
    return internal::is_oriented_manifold_soup(t, vertices);
  };
  // For a soup of triangles only, none dropped, the statistics are those of the triangles: a
  // defect means no polygon mesh, none means one as it is; otherwise (polygons split into fans,
  // faces dropped) the triangles are checked.
  const bool defects = st.non_manifold_edges != 0 || st.non_manifold_vertices != 0 || st.inconsistent_edges != 0;
  bool repaired = false;
  if (options.repair && (as_read ? defects : !is_manifold_triangle_soup(polys, points.size()))) {
    repaired = true;
    std::vector<std::vector<std::size_t>> pv;
    pv.reserve(polys.size());
    for (const auto& t : polys) pv.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});
    Duplication_visitor vis;
    vis.original = &original;
    CGAL::Polygon_mesh_processing::orient_polygon_soup(points, pv, CGAL::parameters::visitor(vis));
    if (pv.size() != polys.size()) throw IO_error(src, "repair changed the number of faces");
    if (!is_manifold_triangle_soup(pv, points.size()))
      throw IO_error(src,
                     "repair could not make the mesh manifold (duplicated or otherwise "
                     "irreparable faces around non-manifold edges)");
    if (options.warnings) {
      std::string what;
      auto add = [&](std::size_t n, const char* one, const char* many) {
        if (!n) return;
        if (!what.empty()) what += ", ";
        what += plural(n, one, many);
      };
      add(st.non_manifold_edges, "non-manifold edge split", "non-manifold edges split");
      add(st.non_manifold_vertices, "non-manifold vertex duplicated", "non-manifold vertices duplicated");
      add(st.inconsistent_edges, "inconsistently oriented edge re-oriented",
          "inconsistently oriented edges re-oriented");
      const std::size_t added = points.size() - original.size();
      if (added) what += (what.empty() ? "" : "; ") + plural(added, "vertex added", "vertices added");
      if (what.empty()) what = "faces re-oriented";
      options.warnings->push_back(src + ": repaired: " + what);
    }
    original.resize(points.size());
    for (std::size_t i = 0; i < pv.size(); ++i) {
      const Triangle t{std::uint32_t(pv[i][0]), std::uint32_t(pv[i][1]), std::uint32_t(pv[i][2])};
      if (keep_uv) {
        std::array<std::uint32_t, 3> u = tri_uv[i];
        for (int k = 0; k < 3; ++k)  // the UV of the original corner holding the same vertex
          for (int j = 0; j < 3; ++j)
            if (original[t[std::size_t(k)]] == tris[i][std::size_t(j)]) u[std::size_t(k)] = tri_uv[i][std::size_t(j)];
        tri_uv[i] = u;
      }
      polys[i] = t;
    }
  }

  return std::move(*construct(points, polys, tri_uv));
}

}  // namespace

void build_textured_mesh(const Polygon_soup& soup, Textured_mesh& out, const Read_options& options) {
  bool uv_seen = false;
  // (the "h:uv" map build_mesh() made is bound; without texture coordinates it made none, and
  // none comes until one is asked for: Textured_mesh::uv_map())
  Textured_mesh built(build_mesh(soup, options, true, uv_seen), Textured_mesh::without_uv_map);
  built.set_has_uvs(uv_seen);
  built.materials() = soup.materials;
  built.set_source(soup.source);
  out = std::move(built);
}

void build_surface_mesh(const Polygon_soup& soup, Surface_mesh& out, const Read_options& options) {
  bool uv_seen = false;
  out = build_mesh(soup, options, false, uv_seen);
}

void read_mesh(const std::string& path, Textured_mesh& out, const Read_options& options) {
  const Polygon_soup soup = read_polygon_soup(path);
  if (options.warnings) options.warnings->insert(options.warnings->end(), soup.warnings.begin(), soup.warnings.end());
  build_textured_mesh(soup, out, options);
}

void read_mesh(const std::string& path, Surface_mesh& out, const Read_options& options) {
  const Polygon_soup soup = read_polygon_soup(path);
  if (options.warnings) options.warnings->insert(options.warnings->end(), soup.warnings.begin(), soup.warnings.end());
  build_surface_mesh(soup, out, options);
}

void write_mesh(const std::string& path, const Textured_mesh& mesh) {
  if (mesh.mesh().number_of_faces() == 0) throw IO_error(path, "refusing to write a mesh without faces");
  Atomic_output out;
  const std::string ext = extension(path);
  if (ext == ".obj") {
    const std::string stem = fs::path(path).stem().string();
    internal::write_obj(path, mesh, out,
                        [&](const Material& m, std::size_t i, const std::string& kind, Atomic_output& o) {
                          const std::string& src = kind == "diffuse" ? m.diffuse_texture : m.normal_texture;
                          return internal::copy_texture_file(path, src, stem + "_" + std::to_string(i) + "_" + kind, o);
                        });
  } else if (ext == ".gltf" || ext == ".glb") {
    internal::write_gltf(path, {Gltf_level{&mesh, std::string("mesh"), -1, -1}}, Gltf_options(), out,
                         &internal::encode_texture_file);
  } else if (ext == ".off") {
    internal::write_off(path, mesh, out);
  } else if (ext == ".ply") {
    internal::write_ply(path, mesh, out);
  } else if (ext == ".stl") {
    internal::write_stl(path, mesh, out);
  } else {
    throw IO_error(path, "unsupported output type '" + ext + "' (expected .obj, .off, .ply, .stl, .gltf or .glb)");
  }
  out.commit();
}

}  // namespace IO
}  // namespace CMGeom

namespace CMGeom {
namespace IO {

void write_gltf(const std::string& path, const std::vector<Gltf_level>& levels, const Gltf_options& options) {
  Atomic_output out;
  internal::write_gltf(path, levels, options, out, &internal::encode_texture_file);
  out.commit();
}

}  // namespace IO
}  // namespace CMGeom

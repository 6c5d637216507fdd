// Format dispatch, validation and construction of Textured_mesh from a soup, geometry writers.
#include "io_internal.h"

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <exception>
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
  const std::string ext = extension(path);
  if (ext == ".obj")
    internal::read_obj(path, soup);
  else if (ext == ".off")
    internal::read_off(path, soup);
  else if (ext == ".ply")
    internal::read_ply(path, soup);
  else if (ext == ".gltf" || ext == ".glb")
    internal::read_gltf(path, soup);
  else
    throw IO_error(path, "unsupported file type '" + ext + "' (expected .obj, .off, .ply, .gltf or .glb)");
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

}  // namespace

void build_textured_mesh(const Polygon_soup& soup, Textured_mesh& out, const Read_options& options) {
  const std::string& src = soup.source.empty() ? std::string("<memory>") : soup.source;
  const std::size_t nf = soup.number_of_faces();
  if (nf == 0) throw IO_error(src, "mesh has no faces");

  // Faces as triangles with their corner UVs; UVs on all faces or on none.
  std::vector<std::array<std::size_t, 3>> tris;
  std::vector<std::array<std::uint32_t, 3>> tri_uv;
  std::vector<std::size_t> tri_face;
  tris.reserve(nf);
  bool uv_seen = false, polygons = false;
  std::size_t first_without_uv = Polygon_soup::no_index;
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t b = soup.face_start[f], n = std::uint32_t(soup.face_size(f));
    if (n < 3) throw IO_error(soup.face_location(f), "face with fewer than 3 corners");
    polygons |= n != 3;
    bool repeated = false, face_has_uv = true;
    for (std::uint32_t i = 0; i < n; ++i) {
      if (soup.corner_vertex[b + i] >= soup.positions.size())
        throw IO_error(soup.face_location(f), "vertex index out of range");
      const std::uint32_t u = soup.corner_uv[b + i];
      if (u != Polygon_soup::no_index && u >= soup.uvs.size())
        throw IO_error(soup.face_location(f), "texture coordinate index out of range");
      face_has_uv &= u != Polygon_soup::no_index;
      for (std::uint32_t j = i + 1; j < n; ++j) repeated |= soup.corner_vertex[b + i] == soup.corner_vertex[b + j];
    }
    uv_seen |= face_has_uv;
    if (!face_has_uv && first_without_uv == Polygon_soup::no_index) first_without_uv = f;
    if (repeated) {
      if (options.drop_repeated_vertex_faces) continue;
      throw IO_error(soup.face_location(f), "face repeats a vertex (degenerate face)");
    }
    // Polygons are split into fans in file order: (c0, c_i, c_i+1).
    for (std::uint32_t i = 1; i + 1 < n; ++i) {
      std::array<std::size_t, 3> t;
      std::array<std::uint32_t, 3> u;
      const std::uint32_t idx[3] = {b, b + i, b + i + 1};
      for (int k = 0; k < 3; ++k) {
        t[std::size_t(k)] = soup.corner_vertex[idx[k]];
        u[std::size_t(k)] = soup.corner_uv[idx[k]];
      }
      tris.push_back(t);
      tri_uv.push_back(u);
      tri_face.push_back(f);
    }
  }
  if (uv_seen && first_without_uv != Polygon_soup::no_index)
    throw IO_error(soup.face_location(first_without_uv),
                   "face has no texture coordinates while other faces have (textured mesh)");
  if (tris.empty()) throw IO_error(src, "mesh has no valid faces");
  for (const auto& p : soup.positions)
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw IO_error(src, "non-finite vertex coordinate");

  std::vector<Point_3> points;
  points.reserve(soup.positions.size());
  for (const auto& p : soup.positions) points.emplace_back(p[0], p[1], p[2]);
  // Builds the Textured_mesh of triangles `ps` over `pts` (UVs `tuv`), apart from `out`.
  auto construct = [&](const std::vector<Point_3>& pts, const std::vector<std::array<std::size_t, 3>>& ps,
                       const std::vector<std::array<std::uint32_t, 3>>& tuv) {
    Textured_mesh built;
    built.set_source(soup.source);
    Surface_mesh& m = built.mesh();
    std::vector<bool> used(pts.size(), !options.remove_unreferenced_vertices);
    if (options.remove_unreferenced_vertices)
      for (const auto& t : ps) used[t[0]] = used[t[1]] = used[t[2]] = true;
    std::vector<Surface_mesh::Vertex_index> vmap(pts.size());
    m.reserve(Surface_mesh::size_type(pts.size()), Surface_mesh::size_type(3 * ps.size() / 2),
              Surface_mesh::size_type(ps.size()));
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (used[i]) vmap[i] = m.add_vertex(pts[i]);
    auto uv = built.uv_map();
    auto mat = built.material_map();
    for (std::size_t i = 0; i < ps.size(); ++i) {
      const auto& t = ps[i];
      const auto f = m.add_face(vmap[t[0]], vmap[t[1]], vmap[t[2]]);
      if (f == Surface_mesh::null_face())
        throw IO_error(soup.face_location(tri_face[i]),
                       "face cannot be added to a manifold mesh (non-manifold configuration after "
                       "splitting polygons into triangles); the option repair (--repair) fixes it");
      mat[f] = soup.face_material[tri_face[i]];
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
    built.set_has_uvs(uv_seen);
    built.materials() = soup.materials;
    return built;
  };

  // Topology checks on the soup (reported with counts and the first location). A soup of
  // triangles only, none dropped, is built at the same time on another core, as it is; the build
  // is kept if the checks find nothing to repair, and its own error reported only after theirs.
  const bool as_read = !polygons && tris.size() == nf;
  Mesh_statistics st;
  std::optional<Textured_mesh> speculative;
  std::exception_ptr speculative_error;
  if (as_read)
    tbb::parallel_invoke([&] { st = analyze_soup(soup); },
                         [&] {
                           try {
                             speculative.emplace(construct(points, tris, tri_uv));
                           } catch (...) {
                             speculative_error = std::current_exception();
                           }
                         });
  else
    st = analyze_soup(soup);
  if (st.degenerate_faces > 0 && !options.allow_degenerate_faces) {
    // repeated-vertex faces were handled above; what remains is zero area
    std::size_t zero_area = 0, first = Polygon_soup::no_index;
    for (std::size_t i = 0; i < tris.size(); ++i) {
      const auto& a = soup.positions[tris[i][0]];
      const auto& b = soup.positions[tris[i][1]];
      const auto& c = soup.positions[tris[i][2]];
      if (CGAL::collinear(Point_3(a[0], a[1], a[2]), Point_3(b[0], b[1], b[2]), Point_3(c[0], c[1], c[2]))) {
        if (!zero_area++) first = tri_face[i];
      }
    }
    if (zero_area)
      throw IO_error(soup.face_location(first),
                     plural(zero_area, "zero-area face", "zero-area faces") +
                         " (first here); the option allow_degenerate_faces (--allow-degenerate) keeps them");
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
  std::vector<std::size_t> original(points.size());
  std::iota(original.begin(), original.end(), std::size_t(0));
  std::vector<std::array<std::size_t, 3>> polys = tris;
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
    for (const auto& t : polys) pv.push_back({t[0], t[1], t[2]});
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
      std::array<std::size_t, 3> t{pv[i][0], pv[i][1], pv[i][2]};
      std::array<std::uint32_t, 3> u = tri_uv[i];
      for (int k = 0; k < 3; ++k)  // the UV of the original corner holding the same vertex
        for (int j = 0; j < 3; ++j)
          if (original[t[std::size_t(k)]] == tris[i][std::size_t(j)]) u[std::size_t(k)] = tri_uv[i][std::size_t(j)];
      polys[i] = t;
      tri_uv[i] = u;
    }
  }

  if (as_read && !repaired) {  // the soup as it is, built above
    if (speculative_error) std::rethrow_exception(speculative_error);
    out = std::move(*speculative);
  } else {
    out = construct(points, polys, tri_uv);
  }
}

void read_mesh(const std::string& path, Textured_mesh& out, const Read_options& options) {
  const Polygon_soup soup = read_polygon_soup(path);
  if (options.warnings) options.warnings->insert(options.warnings->end(), soup.warnings.begin(), soup.warnings.end());
  build_textured_mesh(soup, out, options);
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
  } else {
    throw IO_error(path, "unsupported output type '" + ext + "' (expected .obj, .off, .ply, .gltf or .glb)");
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

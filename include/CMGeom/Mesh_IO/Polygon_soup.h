// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The raw content of a mesh file before it becomes a Surface_mesh: positions, texture
// coordinates and faces whose corners index them, in file order, with the file line of every
// face (for error messages). Every reader produces one; `analyze_soup()` measures it (closed,
// manifold, genus, charts, ...) without needing a valid halfedge structure, which is what
// `cmgeom info` reports on broken input, and `build_textured_mesh()` (mesh_io.h) turns it into a
// Textured_mesh after validation.
//
// Complexity: analyze_soup is O(C log C) for C face corners.
#ifndef CMGEOM_MESH_IO_POLYGON_SOUP_H
#define CMGEOM_MESH_IO_POLYGON_SOUP_H

#include <CMGeom/Mesh_IO/Textured_mesh.h>

#include <array>
#include <cstdint>
#include <string>
#include <unordered_set>
#include <vector>

namespace CMGeom {

struct Polygon_soup {
  static constexpr std::uint32_t no_index = 0xffffffffu;

  std::vector<std::array<double, 3>> positions;
  std::vector<std::array<double, 2>> uvs;
  /// Polygon f has corners [face_start[f], face_start[f+1]) (face_start has size F+1), in file order.
  std::vector<std::uint32_t> face_start{0};
  std::vector<std::uint32_t> corner_vertex;  ///< index into positions
  std::vector<std::uint32_t> corner_uv;      ///< index into uvs, or no_index
  std::vector<int> face_material;            ///< index into materials (0 if none)
  std::vector<std::size_t> face_line;        ///< 1-based file line of each face (0 if binary)
  std::vector<Material> materials;
  std::string source;                 ///< file name, for messages
  std::vector<std::string> warnings;  ///< non-fatal remarks ("file:line: ...")

  std::size_t number_of_faces() const { return face_start.size() - 1; }
  std::size_t face_size(std::size_t f) const { return face_start[f + 1] - face_start[f]; }
  bool has_uvs() const { return !uvs.empty(); }
  /// True when face f has a texture coordinate at every corner.
  bool face_has_uvs(std::size_t f) const;
  /// True when some face has a texture coordinate at every corner: the reader then builds a
  /// textured mesh (and refuses a face without them). Texture coordinates no face uses count for
  /// nothing (unlike has_uvs()).
  bool faces_have_uvs() const;
  /// "file:line" of face f, or "file (face f)" for binary formats.
  std::string face_location(std::size_t f) const;
};

/// The corner each face's fan starts from when a polygon is split into the triangles
/// (c_s, c_s+i, c_s+i+1), as the readers split them (build_textured_mesh()) and the soup metrics
/// sample them (Metrics/soup_metrics.h): s = 0, unless a diagonal of that fan is already an edge of
/// the soup (a side of a polygon, or a diagonal taken by an earlier face), which would give it
/// three or four triangles, or two triangles on the same three vertices (two quads sharing three
/// corners, as Blender's Suzanne has); the fan then starts at the first corner whose diagonals are
/// all new, if there is one. Triangles, and polygons that repeat a vertex, start at 0 and take no
/// diagonal. Empty (every start 0) when the soup has no polygon of more than three corners.
/// Corner indices out of range are taken as they are (the caller checks them). O(C) expected for
/// C corners.
inline std::vector<std::uint32_t> polygon_fan_starts(const Polygon_soup& soup) {
  const std::size_t nf = soup.number_of_faces();
  bool polygons = false;
  for (std::size_t f = 0; f < nf && !polygons; ++f) polygons = soup.face_size(f) > 3;
  if (!polygons) return {};
  const auto key = [](std::uint32_t a, std::uint32_t c) {
    return a < c ? (std::uint64_t(a) << 32) | c : (std::uint64_t(c) << 32) | a;
  };
  std::unordered_set<std::uint64_t> edges;
  edges.reserve(2 * soup.corner_vertex.size());
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t b = soup.face_start[f], n = std::uint32_t(soup.face_size(f));
    for (std::uint32_t i = 0; i < n; ++i)
      edges.insert(key(soup.corner_vertex[b + i], soup.corner_vertex[b + (i + 1) % n]));
  }
  std::vector<std::uint32_t> start(nf, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t b = soup.face_start[f], n = std::uint32_t(soup.face_size(f));
    if (n <= 3) continue;
    bool repeated = false;
    for (std::uint32_t i = 0; i < n && !repeated; ++i)
      for (std::uint32_t j = i + 1; j < n && !repeated; ++j)
        repeated = soup.corner_vertex[b + i] == soup.corner_vertex[b + j];
    if (repeated) continue;
    const auto corner = [&](std::uint32_t s, std::uint32_t i) { return soup.corner_vertex[b + (s + i) % n]; };
    for (std::uint32_t s = 0; s < n; ++s) {
      bool fresh = true;
      for (std::uint32_t i = 2; i + 1 < n && fresh; ++i) fresh = !edges.count(key(corner(s, 0), corner(s, i)));
      if (fresh) {
        start[f] = s;
        break;
      }
    }
    for (std::uint32_t i = 2; i + 1 < n; ++i) edges.insert(key(corner(start[f], 0), corner(start[f], i)));
  }
  return start;
}

/// What `analyze_soup()` measures. Counts refer to the polygons as they are in the file (before
/// build_textured_mesh() splits polygons into fans) and before any repair.
struct Mesh_statistics {
  std::size_t vertices = 0;  ///< referenced vertices
  std::size_t unreferenced_vertices = 0;
  std::size_t faces = 0;
  std::size_t edges = 0;
  std::size_t components = 0;  ///< connected components (faces linked through vertices)
  std::size_t boundary_edges = 0;
  std::size_t boundary_loops = 0;      ///< cycles of boundary edges (at a non-manifold vertex, one pairing is chosen)
  std::size_t non_manifold_edges = 0;  ///< edges with more than two faces
  std::size_t non_manifold_vertices = 0;  ///< vertices whose faces form several fans
  std::size_t inconsistent_edges = 0;     ///< manifold edges whose two faces disagree in orientation
  std::size_t degenerate_faces = 0;       ///< repeated vertex or zero area
  std::size_t invalid_coordinates = 0;    ///< NaN or infinite position or UV values
  std::size_t charts = 0;                 ///< UV charts (0 without UVs)
  bool closed = false;
  bool manifold = false;
  bool oriented = false;
  int euler_characteristic = 0;
  int genus = -1;  ///< total genus, -1 when not manifold
  std::size_t first_non_manifold_vertex = Polygon_soup::no_index;
  std::size_t first_non_manifold_edge_face = Polygon_soup::no_index;
  std::size_t first_degenerate_face = Polygon_soup::no_index;
};

/// Measures a soup. Never throws on bad topology: that is what it reports.
Mesh_statistics analyze_soup(const Polygon_soup& soup);

/// Counts UV charts of a soup: faces are connected across an edge when the two corners at each
/// end of the edge carry the same UV value in both faces (SOURCES.md convention). Faces without
/// UVs are not counted. Optionally writes the chart id of each face (-1 without UVs).
std::size_t count_soup_charts(const Polygon_soup& soup, std::vector<int>* face_chart = nullptr);

}  // namespace CMGeom

#endif  // CMGEOM_MESH_IO_POLYGON_SOUP_H

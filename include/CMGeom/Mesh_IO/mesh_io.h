// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Readers and writers of textured meshes (target CMGeom::Mesh_IO; no image library needed),
// the format chosen by the file's extension (case-insensitive): OBJ + MTL, OFF, PLY, STL (geometry
// only) and glTF 2.0 / GLB. Every error is an IO_error whose message is one line
// "<file>[:<line>]: <what is wrong>". Writers are atomic: every file is written to a temporary and
// renamed into place only when all of them are complete, so a failure never leaves a partial output.
//
// Manual: doc/Mesh_IO/README.md, "Reading and writing (`<CMGeom/Mesh_IO/mesh_io.h>`,
// `<CMGeom/Mesh_IO/textured_mesh_io.h>`)".
#ifndef CMGEOM_MESH_IO_MESH_IO_H
#define CMGEOM_MESH_IO_MESH_IO_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Polygon_soup.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>

#include <string>
#include <vector>

namespace CMGeom {
namespace IO {

/// Options of build_textured_mesh() and the readers.
struct Read_options {
  /// Non-manifold edges/vertices and inconsistent orientation are errors unless this is set;
  /// then CGAL's `orient_polygon_soup` duplicates vertices (carrying UVs along) to repair them.
  bool repair = false;
  /// Zero-area faces are errors unless this is set (then they are kept as they are).
  bool allow_degenerate_faces = false;
  /// Faces that repeat a vertex (a, a, b) are errors unless this is set (then they are dropped).
  bool drop_repeated_vertex_faces = false;
  /// Vertices no face uses are kept (so that vertex order survives read -> write) unless set.
  bool remove_unreferenced_vertices = false;
  /// Where read_mesh() appends non-fatal remarks ("file:line: ..."; a missing MTL file, skipped
  /// unknown statements); null: they are dropped.
  std::vector<std::string>* warnings = nullptr;
};

/// Reads any supported file into a soup; checks syntax, index ranges and finite values.
Polygon_soup read_polygon_soup(const std::string& path);

/// Validates a soup and builds the halfedge mesh: triangles only (readers triangulate),
/// manifold, consistently oriented, finite, non-degenerate (see Read_options), UVs on all
/// faces or on none, texture files present. Vertex order is that of the soup.
void build_textured_mesh(const Polygon_soup& soup, Textured_mesh& out, const Read_options& options = Read_options());

/// read_polygon_soup + build_textured_mesh. Texture images are not decoded here (see
/// read_textured_mesh() in textured_mesh_io.h); their paths are checked to exist.
void read_mesh(const std::string& path, Textured_mesh& out, const Read_options& options = Read_options());

/// The geometry alone: build_textured_mesh() without the corner UVs and face materials, whose
/// maps `out` does not get ("h:uv" is 16 bytes a halfedge, a fifth of a large mesh's memory).
/// The soup is checked as there, its texture coordinates included.
void build_surface_mesh(const Polygon_soup& soup, Surface_mesh& out, const Read_options& options = Read_options());

/// read_polygon_soup + build_surface_mesh.
void read_mesh(const std::string& path, Surface_mesh& out, const Read_options& options = Read_options());

/// Writes .obj (with .mtl when there are materials; texture files referenced by the
/// materials are copied beside it), .off, .ply (binary little-endian), .stl (binary, float
/// coordinates), .gltf (with a .bin and
/// the texture files beside it) or .glb (one file, textures embedded), atomically.
/// Coordinates are printed in the shortest form that reads back to the same double (OBJ, OFF);
/// glTF stores 32-bit floats. Textures are written from their files or embedded bytes (a PNG
/// without its colour-space chunks in glTF, see write_gltf()); write_textured_mesh()
/// (textured_mesh_io.h) also encodes decoded images.
void write_mesh(const std::string& path, const Textured_mesh& mesh);

/// Options of the glTF writer.
struct Gltf_options {
  /// NORMAL per vertex: the area-weighted average of the face normals, the same on both sides
  /// of a UV seam (smooth shading, as the OBJ output is drawn).
  bool normals = true;
  /// KHR_mesh_quantization: positions as 16-bit integers on a uniform grid of the level's
  /// bounding box (the node's scale and translation map them back; at most extent / 131070 off
  /// per coordinate), normals as 8-bit, texture coordinates in [0, 1] as 16-bit normalised.
  /// Vertices closer than the grid step become equal, as in any quantised file.
  bool quantize = false;
};

/// One level of detail for write_gltf().
struct Gltf_level {
  const Textured_mesh* mesh = nullptr;
  std::string name;   ///< node and mesh name
  double error = -1;  ///< written in the node's extras ("error") when >= 0
  double ratio = -1;  ///< written in the node's extras ("ratio") when >= 0
};

/// Writes a glTF 2.0 scene (.gltf + .bin + images, or a single .glb) atomically: one node and
/// mesh per level, one primitive per material used, vertices split where texture coordinates
/// differ (UV seams), 16-bit indices when they fit. Levels after the first are listed by the
/// first node's MSFT_lod extension (finest first) and are not in the scene: viewers without
/// MSFT_lod show the first level. Every node's extras hold its level, face count and, when
/// given, error and ratio. Materials: base colour (factor Kd, texture), normal texture,
/// metallic 0, roughness 1; identical materials and identical images are written once, so
/// levels that share a texture share it in the file. A primitive whose material has a normal
/// map gets TANGENT (unit, along the UV layout's u, w = handedness). Textures must be PNG or
/// JPEG; a PNG loses its colour-space chunks (iCCP, sRGB, gAMA, cHRM: glTF fixes the colour
/// space of its textures, viewers must ignore them), every other byte is kept.
/// Throws IO_error (nothing written) for an empty level, a non-triangle face or another image type.
void write_gltf(const std::string& path, const std::vector<Gltf_level>& levels,
                const Gltf_options& options = Gltf_options());

/// Lower-case extension of a path including the dot ("" when none).
std::string extension(const std::string& path);

}  // namespace IO
}  // namespace CMGeom

#endif  // CMGEOM_MESH_IO_MESH_IO_H

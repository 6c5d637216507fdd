// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Textured meshes with their images (target CMGeom::Image_IO): read_textured_mesh() is
// read_mesh() followed by decoding every material texture; write_textured_mesh() writes
// OBJ + MTL + one PNG per texture (or, for .off/.ply, geometry only), all atomically.
#ifndef CMGEOM_MESH_IO_TEXTURED_MESH_IO_H
#define CMGEOM_MESH_IO_TEXTURED_MESH_IO_H

#include <CMGeom/Mesh_IO/image_io.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

namespace CMGeom {
namespace IO {

/// Decodes every texture of `mesh.materials()` that is not loaded yet (files or embedded bytes).
void load_textures(Textured_mesh& mesh);

/// read_mesh() + load_textures().
void read_textured_mesh(const std::string& path, Textured_mesh& out, const Read_options& options = Read_options());

/// Writes the mesh; for .obj, textures are written as PNG files named
/// "<stem>_<material>_<diffuse|normal>.png" beside it (decoded images are encoded again; textures
/// that were never decoded are copied byte for byte).
/// For .gltf/.glb, decoded images are written as PNG, texture files that are PNG or JPEG as they
/// are, others re-encoded as PNG (see write_textured_gltf()).
void write_textured_mesh(const std::string& path, const Textured_mesh& mesh,
                         const Gltf_options& gltf_options = Gltf_options());

/// write_gltf() for meshes whose textures may exist only as decoded images (a baked atlas):
/// those are encoded as PNG; identical images (same pixels) are written once.
void write_textured_gltf(const std::string& path, const std::vector<Gltf_level>& levels,
                         const Gltf_options& options = Gltf_options());

/// write_textured_mesh() and write_textured_gltf() with their files registered in `out` (see
/// Atomic_output) instead of committed at once: a caller writing several meshes commits them
/// together, so that a failure leaves none of them.
void write_textured_mesh(const std::string& path, const Textured_mesh& mesh, Atomic_output& out,
                         const Gltf_options& gltf_options = Gltf_options());
void write_textured_gltf(const std::string& path, const std::vector<Gltf_level>& levels, Atomic_output& out,
                         const Gltf_options& options = Gltf_options());

}  // namespace IO
}  // namespace CMGeom

#endif  // CMGEOM_MESH_IO_TEXTURED_MESH_IO_H

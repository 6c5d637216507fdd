// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The textured-mesh data model every CMGeom package works on (thesis §3.2: a mesh whose texture
// atlas is cut into charts). It is a CGAL::Surface_mesh<Point_3> (EPICK) plus property maps:
//
//   "h:uv"        per-halfedge (corner) texture coordinate: the UV of vertex target(h) as seen from
//                 face(h). Seams are represented without splitting vertices: the two faces of a
//                 seam edge simply store different UVs at the shared corners.
//   "f:material"  per-face material index into materials() (0 when the file names none).
//
// plus the materials themselves (colour, diffuse texture, optional normal map, as file paths and,
// once loaded, as images). Charts are not stored: compute them with compute_chart_ids()
// (charts.h) when needed, since every collapse may change them.
//
// A mesh without texture coordinates may be held without its "h:uv" map (`without_uv_map`, as
// the readers build an untextured file's mesh: on a 1M-face mesh the map is 51 MB of zeros whose
// filling costs as much as a fifth of the reading); the map is then added, filled with (0, 0),
// the first time it is asked for (uv_map(), uv(), set_uv(), set_has_uvs(true)).
//
// Complexity: O(1) accessors (the first access to a deferred "h:uv" map: O(halfedges)); copying
// is O(size) and rebinds the property maps to the copy.
#ifndef CMGEOM_MESH_IO_TEXTURED_MESH_H
#define CMGEOM_MESH_IO_TEXTURED_MESH_H

#include <CMGeom/config.h>
#include <CMGeom/Mesh_IO/Image.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <atomic>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace CMGeom {

/// The kernel CMGeom defaults to (double coordinates, exact predicates).
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using FT = Kernel::FT;
using Point_3 = Kernel::Point_3;
using Vector_3 = Kernel::Vector_3;
using Point_2 = Kernel::Point_2;
using Vector_2 = Kernel::Vector_2;
/// The reference mesh type of every CMGeom algorithm.
using Surface_mesh = CGAL::Surface_mesh<Point_3>;

/// A material as found in an MTL file or a glTF material.
struct Material {
  std::string name;
  std::array<double, 3> diffuse_color{{0.8, 0.8, 0.8}};  ///< Kd (multiplies the texture)
  std::string diffuse_texture;                           ///< absolute path of map_Kd / baseColorTexture, empty if none
  std::string normal_texture;                            ///< absolute path of map_Bump / bump / norm, empty if none
  /// Encoded image bytes (PNG/JPEG) when the texture is embedded in the file (glTF buffers or
  /// data URIs) instead of being a file of its own.
  std::vector<unsigned char> diffuse_texture_blob;
  Image diffuse_image;  ///< decoded diffuse texture (empty until loaded)
  Image normal_image;   ///< decoded normal map (empty until loaded)

  bool has_diffuse_texture() const {
    return !diffuse_texture.empty() || !diffuse_texture_blob.empty() || !diffuse_image.empty();
  }
};

/// A `Surface_mesh` with per-corner UVs, per-face materials and material images.
class Textured_mesh {
public:
  using Mesh = Surface_mesh;
  using vertex_descriptor = Mesh::Vertex_index;
  using halfedge_descriptor = Mesh::Halfedge_index;
  using edge_descriptor = Mesh::Edge_index;
  using face_descriptor = Mesh::Face_index;
  using UV_map = Mesh::Property_map<halfedge_descriptor, Point_2>;
  using Material_map = Mesh::Property_map<face_descriptor, int>;

  /// The tag of the constructor that leaves out the "h:uv" map until it is asked for.
  struct Without_uv_map {};
  static constexpr Without_uv_map without_uv_map{};

  Textured_mesh() { bind_maps(true); }
  /// Takes `mesh` with its property maps: an "h:uv" or "f:material" map it already has becomes
  /// this mesh's (e.g. a Surface_mesh copied from another Textured_mesh's mesh()); has_uvs() is
  /// false until set.
  explicit Textured_mesh(Mesh mesh) : mesh_(std::move(mesh)) { bind_maps(true); }
  /// As Textured_mesh(Mesh), but a mesh without an "h:uv" map gets one only when it is first asked
  /// for (see the file comment): for a mesh without texture coordinates (has_uvs() false).
  Textured_mesh(Mesh mesh, Without_uv_map) : mesh_(std::move(mesh)) { bind_maps(false); }
  /// (a copy has an "h:uv" map when `other` has one)
  Textured_mesh(const Textured_mesh& other)
      : mesh_(other.mesh_), materials_(other.materials_), has_uvs_(other.has_uvs_), source_(other.source_) {
    bind_maps(false);
  }
  Textured_mesh& operator=(const Textured_mesh& other) {
    if (this != &other) {
      mesh_ = other.mesh_;
      materials_ = other.materials_;
      has_uvs_ = other.has_uvs_;
      source_ = other.source_;
      bind_maps(false);
    }
    return *this;
  }
  Textured_mesh(Textured_mesh&& other) noexcept
      : mesh_(std::move(other.mesh_)),
        materials_(std::move(other.materials_)),
        has_uvs_(other.has_uvs_),
        source_(std::move(other.source_)) {
    bind_maps(false);
    other.bind_maps(false);
  }
  Textured_mesh& operator=(Textured_mesh&& other) noexcept {
    if (this != &other) {
      mesh_ = std::move(other.mesh_);
      materials_ = std::move(other.materials_);
      has_uvs_ = other.has_uvs_;
      source_ = std::move(other.source_);
      bind_maps(false);
      other.bind_maps(false);
    }
    return *this;
  }

  Mesh& mesh() { return mesh_; }
  const Mesh& mesh() const { return mesh_; }

  /// Per-corner texture coordinates ("h:uv"); meaningful only when has_uvs(). A deferred map is
  /// added here, once, even on a const mesh (safe when several threads ask at once; it adds a
  /// property to mesh(), which a thread looking a property up by name at that moment must not race).
  UV_map uv_map() const {
    if (!uv_bound_.load(std::memory_order_acquire)) add_uv_map();
    return uv_;
  }
  /// Whether the "h:uv" map is there (false only while deferred, see the file comment).
  bool has_uv_map() const { return uv_bound_.load(std::memory_order_acquire); }
  /// Per-face material index ("f:material").
  Material_map material_map() const { return material_; }

  Point_2 uv(halfedge_descriptor h) const { return uv_map()[h]; }
  void set_uv(halfedge_descriptor h, const Point_2& p) { uv_map()[h] = p; }
  int material(face_descriptor f) const { return material_[f]; }

  /// True when every face carries texture coordinates.
  bool has_uvs() const { return has_uvs_; }
  void set_has_uvs(bool b) {
    if (b) (void)uv_map();
    has_uvs_ = b;
  }

  std::vector<Material>& materials() { return materials_; }
  const std::vector<Material>& materials() const { return materials_; }

  /// The file this mesh was read from (empty when built in memory); used in error messages.
  const std::string& source() const { return source_; }
  void set_source(std::string s) { source_ = std::move(s); }

  /// Removes everything (mesh, maps' content, materials).
  void clear() {
    mesh_.clear();
    materials_.clear();
    has_uvs_ = false;
    source_.clear();
    bind_maps(true);
  }

private:
  /// Binds the maps mesh_ has, adding "f:material" when missing and "h:uv" when missing and
  /// `with_uv_map`.
  void bind_maps(bool with_uv_map) {
    const auto found = mesh_.property_map<halfedge_descriptor, Point_2>("h:uv");
    if (found.second)
      uv_ = found.first;
    else if (with_uv_map)
      uv_ = mesh_.add_property_map<halfedge_descriptor, Point_2>("h:uv", Point_2(0, 0)).first;
    else
      uv_ = UV_map();
    uv_bound_.store(found.second || with_uv_map, std::memory_order_release);
    material_ = mesh_.add_property_map<face_descriptor, int>("f:material", 0).first;
  }
  /// Adds the deferred "h:uv" map (uv_map()).
  void add_uv_map() const {
    std::lock_guard<std::mutex> lock(uv_mutex_);
    if (uv_bound_.load(std::memory_order_relaxed)) return;
    uv_ = const_cast<Mesh&>(mesh_).add_property_map<halfedge_descriptor, Point_2>("h:uv", Point_2(0, 0)).first;
    uv_bound_.store(true, std::memory_order_release);
  }

  Mesh mesh_;
  mutable UV_map uv_;
  mutable std::atomic<bool> uv_bound_{false};
  mutable std::mutex uv_mutex_;
  Material_map material_;
  std::vector<Material> materials_;
  bool has_uvs_ = false;
  std::string source_;
};

}  // namespace CMGeom

#endif  // CMGEOM_MESH_IO_TEXTURED_MESH_H

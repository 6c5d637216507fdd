// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Deformable Compact Model (thesis chapter 6, §6.2-6.4): Deformable_compact_model and
// Deformable_reconstruction. The base is deformed by any BaseDeformer (Base_deformers.h); every
// base vertex gets the least-squares affine map T_i of its 1-ring (§6.3, Local_deformations.h) and
// every reconstructed point becomes sum_i W_i(p) T_i(Phi(p)) with the blend weights of the
// reconstruction (§6.4). Key choice: the transfer runs inside the CM reconstruction
// (CM::Reconstruction_options::vertex_maps), so regular and adaptive subdivision, sharp-edge
// points, texture coordinates and thread-independent output carry over unchanged, and nothing is
// stored per reconstructed point. Deformable_reconstruction keeps a rest reconstruction with its
// weights, so a further pose only blends the local maps (the cost model of §6.5).
//
// Manual: doc/Deformable_compact_model/README.md, "Headers".
#ifndef CMGEOM_DEFORMABLE_COMPACT_MODEL_DEFORMABLE_COMPACT_MODEL_H
#define CMGEOM_DEFORMABLE_COMPACT_MODEL_DEFORMABLE_COMPACT_MODEL_H

#include <CMGeom/Compact_model/Compact_model.h>
#include <CMGeom/Compact_model/reconstruct.h>
#include <CMGeom/Deformable_compact_model/Local_deformations.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace CMGeom {
namespace DCM {

class Deformable_compact_model {
public:
  /// Keeps a reference to `m` (which must outlive this object) and prepares the local
  /// deformations; the initial pose is the rest pose (identity maps).
  explicit Deformable_compact_model(const CM::Compact_model& m,
                                    const Local_deformation_options& opt = Local_deformation_options())
      : m_(m), solver_(m, opt) {
    m.validate();
    set_deformed_base(m.vertices);
  }

  const CM::Compact_model& model() const { return m_; }
  /// Rest positions of the base vertices (what a BaseDeformer binds).
  const std::vector<Vec3>& base_vertices() const { return m_.vertices; }
  const Local_deformation_solver& solver() const { return solver_; }

  /// Sets the deformed base (one position per base vertex) and computes the local maps (§6.3).
  void set_deformed_base(const std::vector<Vec3>& deformed) {
    solver_.compute(deformed, maps_);
    deformed_ = deformed;
  }
  /// Runs a bound BaseDeformer's current pose and sets it (see Base_deformers.h).
  template <class BaseDeformer>
  void deform(const BaseDeformer& d) {
    std::vector<Vec3> out;
    d.deform(out);
    set_deformed_base(out);
  }
  const std::vector<Vec3>& deformed_base() const { return deformed_; }
  const std::vector<Vertex_affine_map>& vertex_maps() const { return maps_; }

  /// Deformed regular reconstruction at `level` (§4.5.2 + §6.4).
  template <class Traits = CM::Quadric_surface_traits>
  CM::Reconstruction reconstruct_regular(int level, CM::Reconstruction_options opt = CM::Reconstruction_options(),
                                         const Traits& traits = Traits()) const {
    opt.vertex_maps = &maps_;
    return CM::reconstruct_regular(m_, level, opt, traits);
  }
  /// The same into `out`, reusing its memory (one call per frame allocates nothing once `out`
  /// has the right size).
  template <class Traits = CM::Quadric_surface_traits>
  void reconstruct_regular(int level, CM::Reconstruction& out,
                           CM::Reconstruction_options opt = CM::Reconstruction_options(),
                           const Traits& traits = Traits()) const {
    opt.vertex_maps = &maps_;
    CM::reconstruct_regular(m_, level, out, opt, traits);
  }
  /// The same by a Regular_reconstructor of this model (which keeps the base's topology, frames
  /// and, made with `vertex_maps` set in its options, the blend's weight tables between poses);
  /// `opt.projection` is the reconstructor's. \throws Invalid_input if `rec` is of another model.
  template <class Traits>
  void reconstruct_regular(const CM::Regular_reconstructor<Traits>& rec, CM::Reconstruction& out,
                           CM::Reconstruction_options opt = CM::Reconstruction_options()) const {
    rec.reconstruct(out, for_reconstructor(rec, opt));
  }
  /// Only the points and normals of `out`, which holds the regular reconstruction of this model
  /// at `rec`'s level already (from an earlier pose): its triangles, base faces and texture
  /// coordinates do not depend on the pose. Per frame of an animation, after one
  /// reconstruct_regular(rec, out). \throws Invalid_input if `rec` is of another model or the
  /// sizes of `out` are not its level's.
  template <class Traits>
  void reconstruct_regular_points(const CM::Regular_reconstructor<Traits>& rec, CM::Reconstruction& out,
                                  CM::Reconstruction_options opt = CM::Reconstruction_options()) const {
    rec.reconstruct_points(out, for_reconstructor(rec, opt));
  }
  /// Deformed adaptive reconstruction (§4.5.2 + §6.4); `criterion` sees deformed samples.
  template <class Criterion, class Traits = CM::Quadric_surface_traits>
  CM::Reconstruction reconstruct_adaptive(const Criterion& criterion, int max_level,
                                          CM::Reconstruction_options opt = CM::Reconstruction_options(),
                                          const Traits& traits = Traits()) const {
    opt.vertex_maps = &maps_;
    return CM::reconstruct_adaptive(m_, criterion, max_level, opt, traits);
  }

  /// Memory held for the deformation beyond the CM itself (rings, inverses, maps, pose), bytes.
  std::size_t bytes() const {
    return solver_.bytes() + maps_.size() * sizeof(Vertex_affine_map) + deformed_.size() * sizeof(Vec3);
  }

private:
  template <class Traits>
  CM::Reconstruction_options for_reconstructor(const CM::Regular_reconstructor<Traits>& rec,
                                               CM::Reconstruction_options opt) const {
    if (&rec.model() != &m_)
      throw Invalid_input("deformable compact model: the reconstructor is of another compact model");
    opt.projection = rec.projection();
    opt.vertex_maps = &maps_;
    return opt;
  }

  const CM::Compact_model& m_;
  Local_deformation_solver solver_;
  std::vector<Vertex_affine_map> maps_;
  std::vector<Vec3> deformed_;
};

/// A regular reconstruction kept at rest with the blend of §6.4 (which base vertices and weights
/// every point takes), so that a new pose costs only the blend of the local maps (no projection
/// onto the local surfaces): the "local affinity computations" of the thesis' cost model (§6.5),
/// O(R) per pose for R points. The result is bit-identical to
/// Deformable_compact_model::reconstruct_regular (same Φ(p), same weights, same arithmetic).
/// The blend is not stored per point: the points of a base edge or face are consecutive in the
/// output and share their base vertices, and their weights depend only on the grid position, so
/// one table per level serves every edge and face (CM::internal::apply_shared_vertex_maps, four
/// points at a time with AVX; apply_vertex_maps_across, four edges or faces at a time, where they
/// hold fewer than four points: levels 1 and 2, and the base vertices). Memory: the rest points
/// and normals (48 bytes per point), the base edges and faces (8 and 12 bytes each) and the
/// weight tables (O(4^level) bytes).
class Deformable_reconstruction {
public:
  /// Reconstructs `m` at `level` at rest (CM::reconstruct_regular) and records the blend.
  template <class Traits = CM::Quadric_surface_traits>
  Deformable_reconstruction(const CM::Compact_model& m, int level,
                            CM::Reconstruction_options opt = CM::Reconstruction_options(),
                            const Traits& traits = Traits())
      // reconstruct_regular() checks the level before the weight tables are made
      : parallel_(opt.parallel),
        rest_(CM::reconstruct_regular(m, level, without_maps(opt), traits)),
        weights_(std::size_t(1) << level) {
    // Same layout and the same weights as CM::reconstruct_regular's evaluator.
    const CM::internal::Base_topology topo(m);
    vertices_ = m.vertices.size();
    edges_.reserve(2 * topo.edges.size());
    for (const auto& e : topo.edges) edges_.insert(edges_.end(), {e.a, e.b});
    faces_.reserve(3 * m.faces.size());
    for (const auto& f : m.faces) faces_.insert(faces_.end(), {f[0].vertex, f[1].vertex, f[2].vertex});
  }

  const CM::Reconstruction& rest() const { return rest_; }
  std::size_t number_of_points() const { return rest_.points.size(); }

  /// Deformed points and normals for the maps of one pose (one per base vertex); `out` gets the
  /// rest triangles, base faces and uvs the first time (or when it does not match).
  /// \throws CMGeom::Invalid_input if `maps` does not hold one map per base vertex.
  void deform(const std::vector<Vertex_affine_map>& maps, CM::Reconstruction& out) const {
    if (maps.size() != vertices_)
      throw Invalid_input("deformable reconstruction: " + std::to_string(maps.size()) + " vertex maps for " +
                          std::to_string(vertices_) + " base vertices");
    const std::size_t R = rest_.points.size();
    if (out.triangles.size() != rest_.triangles.size() || out.points.size() != R) {
      out = rest_;
    }
    const std::size_t per_edge = weights_.n - 1, per_face = weights_.face.size() / 3;
    const std::size_t E = edges_.size() / 2, F = per_face > 0 ? faces_.size() / 3 : 0;
    const std::size_t edge_base = vertices_, face_base = vertices_ + E * per_edge;
    const CM::Vec3* rp = rest_.points.data();
    const CM::Vec3* rn = rest_.normals.data();
    CM::Vec3* op = out.points.data();
    CM::Vec3* on = out.normals.data();
    // Base vertices (weight 1), then base edges and faces (each a run of consecutive points that
    // share their maps), in tasks of about 256 points. A run of four points or more is mapped
    // four points at a time (apply_shared_vertex_maps), shorter runs four runs at a time
    // (apply_vertex_maps_across: base vertices, and the edges and faces of levels 1 and 2).
    constexpr std::size_t points_per_task = 256;
    auto per_task = [](std::size_t per) {  // elements per task, a multiple of 4
      return std::max<std::size_t>(4, points_per_task / std::max<std::size_t>(1, per) / 4 * 4);
    };
    const std::size_t vertices_per_task = points_per_task, edges_per_task = per_task(per_edge),
                      faces_per_task = per_task(per_face);
    const std::size_t vertex_tasks = (vertices_ + vertices_per_task - 1) / vertices_per_task;
    const std::size_t edge_tasks = per_edge > 0 ? (E + edges_per_task - 1) / edges_per_task : 0;
    const std::size_t face_tasks = (F + faces_per_task - 1) / faces_per_task;
    const double one = 1.;
    CM::internal::for_range(vertex_tasks + edge_tasks + face_tasks, parallel_, [&](std::size_t t) {
      if (t < vertex_tasks) {
        const std::size_t first = t * vertices_per_task, count = std::min(vertices_, first + vertices_per_task) - first;
        const auto vertex = [first](std::size_t e, int) { return std::uint32_t(first + e); };
        CM::internal::apply_vertex_maps_across<1>(maps, vertex, count, 1, &one, rp + first, rn + first, op + first,
                                                  on + first);
      } else if (t < vertex_tasks + edge_tasks) {
        const std::size_t first = (t - vertex_tasks) * edges_per_task;
        blend_elements<2>(maps, edges_.data(), weights_.edge.data(), first, std::min(E, first + edges_per_task),
                          per_edge, edge_base, rp, rn, op, on);
      } else {
        const std::size_t first = (t - vertex_tasks - edge_tasks) * faces_per_task;
        blend_elements<3>(maps, faces_.data(), weights_.face.data(), first, std::min(F, first + faces_per_task),
                          per_face, face_base, rp, rn, op, on);
      }
    });
  }
  void deform(const Deformable_compact_model& dcm, CM::Reconstruction& out) const { deform(dcm.vertex_maps(), out); }

  /// Memory held per pose-independent data (rest points and normals, base edges and faces,
  /// weight tables), bytes.
  std::size_t bytes() const {
    return rest_.points.size() * 2 * sizeof(Vec3) + (edges_.size() + faces_.size()) * sizeof(std::uint32_t) +
           weights_.bytes();
  }

private:
  static CM::Reconstruction_options without_maps(CM::Reconstruction_options opt) {
    opt.vertex_maps = nullptr;
    return opt;
  }
  // The blend of base edges or faces (K = 2 or 3 base vertices each, corners[K e ..]) first ..
  // last-1, whose `per` points each start at base + per e: a run of four points or more four
  // points at a time, shorter runs four runs at a time.
  template <int K>
  static void blend_elements(const std::vector<Vertex_affine_map>& maps, const std::uint32_t* corners, const double* w,
                             std::size_t first, std::size_t last, std::size_t per, std::size_t base, const CM::Vec3* rp,
                             const CM::Vec3* rn, CM::Vec3* op, CM::Vec3* on) {
    if (per < 4) {
      const std::size_t id = base + first * per;
      const auto corner = [corners, first](std::size_t e, int c) { return corners[K * (first + e) + c]; };
      CM::internal::apply_vertex_maps_across<K>(maps, corner, last - first, per, w, rp + id, rn + id, op + id, on + id);
      return;
    }
    for (std::size_t e = first; e < last; ++e) {
      const std::size_t i = base + e * per;
      CM::internal::apply_shared_vertex_maps<K>(maps, corners + K * e, w, per, rp + i, rn + i, op + i, on + i);
    }
  }

  bool parallel_;
  std::size_t vertices_ = 0;
  CM::Reconstruction rest_;
  std::vector<std::uint32_t> edges_;         // 2 base vertices per base edge
  std::vector<std::uint32_t> faces_;         // 3 base vertices per base face
  CM::internal::Map_weight_tables weights_;  // of this level
};

}  // namespace DCM
}  // namespace CMGeom

#endif  // CMGEOM_DEFORMABLE_COMPACT_MODEL_DEFORMABLE_COMPACT_MODEL_H

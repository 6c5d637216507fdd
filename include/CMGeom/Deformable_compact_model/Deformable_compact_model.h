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
  const CM::Compact_model& m_;
  Local_deformation_solver solver_;
  std::vector<Vertex_affine_map> maps_;
  std::vector<Vec3> deformed_;
};

/// A regular reconstruction kept at rest with, for every point, the base vertices and blend
/// weights of §6.4, so that a new pose costs only the blend of the local maps (no projection onto
/// the local surfaces): the "local affinity computations" of the thesis' cost model (§6.5),
/// O(R) per pose for R points. The result is bit-identical to
/// Deformable_compact_model::reconstruct_regular (same Φ(p), same weights, same arithmetic).
/// Memory: the rest points and normals (48 bytes) and 3 indices and weights (36 bytes) per point.
class Deformable_reconstruction {
public:
  /// Reconstructs `m` at `level` at rest (CM::reconstruct_regular) and records the blend.
  template <class Traits = CM::Quadric_surface_traits>
  Deformable_reconstruction(const CM::Compact_model& m, int level,
                            CM::Reconstruction_options opt = CM::Reconstruction_options(),
                            const Traits& traits = Traits())
      : parallel_(opt.parallel) {
    opt.vertex_maps = nullptr;
    rest_ = CM::reconstruct_regular(m, level, opt, traits);
    // Same layout and the same weight arithmetic as CM::reconstruct_regular's evaluator.
    const CM::internal::Base_topology topo(m);
    const std::size_t n = std::size_t(1) << level, V = m.vertices.size(), E = topo.edges.size();
    const std::size_t per_edge = n - 1, per_face = n > 1 ? (n - 1) * (n - 2) / 2 : 0;
    const std::size_t R = rest_.points.size();
    corner_.assign(R, {0, 0, 0});
    weight_.assign(R, {0., 0., 0.});
    for (std::size_t i = 0; i < V; ++i) {
      corner_[i] = {std::uint32_t(i), 0, 0};
      weight_[i] = {1., 0., 0.};
    }
    for (std::size_t e = 0; e < E; ++e)
      for (std::size_t k = 1; k < n; ++k) {
        const double t = double(k) / double(n);
        const double wa = (1. - t) * (1. - t) * (1. - t), wb = t * t * t, sum = wa + wb;
        const std::size_t id = V + e * per_edge + k - 1;
        corner_[id] = {topo.edges[e].a, topo.edges[e].b, 0};
        weight_[id] = {wa / sum, wb / sum, 0.};
      }
    const std::size_t face_base = V + E * per_edge;
    for (std::size_t f = 0; f < m.faces.size(); ++f)
      for (std::size_t j = 1; j + 1 < n; ++j)
        for (std::size_t i = 1; i + j < n; ++i) {
          const double a1 = double(i) / double(n), a2 = double(j) / double(n), a0 = double(n - i - j) / double(n);
          const double w[3] = {a0 * a0 * a0, a1 * a1 * a1, a2 * a2 * a2};
          const double sum = w[0] + w[1] + w[2];
          const std::size_t before = (j - 1) * (n - 2) - (j - 1) * (j - 2) / 2;
          const std::size_t id = face_base + f * per_face + before + (i - 1);
          corner_[id] = {m.faces[f][0].vertex, m.faces[f][1].vertex, m.faces[f][2].vertex};
          weight_[id] = {w[0] / sum, w[1] / sum, w[2] / sum};
        }
  }

  const CM::Reconstruction& rest() const { return rest_; }
  std::size_t number_of_points() const { return rest_.points.size(); }

  /// Deformed points and normals for the maps of one pose (one per base vertex); `out` gets the
  /// rest triangles, base faces and uvs the first time (or when it does not match).
  void deform(const std::vector<Vertex_affine_map>& maps, CM::Reconstruction& out) const {
    const std::size_t R = rest_.points.size();
    if (out.triangles.size() != rest_.triangles.size() || out.points.size() != R) {
      out = rest_;
    }
    CM::internal::for_range((R + 255) / 256, parallel_, [&](std::size_t b) {
      for (std::size_t i = 256 * b; i < std::min(R, 256 * (b + 1)); ++i) {
        CM::Sample s{rest_.points[i], rest_.normals[i]};
        const int k = weight_[i][2] != 0. ? 3 : (weight_[i][1] != 0. ? 2 : 1);
        CM::internal::apply_vertex_maps(maps, k, corner_[i].data(), weight_[i].data(), s);
        out.points[i] = s.point;
        out.normals[i] = s.normal;
      }
    });
  }
  void deform(const Deformable_compact_model& dcm, CM::Reconstruction& out) const { deform(dcm.vertex_maps(), out); }

  /// Memory held per pose-independent data (rest points, normals, corners, weights), bytes.
  std::size_t bytes() const {
    return rest_.points.size() * 2 * sizeof(Vec3) + corner_.size() * sizeof(corner_[0]) +
           weight_.size() * sizeof(weight_[0]);
  }

private:
  bool parallel_;
  CM::Reconstruction rest_;
  std::vector<std::array<std::uint32_t, 3>> corner_;
  std::vector<std::array<double, 3>> weight_;
};

}  // namespace DCM
}  // namespace CMGeom

#endif  // CMGEOM_DEFORMABLE_COMPACT_MODEL_DEFORMABLE_COMPACT_MODEL_H

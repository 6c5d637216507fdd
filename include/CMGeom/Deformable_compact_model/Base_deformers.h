// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Deformers of a Compact Model's base (thesis §6.1: any kind of deformation can be applied to the
// CM): the BaseDeformer concept (bind(rest) once, deform(out) per pose, weights_bytes()) and its
// models Affine_deformer, Vertex_moves_deformer, Pointwise_deformer and Cage_deformer (one cage with
// any CageCoordinates model); Cage_system_deformer.h adds a *Cages system. A deformer only sees the
// base vertices; Deformable_compact_model carries the result to the reconstruction (§6.3-6.4).
// The pose is state of the deformer, set through its own members. Complexity: bind O(N) (Cage_deformer
// O(N K)); deform O(N) (Cage_deformer O(N K)).
//
// Manual: doc/Deformable_compact_model/README.md, "Headers".
#ifndef CMGEOM_DEFORMABLE_COMPACT_MODEL_BASE_DEFORMERS_H
#define CMGEOM_DEFORMABLE_COMPACT_MODEL_BASE_DEFORMERS_H

#include <CMGeom/Cage_deformation/Cage_binding.h>
#include <CMGeom/Cage_deformation/Cage_coordinates.h>
#include <CMGeom/Compact_model/Compact_model.h>
#include <CMGeom/Error.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace DCM {

using CM::Vec3;

/// x -> A x + b (A row-major). Affine maps are reproduced exactly by the deformable CM where
/// the 1-rings are not flat (§6.1 linear reproduction; see Local_deformations.h). The map must be
/// finite and invertible: a singular A (|det A| at most 1e-12 times the cube of its largest entry)
/// flattens the model, every face of the reconstruction degenerate, and is refused (Invalid_input).
class Affine_deformer {
public:
  Affine_deformer() = default;
  Affine_deformer(const std::array<std::array<double, 3>, 3>& A, const Vec3& b) { set_map(A, b); }
  void set_map(const std::array<std::array<double, 3>, 3>& A, const Vec3& b) {
    double largest = 0;
    for (const auto& row : A)
      for (double a : row) {
        if (!std::isfinite(a)) throw Invalid_input("Affine_deformer: the map has a non-finite entry");
        largest = (std::max)(largest, std::abs(a));
      }
    if (!std::isfinite(b.x) || !std::isfinite(b.y) || !std::isfinite(b.z))
      throw Invalid_input("Affine_deformer: the map has a non-finite entry");
    const double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                       A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                       A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    if (!(std::abs(det) > 1e-12 * largest * largest * largest))
      throw Invalid_input("Affine_deformer: the map's linear part is singular (determinant " + std::to_string(det) +
                          "): it would flatten the model, every face degenerate");
    A_ = A;
    b_ = b;
  }
  void bind(const std::vector<Vec3>& rest) { rest_ = rest; }
  void deform(std::vector<Vec3>& out) const {
    out.resize(rest_.size());
    for (std::size_t i = 0; i < rest_.size(); ++i) out[i] = apply(rest_[i]);
  }
  Vec3 apply(const Vec3& p) const {
    return Vec3(A_[0][0] * p.x + A_[0][1] * p.y + A_[0][2] * p.z + b_.x,
                A_[1][0] * p.x + A_[1][1] * p.y + A_[1][2] * p.z + b_.y,
                A_[2][0] * p.x + A_[2][1] * p.y + A_[2][2] * p.z + b_.z);
  }
  std::size_t weights_bytes() const { return 0; }

private:
  std::array<std::array<double, 3>, 3> A_{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  Vec3 b_{0, 0, 0};
  std::vector<Vec3> rest_;
};

/// Direct manipulation: chosen base vertices are moved to given positions, the others stay.
/// (Any smoother surface-based editing can produce its own full pose and use a
/// Pointwise_deformer or pass the positions to Deformable_compact_model::set_deformed_base.)
class Vertex_moves_deformer {
public:
  /// Moves base vertex `v` to `p` (replaces an earlier move of v).
  void move(std::uint32_t v, const Vec3& p) { moves_[v] = p; }
  void clear() { moves_.clear(); }
  const std::map<std::uint32_t, Vec3>& moves() const { return moves_; }
  void bind(const std::vector<Vec3>& rest) { rest_ = rest; }
  void deform(std::vector<Vec3>& out) const {
    out = rest_;
    for (const auto& m : moves_) {
      if (m.first >= out.size())
        throw Invalid_input("vertex move: base vertex " + std::to_string(m.first) + " does not exist (" +
                            std::to_string(out.size()) + " base vertices)");
      out[m.first] = m.second;
    }
  }
  std::size_t weights_bytes() const { return 0; }

private:
  std::map<std::uint32_t, Vec3> moves_;
  std::vector<Vec3> rest_;
};

/// Any function object `Vec3 f(const Vec3&) const` applied to every base vertex.
template <class Function>
class Pointwise_deformer {
public:
  explicit Pointwise_deformer(Function f = Function()) : f_(f) {}
  void bind(const std::vector<Vec3>& rest) { rest_ = rest; }
  void deform(std::vector<Vec3>& out) const {
    out.resize(rest_.size());
    for (std::size_t i = 0; i < rest_.size(); ++i) out[i] = f_(rest_[i]);
  }
  std::size_t weights_bytes() const { return 0; }

private:
  Function f_;
  std::vector<Vec3> rest_;
};

/// One cage (thesis chapter 5): the base vertices are bound once with a CageCoordinates model
/// (mean value, Green, harmonic); set_pose() gives the deformed cage vertices (same order as the
/// rest cage); deform() is one dense product with the stored coordinates.
template <class Coordinates, class Weight = double>
class Cage_deformer {
public:
  explicit Cage_deformer(const Coordinates& coords,
                         const Cage_deformation::Binding_options& opt = Cage_deformation::Binding_options())
      : coords_(coords), opt_(opt), pose_(coords.cage().vertices) {}
  /// Deformed cage vertices (same number and order as the rest cage's).
  void set_pose(const std::vector<Cage_deformation::Vec3>& deformed_cage_vertices) {
    if (deformed_cage_vertices.size() != coords_.cage().vertices.size())
      throw Invalid_input("cage pose has " + std::to_string(deformed_cage_vertices.size()) +
                          " vertices, the cage has " + std::to_string(coords_.cage().vertices.size()));
    pose_ = deformed_cage_vertices;
  }
  void bind(const std::vector<Vec3>& rest) {
    std::vector<Cage_deformation::Vec3> pts(rest.size());
    for (std::size_t i = 0; i < rest.size(); ++i) pts[i] = {rest[i].x, rest[i].y, rest[i].z};
    binding_ = Cage_deformation::bind_points<Weight>(coords_, pts, opt_);
  }
  void deform(std::vector<Vec3>& out) const {
    std::vector<Cage_deformation::Vec3> basis, moved;
    basis.reserve(coords_.number_of_coordinates());
    coords_.deformation_rule()(pose_, std::back_inserter(basis));
    binding_.deform(basis, moved);
    out.resize(moved.size());
    for (std::size_t i = 0; i < moved.size(); ++i) out[i] = Vec3(moved[i][0], moved[i][1], moved[i][2]);
  }
  std::size_t weights_bytes() const { return binding_.weights_bytes(); }
  const Cage_deformation::Cage_binding<Weight>& binding() const { return binding_; }

private:
  Coordinates coords_;
  Cage_deformation::Binding_options opt_;
  std::vector<Cage_deformation::Vec3> pose_;
  Cage_deformation::Cage_binding<Weight> binding_;
};

}  // namespace DCM
}  // namespace CMGeom

#endif  // CMGEOM_DEFORMABLE_COMPACT_MODEL_BASE_DEFORMERS_H

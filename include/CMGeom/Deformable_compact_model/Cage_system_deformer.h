// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Cage_system_deformer: the BaseDeformer (Base_deformers.h) of a *Cages system (thesis §5.3,
// Cage_deformation/Cage_system.h), so that a deformable CM can be driven by several joined cages
// (§6.1 "any kind of deformation"). It is a thin adapter: bind() binds the base vertices with
// Cage_system::bind (sparse rows over the system's global basis, join terms where d_i < 1),
// set_pose() takes the deformed vertices of every cage (description order, internal cages
// included) and propagates them down the hierarchy, deform() is one sparse product.
//
// Complexity: bind as Cage_system::bind for the V base vertices; deform O(nnz) plus the basis
// (O(sum of cage sizes)).
#ifndef CMGEOM_DEFORMABLE_COMPACT_MODEL_CAGE_SYSTEM_DEFORMER_H
#define CMGEOM_DEFORMABLE_COMPACT_MODEL_CAGE_SYSTEM_DEFORMER_H

#include <CMGeom/Cage_deformation/Cage_system.h>
#include <CMGeom/Compact_model/Compact_model.h>
#include <CMGeom/Error.h>

#include <string>
#include <vector>

namespace CMGeom {
namespace DCM {

template <class Weight = double, class F = Cage_deformation::Sine_smoothing,
          class Fh = Cage_deformation::Sine_h_smoothing>
class Cage_system_deformer {
public:
  /// Keeps a reference to `system` (which must outlive the deformer); the initial pose is the
  /// description's own deformed cages.
  explicit Cage_system_deformer(const Cage_deformation::Cage_system& system, const F& f = F(), const Fh& fh = Fh())
      : sys_(system), f_(f), fh_(fh), leaf_pose_(system.deformed_leaf_vertices()) {}

  /// Deformed vertices of every cage of the system (description order).
  void set_pose(const std::vector<std::vector<Cage_deformation::Vec3>>& deformed_cages) {
    if (deformed_cages.size() != sys_.number_of_cages())
      throw Invalid_input("cage-system pose has " + std::to_string(deformed_cages.size()) + " cages, the system has " +
                          std::to_string(sys_.number_of_cages()));
    for (std::size_t c = 0; c < deformed_cages.size(); ++c)
      if (deformed_cages[c].size() != sys_.description().cages[c].rest.vertices.size())
        throw Invalid_input("cage-system pose: cage " + std::to_string(c) + " has " +
                            std::to_string(deformed_cages[c].size()) + " vertices, its rest cage " +
                            std::to_string(sys_.description().cages[c].rest.vertices.size()));
    leaf_pose_ = sys_.deformed_leaf_vertices(deformed_cages);
  }
  void bind(const std::vector<CM::Vec3>& rest) {
    std::vector<Cage_deformation::Vec3> pts(rest.size());
    for (std::size_t i = 0; i < rest.size(); ++i) pts[i] = {rest[i].x, rest[i].y, rest[i].z};
    binding_ = sys_.template bind<Weight>(pts, f_, fh_);
  }
  void deform(std::vector<CM::Vec3>& out) const {
    std::vector<Cage_deformation::Vec3> moved;
    binding_.deform(sys_.basis(leaf_pose_), moved);
    out.resize(moved.size());
    for (std::size_t i = 0; i < moved.size(); ++i) out[i] = CM::Vec3(moved[i][0], moved[i][1], moved[i][2]);
  }
  std::size_t weights_bytes() const { return binding_.weights_bytes(); }
  const Cage_deformation::Cage_system_binding<Weight>& binding() const { return binding_; }

private:
  const Cage_deformation::Cage_system& sys_;
  F f_;
  Fh fh_;
  std::vector<Cage_deformation::Vec3> leaf_pose_;
  Cage_deformation::Cage_system_binding<Weight> binding_;
};

}  // namespace DCM
}  // namespace CMGeom

#endif  // CMGEOM_DEFORMABLE_COMPACT_MODEL_CAGE_SYSTEM_DEFORMER_H

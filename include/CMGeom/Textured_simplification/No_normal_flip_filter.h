// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// No_normal_flip_filter: a model of CGAL's `PlacementFilter` concept that vetoes a collapse when
// a surviving triangle of the edge's star would flip (or collapse to zero area) at the proposed
// placement — the fold-over rule of thesis §3.4.2/§3.5 ("the orthogonal projection ... overlap").
// CMGeom's engine applies the same test itself; pass this filter when running the policies under
// CGAL's `edge_collapse`, whose own test only bounds dihedral angles between link triangles.
// It can wrap another filter (applied first), like CGAL's Bounded_normal_change_filter.
//
// Complexity: O(deg(v0) + deg(v1)) per call, no allocation.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_NO_NORMAL_FLIP_FILTER_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_NO_NORMAL_FLIP_FILTER_H

#include <CMGeom/config.h>
#include <CMGeom/Textured_simplification/internal/collapse_checks.h>

namespace CMGeom {
namespace Textured_simplification {

/// The identity filter (accepts every placement).
struct Identity_filter {
  template <class Profile, class Placement>
  Placement operator()(const Profile&, const Placement& p) const {
    return p;
  }
};

/// Vetoes fold-overs (see the file comment). \tparam BaseFilter a `PlacementFilter` applied first.
template <class BaseFilter = Identity_filter>
class No_normal_flip_filter {
public:
  No_normal_flip_filter(const BaseFilter& base = BaseFilter()) : base_(base) {}

  template <class Profile, class Placement>
  Placement operator()(const Profile& profile, const Placement& placement) const {
    Placement p = base_(profile, placement);
    if (!p) return p;
    if (internal::collapse_flips_a_face(profile.surface_mesh(), profile.vertex_point_map(), profile.v0_v1(),
                                        internal::to_vec3(*p)))
      return Placement();
    return p;
  }

private:
  BaseFilter base_;
};

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_NO_NORMAL_FLIP_FILTER_H

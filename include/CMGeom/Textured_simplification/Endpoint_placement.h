// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Endpoint_placement: a GetPlacement policy (CGAL's concept) that keeps the kept vertex on one of
// the collapsed edge's endpoints, the one with the lower cost under a wrapped GetCost policy. The
// simplified mesh's vertices are then input vertices, which Compact Model bases need (thesis §4.3
// snaps new vertices to input points afterwards; snapping during the collapse lets the engine's
// fold-over test see the final position).
//
// Complexity: two cost evaluations per call.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_ENDPOINT_PLACEMENT_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_ENDPOINT_PLACEMENT_H

#include <CMGeom/config.h>

namespace CMGeom {
namespace Textured_simplification {

/// Of the two endpoints, the one `Cost` finds cheaper (the first on ties); none when the cost is
/// absent at both.
template <class Cost>
struct Endpoint_placement {
  Cost cost;
  template <class Profile>
  auto operator()(const Profile& profile) const -> CMGeom::internal::optional<typename Profile::Point> {
    using Point = typename Profile::Point;
    const auto c0 = cost(profile, CMGeom::internal::optional<Point>(profile.p0()));
    const auto c1 = cost(profile, CMGeom::internal::optional<Point>(profile.p1()));
    if (!c0 && !c1) return CMGeom::internal::optional<Point>();
    if (!c1 || (c0 && *c0 <= *c1)) return CMGeom::internal::optional<Point>(profile.p0());
    return CMGeom::internal::optional<Point>(profile.p1());
  }
};

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_ENDPOINT_PLACEMENT_H

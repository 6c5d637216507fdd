// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Error-driven adaptive reconstruction of a Compact Model (a CMGeom addition to §4.5.2):
// Chord_error_criterion, chord_deviation() and reconstruct_to_vertex_budget(). The criteria of
// §4.5.2 say where to refine, not how far the output is from the surface; here an edge (p1, p2)
// is halved when its chord's midpoint is estimated farther than `tolerance` from the blended
// surface Phi, by |(d . n2) n2 - (d . n1) n1| / 8 (d the chord, n1, n2 the blended end normals:
// the cubic Hermite curve with the projected chord as end tangents), which is first order in the
// turning angle, 0 on a plane, and needs no evaluation at the midpoint.
// reconstruct_to_vertex_budget() bisects log(tolerance) and returns the largest output within a
// vertex budget. The error is measured against Phi, not the input (which the CM no longer has).
//
// Manual: doc/Compact_model/README.md, "Error-driven adaptive reconstruction (CMGeom addition to §4.5.2)".
#ifndef CMGEOM_COMPACT_MODEL_ERROR_CRITERION_H
#define CMGEOM_COMPACT_MODEL_ERROR_CRITERION_H

#include <CMGeom/Compact_model/reconstruct.h>
#include <CMGeom/Error.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

namespace CMGeom {
namespace CM {

/// Estimated distance between the midpoint of the chord (a.point, b.point) and the surface,
/// from the end points and their unit normals (see the file comment).
inline double chord_deviation(const Sample& a, const Sample& b) {
  const Vec3 d = b.point - a.point;
  const Vec3 dev = internal::dot(d, b.normal) * b.normal - internal::dot(d, a.normal) * a.normal;
  const double e = internal::length(dev) / 8.;
  return std::isfinite(e) ? e : 0.;
}

/// Adaptive criterion (§4.5.2 interface): halve an edge whose chord is estimated farther than
/// `tolerance` from the surface (absolute, in model units).
struct Chord_error_criterion {
  double tolerance;
  bool operator()(const Sample& a, const Sample& b) const { return chord_deviation(a, b) > tolerance; }
};

/// What reconstruct_to_vertex_budget() found.
struct Vertex_budget_result {
  Reconstruction reconstruction;
  double tolerance = 0.;    ///< the Chord_error_criterion tolerance of `reconstruction`
  int reconstructions = 0;  ///< adaptive reconstructions run
};

/// Adaptive reconstruction with Chord_error_criterion whose tolerance is chosen so that the
/// output has at most `max_vertices` points, as many as `iterations` bisection steps on
/// log(tolerance) find (see the file comment). `max_level` bounds the halvings of a base edge.
/// When even the base mesh exceeds the budget, the result is the base (level 0). Throws
/// Invalid_input for a budget of 0 or fewer than 1 iteration.
template <class Traits = Quadric_surface_traits>
Vertex_budget_result reconstruct_to_vertex_budget(const Compact_model& m, std::size_t max_vertices, int max_level,
                                                  const Reconstruction_options& opt = Reconstruction_options(),
                                                  const Traits& traits = Traits(), int iterations = 24) {
  if (max_vertices == 0) throw Invalid_input("reconstruct_to_vertex_budget: the budget must be at least 1 vertex");
  if (iterations < 1) throw Invalid_input("reconstruct_to_vertex_budget: at least 1 iteration");
  // Scale of the model: the diagonal of its base vertices' box.
  Vec3 lo = m.vertices.empty() ? Vec3() : m.vertices[0], hi = lo;
  for (const Vec3& v : m.vertices) {
    lo = Vec3(std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z));
    hi = Vec3(std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z));
  }
  const double scale = std::max(internal::length(hi - lo), 1e-300);
  Vertex_budget_result best;
  bool have = false;
  int runs = 0;
  auto run = [&](double tol) {
    Reconstruction r = reconstruct_adaptive(m, Chord_error_criterion{tol}, max_level, opt, traits);
    ++runs;
    const bool fits = r.points.size() <= max_vertices;
    if (fits && (!have || r.points.size() > best.reconstruction.points.size() ||
                 (r.points.size() == best.reconstruction.points.size() && tol < best.tolerance))) {
      best.reconstruction = std::move(r);
      best.tolerance = tol;
      have = true;
    }
    return fits;
  };
  // Bracket: lo_t over the budget, hi_t within it.
  double lo_t = 1e-7 * scale, hi_t = scale;
  if (run(lo_t)) {  // even the finest tolerance fits the budget
    best.reconstructions = runs;
    return best;
  }
  if (!run(hi_t)) {
    // Only a base with more vertices than the budget gets here (a tolerance of the model's size
    // splits almost nothing): give the base itself.
    best.reconstruction = reconstruct_adaptive(m, Chord_error_criterion{hi_t}, 0, opt, traits);
    best.tolerance = hi_t;
    best.reconstructions = runs + 1;
    return best;
  }
  for (int i = 2; i < iterations; ++i) {
    const double mid = std::sqrt(lo_t * hi_t);
    if (run(mid))
      hi_t = mid;
    else
      lo_t = mid;
    if (hi_t / lo_t < 1.0005) break;
  }
  best.reconstructions = runs;
  return best;
}

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_ERROR_CRITERION_H

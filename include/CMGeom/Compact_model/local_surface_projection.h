// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Geometry on one local surface S(x1, x2) = v + x1 U + x2 V + h(x1, x2) N (thesis §4.4.1) and on
// the intersection of two (§4.5.1): evaluation, normal, the two projections S-bar(p) of §4.5.1
// (along N, and closest point), and the point of S^n ∩ S^m ∩ pi closest to p for points on sharp
// edges. The thesis says "Newton iteration scheme" without details; here the closest point is
// Newton on the squared distance (Gauss-Newton where the Hessian is not positive definite), never
// farther than the projection along N, and the sharp-edge point is Newton on three equations in
// R^3 started at the mean of the two projections along N, pulled back to that start when it lands
// far from the edge. Both have bounded iteration counts, so every call is O(1).
//
// Manual: doc/Compact_model/README.md, "Choices where the thesis is open (and why)".
#ifndef CMGEOM_COMPACT_MODEL_LOCAL_SURFACE_PROJECTION_H
#define CMGEOM_COMPACT_MODEL_LOCAL_SURFACE_PROJECTION_H

#include <CMGeom/Compact_model/Local_surface_traits.h>

#include <algorithm>
#include <cmath>

namespace CMGeom {
namespace CM {

/// Point S(x1, x2) in world coordinates.
template <class Traits = Quadric_surface_traits>
Vec3 surface_point(const Local_frame& f, const Local_surface& s, double x1, double x2,
                   const Traits& traits = Traits()) {
  return f.to_world(x1, x2, traits.height(s, x1, x2));
}

/// Unit normal of S at (x1, x2): N - h_x1 U - h_x2 V normalised (NS of §4.4.1 at the origin).
/// Where the derivatives are not finite (cone apex) the frame normal N is returned.
template <class Traits = Quadric_surface_traits>
Vec3 surface_normal(const Local_frame& f, const Local_surface& s, double x1, double x2,
                    const Traits& traits = Traits()) {
  double d[5];
  traits.height(s, x1, x2, d);
  if (!std::isfinite(d[0]) || !std::isfinite(d[1])) return f.N;
  return internal::normalized(f.N - d[0] * f.U - d[1] * f.V);
}

/// S-bar(p) along the frame normal: the point of S above the (U, V) coordinates of p.
template <class Traits = Quadric_surface_traits>
Vec3 project_along_normal(const Local_frame& f, const Local_surface& s, const Vec3& p,
                          const Traits& traits = Traits()) {
  const Vec3 l = f.to_local(p);
  return surface_point(f, s, l.x, l.y, traits);
}

/// S-bar(p) as the point of S closest to p (Newton, see the file comment); returns the local
/// coordinates (x1, x2) through `uv` when given.
template <class Traits = Quadric_surface_traits>
Vec3 closest_point(const Local_frame& f, const Local_surface& s, const Vec3& p, const Traits& traits = Traits(),
                   double* uv = nullptr) {
  const Vec3 l = f.to_local(p);
  double x = l.x, y = l.y;
  const double scale = 1e-13 * (std::abs(l.x) + std::abs(l.y) + std::abs(l.z) + 1e-300);
  bool ok = true;
  for (int it = 0; it < 16; ++it) {
    double d[5];
    const double h = traits.height(s, x, y, d);
    if (!std::isfinite(h) || !std::isfinite(d[0]) || !std::isfinite(d[2])) {
      ok = false;
      break;
    }
    const double r = h - l.z;
    const double g0 = (x - l.x) + r * d[0], g1 = (y - l.y) + r * d[1];
    double a = 1 + d[0] * d[0] + r * d[2], b = d[0] * d[1] + r * d[3], c = 1 + d[1] * d[1] + r * d[4];
    double det = a * c - b * b;
    if (!(a > 0 && det > 1e-300)) {  // Gauss-Newton
      a = 1 + d[0] * d[0];
      b = d[0] * d[1];
      c = 1 + d[1] * d[1];
      det = a * c - b * b;
    }
    const double dx = -(c * g0 - b * g1) / det, dy = -(a * g1 - b * g0) / det;
    x += dx;
    y += dy;
    if (std::abs(dx) + std::abs(dy) <= scale) break;
  }
  if (ok && std::isfinite(x) && std::isfinite(y)) {
    // Safeguard: Newton may run to another sheet far away; never return a point farther from p
    // than the projection along N.
    const double hx = traits.height(s, x, y), h0 = traits.height(s, l.x, l.y);
    const double dn = (x - l.x) * (x - l.x) + (y - l.y) * (y - l.y) + (hx - l.z) * (hx - l.z);
    if (!(dn <= (h0 - l.z) * (h0 - l.z))) ok = false;
  }
  if (!ok || !std::isfinite(x) || !std::isfinite(y)) {
    x = l.x;
    y = l.y;
  }
  if (uv) {
    uv[0] = x;
    uv[1] = y;
  }
  return surface_point(f, s, x, y, traits);
}

/// The point of S1 ∩ S2 ∩ pi closest to p, pi the plane through p orthogonal to the unit
/// direction `t` (§4.5.1, points on sharp edges; both frames at the edge's end vertex).
/// `converged` (optional) tells whether Newton converged; when it did not, the mean of the two
/// projections along N moved into pi (the start) is returned. A converged point farther from p
/// than reach = |p - vertex| + |start - p| is moved towards the start, reaching it at two reaches
/// (a spike guard, see the manual): the result is never farther than 1.25 reaches from p.
template <class Traits = Quadric_surface_traits>
Vec3 sharp_edge_point(const Local_frame& f1, const Local_surface& s1, const Local_frame& f2, const Local_surface& s2,
                      const Vec3& p, const Vec3& t, const Traits& traits = Traits(), bool* converged = nullptr) {
  using internal::dot;
  Vec3 q = 0.5 * (project_along_normal(f1, s1, p, traits) + project_along_normal(f2, s2, p, traits));
  q -= dot(q - p, t) * t;
  const Vec3 start = q;
  const double scale = internal::length(start - p) + internal::length(p - f1.origin) + 1e-300;
  const double tolerance2 = (1e-13 * scale) * (1e-13 * scale);  // (squared: no square root per step)
  bool ok = false;
  for (int it = 0; it < 20; ++it) {
    double d1[5], d2[5];
    const Vec3 a = q - f1.origin, b = q - f2.origin;
    const double x1 = dot(a, f1.U), y1 = dot(a, f1.V), x2 = dot(b, f2.U), y2 = dot(b, f2.V);
    const double r1 = dot(a, f1.N) - traits.height(s1, x1, y1, d1);
    const double r2 = dot(b, f2.N) - traits.height(s2, x2, y2, d2);
    const double r3 = dot(q - p, t);
    if (!std::isfinite(r1 + r2 + d1[0] + d1[1] + d2[0] + d2[1])) break;
    const Vec3 g1 = f1.N - d1[0] * f1.U - d1[1] * f1.V;
    const Vec3 g2 = f2.N - d2[0] * f2.U - d2[1] * f2.V;
    // Solve [g1; g2; t] dq = -r by Cramer's rule (rows g1, g2, t).
    const Vec3 c12 = internal::cross(g2, t), c20 = internal::cross(t, g1), c01 = internal::cross(g1, g2);
    const double det = dot(g1, c12);
    if (!(det * det > 1e-28 * (dot(g1, g1) * dot(g2, g2)))) break;  // |det| > 1e-14 |g1| |g2|, squared
    const Vec3 dq = (-1. / det) * (r1 * c12 + r2 * c20 + r3 * c01);
    q += dq;
    if (!std::isfinite(q.x + q.y + q.z)) break;
    if (dot(dq, dq) <= tolerance2) {
      ok = true;
      break;
    }
  }
  // Far jumps mean Newton left for another branch of the intersection: keep the start.
  if (ok && internal::length(q - start) > 10. * (internal::length(start - p) + 1e-12 * scale) + 1e-9 * scale)
    ok = false;
  if (converged) *converged = ok;
  if (!ok) return start;
  // Reach: a crease through the vertex (f1.origin) that meets pi farther from p than p's distance
  // to the vertex, plus the start's own offset, leaves the edge at more than 45 degrees; the two
  // surfaces then intersect where neither was fitted (nearly tangent surfaces at a dart, or an
  // extrapolated sector), and that point is a spike. Between one and two reaches the result moves
  // linearly from the intersection to the start, so that it stays continuous along the edge;
  // beyond two it is the start. The result is within 1.25 reaches of p (the blend's distance is at
  // most (2 - r) r + (r - 1) reaches, largest at r = 1.5).
  const double r = internal::length(q - p) / scale;  // scale is the reach
  if (!(r > 1.)) return q;
  const double lambda = std::max(0., 2. - r);
  return lambda * q + (1. - lambda) * start;
}

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_LOCAL_SURFACE_PROJECTION_H

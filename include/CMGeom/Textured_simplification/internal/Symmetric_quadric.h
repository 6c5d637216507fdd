// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// A quadric error function Q(u) = u^T A u + 2 b^T u + c stored as its 10 distinct coefficients
// (thesis §3.4: Q = (A, b, c)), with the operations the simplification policies need: the
// fundamental quadric of a plane, weighted sums, evaluation, a singular-safe minimiser on an edge
// and the local area distortion weight of §3.4.1. Every operation is O(1); the eigen
// decomposition of the 3x3 block uses Eigen's closed-form solver.
//
// Why 10 doubles instead of CGAL's 4x4 Eigen matrix: 80 bytes instead of 128 per vertex and no
// redundant arithmetic on the symmetric half; the policies touch these in their hot loop.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_SYMMETRIC_QUADRIC_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_SYMMETRIC_QUADRIC_H

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>

namespace CMGeom {
namespace Textured_simplification {
namespace internal {

using Vec3 = std::array<double, 3>;

inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

/// Q(u) = u^T A u + 2 b^T u + c with A symmetric: (a00 a01 a02 a11 a12 a22), b, c.
struct Symmetric_quadric {
  double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0;
  double b0 = 0, b1 = 0, b2 = 0;
  double c = 0;

  /// weight * (n n^T, d n, d^2): the squared distance to the plane n.u + d = 0 (|n| = 1).
  static Symmetric_quadric plane(const Vec3& n, double d, double weight) {
    Symmetric_quadric q;
    q.a00 = weight * n[0] * n[0];
    q.a01 = weight * n[0] * n[1];
    q.a02 = weight * n[0] * n[2];
    q.a11 = weight * n[1] * n[1];
    q.a12 = weight * n[1] * n[2];
    q.a22 = weight * n[2] * n[2];
    q.b0 = weight * d * n[0];
    q.b1 = weight * d * n[1];
    q.b2 = weight * d * n[2];
    q.c = weight * d * d;
    return q;
  }

  Symmetric_quadric& operator+=(const Symmetric_quadric& o) {
    a00 += o.a00;
    a01 += o.a01;
    a02 += o.a02;
    a11 += o.a11;
    a12 += o.a12;
    a22 += o.a22;
    b0 += o.b0;
    b1 += o.b1;
    b2 += o.b2;
    c += o.c;
    return *this;
  }
  Symmetric_quadric& operator*=(double s) {
    a00 *= s;
    a01 *= s;
    a02 *= s;
    a11 *= s;
    a12 *= s;
    a22 *= s;
    b0 *= s;
    b1 *= s;
    b2 *= s;
    c *= s;
    return *this;
  }
  /// s0 * q0 + s1 * q1
  static Symmetric_quadric combine(const Symmetric_quadric& q0, double s0, const Symmetric_quadric& q1, double s1) {
    Symmetric_quadric q;
    q.a00 = s0 * q0.a00 + s1 * q1.a00;
    q.a01 = s0 * q0.a01 + s1 * q1.a01;
    q.a02 = s0 * q0.a02 + s1 * q1.a02;
    q.a11 = s0 * q0.a11 + s1 * q1.a11;
    q.a12 = s0 * q0.a12 + s1 * q1.a12;
    q.a22 = s0 * q0.a22 + s1 * q1.a22;
    q.b0 = s0 * q0.b0 + s1 * q1.b0;
    q.b1 = s0 * q0.b1 + s1 * q1.b1;
    q.b2 = s0 * q0.b2 + s1 * q1.b2;
    q.c = s0 * q0.c + s1 * q1.c;
    return q;
  }

  double trace() const { return a00 + a11 + a22; }

  Vec3 A_times(const Vec3& u) const {
    return {a00 * u[0] + a01 * u[1] + a02 * u[2], a01 * u[0] + a11 * u[1] + a12 * u[2],
            a02 * u[0] + a12 * u[1] + a22 * u[2]};
  }

  double operator()(const Vec3& u) const {
    const Vec3 Au = A_times(u);
    return dot(u, Au) + 2.0 * (b0 * u[0] + b1 * u[1] + b2 * u[2]) + c;
  }

  /// Solves A u = -b when A is well conditioned. The threshold is relative (det against the cube
  /// of the trace) so the test does not depend on the model's scale.
  bool solve(Vec3& u) const {
    const double c00 = a11 * a22 - a12 * a12;
    const double c01 = a02 * a12 - a01 * a22;
    const double c02 = a01 * a12 - a02 * a11;
    const double det = a00 * c00 + a01 * c01 + a02 * c02;
    const double t = trace();
    if (!(t > 0) || !(std::abs(det) > 1e-9 * t * t * t)) return false;
    const double c11 = a00 * a22 - a02 * a02;
    const double c12 = a01 * a02 - a00 * a12;
    const double c22 = a00 * a11 - a01 * a01;
    const double inv = -1.0 / det;
    u = {inv * (c00 * b0 + c01 * b1 + c02 * b2), inv * (c01 * b0 + c11 * b1 + c12 * b2),
         inv * (c02 * b0 + c12 * b1 + c22 * b2)};
    return std::isfinite(u[0]) && std::isfinite(u[1]) && std::isfinite(u[2]);
  }

  /// The placement of an edge collapse (p0, p1) minimising this quadric:
  ///  1. the free minimiser -A^{-1} b when A is well conditioned and the minimiser lies within
  ///     two edge lengths of the edge midpoint (farther means the solve extrapolates along a
  ///     nearly flat direction, a known source of spikes);
  ///  2. otherwise the minimiser on the segment [p0, p1] (a 1-D quadratic);
  ///  3. if Q is constant along the segment, the best of midpoint, p0, p1 (midpoint first on
  ///     ties: it gives better shaped triangles on flat regions).
  Vec3 minimiser_on_edge(const Vec3& p0, const Vec3& p1) const {
    const Vec3 d = sub(p1, p0);
    const double l2 = dot(d, d);
    Vec3 u;
    if (solve(u)) {
      const Vec3 m = scale(add(p0, p1), 0.5);
      const Vec3 um = sub(u, m);
      if (dot(um, um) <= 4.0 * l2) return u;
    }
    const Vec3 Ad = A_times(d);
    const double dAd = dot(d, Ad);
    if (dAd > 1e-12 * trace() * l2) {
      const Vec3 Ap0 = A_times(p0);
      const double g = dot(d, Ap0) + (b0 * d[0] + b1 * d[1] + b2 * d[2]);
      const double t = std::clamp(-g / dAd, 0.0, 1.0);
      return add(p0, scale(d, t));
    }
    const Vec3 m = scale(add(p0, p1), 0.5);
    const double qm = (*this)(m), q0 = (*this)(p0), q1 = (*this)(p1);
    if (qm <= q0 && qm <= q1) return m;
    return q0 <= q1 ? p0 : p1;
  }

  /// Local area distortion measure of §3.4.1: (trace(A) - lambda) / (trace(A) + lambda), lambda
  /// the eigenvalue of A whose eigenvector is closest to `normal`. Returns a value in [0, 1]
  /// (A is positive semi-definite); a zero A (no faces) returns 1 so isolated data is kept.
  double area_distortion(const Vec3& normal) const {
    const double t = trace();
    if (!(t > 0)) return 1.0;
    Eigen::Matrix3d A;
    A << a00, a01, a02, a01, a11, a12, a02, a12, a22;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
    es.computeDirect(A, Eigen::EigenvaluesOnly);
    const Eigen::Vector3d n(normal[0], normal[1], normal[2]);
    int best = 2;  // eigenvalues ascend: the largest is the dominant plane normal
    if (n.squaredNorm() > 0) {
      // Which eigenvector is closest to n, without computing the eigenvectors (half of the cost
      // of the closed-form solver): with distinct eigenvalues l_i and u_i = (A - l_i I) n, the
      // squared cosine of n with eigenvector i, times |n|^2, is n^T P_i n where
      // P_i = prod_{j != i} (A - l_j I) / (l_i - l_j) is the projector on it, i.e.
      // u_j . u_k / ((l_i - l_j)(l_i - l_k)). Eigenvalues closer than 1e-6 trace(A) (their
      // eigenvectors are then ill-defined and the divisions inaccurate) take the eigenvectors.
      const Eigen::Vector3d& l = es.eigenvalues();
      const double g01 = l(1) - l(0), g12 = l(2) - l(1);
      if (g01 > 1e-6 * t && g12 > 1e-6 * t) {
        const Eigen::Vector3d An = A * n;
        const Eigen::Vector3d u0 = An - l(0) * n, u1 = An - l(1) * n, u2 = An - l(2) * n;
        const double c[3] = {u1.dot(u2) / (g01 * (g01 + g12)), -u0.dot(u2) / (g01 * g12),
                             u0.dot(u1) / ((g01 + g12) * g12)};
        double best_c = -1;
        for (int i = 0; i < 3; ++i)
          if (c[i] > best_c) {
            best_c = c[i];
            best = i;
          }
      } else {
        es.computeDirect(A);  // same eigenvalues, now with eigenvectors
        double best_dot = -1;
        for (int i = 0; i < 3; ++i) {
          const double dd = std::abs(es.eigenvectors().col(i).dot(n));
          if (dd > best_dot) {
            best_dot = dd;
            best = i;
          }
        }
      }
    }
    const double lambda = std::clamp(es.eigenvalues()(best), 0.0, t);
    return (t - lambda) / (t + lambda);
  }
};

}  // namespace internal
}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_SYMMETRIC_QUADRIC_H

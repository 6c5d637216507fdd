// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Definitions of the local-surface fits declared in Local_surface_traits.h. Included by that
// header (functions inline) in header-only use; compiled once into CMGeom::Compact_model
// (src/Compact_model/local_surface_fits.cpp) otherwise.
#ifndef CMGEOM_COMPACT_MODEL_INTERNAL_LOCAL_SURFACE_TRAITS_IMPL_H
#define CMGEOM_COMPACT_MODEL_INTERNAL_LOCAL_SURFACE_TRAITS_IMPL_H

#include <CMGeom/Compact_model/Local_surface_traits.h>

#include <Eigen/Dense>

#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace CMGeom {
namespace CM {

namespace internal {

// Least squares sum_p (X(p) . C - rhs(p))^2 over monomials x^i y^j with total degree 1..3 listed
// in `exps`. Assembled in coordinates divided by the RMS radius `h` of the points (a change of
// unit that keeps the normal matrix well conditioned for tiny or huge models), solved by LDLT,
// minimum-norm solution when rank deficient; coefficients are scaled back by h^-(i+j).
template <int K, class Rhs>
bool fit_monomials(const std::vector<Vec3>& pts, const std::array<std::array<int, 2>, K>& exps, Rhs rhs, double* out) {
  for (int k = 0; k < K; ++k) out[k] = 0.;
  if (pts.empty()) return false;
  double r2 = 0.;
  for (const Vec3& p : pts) r2 += p.x * p.x + p.y * p.y;
  const double h = std::sqrt(r2 / double(pts.size()));
  if (!(h > 0.) || !std::isfinite(h)) return false;
  const double inv = 1. / h;
  Eigen::Matrix<double, K, K> A = Eigen::Matrix<double, K, K>::Zero();
  Eigen::Matrix<double, K, 1> b = Eigen::Matrix<double, K, 1>::Zero();
  Eigen::Matrix<double, K, 1> X;
  for (const Vec3& p : pts) {
    const double x = p.x * inv, y = p.y * inv;
    const double px[4] = {1., x, x * x, x * x * x}, py[4] = {1., y, y * y, y * y * y};
    for (int k = 0; k < K; ++k) X[k] = px[exps[k][0]] * py[exps[k][1]];
    A.noalias() += X * X.transpose();
    b += rhs(p) * X;
  }
  Eigen::Matrix<double, K, 1> C;
  Eigen::LDLT<Eigen::Matrix<double, K, K>> ldlt(A);
  if (ldlt.info() == Eigen::Success && ldlt.isPositive() && ldlt.rcond() > 1e-13) {
    C = ldlt.solve(b);
  } else {
    // Rare (rank-deficient sets): one dynamic-size decomposition serves every K, which keeps the
    // compile time of this file down (a fixed-size one per K costs ~10 s each at -O2).
    const Eigen::MatrixXd Ad = A;
    const Eigen::VectorXd bd = b;
    C = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(Ad).solve(bd);
  }
  for (int k = 0; k < K; ++k) {
    if (!std::isfinite(C[k])) return false;
    out[k] = C[k] * std::pow(inv, exps[k][0] + exps[k][1]);
  }
  return true;
}

inline const std::array<std::array<int, 2>, 5>& quadric_exponents() {
  static const std::array<std::array<int, 2>, 5> e{{{2, 0}, {1, 1}, {0, 2}, {1, 0}, {0, 1}}};
  return e;
}
inline const std::array<std::array<int, 2>, 9>& cubic_exponents() {
  static const std::array<std::array<int, 2>, 9> e{
      {{2, 0}, {1, 1}, {0, 2}, {1, 0}, {0, 1}, {3, 0}, {2, 1}, {1, 2}, {0, 3}}};
  return e;
}

inline double rms_height_error(const Local_surface& s, const std::vector<Vec3>& pts) {
  if (pts.empty()) return 0.;
  double e = 0.;
  for (const Vec3& p : pts) {
    const double r = evaluate_height(s, p.x, p.y) - p.z;
    e += r * r;
  }
  return std::sqrt(e / double(pts.size()));
}

}  // namespace internal

CMGEOM_CM_INLINE Fit_result fit_quadric(const std::vector<Vec3>& local_points) {
  Fit_result r;
  r.surface.model = QUADRIC_MODEL;
  r.ok = internal::fit_monomials<5>(
      local_points, internal::quadric_exponents(), [](const Vec3& p) { return p.z; }, r.surface.c.data());
  r.error = r.ok ? internal::rms_height_error(r.surface, local_points) : std::numeric_limits<double>::infinity();
  return r;
}

CMGEOM_CM_INLINE Fit_result fit_plane(const std::vector<Vec3>& local_points) {
  static const std::array<std::array<int, 2>, 2> e{{{1, 0}, {0, 1}}};
  Fit_result r;
  r.surface.model = QUADRIC_MODEL;
  double de[2];
  r.ok = internal::fit_monomials<2>(
      local_points, e, [](const Vec3& p) { return p.z; }, de);
  r.surface.c[3] = de[0];
  r.surface.c[4] = de[1];
  r.error = r.ok ? internal::rms_height_error(r.surface, local_points) : std::numeric_limits<double>::infinity();
  return r;
}

CMGEOM_CM_INLINE Fit_result fit_cone(const std::vector<Vec3>& local_points) {
  Fit_result r;
  r.surface.model = CONE_MODEL;
  r.ok = internal::fit_monomials<5>(
      local_points, internal::quadric_exponents(), [](const Vec3& p) { return p.z * p.z; }, r.surface.c.data());
  double side = 0.;
  for (const Vec3& p : local_points) side += p.z;
  r.surface.c[5] = side < 0. ? -1. : 1.;
  r.error = r.ok ? internal::rms_height_error(r.surface, local_points) : std::numeric_limits<double>::infinity();
  return r;
}

CMGEOM_CM_INLINE Fit_result fit_cubic(const std::vector<Vec3>& local_points) {
  Fit_result q = fit_quadric(local_points);
  if (local_points.size() < 9) return q;
  Fit_result r;
  r.surface.model = CUBIC_MODEL;
  r.ok = internal::fit_monomials<9>(
      local_points, internal::cubic_exponents(), [](const Vec3& p) { return p.z; }, r.surface.c.data());
  r.error = r.ok ? internal::rms_height_error(r.surface, local_points) : std::numeric_limits<double>::infinity();
  return (r.ok && r.error <= q.error) ? r : q;
}

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_INTERNAL_LOCAL_SURFACE_TRAITS_IMPL_H

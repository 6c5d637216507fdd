// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Local surfaces of a Compact Model (thesis §4.4.1) and the `LocalSurfaceTraits` concept that
// fits them, with its models Quadric_surface_traits (the thesis, default) and
// Cubic_surface_traits (a CMGeom addition). A local surface is a height x3 = h(x1, x2) in the
// frame (v; U, V, N) of a base vertex, U built from N as in §4.4.1: the quadric
// a x1^2 + b x1x2 + c x2^2 + d x1 + e x2, the cone s sqrt(Q) with Q fitted to x3^2 and the side s
// stored as a 6th coefficient, or the quadric plus the four cubic monomials. Every model passes
// through v, so Phi(v) = v. Fits solve the least-squares normal equations by LDLT in coordinates
// scaled by the points' RMS radius (minimum-norm solution when rank-deficient); quadric and cone
// are compared by the RMS of their height residuals. A CM file stores each list's model id, so
// evaluate_height() evaluates any stored surface whatever traits built it.
//
// Manual: doc/Compact_model/README.md, "Choices where the thesis is open (and why)".
#ifndef CMGEOM_COMPACT_MODEL_LOCAL_SURFACE_TRAITS_H
#define CMGEOM_COMPACT_MODEL_LOCAL_SURFACE_TRAITS_H

#include <CMGeom/Compact_model/internal/Vec3.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace CMGeom {
namespace CM {

using internal::Vec3;

/// The local frame (origin; U, V, N) of §4.4.1.
struct Local_frame {
  Vec3 origin, U, V, N;
  Local_frame() : U(1, 0, 0), V(0, 1, 0), N(0, 0, 1) {}
  /// Frame at `o` with unit normal direction `n` (normalised here), U and V as in §4.4.1.
  Local_frame(const Vec3& o, const Vec3& n) : origin(o), N(internal::normalized(n)) {
    const double r2 = N.x * N.x + N.y * N.y;
    if (r2 > 0.) {
      const double r = std::sqrt(r2);
      U = Vec3(N.y / r, -N.x / r, 0.);
    } else {
      U = Vec3(1., 0., 0.);
    }
    V = internal::cross(N, U);
  }
  Vec3 to_local(const Vec3& p) const {
    const Vec3 d = p - origin;
    return Vec3(internal::dot(d, U), internal::dot(d, V), internal::dot(d, N));
  }
  Vec3 to_world(double x1, double x2, double x3) const { return origin + x1 * U + x2 * V + x3 * N; }
  Vec3 direction_to_world(const Vec3& d) const { return d.x * U + d.y * V + d.z * N; }
};

/// Model ids, stored in CM files (never renumber).
enum Surface_model : std::uint8_t { QUADRIC_MODEL = 0, CONE_MODEL = 1, CUBIC_MODEL = 2 };

/// Number of stored coefficients of a model (0 for an unknown id).
inline int number_of_coefficients(std::uint8_t model) {
  switch (model) {
    case QUADRIC_MODEL:
      return 5;
    case CONE_MODEL:
      return 6;
    case CUBIC_MODEL:
      return 9;
    default:
      return 0;
  }
}

/// A local surface: a model id and its coefficients (unused ones are 0).
struct Local_surface {
  std::uint8_t model = QUADRIC_MODEL;
  std::array<double, 9> c{};
  bool operator==(const Local_surface& o) const { return model == o.model && c == o.c; }
  bool is_cone() const { return model == CONE_MODEL; }
};

namespace internal {
// Heights of the cone and cubic models (out of line: evaluate_height inlines the common quadric).
inline double evaluate_height_other(const Local_surface& s, double x, double y, double* d);
}  // namespace internal

/// Height of a stored surface at (x1, x2) of its frame; `d` (optional) receives
/// h_x1, h_x2, h_x1x1, h_x1x2, h_x2x2. For a cone at (or beyond) its apex the derivatives are
/// infinite and `d[0]` is set to NaN so that callers fall back to the projection along N.
inline double evaluate_height(const Local_surface& s, double x, double y, double* d = nullptr) {
  if (s.model == CONE_MODEL || s.model == CUBIC_MODEL) return internal::evaluate_height_other(s, x, y, d);
  const auto& c = s.c;  // quadric (unknown ids are refused by the readers)
  if (d) {
    d[0] = 2 * c[0] * x + c[1] * y + c[3];
    d[1] = c[1] * x + 2 * c[2] * y + c[4];
    d[2] = 2 * c[0];
    d[3] = c[1];
    d[4] = 2 * c[2];
  }
  return c[0] * x * x + c[1] * x * y + c[2] * y * y + c[3] * x + c[4] * y;
}

namespace internal {
inline double evaluate_height_other(const Local_surface& s, double x, double y, double* d) {
  const auto& c = s.c;
  switch (s.model) {
    case CUBIC_MODEL: {
      const double h = c[0] * x * x + c[1] * x * y + c[2] * y * y + c[3] * x + c[4] * y + c[5] * x * x * x +
                       c[6] * x * x * y + c[7] * x * y * y + c[8] * y * y * y;
      if (d) {
        d[0] = 2 * c[0] * x + c[1] * y + c[3] + 3 * c[5] * x * x + 2 * c[6] * x * y + c[7] * y * y;
        d[1] = c[1] * x + 2 * c[2] * y + c[4] + c[6] * x * x + 2 * c[7] * x * y + 3 * c[8] * y * y;
        d[2] = 2 * c[0] + 6 * c[5] * x + 2 * c[6] * y;
        d[3] = c[1] + 2 * c[6] * x + 2 * c[7] * y;
        d[4] = 2 * c[2] + 2 * c[7] * x + 6 * c[8] * y;
      }
      return h;
    }
    default: {  // CONE_MODEL
      const double q = c[0] * x * x + c[1] * x * y + c[2] * y * y + c[3] * x + c[4] * y;
      const double sgn = c[5] < 0 ? -1. : 1.;
      if (q <= 0.) {
        if (d) d[0] = d[1] = d[2] = d[3] = d[4] = std::numeric_limits<double>::quiet_NaN();
        return 0.;
      }
      const double r = std::sqrt(q);
      if (d) {
        const double qx = 2 * c[0] * x + c[1] * y + c[3], qy = c[1] * x + 2 * c[2] * y + c[4];
        const double qxx = 2 * c[0], qxy = c[1], qyy = 2 * c[2];
        // h = s r, h_x = s q_x / (2r), h_xy = s (q_xy / (2r) - q_x q_y / (4 r^3)).
        d[0] = sgn * qx / (2 * r);
        d[1] = sgn * qy / (2 * r);
        d[2] = sgn * (qxx / (2 * r) - qx * qx / (4 * q * r));
        d[3] = sgn * (qxy / (2 * r) - qx * qy / (4 * q * r));
        d[4] = sgn * (qyy / (2 * r) - qy * qy / (4 * q * r));
      }
      return sgn * r;
    }
  }
}
}  // namespace internal

/// Result of a fit: the surface, its RMS height residual over the points, and whether a
/// surface was produced.
struct Fit_result {
  Local_surface surface;
  double error = std::numeric_limits<double>::infinity();
  bool ok = false;
};

// The fits below are compiled once into CMGeom::Compact_model when a program links it
// (CMGEOM_COMPACT_MODEL_PRECOMPILED), and defined inline by internal/Local_surface_traits_impl.h
// otherwise. Their Eigen solvers (LDLT with a condition estimate, complete orthogonal
// decomposition) for 2x2, 5x5 and 9x9 systems are instantiated wherever the definitions are
// seen, used or not: ~40 s of compile time per translation unit at -O2.
#ifdef CMGEOM_COMPACT_MODEL_PRECOMPILED
#define CMGEOM_CM_INLINE
#else
#define CMGEOM_CM_INLINE inline
#endif

/// Quadric z = Q(x1, x2) by the 5x5 normal equations of §4.4.1 (points in local coordinates).
CMGEOM_CM_INLINE Fit_result fit_quadric(const std::vector<Vec3>& local_points);

/// Tangent plane z = d x1 + e x2 (a quadric with a = b = c = 0), for sets too small for a quadric.
CMGEOM_CM_INLINE Fit_result fit_plane(const std::vector<Vec3>& local_points);

/// Conical surface z = s sqrt(Q(x1, x2)), Q fitted to z^2 (§4.4.1).
CMGEOM_CM_INLINE Fit_result fit_cone(const std::vector<Vec3>& local_points);

/// Cubic height function (9x9 normal equations). Falls back to the quadric when there are fewer
/// than 9 points (a cubic would interpolate noise) and keeps the better of the two otherwise.
CMGEOM_CM_INLINE Fit_result fit_cubic(const std::vector<Vec3>& local_points);

/// The thesis' traits (default): quadric local surfaces, cones for cone-type vertices.
struct Quadric_surface_traits {
  Fit_result fit(const std::vector<Vec3>& local_points) const { return fit_quadric(local_points); }
  Fit_result fit_cone(const std::vector<Vec3>& local_points) const { return CM::fit_cone(local_points); }
  double height(const Local_surface& s, double x1, double x2, double* d = nullptr) const {
    return evaluate_height(s, x1, x2, d);
  }
};

/// Cubic local surfaces (better where a quadric cannot follow an inflection, e.g. on the
/// saddles of the trim-star), cones as in the thesis.
struct Cubic_surface_traits {
  Fit_result fit(const std::vector<Vec3>& local_points) const { return fit_cubic(local_points); }
  Fit_result fit_cone(const std::vector<Vec3>& local_points) const { return CM::fit_cone(local_points); }
  double height(const Local_surface& s, double x1, double x2, double* d = nullptr) const {
    return evaluate_height(s, x1, x2, d);
  }
};

}  // namespace CM
}  // namespace CMGeom

#ifndef CMGEOM_COMPACT_MODEL_PRECOMPILED
#include <CMGeom/Compact_model/internal/Local_surface_traits_impl.h>
#endif

#endif  // CMGEOM_COMPACT_MODEL_LOCAL_SURFACE_TRAITS_H

// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// A plain double 3-vector for the hot numeric kernels of the Compact_model package (fitting,
// projection, blending). The package converts CGAL points to this type once, so the inner loops
// of reconstruction work on flat arrays of doubles. Every operation is O(1).
#ifndef CMGEOM_COMPACT_MODEL_INTERNAL_VEC3_H
#define CMGEOM_COMPACT_MODEL_INTERNAL_VEC3_H

#include <cmath>

namespace CMGeom {
namespace CM {
namespace internal {

struct Vec3 {
  double x = 0., y = 0., z = 0.;
  Vec3() = default;
  Vec3(double a, double b, double c) : x(a), y(b), z(c) {}
  double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
  Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
  Vec3& operator*=(double s) { x *= s; y *= s; z *= s; return *this; }
  bool operator==(const Vec3& o) const { return x == o.x && y == o.y && z == o.z; }
  bool operator!=(const Vec3& o) const { return !(*this == o); }
};

inline Vec3 operator+(Vec3 a, const Vec3& b) { return a += b; }
inline Vec3 operator-(Vec3 a, const Vec3& b) { return a -= b; }
inline Vec3 operator-(const Vec3& a) { return Vec3(-a.x, -a.y, -a.z); }
inline Vec3 operator*(double s, Vec3 a) { return a *= s; }
inline Vec3 operator*(Vec3 a, double s) { return a *= s; }
inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return Vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
inline double squared_length(const Vec3& a) { return dot(a, a); }
inline double length(const Vec3& a) { return std::sqrt(dot(a, a)); }
inline Vec3 normalized(const Vec3& a) {
  const double l = length(a);
  return l > 0. ? a * (1. / l) : a;
}

}  // namespace internal
}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_INTERNAL_VEC3_H

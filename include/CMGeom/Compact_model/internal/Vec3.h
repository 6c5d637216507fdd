// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// A plain double 3-vector for the hot numeric kernels of the Compact_model package (fitting,
// projection, blending). The package converts CGAL points to this type once, so the inner loops
// of reconstruction work on flat arrays of doubles. Every operation is O(1).
#ifndef CMGEOM_COMPACT_MODEL_INTERNAL_VEC3_H
#define CMGEOM_COMPACT_MODEL_INTERNAL_VEC3_H

#include <algorithm>
#include <cmath>

namespace CMGeom {
namespace CM {
namespace internal {

struct Vec3 {
  double x = 0., y = 0., z = 0.;
  Vec3() = default;
  Vec3(double a, double b, double c) : x(a), y(b), z(c) {}
  double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  Vec3& operator+=(const Vec3& o) {
    x += o.x;
    y += o.y;
    z += o.z;
    return *this;
  }
  Vec3& operator-=(const Vec3& o) {
    x -= o.x;
    y -= o.y;
    z -= o.z;
    return *this;
  }
  Vec3& operator*=(double s) {
    x *= s;
    y *= s;
    z *= s;
    return *this;
  }
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

// The squared distance from p to an axis-aligned box (any type with min(i) and max(i), such as
// CGAL::Bbox_3); 0 inside. The bound by which AABB-tree searches skip a box (Metrics' closest
// point, the atlas baking's facing closest point).
template <class Box>
inline double squared_distance_to_box(const Vec3& p, const Box& b) {
  double d = 0.;
  for (int i = 0; i < 3; ++i) {
    const double lo = b.min(i), hi = b.max(i), c = p[i];
    const double e = c < lo ? lo - c : (c > hi ? c - hi : 0.0);
    d += e * e;
  }
  return d;
}

// The bounding sphere of triangle abc about its centroid: the centroid and the largest distance
// from it to a corner. A point whose distance to the sphere exceeds d is farther than d from the
// triangle: nearest-triangle searches skip triangles with it (Surface_memory, Hausdorff_bound,
// the collapse history's mapping).
struct Centroid_sphere {
  Vec3 centre;
  double radius;
};
inline Centroid_sphere centroid_sphere(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 g = (1. / 3.) * (a + b + c);
  return {g, std::sqrt((std::max)({squared_length(a - g), squared_length(b - g), squared_length(c - g)}))};
}

// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5); used by the
// Compact_model fits and by Textured_simplification's atlas baking.
inline Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double sum = va + vb + vc;
  if (!(sum > 0.)) return a;  // a degenerate triangle: every region test failed
  const double den = 1. / sum;
  return a + (vb * den) * ab + (vc * den) * ac;
}

// Barycentric coordinates (of a, b, c) of the point of triangle abc closest to p: the regions of
// closest_on_triangle(), with the weights kept (a degenerate triangle gives a).
inline Vec3 closest_barycentric_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return Vec3(1., 0., 0.);
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return Vec3(0., 1., 0.);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double t = d1 / (d1 - d3);
    return Vec3(1. - t, t, 0.);
  }
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return Vec3(0., 0., 1.);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double t = d2 / (d2 - d6);
    return Vec3(1. - t, 0., t);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return Vec3(0., 1. - t, t);
  }
  const double sum = va + vb + vc;
  if (!(sum > 0.)) return Vec3(1., 0., 0.);
  const double den = 1. / sum;
  return Vec3(1. - (vb + vc) * den, vb * den, vc * den);
}

}  // namespace internal
}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_INTERNAL_VEC3_H

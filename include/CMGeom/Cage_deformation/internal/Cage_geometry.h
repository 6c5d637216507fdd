// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Per-cage quantities shared by the closed-form coordinate kernels (mean value and Green), stored
// as flat arrays so that one query runs over contiguous memory: vertex positions, the undirected
// edges (every per-edge quantity of a query -- the spherical arc of MVC, the edge integral of
// Green -- is computed once and used by both incident triangles), and per triangle the unit
// normal, the plane offset, the area and the three affine functions giving the barycentric
// coordinates of the projection of a point on the triangle's plane.
//
// Complexity: O(n + m log m) to build, O(n + m) memory.
#ifndef CMGEOM_CAGE_DEFORMATION_INTERNAL_CAGE_GEOMETRY_H
#define CMGEOM_CAGE_DEFORMATION_INTERNAL_CAGE_GEOMETRY_H

#include <CMGeom/Cage_deformation/Triangle_cage.h>
#include <CMGeom/Cage_deformation/internal/Simd_math.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {
namespace internal {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 must be three packed doubles");

struct Cage_geometry {
  std::size_t n = 0, m = 0, E = 0;
  double L = 0;  // bbox diagonal
  std::vector<Vec3> v;
  std::vector<std::array<std::uint32_t, 2>> edge;  // canonical direction a < b (stored indices)
  std::vector<double> edge_length;
  std::vector<std::int32_t> edge_a, edge_b;  // same as `edge`, as separate arrays (SIMD gathers)
  // SoA copies of tri / tri_edge / tri_sign for the SIMD triangle loops (index k * m + t), and
  // for every vertex the list of its triangle corners (k * m + t), in CSR form.
  std::vector<std::int32_t> corner_vertex, corner_edge, corner_vertex3;  // vertex3 = 3 * vertex
  std::vector<double> corner_sign;
  std::vector<std::int32_t> vertex_corner_start, vertex_corner;
  // per triangle
  std::vector<std::array<std::uint32_t, 3>> tri;
  std::vector<std::array<std::uint32_t, 3>> tri_edge;  // edge opposite corner k: (k+1, k+2)
  std::vector<std::array<double, 3>> tri_sign;         // +1 if (k+1 -> k+2) is canonical
  std::vector<Vec3> normal;                            // unit, outward
  std::vector<double> offset;                          // normal . q0
  std::vector<double> area;
  // barycentric of the projection: beta_k(x) = bary[k] . x + bary_off[k]
  std::vector<std::array<Vec3, 3>> bary;
  std::vector<std::array<double, 3>> bary_off;
  std::vector<std::array<double, 3>> height;  // 2A / l_k: beta_k * height_k = in-plane distance

  explicit Cage_geometry(const Triangle_cage& cage) { build(cage); }
  Cage_geometry() = default;

  void build(const Triangle_cage& cage) {
    n = cage.vertices.size();
    m = cage.triangles.size();
    L = cage.bbox_diagonal();
    v = cage.vertices;
    tri = cage.triangles;
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> index;
    tri_edge.resize(m);
    tri_sign.resize(m);
    normal.resize(m);
    offset.resize(m);
    area.resize(m);
    bary.resize(m);
    bary_off.resize(m);
    height.resize(m);
    for (std::size_t t = 0; t < m; ++t) {
      const auto& q = tri[t];
      for (int k = 0; k < 3; ++k) {
        std::uint32_t a = q[(k + 1) % 3], b = q[(k + 2) % 3];
        std::pair<std::uint32_t, std::uint32_t> key(std::min(a, b), std::max(a, b));
        auto it = index.find(key);
        if (it == index.end()) {
          it = index.emplace(key, std::uint32_t(edge.size())).first;
          edge.push_back({key.first, key.second});
          edge_length.push_back(norm(sub(v[key.second], v[key.first])));
        }
        tri_edge[t][k] = it->second;
        tri_sign[t][k] = (a < b) ? 1.0 : -1.0;
      }
      const Vec3 nn = cross(sub(v[q[1]], v[q[0]]), sub(v[q[2]], v[q[0]]));
      const double twoA = norm(nn);
      area[t] = 0.5 * twoA;
      normal[t] = mul(1.0 / twoA, nn);
      offset[t] = dot(normal[t], v[q[0]]);
      for (int k = 0; k < 3; ++k) {
        const Vec3& p1 = v[q[(k + 1) % 3]];
        const Vec3 g = sub(v[q[(k + 2) % 3]], p1);
        // beta_k(x) = ((n x g) . (x - p1)) / 2A: the signed area opposite corner k.
        bary[t][k] = mul(1.0 / twoA, cross(normal[t], g));
        bary_off[t][k] = -dot(bary[t][k], p1);
        height[t][k] = twoA / norm(g);
      }
    }
    E = edge.size();
    for (const auto& e : edge) {
      edge_a.push_back(std::int32_t(e[0]));
      edge_b.push_back(std::int32_t(e[1]));
    }
    corner_vertex.resize(3 * m);
    corner_vertex3.resize(3 * m);
    corner_edge.resize(3 * m);
    corner_sign.resize(3 * m);
    vertex_corner_start.assign(n + 1, 0);
    for (std::size_t k = 0; k < 3; ++k)
      for (std::size_t t = 0; t < m; ++t) {
        corner_vertex[k * m + t] = std::int32_t(tri[t][k]);
        corner_vertex3[k * m + t] = std::int32_t(3 * tri[t][k]);
        corner_edge[k * m + t] = std::int32_t(tri_edge[t][k]);
        corner_sign[k * m + t] = tri_sign[t][k];
        ++vertex_corner_start[tri[t][k] + 1];
      }
    for (std::size_t i = 0; i < n; ++i) vertex_corner_start[i + 1] += vertex_corner_start[i];
    vertex_corner.resize(3 * m);
    std::vector<std::int32_t> fill(vertex_corner_start.begin(), vertex_corner_start.end() - 1);
    for (std::size_t c = 0; c < 3 * m; ++c)
      vertex_corner[std::size_t(fill[std::size_t(corner_vertex[c])]++)] = std::int32_t(c);
  }

  double signed_distance(std::size_t t, const Vec3& x) const { return dot(normal[t], x) - offset[t]; }

  /// Barycentric coordinates of the projection of x on the plane of t (sum 1, may be negative).
  std::array<double, 3> plane_barycentrics(std::size_t t, const Vec3& x) const {
    std::array<double, 3> b;
    for (int k = 0; k < 3; ++k) b[k] = dot(bary[t][k], x) + bary_off[t][k];
    return b;
  }

  /// Largest in-plane distance of the projection of x outside triangle t (<= 0 inside).
  double outside_distance(std::size_t t, const std::array<double, 3>& b) const {
    double d = -1e300;
    for (int k = 0; k < 3; ++k) d = std::max(d, -b[k] * height[t][k]);
    return d;
  }

  /// Euclidean distance from x to triangle t; `bary` receives the barycentric coordinates of
  /// the closest point of the closed triangle.
  double distance_to_triangle(std::size_t t, const Vec3& x, std::array<double, 3>* bary_out = nullptr) const {
    const std::array<double, 3> b = plane_barycentrics(t, x);
    const double h = signed_distance(t, x);
    if (b[0] >= 0 && b[1] >= 0 && b[2] >= 0) {
      if (bary_out) *bary_out = b;
      return std::abs(h);
    }
    double best = 1e300;
    for (int k = 0; k < 3; ++k) {
      const Vec3& a = v[tri[t][k]];
      const Vec3& c = v[tri[t][(k + 1) % 3]];
      const Vec3 ac = sub(c, a);
      double s = dot(sub(x, a), ac) / dot(ac, ac);
      s = std::min(1.0, std::max(0.0, s));
      const double d = norm(sub(x, add(a, mul(s, ac))));
      if (d < best) {
        best = d;
        if (bary_out) {
          std::array<double, 3> r{0, 0, 0};
          r[k] = 1 - s;
          r[(k + 1) % 3] = s;
          *bary_out = r;
        }
      }
    }
    return best;
  }

  /// Winding number of the cage around x (sum of signed solid angles / 4 pi).
  double winding_number(const Vec3& x) const {
#ifdef CMGEOM_CAGE_SIMD_AVX2
    if (has_avx2()) return winding_number_avx2(x);
#endif
    double w = 0;
    for (std::size_t t = 0; t < m; ++t) {
      const Vec3 a = sub(v[tri[t][0]], x), b = sub(v[tri[t][1]], x), c = sub(v[tri[t][2]], x);
      const double la = norm(a), lb = norm(b), lc = norm(c);
      const double det = dot(a, cross(b, c));
      const double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
      w += std::atan2(det, den);
    }
    return w / (2.0 * 3.14159265358979323846);
  }

#ifdef CMGEOM_CAGE_SIMD_AVX2
  __attribute__((target("avx2,fma"))) double winding_number_avx2(const Vec3& x) const {
    const __m256d px = _mm256_set1_pd(x[0]), py = _mm256_set1_pd(x[1]), pz = _mm256_set1_pd(x[2]);
    const double* base = v[0].data();
    __m256d acc = _mm256_setzero_pd();
    std::size_t t = 0;
    for (; t + 4 <= m; t += 4) {
      __m256d ex[3], ey[3], ez[3], r[3];
      for (std::size_t k = 0; k < 3; ++k) {
        const __m128i i3 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(corner_vertex3.data() + k * m + t));
        ex[k] = _mm256_sub_pd(gather_avx2(base, i3), px);
        ey[k] = _mm256_sub_pd(gather_avx2(base + 1, i3), py);
        ez[k] = _mm256_sub_pd(gather_avx2(base + 2, i3), pz);
        r[k] =
            _mm256_sqrt_pd(_mm256_fmadd_pd(ex[k], ex[k], _mm256_fmadd_pd(ey[k], ey[k], _mm256_mul_pd(ez[k], ez[k]))));
      }
      // det = e0 . (e1 x e2)
      const __m256d cx = _mm256_fmsub_pd(ey[1], ez[2], _mm256_mul_pd(ez[1], ey[2]));
      const __m256d cy = _mm256_fmsub_pd(ez[1], ex[2], _mm256_mul_pd(ex[1], ez[2]));
      const __m256d cz = _mm256_fmsub_pd(ex[1], ey[2], _mm256_mul_pd(ey[1], ex[2]));
      const __m256d det = _mm256_fmadd_pd(ex[0], cx, _mm256_fmadd_pd(ey[0], cy, _mm256_mul_pd(ez[0], cz)));
      const __m256d d01 = _mm256_fmadd_pd(ex[0], ex[1], _mm256_fmadd_pd(ey[0], ey[1], _mm256_mul_pd(ez[0], ez[1])));
      const __m256d d12 = _mm256_fmadd_pd(ex[1], ex[2], _mm256_fmadd_pd(ey[1], ey[2], _mm256_mul_pd(ez[1], ez[2])));
      const __m256d d20 = _mm256_fmadd_pd(ex[2], ex[0], _mm256_fmadd_pd(ey[2], ey[0], _mm256_mul_pd(ez[2], ez[0])));
      __m256d den = _mm256_mul_pd(_mm256_mul_pd(r[0], r[1]), r[2]);
      den = _mm256_fmadd_pd(d01, r[2], den);
      den = _mm256_fmadd_pd(d12, r[0], den);
      den = _mm256_fmadd_pd(d20, r[1], den);
      acc = _mm256_add_pd(acc, atan2_avx2(det, den));
    }
    alignas(32) double l[4];
    _mm256_store_pd(l, acc);
    double w = (l[0] + l[1]) + (l[2] + l[3]);
    for (; t < m; ++t) {
      const Vec3 a = sub(v[tri[t][0]], x), b = sub(v[tri[t][1]], x), c = sub(v[tri[t][2]], x);
      const double la = norm(a), lb = norm(b), lc = norm(c);
      const double det = dot(a, cross(b, c));
      const double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
      w += fast_atan2(det, den);
    }
    return w / (2.0 * k_pi);
  }
#endif
};

}  // namespace internal
}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_INTERNAL_CAGE_GEOMETRY_H

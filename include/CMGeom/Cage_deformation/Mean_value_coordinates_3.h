// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Mean_value_coordinates_3: 3D mean value coordinates of Ju, Schaefer and Warren (2005) for a closed
// triangle cage, a model of CageCoordinates (Cage_coordinates.h). They are the default coordinates
// of *Cages (thesis §5.3.1, "MVC"): defined everywhere in space, smooth off the cage, interpolating
// on it, and reproducing every affine map of the cage. Vector form: the mean vector of each
// spherical triangle is expanded in its three vertex directions. Key choices for robustness: every
// arc by atan2 (no asin/acos of rounded values), once per cage edge; tolerances relative to the
// cage's diagonal L (eps = 1e-8), with points near a vertex or a face snapped to its exact values.
// Complexity: O(n + m) per query, 4 edges at a time with AVX2 when the CPU has it; thread-safe.
//
// Manual: doc/Cage_deformation/README.md, "Methods and the choices made".
#ifndef CMGEOM_CAGE_DEFORMATION_MEAN_VALUE_COORDINATES_3_H
#define CMGEOM_CAGE_DEFORMATION_MEAN_VALUE_COORDINATES_3_H

#include <CMGeom/Cage_deformation/Cage_coordinates.h>
#include <CMGeom/Cage_deformation/internal/Cage_geometry.h>
#include <CMGeom/Cage_deformation/internal/Simd_math.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {

class Mean_value_coordinates_3 {
public:
  using Deformation_rule = Vertex_deformation_rule;

  /// `cage` must be validated (validate_cage()). `relative_tolerance` is eps above.
  explicit Mean_value_coordinates_3(const Triangle_cage& cage, double relative_tolerance = 1e-8)
      : cage_(std::make_shared<Triangle_cage>(cage)),
        g_(std::make_shared<internal::Cage_geometry>(cage)),
        tol_(relative_tolerance * g_->L) {}

  std::size_t number_of_coordinates() const { return g_->n; }
  const Triangle_cage& cage() const { return *cage_; }
  Deformation_rule deformation_rule() const { return Deformation_rule(g_->n); }
  /// Absolute snapping tolerance (eps * L).
  double tolerance() const { return tol_; }

  template <class Point, class OutputIterator>
  Coordinate_status operator()(const Point& query, OutputIterator out) const {
    const internal::Cage_geometry& g = *g_;
    const Vec3 x = internal::to_vec3(query);
    Scratch& s = scratch();
    s.resize(g.n, g.E, g.m);

    // 1. Unit directions per vertex; snap to a vertex.
    for (std::size_t i = 0; i < g.n; ++i) {
      const double ax = g.v[i][0] - x[0], ay = g.v[i][1] - x[1], az = g.v[i][2] - x[2];
      const double d = std::sqrt(ax * ax + ay * ay + az * az);
      if (d <= tol_) return write_unit(i, out);
      const double inv = 1.0 / d;
      s.ux[i] = ax * inv;
      s.uy[i] = ay * inv;
      s.uz[i] = az * inv;
      s.inv_d[i] = inv;
      s.w[i] = 0;
    }
    // 2. Triangles whose plane passes (nearly) through x: on the face, or skipped.
    double all_ones;
    {
      const std::uint64_t bits = ~std::uint64_t(0);
      std::memcpy(&all_ones, &bits, sizeof bits);
    }
    for (std::size_t t = 0; t < g.m; ++t) {
      s.skip[t] = 0;
      s.keep[t] = all_ones;
      const double h = g.signed_distance(t, x);
      if (std::abs(h) <= tol_) {
        const std::array<double, 3> b = g.plane_barycentrics(t, x);
        if (g.outside_distance(t, b) <= tol_) return write_face(t, b, out);
        s.skip[t] = 1;
        s.keep[t] = 0.0;
      }
    }
    // 3. Per edge: theta / sin(theta) times the (unnormalised) wedge normal u_a x u_b.
    //    sin(theta) == 0 only when x is on the edge's line; both triangles are then skipped (or
    //    x is on the edge and we returned above), so the value is never used.
#ifdef CMGEOM_CAGE_SIMD_AVX2
    if (internal::has_avx2())
      edges_avx2(g, s);
    else
#endif
      edges_scalar(g, s, 0, [](double y, double x) { return std::atan2(y, x); });
      // 4. Per triangle: mean vector and its expansion in the vertex directions.
#ifdef CMGEOM_CAGE_SIMD_AVX2
    if (internal::has_avx2()) {
      triangles_avx2(g, s);
      // gather the corner contributions of every vertex
      for (std::size_t i = 0; i < g.n; ++i) {
        double acc = 0;
        for (std::int32_t c = g.vertex_corner_start[i]; c < g.vertex_corner_start[i + 1]; ++c)
          acc += s.wc[std::size_t(g.vertex_corner[std::size_t(c)])];
        s.w[i] = acc;
      }
    } else
#endif
      for (std::size_t t = 0; t < g.m; ++t) {
        if (s.skip[t]) continue;
        const auto& q = g.tri[t];
        const auto& te = g.tri_edge[t];
        const auto& sg = g.tri_sign[t];
        double mx = 0, my = 0, mz = 0;
        double c[3][3];
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t e = te[k];
          mx += sg[k] * s.gx[e];
          my += sg[k] * s.gy[e];
          mz += sg[k] * s.gz[e];
          c[k][0] = sg[k] * s.cx[e];
          c[k][1] = sg[k] * s.cy[e];
          c[k][2] = sg[k] * s.cz[e];
        }
        // det[u0,u1,u2] = u0 . (u1 x u2) = D / (d0 d1 d2); N_k / D = c_k / (d_k det).
        const double det = s.ux[q[0]] * c[0][0] + s.uy[q[0]] * c[0][1] + s.uz[q[0]] * c[0][2];
        const double f = 0.5 / det;
        for (int k = 0; k < 3; ++k) s.w[q[k]] += f * (mx * c[k][0] + my * c[k][1] + mz * c[k][2]);
      }
    double sum = 0;
    for (std::size_t i = 0; i < g.n; ++i) {
      s.w[i] *= s.inv_d[i];
      sum += s.w[i];
    }
    const double inv = 1.0 / sum;
    for (std::size_t i = 0; i < g.n; ++i) *out++ = s.w[i] * inv;
    return Coordinate_status::regular;
  }

private:
  struct Scratch {
    std::vector<double> ux, uy, uz, inv_d, w, cx, cy, cz, gx, gy, gz;
    std::vector<unsigned char> skip;
    std::vector<double> keep;  // per triangle: all-ones bits (used) or 0 (skipped)
    std::vector<double> wc;    // per triangle corner k * m + t
    void resize(std::size_t n, std::size_t E, std::size_t m) {
      if (ux.size() < n)
        for (auto* p : {&ux, &uy, &uz, &inv_d, &w}) p->resize(n);
      if (cx.size() < E)
        for (auto* p : {&cx, &cy, &cz, &gx, &gy, &gz}) p->resize(E);
      if (skip.size() < m) {
        skip.resize(m);
        keep.resize(m);
        wc.resize(3 * m);
      }
    }
  };
  static Scratch& scratch() {
    thread_local Scratch s;
    return s;
  }

  // Step 3 for edges first..E-1: the arc of each edge seen from x (cross product of the unit
  // directions of its ends, and (arc angle / |cross|) times it). `atan2` is std::atan2 on the
  // plain path and the vector kernel's own atan2 for the tail of the AVX2 path.
  template <class Atan2>
  static void edges_scalar(const internal::Cage_geometry& g, Scratch& s, std::size_t first, Atan2 atan2) {
    for (std::size_t e = first; e < g.E; ++e) {
      const std::uint32_t a = g.edge[e][0], b = g.edge[e][1];
      const double cx = s.uy[a] * s.uz[b] - s.uz[a] * s.uy[b];
      const double cy = s.uz[a] * s.ux[b] - s.ux[a] * s.uz[b];
      const double cz = s.ux[a] * s.uy[b] - s.uy[a] * s.ux[b];
      const double sn = std::sqrt(cx * cx + cy * cy + cz * cz);
      const double cs = s.ux[a] * s.ux[b] + s.uy[a] * s.uy[b] + s.uz[a] * s.uz[b];
      const double f = sn > 0 ? atan2(sn, cs) / sn : 0.0;
      s.cx[e] = cx;
      s.cy[e] = cy;
      s.cz[e] = cz;
      s.gx[e] = f * cx;
      s.gy[e] = f * cy;
      s.gz[e] = f * cz;
    }
  }

#ifdef CMGEOM_CAGE_SIMD_AVX2
  // Step 3 on four edges at a time (gathers of the endpoint directions, branch-free atan2).
  __attribute__((target("avx2,fma"))) static void edges_avx2(const internal::Cage_geometry& g, Scratch& s) {
    std::size_t e = 0;
    for (; e + 4 <= g.E; e += 4) {
      const __m128i ia = _mm_loadu_si128(reinterpret_cast<const __m128i*>(g.edge_a.data() + e));
      const __m128i ib = _mm_loadu_si128(reinterpret_cast<const __m128i*>(g.edge_b.data() + e));
      const __m256d ax = internal::gather_avx2(s.ux.data(), ia);
      const __m256d ay = internal::gather_avx2(s.uy.data(), ia);
      const __m256d az = internal::gather_avx2(s.uz.data(), ia);
      const __m256d bx = internal::gather_avx2(s.ux.data(), ib);
      const __m256d by = internal::gather_avx2(s.uy.data(), ib);
      const __m256d bz = internal::gather_avx2(s.uz.data(), ib);
      const __m256d cx = _mm256_fmsub_pd(ay, bz, _mm256_mul_pd(az, by));
      const __m256d cy = _mm256_fmsub_pd(az, bx, _mm256_mul_pd(ax, bz));
      const __m256d cz = _mm256_fmsub_pd(ax, by, _mm256_mul_pd(ay, bx));
      const __m256d sn = _mm256_sqrt_pd(_mm256_fmadd_pd(cx, cx, _mm256_fmadd_pd(cy, cy, _mm256_mul_pd(cz, cz))));
      const __m256d cs = _mm256_fmadd_pd(ax, bx, _mm256_fmadd_pd(ay, by, _mm256_mul_pd(az, bz)));
      const __m256d th = internal::atan2_nonneg_avx2(sn, cs);
      const __m256d pos = _mm256_cmp_pd(sn, _mm256_setzero_pd(), _CMP_GT_OQ);
      const __m256d f = _mm256_and_pd(pos, _mm256_div_pd(th, _mm256_blendv_pd(_mm256_set1_pd(1.0), sn, pos)));
      _mm256_storeu_pd(s.cx.data() + e, cx);
      _mm256_storeu_pd(s.cy.data() + e, cy);
      _mm256_storeu_pd(s.cz.data() + e, cz);
      _mm256_storeu_pd(s.gx.data() + e, _mm256_mul_pd(f, cx));
      _mm256_storeu_pd(s.gy.data() + e, _mm256_mul_pd(f, cy));
      _mm256_storeu_pd(s.gz.data() + e, _mm256_mul_pd(f, cz));
    }
    // The tail uses the same atan2 as the vector lanes, so results do not depend on the position.
    edges_scalar(g, s, e, [](double y, double x) { return internal::atan2_nonneg(y, x); });
  }

  // Step 4 on four triangles at a time: gathers of the edge quantities, corner contributions
  // stored per corner (no scatter conflicts between triangles sharing a vertex).
  __attribute__((target("avx2,fma"))) static void triangles_avx2(const internal::Cage_geometry& g, Scratch& s) {
    const std::size_t m = g.m;
    std::size_t t = 0;
    const __m256d half = _mm256_set1_pd(0.5), one = _mm256_set1_pd(1.0);
    for (; t + 4 <= m; t += 4) {
      __m256d mx = _mm256_setzero_pd(), my = mx, mz = mx;
      __m256d c[3][3];
      for (int k = 0; k < 3; ++k) {
        const __m128i ie = _mm_loadu_si128(reinterpret_cast<const __m128i*>(g.corner_edge.data() + k * m + t));
        const __m256d sg = _mm256_loadu_pd(g.corner_sign.data() + k * m + t);
        c[k][0] = _mm256_mul_pd(sg, internal::gather_avx2(s.cx.data(), ie));
        c[k][1] = _mm256_mul_pd(sg, internal::gather_avx2(s.cy.data(), ie));
        c[k][2] = _mm256_mul_pd(sg, internal::gather_avx2(s.cz.data(), ie));
        mx = _mm256_fmadd_pd(sg, internal::gather_avx2(s.gx.data(), ie), mx);
        my = _mm256_fmadd_pd(sg, internal::gather_avx2(s.gy.data(), ie), my);
        mz = _mm256_fmadd_pd(sg, internal::gather_avx2(s.gz.data(), ie), mz);
      }
      const __m128i iq = _mm_loadu_si128(reinterpret_cast<const __m128i*>(g.corner_vertex.data() + t));
      const __m256d det =
          _mm256_fmadd_pd(internal::gather_avx2(s.ux.data(), iq), c[0][0],
                          _mm256_fmadd_pd(internal::gather_avx2(s.uy.data(), iq), c[0][1],
                                          _mm256_mul_pd(internal::gather_avx2(s.uz.data(), iq), c[0][2])));
      const __m256d keep = _mm256_loadu_pd(s.keep.data() + t);
      const __m256d f = _mm256_and_pd(keep, _mm256_div_pd(half, _mm256_blendv_pd(one, det, keep)));
      for (int k = 0; k < 3; ++k) {
        const __m256d d = _mm256_fmadd_pd(mx, c[k][0], _mm256_fmadd_pd(my, c[k][1], _mm256_mul_pd(mz, c[k][2])));
        _mm256_storeu_pd(s.wc.data() + k * m + t, _mm256_mul_pd(f, d));
      }
    }
    for (; t < m; ++t) {
      double mx = 0, my = 0, mz = 0, c[3][3];
      for (std::size_t k = 0; k < 3; ++k) {
        const std::size_t e = std::size_t(g.corner_edge[k * m + t]);
        const double sg = g.corner_sign[k * m + t];
        mx += sg * s.gx[e];
        my += sg * s.gy[e];
        mz += sg * s.gz[e];
        c[k][0] = sg * s.cx[e];
        c[k][1] = sg * s.cy[e];
        c[k][2] = sg * s.cz[e];
      }
      const std::size_t q0 = std::size_t(g.corner_vertex[t]);
      const double det = s.ux[q0] * c[0][0] + s.uy[q0] * c[0][1] + s.uz[q0] * c[0][2];
      const double f = s.skip[t] ? 0.0 : 0.5 / det;
      for (std::size_t k = 0; k < 3; ++k) s.wc[k * m + t] = f * (mx * c[k][0] + my * c[k][1] + mz * c[k][2]);
    }
  }
#endif

  template <class OutputIterator>
  Coordinate_status write_unit(std::size_t i, OutputIterator out) const {
    for (std::size_t k = 0; k < g_->n; ++k) *out++ = (k == i) ? 1.0 : 0.0;
    return Coordinate_status::on_boundary;
  }
  template <class OutputIterator>
  Coordinate_status write_face(std::size_t t, std::array<double, 3> b, OutputIterator out) const {
    double sum = 0;
    for (double& x : b) sum += (x = std::max(0.0, x));
    Scratch& s = scratch();
    for (std::size_t k = 0; k < g_->n; ++k) s.w[k] = 0;
    for (int k = 0; k < 3; ++k) s.w[g_->tri[t][k]] += b[k] / sum;
    for (std::size_t k = 0; k < g_->n; ++k) *out++ = s.w[k];
    return Coordinate_status::on_boundary;
  }

  std::shared_ptr<const Triangle_cage> cage_;
  std::shared_ptr<const internal::Cage_geometry> g_;
  double tol_;
};

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_MEAN_VALUE_COORDINATES_3_H

// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Green_coordinates_3 and Green_rule: Green coordinates of Lipman, Levin and Cohen-Or (2008) for a
// closed triangle cage, a model of CageCoordinates (Cage_coordinates.h) with K = n + m coordinates
// (one per cage vertex, then one per cage triangle). Thesis §5.2 and §5.3.1 use them as the
// shape-preserving alternative to MVC: x' = sum_i phi_i(x) c'_i + sum_j psi_j(x) s_j n'_j, with s_j
// Lipman's stretch factor. Closed form per triangle, with the edge integral rewritten so that it
// does not cancel near an edge. Key choices where the paper leaves room: a point outside the cage
// is continued through an exit face (status extended, exact for similarities); a point on the cage
// gets the interior limit, extrapolated linearly (status on_boundary). Complexity: O(n + m) per
// query, 4 triangles at a time with AVX2 when the CPU has it; thread-safe.
//
// Manual: doc/Cage_deformation/README.md, "Methods and the choices made".
#ifndef CMGEOM_CAGE_DEFORMATION_GREEN_COORDINATES_3_H
#define CMGEOM_CAGE_DEFORMATION_GREEN_COORDINATES_3_H

#include <CMGeom/Cage_deformation/Cage_coordinates.h>
#include <CMGeom/Cage_deformation/internal/Cage_geometry.h>
#include <CMGeom/Cage_deformation/internal/Simd_math.h>

#include <cmath>
#include <memory>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {

/// CageDeformationRule of Green coordinates: deformed vertices, then s_j n'_j per triangle with
/// s_j = sqrt(|u'|^2 |v|^2 - 2 (u'.v')(u.v) + |v'|^2 |u|^2) / (sqrt(8) area_j) (Lipman et al.
/// 2008, §4.2: the stretch of the triangle's edges; 1 at rest, k under a uniform scale by k).
class Green_rule {
public:
  Green_rule() = default;
  explicit Green_rule(const Triangle_cage& rest) : rest_(std::make_shared<Triangle_cage>(rest)) {}
  std::size_t number_of_coordinates() const { return rest_->vertices.size() + rest_->triangles.size(); }
  template <class OutputIterator>
  void operator()(const std::vector<Vec3>& def, OutputIterator basis) const {
    using namespace internal;
    CGAL_precondition(def.size() == rest_->vertices.size());
    for (const Vec3& p : def) *basis++ = p;
    for (const auto& t : rest_->triangles) {
      const Vec3 u = sub(rest_->vertices[t[1]], rest_->vertices[t[0]]);
      const Vec3 v = sub(rest_->vertices[t[2]], rest_->vertices[t[0]]);
      const Vec3 u2 = sub(def[t[1]], def[t[0]]);
      const Vec3 v2 = sub(def[t[2]], def[t[0]]);
      const Vec3 n2 = cross(u2, v2);
      const double a2 = norm(n2);
      const double area = 0.5 * norm(cross(u, v));
      const double s2 = dot(u2, u2) * dot(v, v) - 2.0 * dot(u2, v2) * dot(u, v) + dot(v2, v2) * dot(u, u);
      const double s = std::sqrt(std::max(0.0, s2)) / (std::sqrt(8.0) * area);
      // A deformed triangle collapsed to a segment has no normal; its term is dropped.
      *basis++ = a2 > 0 ? mul(s / a2, n2) : Vec3{0, 0, 0};
    }
  }

private:
  std::shared_ptr<const Triangle_cage> rest_;
};

class Green_coordinates_3 {
public:
  using Deformation_rule = Green_rule;

  explicit Green_coordinates_3(const Triangle_cage& cage, double relative_tolerance = 1e-8)
      : cage_(std::make_shared<Triangle_cage>(cage)),
        g_(std::make_shared<internal::Cage_geometry>(cage)),
        tol_(relative_tolerance * g_->L) {
    const auto& g = *g_;
    ng_.resize(g.m);
    for (std::size_t t = 0; t < g.m; ++t)
      for (int k = 0; k < 3; ++k)  // n x g_k, g_k = q_{k+1} - q_{k+2}
        ng_[t][k] = internal::cross(g.normal[t], internal::sub(g.v[g.tri[t][(k + 1) % 3]], g.v[g.tri[t][(k + 2) % 3]]));
    nx_.resize(g.m);
    ny_.resize(g.m);
    nz_.resize(g.m);
    inv2a_.resize(g.m);
    ngx_.resize(3 * g.m);
    ngy_.resize(3 * g.m);
    ngz_.resize(3 * g.m);
    for (std::size_t t = 0; t < g.m; ++t) {
      nx_[t] = g.normal[t][0];
      ny_[t] = g.normal[t][1];
      nz_[t] = g.normal[t][2];
      inv2a_[t] = 1.0 / (2.0 * g.area[t]);
      for (std::size_t k = 0; k < 3; ++k) {
        ngx_[k * g.m + t] = ng_[t][k][0];
        ngy_[k * g.m + t] = ng_[t][k][1];
        ngz_[k * g.m + t] = ng_[t][k][2];
      }
    }
  }

  std::size_t number_of_coordinates() const { return g_->n + g_->m; }
  const Triangle_cage& cage() const { return *cage_; }
  Deformation_rule deformation_rule() const { return Green_rule(*cage_); }
  double tolerance() const { return tol_; }

  template <class Point, class OutputIterator>
  Coordinate_status operator()(const Point& query, OutputIterator out) const {
    const internal::Cage_geometry& g = *g_;
    const Vec3 x = internal::to_vec3(query);
    Scratch& s = scratch();
    s.resize(g.n, g.E, g.m);

    // On the cage: interior limit by linear extrapolation from two interior points.
    Vec3 inward{0, 0, 0};
    std::size_t first = g.m;
    for (std::size_t t = 0; t < g.m; ++t) {
      if (std::abs(g.signed_distance(t, x)) > tol_) continue;
      if (g.distance_to_triangle(t, x) > tol_) continue;
      if (first == g.m) first = t;
      inward = internal::sub(inward, g.normal[t]);
    }
    if (first < g.m) {
      // Inward direction: minus the sum of the normals of the faces touching x (the interior
      // side of an edge or vertex); if that leaves the cage (very sharp features), the inward
      // normal of one touching face.
      const double delta = 1e-5 * g.L;
      const double len = internal::norm(inward);
      Vec3 d = len > 0 ? internal::mul(delta / len, inward) : internal::mul(-delta, g.normal[first]);
      for (int attempt = 0; attempt < 2; ++attempt) {
        const double w1 = evaluate(internal::add(x, d), s.phi.data(), s.psi.data());
        s.phi2.assign(s.phi.begin(), s.phi.begin() + g.n);
        s.psi2.assign(s.psi.begin(), s.psi.begin() + g.m);
        const double w2 = evaluate(internal::add(x, internal::mul(2.0, d)), s.phi.data(), s.psi.data());
        if (w1 > 0.5 && w2 > 0.5) break;
        d = internal::mul(-delta, g.normal[first]);
      }
      for (std::size_t i = 0; i < g.n; ++i) *out++ = 2.0 * s.phi2[i] - s.phi[i];
      for (std::size_t j = 0; j < g.m; ++j) *out++ = 2.0 * s.psi2[j] - s.psi[j];
      return Coordinate_status::on_boundary;
    }

    const double winding = evaluate(x, s.phi.data(), s.psi.data());
    Coordinate_status status = Coordinate_status::regular;
    if (winding < 0.5) {
      // Exterior extension through the exit face.
      std::size_t best = g.m;
      double best_h = 1e300;
      for (std::size_t t = 0; t < g.m; ++t) {
        const double h = g.signed_distance(t, x);
        if (h <= 0 || h >= best_h) continue;
        if (g.outside_distance(t, g.plane_barycentrics(t, x)) <= 0) {
          best = t;
          best_h = h;
        }
      }
      if (best == g.m) {
        double best_d = 1e300;
        for (std::size_t t = 0; t < g.m; ++t) {
          const double d = g.distance_to_triangle(t, x);
          if (d < best_d) {
            best_d = d;
            best = t;
          }
        }
      }
      const std::array<double, 3> a = g.plane_barycentrics(best, x);
      for (int k = 0; k < 3; ++k) s.phi[g.tri[best][k]] += a[k];
      s.psi[best] += g.signed_distance(best, x);
      status = Coordinate_status::extended;
    }
    for (std::size_t i = 0; i < g.n; ++i) *out++ = s.phi[i];
    for (std::size_t j = 0; j < g.m; ++j) *out++ = s.psi[j];
    return status;
  }

  /// Winding number of the cage around x (sum of the vertex terms): 1 inside, 0 outside.
  template <class Point>
  double winding_number(const Point& query) const {
    Scratch& s = scratch();
    s.resize(g_->n, g_->E, g_->m);
    return evaluate(internal::to_vec3(query), s.phi.data(), s.psi.data());
  }

private:
  struct Scratch {
    std::vector<double> ex, ey, ez, r, phi, psi, C, jx, jy, jz, phi2, psi2, pc;
    void resize(std::size_t n, std::size_t E, std::size_t m) {
      if (ex.size() < n)
        for (auto* p : {&ex, &ey, &ez, &r, &phi}) p->resize(n);
      if (C.size() < E)
        for (auto* p : {&C, &jx, &jy, &jz}) p->resize(E);
      if (psi.size() < m) {
        psi.resize(m);
        pc.resize(3 * m);
      }
    }
  };
  static Scratch& scratch() {
    thread_local Scratch s;
    return s;
  }

  // The raw integrals at x (no boundary or exterior handling). Returns the winding number.
  double evaluate(const Vec3& x, double* phi, double* psi) const {
    const internal::Cage_geometry& g = *g_;
    Scratch& s = scratch();
    constexpr double inv4pi = 0.25 / 3.14159265358979323846;
    constexpr double inv2pi = 0.5 / 3.14159265358979323846;
    for (std::size_t i = 0; i < g.n; ++i) {
      const double ax = g.v[i][0] - x[0], ay = g.v[i][1] - x[1], az = g.v[i][2] - x[2];
      s.ex[i] = ax;
      s.ey[i] = ay;
      s.ez[i] = az;
      s.r[i] = std::sqrt(ax * ax + ay * ay + az * az);
      phi[i] = 0;
    }
#ifdef CMGEOM_CAGE_SIMD_AVX2
    if (internal::has_avx2()) return evaluate_avx2(g, s, phi, psi);
#endif
    for (std::size_t e = 0; e < g.E; ++e) {
      const std::uint32_t a = g.edge[e][0], b = g.edge[e][1];
      const double jx = s.ey[a] * s.ez[b] - s.ez[a] * s.ey[b];
      const double jy = s.ez[a] * s.ex[b] - s.ex[a] * s.ez[b];
      const double jz = s.ex[a] * s.ey[b] - s.ey[a] * s.ex[b];
      const double dab = s.ex[a] * s.ex[b] + s.ey[a] * s.ey[b] + s.ez[a] * s.ez[b];
      const double l = g.edge_length[e];
      const double R = s.r[a] + s.r[b];
      const double cr2 = jx * jx + jy * jy + jz * jz;
      // (R + l)/(R - l). Near the edge (angle between e_a and e_b >= 90 degrees) R - l cancels:
      // there R - l = 2|e_a x e_b|^2 / ((r_a r_b - e_a.e_b)(R + l)); elsewhere R - l >= 0.29
      // min(r_a, r_b) is computed directly (and the other form would be 0/0 on the edge's line).
      const double ratio = dab < 0 ? (R + l) * (R + l) * (s.r[a] * s.r[b] - dab) / (2.0 * cr2) : (R + l) / (R - l);
      s.C[e] = std::log(ratio) * inv4pi / l;
      s.jx[e] = jx;  // e_a x e_b, canonical direction
      s.jy[e] = jy;
      s.jz[e] = jz;
    }
    double winding = 0;
    for (std::size_t t = 0; t < g.m; ++t) {
      const auto& q = g.tri[t];
      const auto& te = g.tri_edge[t];
      const auto& sg = g.tri_sign[t];
      const Vec3& n = g.normal[t];
      const std::uint32_t i0 = q[0], i1 = q[1], i2 = q[2];
      // J_k = e_{k+2} x e_{k+1} = -(sign) * (e_a x e_b) of the edge opposite k.
      double J[3][3];
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t e = te[k];
        J[k][0] = -sg[k] * s.jx[e];
        J[k][1] = -sg[k] * s.jy[e];
        J[k][2] = -sg[k] * s.jz[e];
      }
      // det = e0 . (e1 x e2) = -e0 . J_0
      const double det = -(s.ex[i0] * J[0][0] + s.ey[i0] * J[0][1] + s.ez[i0] * J[0][2]);
      const double d01 = s.ex[i0] * s.ex[i1] + s.ey[i0] * s.ey[i1] + s.ez[i0] * s.ez[i1];
      const double d12 = s.ex[i1] * s.ex[i2] + s.ey[i1] * s.ey[i2] + s.ez[i1] * s.ez[i2];
      const double d20 = s.ex[i2] * s.ex[i0] + s.ey[i2] * s.ey[i0] + s.ez[i2] * s.ez[i0];
      const double den = s.r[i0] * s.r[i1] * s.r[i2] + d01 * s.r[i2] + d12 * s.r[i0] + d20 * s.r[i1];
      const double omega = std::atan2(det, den) * inv2pi;
      winding += omega;
      const double twoA = 2.0 * g.area[t];
      double ps = -omega * det / twoA;  // -3 omega V / A with V = det / 6
      double Px = -omega * n[0], Py = -omega * n[1], Pz = -omega * n[2];
      for (int k = 0; k < 3; ++k) {
        const double C = s.C[te[k]];
        ps -= C * (J[k][0] * n[0] + J[k][1] * n[1] + J[k][2] * n[2]);
        Px += C * ng_[t][k][0];
        Py += C * ng_[t][k][1];
        Pz += C * ng_[t][k][2];
      }
      psi[t] = ps;
      const double f = 1.0 / twoA;
      for (int k = 0; k < 3; ++k) phi[q[k]] += f * (Px * J[k][0] + Py * J[k][1] + Pz * J[k][2]);
    }
    return winding;
  }

#ifdef CMGEOM_CAGE_SIMD_AVX2
  // evaluate() on 4 edges / 4 triangles per instruction; corner contributions go to s.pc
  // (index k * m + t) and are summed per vertex afterwards (no scatter conflicts).
  __attribute__((target("avx2,fma"))) double evaluate_avx2(const internal::Cage_geometry& g, Scratch& s, double* phi,
                                                           double* psi) const {
    const std::size_t m = g.m, E = g.E;
    const __m256d zero = _mm256_setzero_pd();
    const __m256d inv4pi = _mm256_set1_pd(0.25 / internal::k_pi);
    std::size_t e = 0;
    for (; e + 4 <= E; e += 4) {
      const __m128i ia = _mm_loadu_si128(reinterpret_cast<const __m128i*>(g.edge_a.data() + e));
      const __m128i ib = _mm_loadu_si128(reinterpret_cast<const __m128i*>(g.edge_b.data() + e));
      const __m256d ax = internal::gather_avx2(s.ex.data(), ia), ay = internal::gather_avx2(s.ey.data(), ia),
                    az = internal::gather_avx2(s.ez.data(), ia), ra = internal::gather_avx2(s.r.data(), ia);
      const __m256d bx = internal::gather_avx2(s.ex.data(), ib), by = internal::gather_avx2(s.ey.data(), ib),
                    bz = internal::gather_avx2(s.ez.data(), ib), rb = internal::gather_avx2(s.r.data(), ib);
      const __m256d jx = _mm256_fmsub_pd(ay, bz, _mm256_mul_pd(az, by));
      const __m256d jy = _mm256_fmsub_pd(az, bx, _mm256_mul_pd(ax, bz));
      const __m256d jz = _mm256_fmsub_pd(ax, by, _mm256_mul_pd(ay, bx));
      const __m256d dab = _mm256_fmadd_pd(ax, bx, _mm256_fmadd_pd(ay, by, _mm256_mul_pd(az, bz)));
      const __m256d l = _mm256_loadu_pd(g.edge_length.data() + e);
      const __m256d R = _mm256_add_pd(ra, rb);
      const __m256d cr2 = _mm256_fmadd_pd(jx, jx, _mm256_fmadd_pd(jy, jy, _mm256_mul_pd(jz, jz)));
      const __m256d Rl = _mm256_add_pd(R, l);
      const __m256d near = _mm256_cmp_pd(dab, zero, _CMP_LT_OQ);
      const __m256d num =
          _mm256_blendv_pd(Rl, _mm256_mul_pd(_mm256_mul_pd(Rl, Rl), _mm256_fmsub_pd(ra, rb, dab)), near);
      const __m256d den = _mm256_blendv_pd(_mm256_sub_pd(R, l), _mm256_add_pd(cr2, cr2), near);
      const __m256d C = _mm256_div_pd(_mm256_mul_pd(internal::log_avx2(_mm256_div_pd(num, den)), inv4pi), l);
      _mm256_storeu_pd(s.C.data() + e, C);
      _mm256_storeu_pd(s.jx.data() + e, jx);
      _mm256_storeu_pd(s.jy.data() + e, jy);
      _mm256_storeu_pd(s.jz.data() + e, jz);
    }
    for (; e < E; ++e) {
      const std::uint32_t a = g.edge[e][0], b = g.edge[e][1];
      const double jx = s.ey[a] * s.ez[b] - s.ez[a] * s.ey[b];
      const double jy = s.ez[a] * s.ex[b] - s.ex[a] * s.ez[b];
      const double jz = s.ex[a] * s.ey[b] - s.ey[a] * s.ex[b];
      const double dab = s.ex[a] * s.ex[b] + s.ey[a] * s.ey[b] + s.ez[a] * s.ez[b];
      const double l = g.edge_length[e], R = s.r[a] + s.r[b];
      const double cr2 = jx * jx + jy * jy + jz * jz;
      const double ratio = dab < 0 ? (R + l) * (R + l) * (s.r[a] * s.r[b] - dab) / (2.0 * cr2) : (R + l) / (R - l);
      s.C[e] = internal::fast_log(ratio) * (0.25 / internal::k_pi) / l;
      s.jx[e] = jx;
      s.jy[e] = jy;
      s.jz[e] = jz;
    }
    const __m256d inv2pi = _mm256_set1_pd(0.5 / internal::k_pi);
    __m256d wsum = zero;
    std::size_t t = 0;
    for (; t + 4 <= m; t += 4) {
      __m128i iq[3];
      __m256d ex[3], ey[3], ez[3], r[3], J[3][3], C[3];
      for (int k = 0; k < 3; ++k) {
        iq[k] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(g.corner_vertex.data() + k * m + t));
        ex[k] = internal::gather_avx2(s.ex.data(), iq[k]);
        ey[k] = internal::gather_avx2(s.ey.data(), iq[k]);
        ez[k] = internal::gather_avx2(s.ez.data(), iq[k]);
        r[k] = internal::gather_avx2(s.r.data(), iq[k]);
        const __m128i ie = _mm_loadu_si128(reinterpret_cast<const __m128i*>(g.corner_edge.data() + k * m + t));
        // J_k = -(sign) (e_a x e_b) of the edge opposite corner k
        const __m256d ms = _mm256_sub_pd(zero, _mm256_loadu_pd(g.corner_sign.data() + k * m + t));
        J[k][0] = _mm256_mul_pd(ms, internal::gather_avx2(s.jx.data(), ie));
        J[k][1] = _mm256_mul_pd(ms, internal::gather_avx2(s.jy.data(), ie));
        J[k][2] = _mm256_mul_pd(ms, internal::gather_avx2(s.jz.data(), ie));
        C[k] = internal::gather_avx2(s.C.data(), ie);
      }
      const __m256d det = _mm256_sub_pd(
          zero, _mm256_fmadd_pd(ex[0], J[0][0], _mm256_fmadd_pd(ey[0], J[0][1], _mm256_mul_pd(ez[0], J[0][2]))));
      // (lambdas would not inherit the target attribute: the three dot products are spelled out)
      const __m256d d01 = _mm256_fmadd_pd(ex[0], ex[1], _mm256_fmadd_pd(ey[0], ey[1], _mm256_mul_pd(ez[0], ez[1])));
      const __m256d d12 = _mm256_fmadd_pd(ex[1], ex[2], _mm256_fmadd_pd(ey[1], ey[2], _mm256_mul_pd(ez[1], ez[2])));
      const __m256d d20 = _mm256_fmadd_pd(ex[2], ex[0], _mm256_fmadd_pd(ey[2], ey[0], _mm256_mul_pd(ez[2], ez[0])));
      __m256d den = _mm256_mul_pd(_mm256_mul_pd(r[0], r[1]), r[2]);
      den = _mm256_fmadd_pd(d01, r[2], den);
      den = _mm256_fmadd_pd(d12, r[0], den);
      den = _mm256_fmadd_pd(d20, r[1], den);
      const __m256d omega = _mm256_mul_pd(internal::atan2_avx2(det, den), inv2pi);
      wsum = _mm256_add_pd(wsum, omega);
      const __m256d nx = _mm256_loadu_pd(nx_.data() + t), ny = _mm256_loadu_pd(ny_.data() + t),
                    nz = _mm256_loadu_pd(nz_.data() + t), i2a = _mm256_loadu_pd(inv2a_.data() + t);
      __m256d ps = _mm256_sub_pd(zero, _mm256_mul_pd(_mm256_mul_pd(omega, det), i2a));
      __m256d Px = _mm256_sub_pd(zero, _mm256_mul_pd(omega, nx));
      __m256d Py = _mm256_sub_pd(zero, _mm256_mul_pd(omega, ny));
      __m256d Pz = _mm256_sub_pd(zero, _mm256_mul_pd(omega, nz));
      for (int k = 0; k < 3; ++k) {
        const __m256d jn = _mm256_fmadd_pd(J[k][0], nx, _mm256_fmadd_pd(J[k][1], ny, _mm256_mul_pd(J[k][2], nz)));
        ps = _mm256_fnmadd_pd(C[k], jn, ps);
        Px = _mm256_fmadd_pd(C[k], _mm256_loadu_pd(ngx_.data() + k * m + t), Px);
        Py = _mm256_fmadd_pd(C[k], _mm256_loadu_pd(ngy_.data() + k * m + t), Py);
        Pz = _mm256_fmadd_pd(C[k], _mm256_loadu_pd(ngz_.data() + k * m + t), Pz);
      }
      _mm256_storeu_pd(psi + t, ps);
      for (int k = 0; k < 3; ++k) {
        const __m256d pj = _mm256_fmadd_pd(Px, J[k][0], _mm256_fmadd_pd(Py, J[k][1], _mm256_mul_pd(Pz, J[k][2])));
        _mm256_storeu_pd(s.pc.data() + k * m + t, _mm256_mul_pd(pj, i2a));
      }
    }
    alignas(32) double wl[4];
    _mm256_store_pd(wl, wsum);
    double winding = (wl[0] + wl[1]) + (wl[2] + wl[3]);
    for (; t < m; ++t) {
      std::size_t q[3], te[3];
      double J[3][3];
      for (std::size_t k = 0; k < 3; ++k) {
        q[k] = std::size_t(g.corner_vertex[k * m + t]);
        te[k] = std::size_t(g.corner_edge[k * m + t]);
        const double sg = -g.corner_sign[k * m + t];
        J[k][0] = sg * s.jx[te[k]];
        J[k][1] = sg * s.jy[te[k]];
        J[k][2] = sg * s.jz[te[k]];
      }
      const double det = -(s.ex[q[0]] * J[0][0] + s.ey[q[0]] * J[0][1] + s.ez[q[0]] * J[0][2]);
      auto d = [&](std::size_t i, std::size_t j) { return s.ex[i] * s.ex[j] + s.ey[i] * s.ey[j] + s.ez[i] * s.ez[j]; };
      const double den = s.r[q[0]] * s.r[q[1]] * s.r[q[2]] + d(q[0], q[1]) * s.r[q[2]] + d(q[1], q[2]) * s.r[q[0]] +
                         d(q[2], q[0]) * s.r[q[1]];
      const double omega = internal::fast_atan2(det, den) * (0.5 / internal::k_pi);
      winding += omega;
      double ps = -omega * det * inv2a_[t];
      double Px = -omega * nx_[t], Py = -omega * ny_[t], Pz = -omega * nz_[t];
      for (std::size_t k = 0; k < 3; ++k) {
        const double C = s.C[te[k]];
        ps -= C * (J[k][0] * nx_[t] + J[k][1] * ny_[t] + J[k][2] * nz_[t]);
        Px += C * ngx_[k * m + t];
        Py += C * ngy_[k * m + t];
        Pz += C * ngz_[k * m + t];
      }
      psi[t] = ps;
      for (std::size_t k = 0; k < 3; ++k) s.pc[k * m + t] = (Px * J[k][0] + Py * J[k][1] + Pz * J[k][2]) * inv2a_[t];
    }
    for (std::size_t i = 0; i < g.n; ++i) {
      double acc = 0;
      for (std::int32_t c = g.vertex_corner_start[i]; c < g.vertex_corner_start[i + 1]; ++c)
        acc += s.pc[std::size_t(g.vertex_corner[std::size_t(c)])];
      phi[i] = acc;
    }
    return winding;
  }
#endif

  std::shared_ptr<const Triangle_cage> cage_;
  std::shared_ptr<const internal::Cage_geometry> g_;
  std::vector<std::array<Vec3, 3>> ng_;
  // SoA copies for the SIMD path: normals, 1 / 2A per triangle; n x g_k per corner k * m + t
  std::vector<double> nx_, ny_, nz_, inv2a_, ngx_, ngy_, ngz_;
  double tol_;
};

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_GREEN_COORDINATES_3_H

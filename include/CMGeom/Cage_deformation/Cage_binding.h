// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Binding and deformation (thesis §5.1: "transforming a point by a linear combination of the cage
// geometry using a set of precalculated coordinates"). bind_points() evaluates any CageCoordinates model
// at every point of a mesh once (TBB-parallel) and stores the N x K weights densely or sparsely,
// as float or double; Cage_binding::deform() then maps the K basis vectors of a deformed cage
// (CageDeformationRule) to the N deformed positions, x'_v = sum_k W[v][k] B_k.
//
// deform() is the per-frame hot loop: it allocates nothing, runs over rows in parallel, and reads
// the weights once, so it is bound by memory bandwidth. The dense kernel is written with AVX2/FMA
// intrinsics chosen at run time (__builtin_cpu_supports), because the project builds with plain
// -O2 (no -march), which neither vectorises floating-point reductions nor uses AVX; a portable
// scalar kernel with four independent accumulators is the fallback.
//
// Complexity: bind_points O(N (n + m)) coordinate evaluations; deform O(N K) dense, O(nnz) sparse.
#ifndef CMGEOM_CAGE_DEFORMATION_CAGE_BINDING_H
#define CMGEOM_CAGE_DEFORMATION_CAGE_BINDING_H

#include <CMGeom/Cage_deformation/Cage_coordinates.h>
#include <CMGeom/Cage_deformation/internal/Simd_math.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>


namespace CMGeom {
namespace Cage_deformation {

enum class Weight_storage { dense, sparse };

struct Binding_options {
  Weight_storage storage = Weight_storage::dense;
  /// Sparse storage drops weights with |w| <= threshold (0 keeps every non-zero, so the
  /// deformation is unchanged; a positive value trades accuracy for memory).
  double sparse_threshold = 0.0;
};

/// Precomputed coordinates of N points with respect to one cage. Weight: float or double.
template <class Weight = double>
class Cage_binding {
  static_assert(std::is_same<Weight, float>::value || std::is_same<Weight, double>::value,
                "Weight must be float or double");

public:
  Cage_binding() = default;

  std::size_t number_of_points() const { return rows_; }
  std::size_t number_of_coordinates() const { return K_; }
  Weight_storage storage() const { return storage_; }
  /// Memory held by the weights (values, plus column indices and row starts when sparse).
  std::size_t weights_bytes() const {
    return values_.size() * sizeof(Weight) + columns_.size() * sizeof(std::uint32_t) +
           row_start_.size() * sizeof(std::size_t);
  }
  std::size_t number_of_stored_weights() const { return values_.size(); }
  const std::vector<Coordinate_status>& status() const { return status_; }
  std::size_t count(Coordinate_status s) const {
    return std::size_t(std::count(status_.begin(), status_.end(), s));
  }

  /// Weight of coordinate k for point v (0 when not stored).
  double weight(std::size_t v, std::size_t k) const {
    if (storage_ == Weight_storage::dense) return values_[v * K_ + k];
    for (std::size_t i = row_start_[v]; i < row_start_[v + 1]; ++i)
      if (columns_[i] == k) return values_[i];
    return 0;
  }

  /// x'_v = sum_k W[v][k] basis[k] for every point; `out` must hold number_of_points() values.
  void deform(const std::vector<Vec3>& basis, Vec3* out) const {
    CGAL_precondition(basis.size() == K_);
    const Vec3* B = basis.data();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows_, 512),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        if (storage_ == Weight_storage::dense)
                          dense_rows(r.begin(), r.end(), B, out);
                        else
                          sparse_rows(r.begin(), r.end(), B, out);
                      });
  }
  void deform(const std::vector<Vec3>& basis, std::vector<Vec3>& out) const {
    out.resize(rows_);
    deform(basis, out.data());
  }
  /// Convenience: basis from a CageDeformationRule and the deformed cage vertices.
  template <class Rule>
  void deform(const Rule& rule, const std::vector<Vec3>& deformed_vertices,
              std::vector<Vec3>& out) const {
    std::vector<Vec3> basis;
    basis.reserve(rule.number_of_coordinates());
    rule(deformed_vertices, std::back_inserter(basis));
    deform(basis, out);
  }

  /// A sparse binding from CSR rows (`row_start` holds N + 1 offsets into `columns`/`values`),
  /// for callers that assemble the rows themselves (Cage_system, §5.3).
  static Cage_binding from_sparse_rows(std::size_t K, std::vector<std::size_t> row_start,
                                       std::vector<std::uint32_t> columns, std::vector<Weight> values,
                                       std::vector<Coordinate_status> status) {
    CGAL_precondition(!row_start.empty() && row_start.back() == columns.size() &&
                      columns.size() == values.size() && status.size() + 1 == row_start.size());
    Cage_binding b;
    b.rows_ = status.size();
    b.K_ = K;
    b.storage_ = Weight_storage::sparse;
    b.row_start_ = std::move(row_start);
    b.columns_ = std::move(columns);
    b.values_ = std::move(values);
    b.status_ = std::move(status);
    return b;
  }

  // Raw access, for the benchmark and for packages that combine several bindings.
  const std::vector<Weight>& values() const { return values_; }
  const std::vector<std::uint32_t>& columns() const { return columns_; }
  const std::vector<std::size_t>& row_start() const { return row_start_; }

private:
  template <class W, class C, class PR>
  friend Cage_binding<W> bind_points(const C&, const PR&, const Binding_options&);

  void dense_rows(std::size_t b, std::size_t e, const Vec3* B, Vec3* out) const {
#ifdef CMGEOM_CAGE_SIMD_AVX2
    if (internal::has_avx2()) {
      dense_rows_avx2(values_.data(), K_, b, e, B, out);
      return;
    }
#endif
    for (std::size_t v = b; v < e; ++v) {
      const Weight* w = values_.data() + v * K_;
      double s[4][3] = {};
      std::size_t k = 0;
      for (; k + 4 <= K_; k += 4)
        for (int j = 0; j < 4; ++j)
          for (int c = 0; c < 3; ++c) s[j][c] += double(w[k + j]) * B[k + j][c];
      for (; k < K_; ++k)
        for (int c = 0; c < 3; ++c) s[0][c] += double(w[k]) * B[k][c];
      for (int c = 0; c < 3; ++c) out[v][c] = (s[0][c] + s[1][c]) + (s[2][c] + s[3][c]);
    }
  }

  void sparse_rows(std::size_t b, std::size_t e, const Vec3* B, Vec3* out) const {
    for (std::size_t v = b; v < e; ++v) {
      double sx = 0, sy = 0, sz = 0;
      for (std::size_t i = row_start_[v]; i < row_start_[v + 1]; ++i) {
        const double w = values_[i];
        const Vec3& p = B[columns_[i]];
        sx += w * p[0];
        sy += w * p[1];
        sz += w * p[2];
      }
      out[v] = {sx, sy, sz};
    }
  }

#ifdef CMGEOM_CAGE_SIMD_AVX2
  // The basis is transposed to SoA in chunks of 1024 columns (24 KB, stays in L1), so each row is
  // three streaming dot products over its weights; float weights are widened to double.
  __attribute__((target("avx2,fma"))) static void dense_rows_avx2(const Weight* W, std::size_t K,
                                                                   std::size_t b, std::size_t e,
                                                                   const Vec3* B, Vec3* out) {
    constexpr std::size_t chunk = 1024;  // basis columns transposed per pass (24 KB, in L1)
    alignas(32) double bx[chunk], by[chunk], bz[chunk];
    for (std::size_t k0 = 0; k0 < K; k0 += chunk) {
      const std::size_t kn = std::min(chunk, K - k0);
      for (std::size_t k = 0; k < kn; ++k) {
        bx[k] = B[k0 + k][0];
        by[k] = B[k0 + k][1];
        bz[k] = B[k0 + k][2];
      }
      for (std::size_t v = b; v < e; ++v) {
        const Weight* w = W + v * K + k0;
        __m256d ax = _mm256_setzero_pd(), ay = _mm256_setzero_pd(), az = _mm256_setzero_pd();
        __m256d cx = _mm256_setzero_pd(), cy = _mm256_setzero_pd(), cz = _mm256_setzero_pd();
        std::size_t k = 0;
        for (; k + 8 <= kn; k += 8) {
          __m256d w0, w1;
          if constexpr (std::is_same<Weight, float>::value) {
            const __m256 wf = _mm256_loadu_ps(w + k);
            w0 = _mm256_cvtps_pd(_mm256_castps256_ps128(wf));
            w1 = _mm256_cvtps_pd(_mm256_extractf128_ps(wf, 1));
          } else {
            w0 = _mm256_loadu_pd(w + k);
            w1 = _mm256_loadu_pd(w + k + 4);
          }
          ax = _mm256_fmadd_pd(w0, _mm256_load_pd(bx + k), ax);
          ay = _mm256_fmadd_pd(w0, _mm256_load_pd(by + k), ay);
          az = _mm256_fmadd_pd(w0, _mm256_load_pd(bz + k), az);
          cx = _mm256_fmadd_pd(w1, _mm256_load_pd(bx + k + 4), cx);
          cy = _mm256_fmadd_pd(w1, _mm256_load_pd(by + k + 4), cy);
          cz = _mm256_fmadd_pd(w1, _mm256_load_pd(bz + k + 4), cz);
        }
        ax = _mm256_add_pd(ax, cx);
        ay = _mm256_add_pd(ay, cy);
        az = _mm256_add_pd(az, cz);
        alignas(32) double tx[4], ty[4], tz[4];
        _mm256_store_pd(tx, ax);
        _mm256_store_pd(ty, ay);
        _mm256_store_pd(tz, az);
        double sx = (tx[0] + tx[1]) + (tx[2] + tx[3]);
        double sy = (ty[0] + ty[1]) + (ty[2] + ty[3]);
        double sz = (tz[0] + tz[1]) + (tz[2] + tz[3]);
        for (; k < kn; ++k) {
          const double wk = double(w[k]);
          sx += wk * bx[k];
          sy += wk * by[k];
          sz += wk * bz[k];
        }
        if (k0 == 0)
          out[v] = {sx, sy, sz};
        else
          out[v] = {out[v][0] + sx, out[v][1] + sy, out[v][2] + sz};
      }
    }
  }
#endif

  std::size_t rows_ = 0, K_ = 0;
  Weight_storage storage_ = Weight_storage::dense;
  std::vector<Weight> values_;
  std::vector<std::uint32_t> columns_;
  std::vector<std::size_t> row_start_;
  std::vector<Coordinate_status> status_;
};

/// Evaluates `coords` (a CageCoordinates model) at every point of `points` (a random-access
/// range of CGAL points or 3-arrays), in parallel; results do not depend on the thread count.
template <class Weight = double, class Coordinates, class PointRange>
Cage_binding<Weight> bind_points(const Coordinates& coords, const PointRange& points,
                          const Binding_options& options = Binding_options()) {
  Cage_binding<Weight> b;
  const std::size_t N = std::size_t(std::distance(std::begin(points), std::end(points)));
  const std::size_t K = coords.number_of_coordinates();
  b.rows_ = N;
  b.K_ = K;
  b.storage_ = options.storage;
  b.status_.resize(N);
  auto first = std::begin(points);
  if (options.storage == Weight_storage::dense) {
    b.values_.resize(N * K);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, N, 16),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t v = r.begin(); v < r.end(); ++v)
                          b.status_[v] = coords(*(first + v), b.values_.data() + v * K);
                      });
    return b;
  }
  // Sparse: blocks of rows are computed independently, then concatenated in order.
  constexpr std::size_t block = 256;
  const std::size_t nblocks = (N + block - 1) / block;
  std::vector<std::vector<Weight>> vals(nblocks);
  std::vector<std::vector<std::uint32_t>> cols(nblocks);
  std::vector<std::vector<std::size_t>> counts(nblocks);
  const double thr = options.sparse_threshold;
  tbb::parallel_for(std::size_t(0), nblocks, [&](std::size_t bi) {
    std::vector<double> row(K);
    for (std::size_t v = bi * block; v < std::min(N, (bi + 1) * block); ++v) {
      b.status_[v] = coords(*(first + v), row.begin());
      std::size_t c = 0;
      for (std::size_t k = 0; k < K; ++k)
        if (std::abs(row[k]) > thr) {
          vals[bi].push_back(Weight(row[k]));
          cols[bi].push_back(std::uint32_t(k));
          ++c;
        }
      counts[bi].push_back(c);
    }
  });
  b.row_start_.assign(1, 0);
  b.row_start_.reserve(N + 1);
  for (std::size_t bi = 0; bi < nblocks; ++bi) {
    for (std::size_t c : counts[bi]) b.row_start_.push_back(b.row_start_.back() + c);
    b.values_.insert(b.values_.end(), vals[bi].begin(), vals[bi].end());
    b.columns_.insert(b.columns_.end(), cols[bi].begin(), cols[bi].end());
  }
  return b;
}

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_CAGE_BINDING_H

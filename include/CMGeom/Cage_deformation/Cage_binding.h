// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Binding and deformation (thesis §5.1: a point is transformed by a linear combination of the cage
// geometry with precalculated coordinates): bind_points() evaluates any CageCoordinates model at
// every point once (TBB-parallel) and stores the N x K weights dense, sparse (CSR) or grouped, as
// float or double; Cage_binding::deform() maps the K basis vectors of a deformed cage to the N
// positions, x'_v = sum_k W[v][k] B_k. deform() is the per-frame hot loop: it allocates nothing,
// runs over rows in parallel and reads the weights once, so it is bound by memory bandwidth; its
// dense kernel uses AVX2/FMA chosen at run time, as the project builds without -march. Grouped
// storage, for the rows of a *Cages system, keeps each column pattern once and a weight costs its
// value only. Complexity: binding O(N (n + m)); deform O(N K) dense, O(nnz) sparse and grouped.
//
// Manual: doc/Cage_deformation/README.md, "Methods and the choices made".
#ifndef CMGEOM_CAGE_DEFORMATION_CAGE_BINDING_H
#define CMGEOM_CAGE_DEFORMATION_CAGE_BINDING_H

#include <CMGeom/Cage_deformation/Cage_coordinates.h>
#include <CMGeom/Cage_deformation/internal/Simd_math.h>
#include <CMGeom/Progress.h>
#include <CMGeom/internal/huge_pages.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <unordered_map>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {

/// dense: N x K values; sparse: CSR rows; grouped: rows sharing a column pattern stored as dense
/// blocks (see the header comment).
enum class Weight_storage { dense, sparse, grouped };

struct Binding_options {
  Weight_storage storage = Weight_storage::dense;
  /// Sparse and grouped storage drop weights with |w| <= threshold (0 keeps every non-zero, so
  /// the deformation is unchanged; a positive value trades accuracy for memory).
  double sparse_threshold = 0.0;
  /// Optional progress hook of bind_points() (CMGeom/Progress.h): the fraction of the points
  /// bound, from the calling thread, at a bounded rate; it must be cheap. Empty: no reports.
  Progress_callback progress;
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
  /// Memory held by the weights (values, plus column indices and row starts when sparse, plus
  /// patterns, group offsets and point indices when grouped).
  std::size_t weights_bytes() const {
    return values_.size() * sizeof(Weight) + columns_.size() * sizeof(std::uint32_t) +
           row_start_.size() * sizeof(std::size_t) + point_of_.size() * sizeof(std::uint32_t) +
           group_column_start_.size() * sizeof(std::size_t) + group_row_start_.size() * sizeof(std::uint32_t) +
           group_value_start_.size() * sizeof(std::size_t) + blocks_.size() * sizeof(blocks_[0]) +
           runs_.size() * sizeof(runs_[0]);
  }
  /// Number of column patterns (grouped storage; 0 otherwise).
  std::size_t number_of_groups() const { return group_row_start_.empty() ? 0 : group_row_start_.size() - 1; }
  std::size_t number_of_stored_weights() const { return values_.size(); }
  const std::vector<Coordinate_status>& status() const { return status_; }
  std::size_t count(Coordinate_status s) const { return std::size_t(std::count(status_.begin(), status_.end(), s)); }

  /// Weight of coordinate k for point v (0 when not stored). O(1) dense, O(row) sparse, O(N)
  /// grouped (the stored row of a point is searched; meant for tests and inspection).
  double weight(std::size_t v, std::size_t k) const {
    if (storage_ == Weight_storage::dense) return values_[v * K_ + k];
    if (storage_ == Weight_storage::sparse) {
      for (std::size_t i = row_start_[v]; i < row_start_[v + 1]; ++i)
        if (columns_[i] == k) return values_[i];
      return 0;
    }
    const std::size_t s = stored_row(v);
    if (s >= rows_) return 0;
    const std::size_t g =
        std::size_t(std::upper_bound(group_row_start_.begin(), group_row_start_.end(), std::uint32_t(s)) -
                    group_row_start_.begin()) -
        1;
    const std::size_t n = group_column_start_[g + 1] - group_column_start_[g];
    for (std::size_t c = 0; c < n; ++c)
      if (columns_[group_column_start_[g] + c] == k)
        return values_[group_value_start_[g] + (s - group_row_start_[g]) * n + c];
    return 0;
  }

  /// x'_v = sum_k W[v][k] basis[k] for every point; `out` must hold number_of_points() values.
  void deform(const std::vector<Vec3>& basis, Vec3* out) const {
    CGAL_precondition(basis.size() == K_);
    const Vec3* B = basis.data();
    if (storage_ == Weight_storage::grouped) {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks_.size(), 1),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i < r.end(); ++i) grouped_block(blocks_[i], B, out);
                        });
      return;
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows_, 512), [&](const tbb::blocked_range<std::size_t>& r) {
      if (storage_ == Weight_storage::dense)
        dense_rows(r.begin(), r.end(), B, out);
      else
        sparse_rows(r.begin(), r.end(), B, out);
    });
  }
  void deform(const std::vector<Vec3>& basis, std::vector<Vec3>& out) const {
    CMGeom::internal::resize_on_huge_pages(out, rows_);
    deform(basis, out.data());
  }
  /// Convenience: basis from a CageDeformationRule and the deformed cage vertices.
  template <class Rule>
  void deform(const Rule& rule, const std::vector<Vec3>& deformed_vertices, std::vector<Vec3>& out) const {
    std::vector<Vec3> basis;
    basis.reserve(rule.number_of_coordinates());
    rule(deformed_vertices, std::back_inserter(basis));
    deform(basis, out);
  }

  /// A sparse or grouped binding from CSR rows (`row_start` holds N + 1 offsets into
  /// `columns`/`values`, columns of a row in any fixed order), for callers that assemble the rows
  /// themselves (Cage_system, §5.3). Grouping keeps every value and its order within the row, so
  /// both storages give the same weights.
  static Cage_binding from_sparse_rows(std::size_t K, std::vector<std::size_t> row_start,
                                       std::vector<std::uint32_t> columns, std::vector<Weight> values,
                                       std::vector<Coordinate_status> status,
                                       Weight_storage storage = Weight_storage::sparse) {
    CGAL_precondition(!row_start.empty() && row_start.back() == columns.size() && columns.size() == values.size() &&
                      status.size() + 1 == row_start.size());
    CGAL_precondition(storage != Weight_storage::dense);
    if (storage == Weight_storage::grouped) return grouped_from_rows(K, row_start, columns, values, std::move(status));
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

  /// Rows [begin, end) of the stored order, all in group `group`.
  struct Block {
    std::uint32_t group, begin, end;
  };
  /// Stored rows from `stored` on (to the next run) belong to points `point`, `point` + 1, ...
  struct Run {
    std::uint32_t stored, point;
  };
  static constexpr std::uint32_t rows_per_block = 256;

  static Cage_binding grouped_from_rows(std::size_t K, const std::vector<std::size_t>& row_start,
                                        const std::vector<std::uint32_t>& columns, const std::vector<Weight>& values,
                                        std::vector<Coordinate_status> status) {
    const std::size_t N = status.size();
    CGAL_precondition(N < std::size_t(std::numeric_limits<std::uint32_t>::max()));
    Cage_binding b;
    b.rows_ = N;
    b.K_ = K;
    b.storage_ = Weight_storage::grouped;
    b.status_ = std::move(status);
    // Patterns by hash of the column list; groups numbered in order of first appearance.
    std::unordered_multimap<std::uint64_t, std::uint32_t> by_hash;
    std::vector<std::size_t> first_row;  // a row of each group (its pattern)
    std::vector<std::uint32_t> group_of(N), count;
    auto same = [&](std::size_t a, std::size_t c) {
      return row_start[a + 1] - row_start[a] == row_start[c + 1] - row_start[c] &&
             std::equal(columns.begin() + std::ptrdiff_t(row_start[a]),
                        columns.begin() + std::ptrdiff_t(row_start[a + 1]),
                        columns.begin() + std::ptrdiff_t(row_start[c]));
    };
    for (std::size_t v = 0; v < N; ++v) {
      std::uint64_t h = 1469598103934665603ull;  // FNV-1a over the column indices
      for (std::size_t i = row_start[v]; i < row_start[v + 1]; ++i) h = (h ^ columns[i]) * 1099511628211ull;
      std::uint32_t g = std::uint32_t(first_row.size());
      auto range = by_hash.equal_range(h);
      for (auto it = range.first; it != range.second; ++it)
        if (same(first_row[it->second], v)) {
          g = it->second;
          break;
        }
      if (g == first_row.size()) {
        by_hash.emplace(h, g);
        first_row.push_back(v);
        count.push_back(0);
      }
      group_of[v] = g;
      ++count[g];
    }
    const std::size_t G = first_row.size();
    b.group_column_start_.assign(1, 0);
    b.group_row_start_.assign(1, 0);
    b.group_value_start_.assign(1, 0);
    for (std::size_t g = 0; g < G; ++g) {
      const std::size_t v = first_row[g], n = row_start[v + 1] - row_start[v];
      b.columns_.insert(b.columns_.end(), columns.begin() + std::ptrdiff_t(row_start[v]),
                        columns.begin() + std::ptrdiff_t(row_start[v + 1]));
      b.group_column_start_.push_back(b.columns_.size());
      b.group_row_start_.push_back(b.group_row_start_.back() + count[g]);
      b.group_value_start_.push_back(b.group_value_start_.back() + std::size_t(count[g]) * n);
    }
    // Stored order: by group, then by point index (a counting sort, so it is deterministic).
    std::vector<std::uint32_t> next(b.group_row_start_.begin(), b.group_row_start_.end() - 1);
    b.point_of_.resize(N);
    CMGeom::internal::resize_on_huge_pages(b.values_, values.size());
    for (std::size_t v = 0; v < N; ++v) {
      const std::uint32_t g = group_of[v], s = next[g]++;
      b.point_of_[s] = std::uint32_t(v);
      const std::size_t n = row_start[v + 1] - row_start[v];
      std::copy(values.begin() + std::ptrdiff_t(row_start[v]), values.begin() + std::ptrdiff_t(row_start[v + 1]),
                b.values_.begin() + std::ptrdiff_t(b.group_value_start_[g] + (s - b.group_row_start_[g]) * n));
    }
    for (std::uint32_t g = 0; g < G; ++g)
      for (std::uint32_t s = b.group_row_start_[g]; s < b.group_row_start_[g + 1]; s += rows_per_block)
        b.blocks_.push_back({g, s, std::min(s + rows_per_block, b.group_row_start_[g + 1])});
    // Consecutive points of a group (meshes list neighbouring vertices together) are runs: when
    // the runs are on average longer than two rows, they replace the per-row point indices.
    std::vector<Run> runs;
    for (std::uint32_t s = 0; s < N; ++s)
      if (s == 0 || b.point_of_[s] != b.point_of_[s - 1] + 1) runs.push_back({s, b.point_of_[s]});
    if (runs.size() * sizeof(Run) < N * sizeof(std::uint32_t)) {
      b.runs_ = std::move(runs);
      b.point_of_ = std::vector<std::uint32_t>();
    }
    return b;
  }

  // Stored row of point v (grouped storage), N if none.
  std::size_t stored_row(std::size_t v) const {
    if (!point_of_.empty())
      return std::size_t(std::find(point_of_.begin(), point_of_.end(), std::uint32_t(v)) - point_of_.begin());
    for (std::size_t r = 0; r < runs_.size(); ++r) {
      const std::size_t len = (r + 1 < runs_.size() ? runs_[r + 1].stored : rows_) - runs_[r].stored;
      if (v >= runs_[r].point && v < runs_[r].point + len) return runs_[r].stored + (v - runs_[r].point);
    }
    return rows_;
  }

  void grouped_block(const Block& blk, const Vec3* B, Vec3* out) const {
    const std::size_t g = blk.group, first = group_row_start_[g];
    const std::size_t n = group_column_start_[g + 1] - group_column_start_[g];
    const Weight* W = values_.data() + group_value_start_[g];
    const std::uint32_t* cols = columns_.data() + group_column_start_[g];
    auto kernel = [&](const Weight* Wb, std::size_t rows, Vec3* o, const std::uint32_t* points) {
#ifdef CMGEOM_CAGE_SIMD_AVX2
      if (internal::has_avx2()) {
        dense_rows_avx2(Wb, n, 0, rows, B, o, cols, points);
        return;
      }
#endif
      dense_rows_scalar(Wb, n, 0, rows, B, o, cols, points);
    };
    const Weight* Wb = W + (blk.begin - first) * n;
    const std::size_t rows = blk.end - blk.begin;
    if (!point_of_.empty()) {
      kernel(Wb, rows, out, point_of_.data() + blk.begin);
      return;
    }
    // Runs: compute the block's rows in order, then copy each run's slice to its points.
    Vec3 tmp[rows_per_block];
    kernel(Wb, rows, tmp, nullptr);
    std::size_t r = std::size_t(std::upper_bound(runs_.begin(), runs_.end(), blk.begin,
                                                 [](std::uint32_t s, const Run& x) { return s < x.stored; }) -
                                runs_.begin()) -
                    1;
    for (std::uint32_t s = blk.begin; s < blk.end;) {
      const std::uint32_t run_end = r + 1 < runs_.size() ? runs_[r + 1].stored : std::uint32_t(rows_);
      const std::uint32_t stop = std::min(run_end, blk.end);
      std::copy(tmp + (s - blk.begin), tmp + (stop - blk.begin), out + runs_[r].point + (s - runs_[r].stored));
      s = stop;
      ++r;
    }
  }

  void dense_rows(std::size_t b, std::size_t e, const Vec3* B, Vec3* out) const {
#ifdef CMGEOM_CAGE_SIMD_AVX2
    if (internal::has_avx2()) {
      dense_rows_avx2(values_.data(), K_, b, e, B, out, nullptr, nullptr);
      return;
    }
#endif
    dense_rows_scalar(values_.data(), K_, b, e, B, out, nullptr, nullptr);
  }

  // Rows b..e of the row-major block W (K weights per row). Column k of a row multiplies
  // B[cols[k]] (B[k] when cols is null); row v goes to out[points[v]] (out[v] when null).
  static void dense_rows_scalar(const Weight* W, std::size_t K, std::size_t b, std::size_t e, const Vec3* B, Vec3* out,
                                const std::uint32_t* cols, const std::uint32_t* points) {
    for (std::size_t v = b; v < e; ++v) {
      const Weight* w = W + v * K;
      double s[4][3] = {};
      std::size_t k = 0;
      for (; k + 4 <= K; k += 4)
        for (int j = 0; j < 4; ++j) {
          const Vec3& p = B[cols ? cols[k + j] : k + j];
          for (int c = 0; c < 3; ++c) s[j][c] += double(w[k + j]) * p[c];
        }
      for (; k < K; ++k) {
        const Vec3& p = B[cols ? cols[k] : k];
        for (int c = 0; c < 3; ++c) s[0][c] += double(w[k]) * p[c];
      }
      Vec3& o = out[points ? points[v] : v];
      for (int c = 0; c < 3; ++c) o[c] = (s[0][c] + s[1][c]) + (s[2][c] + s[3][c]);
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
  // `cols` and `points` as in dense_rows_scalar.
  __attribute__((target("avx2,fma"))) static void dense_rows_avx2(const Weight* W, std::size_t K, std::size_t b,
                                                                  std::size_t e, const Vec3* B, Vec3* out,
                                                                  const std::uint32_t* cols,
                                                                  const std::uint32_t* points) {
    constexpr std::size_t chunk = 1024;  // basis columns transposed per pass (24 KB, in L1)
    alignas(32) double bx[chunk], by[chunk], bz[chunk];
    for (std::size_t k0 = 0; k0 < K; k0 += chunk) {
      const std::size_t kn = std::min(chunk, K - k0);
      for (std::size_t k = 0; k < kn; ++k) {
        const Vec3& p = B[cols ? cols[k0 + k] : k0 + k];
        bx[k] = p[0];
        by[k] = p[1];
        bz[k] = p[2];
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
        Vec3& o = out[points ? points[v] : v];
        if (k0 == 0)
          o = {sx, sy, sz};
        else
          o = {o[0] + sx, o[1] + sy, o[2] + sz};
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
  // Grouped storage: group g has the pattern columns_[group_column_start_[g] ..), the stored
  // rows group_row_start_[g] .. group_row_start_[g + 1] (point indices in point_of_) and their
  // values from group_value_start_[g] on, row after row.
  // The point of each stored row is point_of_[s], or given by runs_ when these are shorter.
  std::vector<std::uint32_t> point_of_, group_row_start_;
  std::vector<std::size_t> group_column_start_, group_value_start_;
  std::vector<Block> blocks_;
  std::vector<Run> runs_;
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
  CMGeom::internal::Progress_reporter progress(options.progress);
  // The points' share: all of it for dense storage; sparse storage then concatenates the
  // blocks and grouped storage groups the rows (measured: a few percent of the time).
  progress.phase(0., options.storage == Weight_storage::dense ? 1. : 0.95, N);
  if (options.storage == Weight_storage::dense) {
    // (a large block of weights on huge pages, its fresh pages faulted in on all cores: binding
    // 537k points to 98 mean value coordinates 3.0 -> 2.3 s, doc/Cage_deformation/README.md)
    CMGeom::internal::resize_on_huge_pages(b.values_, N * K);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, N, 16), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t v = r.begin(); v < r.end(); ++v) b.status_[v] = coords(*(first + v), b.values_.data() + v * K);
      progress.add(r.size());
    });
    progress.finish();
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
    progress.add(std::min(N, (bi + 1) * block) - bi * block);
  });
  b.row_start_.assign(1, 0);
  b.row_start_.reserve(N + 1);
  {
    std::size_t total = 0;
    for (const auto& v : vals) total += v.size();
    CMGeom::internal::reserve_on_huge_pages(b.values_, total);
    CMGeom::internal::reserve_on_huge_pages(b.columns_, total);
  }
  for (std::size_t bi = 0; bi < nblocks; ++bi) {
    for (std::size_t c : counts[bi]) b.row_start_.push_back(b.row_start_.back() + c);
    b.values_.insert(b.values_.end(), vals[bi].begin(), vals[bi].end());
    b.columns_.insert(b.columns_.end(), cols[bi].begin(), cols[bi].end());
  }
  if (options.storage == Weight_storage::grouped)  // one returned object (see the note below)
    b = Cage_binding<Weight>::from_sparse_rows(K, std::move(b.row_start_), std::move(b.columns_), std::move(b.values_),
                                               std::move(b.status_), Weight_storage::grouped);
  progress.finish();
  // bind_points returns `b` from every path: a second returned object made the ThreadSanitizer
  // build (test scheduler of test/Reliability/tsan_tbb_runtime.cpp) crash in the parallel loop
  // above, reading a clobbered task_group_context; the other builds were clean.
  return b;
}

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_CAGE_BINDING_H

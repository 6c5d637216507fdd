// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The index texture of thesis §3.3 and its per-collapse resampling through the bijective mappings
// of §3.6, CPU backend (the reference: deterministic, no dependency beyond TBB): Texture_domain,
// Chart_map (the chart of every texel of the original layout), Index_texture (a Chart_map with
// two floats per texel, a position in the original atlas), rasterize_triangle() (fixed point,
// texel centres, top-left rule, as GL rasterisers), Index_texture_resampler (the resampler hook of
// Chart_constraint_visitor) and generate_texture() (the output texture looked up through the index
// texture, then dilated into the gutters). Key choice: every texel gets a chart-aware bilinear
// sample, computed in float in a fixed order without fused multiply-add, so a GL backend can
// reproduce it bit for bit. Complexity: O(texels of the new triangles × star size) per collapse;
// O(W·H) for set-up, texture generation and dilation.
//
// Manual: doc/Textured_simplification/README.md, "What happens at each collapse".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_INDEX_TEXTURE_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_INDEX_TEXTURE_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Image.h>
#include <CMGeom/Textured_simplification/Chart_constraints.h>
#include <CMGeom/internal/huge_pages.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace CMGeom {
namespace Textured_simplification {

namespace internal {

/// f(y_begin, y_end) over rows [0, height) in parallel (TBB); every texel pass of this file
/// computes each texel from data the pass does not write, so the result does not depend on the
/// number of threads.
template <class F>
void parallel_rows(int height, const F& f) {
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 16),
                    [&](const tbb::blocked_range<int>& r) { f(r.begin(), r.end()); });
}

}  // namespace internal

/// The UV rectangle [u0, u0 + du] x [v0, v0 + dv] covered by width x height texels.
struct Texture_domain {
  double u0 = 0, v0 = 0, du = 1, dv = 1;
  int width = 0, height = 0;
  UV2 to_texel(const UV2& uv) const { return {{(uv[0] - u0) / du * width, (uv[1] - v0) / dv * height}}; }
  UV2 from_texel(double x, double y) const { return {{u0 + x / width * du, v0 + y / height * dv}}; }
  /// Normalised output UV (the output texture covers exactly the domain).
  UV2 to_output_uv(const UV2& uv) const { return {{(uv[0] - u0) / du, (uv[1] - v0) / dv}}; }
};

/// Texture domain of a UV layout: [0,1]² grown to the UVs' bounding box; `size` texels per UV
/// unit horizontally (`size_v` vertically), capped at `max_side`.
inline Texture_domain make_texture_domain(const std::vector<std::array<UV2, 3>>& tris, int size_u, int size_v,
                                          int max_side) {
  double umin = 0, vmin = 0, umax = 1, vmax = 1;
  for (const auto& t : tris)
    for (const auto& p : t) {
      umin = (std::min)(umin, p[0]);
      umax = (std::max)(umax, p[0]);
      vmin = (std::min)(vmin, p[1]);
      vmax = (std::max)(vmax, p[1]);
    }
  Texture_domain d;
  d.u0 = umin;
  d.v0 = vmin;
  d.du = umax - umin;
  d.dv = vmax - vmin;
  double w = d.du * size_u, h = d.dv * size_v;
  const double s = (std::max)(w, h) > max_side ? max_side / (std::max)(w, h) : 1.0;
  d.width = (std::max)(1, int(std::lround(w * s)));
  d.height = (std::max)(1, int(std::lround(h * s)));
  return d;
}

/// Sub-texel steps per texel of rasterize_triangle (8 bits, as GL rasterisers snap).
constexpr std::int64_t rasterizer_subtexel_steps = 256;

/// Whether rasterize_triangle() draws a triangle with these corners at all (finite, within
/// 1e7 texels); a GPU backend skips the same triangles.
inline bool rasterizable(const std::array<UV2, 3>& t) {
  for (const UV2& c : t)
    if (!std::isfinite(c[0]) || !std::isfinite(c[1]) || std::abs(c[0]) > 1e7 || std::abs(c[1]) > 1e7) return false;
  return true;
}

/// A rasterizable coordinate snapped to the rasteriser's sub-texel grid, in sub-texel steps.
inline std::int64_t snap_to_subtexel(double x) { return std::llround(x * double(rasterizer_subtexel_steps)); }

/// Calls f(x, y) for every texel whose centre (x + .5, y + .5) is covered by triangle `t` (texel
/// coordinates), with 8 sub-texel bits and the top-left rule, clipped to [0,W) x [0,H) and to
/// the rows [y_begin, y_end), row by row upwards, each row left to right.
template <class F>
void rasterize_triangle(const std::array<UV2, 3>& t, int W, int H, int y_begin, int y_end, F&& f) {
  constexpr std::int64_t S = rasterizer_subtexel_steps, HALF = S / 2;
  if (!rasterizable(t)) return;
  std::int64_t X[3], Y[3];
  for (int i = 0; i < 3; ++i) {
    X[i] = snap_to_subtexel(t[i][0]);
    Y[i] = snap_to_subtexel(t[i][1]);
  }
  const std::int64_t area = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
  if (area == 0) return;
  if (area < 0) {
    std::swap(X[1], X[2]);
    std::swap(Y[1], Y[2]);
  }
  const std::int64_t minx = (std::min)({X[0], X[1], X[2]}), maxx = (std::max)({X[0], X[1], X[2]});
  const std::int64_t miny = (std::min)({Y[0], Y[1], Y[2]}), maxy = (std::max)({Y[0], Y[1], Y[2]});
  auto ceil_div = [](std::int64_t a, std::int64_t b) { return a >= 0 ? (a + b - 1) / b : -((-a) / b); };
  auto floor_div = [](std::int64_t a, std::int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); };
  const int xlo = int((std::max<std::int64_t>)(ceil_div(minx - HALF, S), 0));
  const int xhi = int((std::min<std::int64_t>)(floor_div(maxx - HALF, S), W - 1));
  const int ylo = int((std::max<std::int64_t>)(ceil_div(miny - HALF, S), (std::max)(y_begin, 0)));
  const int yhi = int((std::min<std::int64_t>)(floor_div(maxy - HALF, S), (std::min)(y_end, H) - 1));
  if (xlo > xhi || ylo > yhi) return;
  std::int64_t A[3], B[3], C[3];
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const std::int64_t dx = X[j] - X[i], dy = Y[j] - Y[i];
    A[i] = -dy;
    B[i] = dx;
    const bool top_left = (dy == 0 && dx < 0) || dy < 0;
    C[i] = dy * X[i] - dx * Y[i] + (top_left ? 0 : -1);
  }
  // Per row, the covered texels are an interval: edge function i at texel x is
  // e_i(xlo) + A_i S (x - xlo), so e_i >= 0 bounds x from below (A_i > 0) or above (A_i < 0),
  // in exact integer arithmetic (the same texels as testing every texel of the bounding box).
  for (int y = ylo; y <= yhi; ++y) {
    const std::int64_t py = std::int64_t(y) * S + HALF;
    std::int64_t lo = xlo, hi = xhi;
    for (int i = 0; i < 3 && lo <= hi; ++i) {
      const std::int64_t e0 = A[i] * (std::int64_t(xlo) * S + HALF) + B[i] * py + C[i];
      const std::int64_t step = A[i] * S;
      if (step > 0)
        lo = (std::max)(lo, xlo + (e0 >= 0 ? 0 : ceil_div(-e0, step)));
      else if (step < 0)
        hi = (std::min)(hi, xlo + (e0 < 0 ? -1 : e0 / -step));
      else if (e0 < 0)
        hi = lo - 1;
    }
    for (std::int64_t x = lo; x <= hi; ++x) f(int(x), y);
  }
}

/// Every row: the texels whose centre is covered by triangle `t` (see above).
template <class F>
void rasterize_triangle(const std::array<UV2, 3>& t, int W, int H, F&& f) {
  rasterize_triangle(t, W, H, 0, H, std::forward<F>(f));
}

/// The barycentric coordinates of the centre of texel (x, y) in triangle `t` (texel coordinates);
/// `twice_area` is twice t's signed area (internal::signed_area_2), not 0.
inline std::array<double, 3> texel_centre_barycentric(const std::array<UV2, 3>& t, double twice_area, int x, int y) {
  const double cx = x + 0.5, cy = y + 0.5;
  const double b1 = ((cx - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (cy - t[0][1])) / twice_area;
  const double b2 = ((t[1][0] - t[0][0]) * (cy - t[0][1]) - (cx - t[0][0]) * (t[1][1] - t[0][1])) / twice_area;
  return {{1 - b1 - b2, b1, b2}};
}

/// The chart map of an original UV layout (§3.3): per texel of a Texture_domain, the chart id + 1
/// of the layout's triangle whose rasterisation covers the texel centre (0: none), grown into the
/// gutters by a few rings. The part of the index texture that lookups in the original's texture
/// need (sample_original(), the new atlas' Atlas_source, the chart-growth test); 4 bytes per texel
/// where the index texture takes 12.
class Chart_map {
public:
  Chart_map() = default;

  /// The chart map of `triangles` (UVs of `domain`) with `chart_ids` (>= 0), grown by
  /// `chart_margin` rings (each ring gives a texel outside every chart the smallest id among its 8
  /// neighbours). With `mark_overlaps`, texels covered by two triangles get the id `contested`
  /// (used for region tests, never for resampling).
  Chart_map(const Texture_domain& domain, const std::vector<std::array<UV2, 3>>& triangles,
            const std::vector<int>& chart_ids, int chart_margin = 2, bool mark_overlaps = false)
      : domain_(domain),
        w_(domain.width),
        h_(domain.height),
        chart_(CMGeom::internal::filled_on_huge_pages(std::size_t(w_) * std::size_t(h_), 0u)) {
    for (std::size_t i = 0; i < triangles.size(); ++i) {
      std::array<UV2, 3> t;
      for (int c = 0; c < 3; ++c) t[c] = domain.to_texel(triangles[i][c]);
      const std::uint32_t id = std::uint32_t(chart_ids[i] + 1);
      rasterize_triangle(t, w_, h_, [&](int x, int y) {
        std::uint32_t& c = chart_[std::size_t(y) * w_ + x];
        c = (mark_overlaps && c != 0) ? contested : id;
      });
    }
    // grow the charts into the gutters (first ring first; ties: smallest neighbour id)
    std::vector<std::uint32_t> next;
    for (int ring = 0; ring < chart_margin; ++ring) {
      // (every texel of `next` is written below: no copy of the map first)
      if (next.size() != chart_.size()) CMGeom::internal::resize_on_huge_pages(next, chart_.size());
      // (the smallest non-zero id of the 3 x 3 neighbourhood is 1 + the smallest id - 1 in
      // unsigned arithmetic, where 0 - 1 is the largest value: 0 when there is none; taken down
      // the columns, then along the row, in loops the compiler vectorises)
      internal::parallel_rows(h_, [&](int y0, int y1) {
        const std::size_t w = std::size_t(w_);
        std::vector<std::uint32_t> column(w + 2, 0xffffffffu);  // (a margin each side)
        for (int y = y0; y < y1; ++y) {
          const std::uint32_t* row = chart_.data() + std::size_t(y) * w;
          const std::uint32_t* above = y > 0 ? row - w : row;
          const std::uint32_t* below = y + 1 < h_ ? row + w : row;
          for (std::size_t x = 0; x < w; ++x)
            column[x + 1] = (std::min)((std::min)(above[x] - 1u, row[x] - 1u), below[x] - 1u);
          std::uint32_t* out = next.data() + std::size_t(y) * w;
          for (std::size_t x = 0; x < w; ++x) {
            const std::uint32_t least = (std::min)((std::min)(column[x], column[x + 1]), column[x + 2]) + 1u;
            out[x] = row[x] != 0 ? row[x] : least;
          }
        }
      });
      chart_.swap(next);
    }
  }

  static constexpr std::uint32_t contested = 0xffffffffu;

  int width() const { return w_; }
  int height() const { return h_; }
  const Texture_domain& domain() const { return domain_; }
  /// Chart id + 1 of the original layout at texel (x, y) (0: no chart).
  std::uint32_t chart(int x, int y) const { return chart_[std::size_t(y) * std::size_t(w_) + std::size_t(x)]; }
  /// Chart of an original-atlas position (texel units), 0 when outside.
  std::uint32_t chart_of(float ax, float ay) const {
    if (!(ax >= 0.f) || !(ay >= 0.f)) return 0u;
    const int x = (std::min)(int(ax), w_ - 1), y = (std::min)(int(ay), h_ - 1);
    return chart(x, y);
  }

protected:
  Texture_domain domain_;
  int w_ = 0, h_ = 0;
  std::vector<std::uint32_t> chart_;
};

/// Index texture (§3.3): per texel, a position in the original atlas (two floats, the identity at
/// first: the texel's own centre), with the chart map of the original layout (Chart_map).
class Index_texture : public Chart_map {
public:
  Index_texture() = default;

  /// Identity index texture over `domain`; `triangles`/`chart_ids` (chart ids >= 0) are the
  /// original UV layout, whose chart map is grown by `chart_margin` rings (Chart_map).
  Index_texture(const Texture_domain& domain, const std::vector<std::array<UV2, 3>>& triangles,
                const std::vector<int>& chart_ids, int chart_margin = 2, bool mark_overlaps = false)
      : Chart_map(domain, triangles, chart_ids, chart_margin, mark_overlaps),
        idx_(CMGeom::internal::filled_on_huge_pages(std::size_t(2) * std::size_t(w_) * std::size_t(h_), 0.f)) {
    internal::parallel_rows(h_, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < w_; ++x) {
          float* p = at(x, y);
          p[0] = float(x) + 0.5f;
          p[1] = float(y) + 0.5f;
        }
    });
  }

  float* at(int x, int y) { return &idx_[2 * (std::size_t(y) * std::size_t(w_) + std::size_t(x))]; }
  const float* at(int x, int y) const { return &idx_[2 * (std::size_t(y) * std::size_t(w_) + std::size_t(x))]; }
  const std::vector<float>& data() const { return idx_; }
  std::vector<float>& data() { return idx_; }

private:
  std::vector<float> idx_;
};

namespace internal {

/// 2x3 affine map taking triangle `from` to triangle `to` (double); false if `from` is flat.
inline bool affine_map(const std::array<UV2, 3>& from, const std::array<UV2, 3>& to, double M[2][3]) {
  const double x0 = from[0][0], y0 = from[0][1];
  const double e1x = from[1][0] - x0, e1y = from[1][1] - y0, e2x = from[2][0] - x0, e2y = from[2][1] - y0;
  const double det = e1x * e2y - e1y * e2x;
  if (!(std::abs(det) > 0)) return false;
  for (int c = 0; c < 2; ++c) {
    const double s0 = to[0][c], d1 = to[1][c] - s0, d2 = to[2][c] - s0;
    const double gx = (d1 * e2y - d2 * e1y) / det, gy = (d2 * e1x - d1 * e2x) / det;
    M[c][0] = gx;
    M[c][1] = gy;
    M[c][2] = s0 - gx * x0 - gy * y0;
  }
  return true;
}

inline void compose(const double A[2][3], const double B[2][3], double out[2][3]) {  // A ∘ B
  for (int r = 0; r < 2; ++r) {
    out[r][0] = A[r][0] * B[0][0] + A[r][1] * B[1][0];
    out[r][1] = A[r][0] * B[0][1] + A[r][1] * B[1][1];
    out[r][2] = A[r][0] * B[0][2] + A[r][1] * B[1][2] + A[r][2];
  }
}

/// What one collapse asks of a resampling backend, computed once on the CPU (in double, then
/// rounded where the file comment says) so that every backend evaluates the same numbers:
///  * per old star triangle t_j: its wedge, and its barycentrics in π as affine functions of a
///    point of π (l1 = b0 x + b1 y + b2, l2 = b3 x + b4 y + b5), `valid` when PM_{t_j} inverts;
///  * per wedge: the texel rectangle of the old index texture a collapse reads (its copy);
///  * per new texture triangle t̄': its texel-space corners (`dst`), the map PM_{t'} (texel ->
///    π, double) and, for every old t_j, the composed map PM_{t_j}⁻¹ ∘ PM_{t'} in float.
/// The per-texel rule (select_old_triangle, map_to_old, Index_texture_resampler::sample) is
/// the part a GPU backend mirrors in its shader.
struct Resampling_plan {
  struct Rect {
    int x0, y0, x1, y1;  ///< inclusive; empty when x0 > x1 or y0 > y1
    bool empty() const { return x0 > x1 || y0 > y1; }
  };
  struct Old_triangle {
    std::array<double, 6> bary;
    int wedge;
    bool valid;
  };
  struct New_triangle {
    std::array<UV2, 3> dst;  ///< texel coordinates
    double pm[2][3];         ///< texel of t̄' -> π
  };
  Rect rects[2]{};
  std::vector<Old_triangle> old;
  std::vector<New_triangle> added;
  std::vector<std::array<float, 6>> maps;  ///< added.size() x old.size(), row-major

  const std::array<float, 6>& map(std::size_t k, std::size_t j) const { return maps[k * old.size() + j]; }

  void build(const Collapse_record& rec, const Texture_domain& dom, int W, int H) {
    const std::size_t n = rec.star.size();
    // frame of π
    const auto& nrm = rec.normal;
    Vec3 a = std::abs(nrm[0]) < 0.9 ? Vec3{{1, 0, 0}} : Vec3{{0, 1, 0}};
    Vec3 e1 = cross(nrm, a);
    e1 = scale(e1, 1.0 / norm(e1));
    const Vec3 e2 = cross(nrm, e1);
    auto proj = [&](const Vec3& p) {
      const Vec3 d = sub(p, rec.placement);
      return UV2{{dot(d, e1), dot(d, e2)}};
    };
    old_src_.resize(n);
    old_proj_.resize(n);
    old.resize(n);
    pm_inv_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      for (int c = 0; c < 3; ++c) {
        old_src_[k][c] = dom.to_texel(rec.star[k].uv[c]);
        old_proj_[k][c] = proj(rec.star[k].p[c]);
      }
      Old_triangle& o = old[k];
      o.wedge = rec.star[k].wedge;
      o.valid = affine_map(old_proj_[k], old_src_[k], pm_inv_[k].m);  // π -> old texel of t̄_k
      const auto& t = old_proj_[k];
      const double d = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
      auto& b = o.bary;
      if (d == 0) {
        b = {{0, 0, -1e300, 0, 0, -1e300}};
        continue;
      }
      b[0] = (t[2][1] - t[0][1]) / d;
      b[1] = -(t[2][0] - t[0][0]) / d;
      b[2] = -(b[0] * t[0][0] + b[1] * t[0][1]);
      b[3] = -(t[1][1] - t[0][1]) / d;
      b[4] = (t[1][0] - t[0][0]) / d;
      b[5] = -(b[3] * t[0][0] + b[4] * t[0][1]);
    }
    // the old regions read, one per wedge (§3.6: read from a copy, never from what is written)
    for (int w = 0; w < 2; ++w) {
      Rect& r = rects[w];
      r = Rect{W, H, -1, -1};
      for (std::size_t k = 0; k < n; ++k) {
        if (rec.star[k].wedge != w) continue;
        for (int c = 0; c < 3; ++c) {
          r.x0 = (std::min)(r.x0, int(std::floor(old_src_[k][c][0])) - 2);
          r.y0 = (std::min)(r.y0, int(std::floor(old_src_[k][c][1])) - 2);
          r.x1 = (std::max)(r.x1, int(std::floor(old_src_[k][c][0])) + 2);
          r.y1 = (std::max)(r.y1, int(std::floor(old_src_[k][c][1])) + 2);
        }
      }
      r.x0 = (std::max)(r.x0, 0);
      r.y0 = (std::max)(r.y0, 0);
      r.x1 = (std::min)(r.x1, W - 1);
      r.y1 = (std::min)(r.y1, H - 1);
    }
    // the new texture triangles and their maps into the old ones
    added.clear();
    maps.clear();
    for (std::size_t k = 0; k < n; ++k) {
      if (rec.star[k].removed || rec.star[k].unchanged) continue;
      const auto nuv = rec.new_uvs(k);
      const auto np = rec.new_positions(k);
      New_triangle t;
      std::array<UV2, 3> dproj;
      for (int c = 0; c < 3; ++c) {
        t.dst[c] = dom.to_texel(nuv[c]);
        dproj[c] = proj(np[c]);
      }
      if (!affine_map(t.dst, dproj, t.pm)) continue;
      added.push_back(t);
      for (std::size_t j = 0; j < n; ++j) {
        std::array<float, 6> m{};
        double M[2][3];
        if (old[j].valid) {
          compose(pm_inv_[j].m, t.pm, M);
          for (int r = 0; r < 2; ++r)
            for (int c = 0; c < 3; ++c) m[std::size_t(3 * r + c)] = float(M[r][c]);
        }
        maps.push_back(m);
      }
    }
  }

  /// The old triangle whose projection contains the image in π of texel centre (x, y) of new
  /// triangle k (else the one with the largest smallest barycentric); old.size() when none.
  std::size_t select_old_triangle(std::size_t k, int x, int y) const {
    const double(&pm)[2][3] = added[k].pm;
    const double cx = x + 0.5, cy = y + 0.5;
    const double qx = pm[0][0] * cx + pm[0][1] * cy + pm[0][2];
    const double qy = pm[1][0] * cx + pm[1][1] * cy + pm[1][2];
    const std::size_t n = old.size();
    std::size_t best = n;
    double best_score = -1e300;
    for (std::size_t j = 0; j < n; ++j) {
      if (!old[j].valid) continue;
      const auto& b = old[j].bary;
      const double l1 = b[0] * qx + b[1] * qy + b[2], l2 = b[3] * qx + b[4] * qy + b[5];
      const double s = (std::min)({1.0 - l1 - l2, l1, l2});
      if (s > best_score) {
        best_score = s;
        best = j;
        if (s >= 0) break;
      }
    }
    return best;
  }

  /// Position in the old index texture (texel units) of texel centre (x, y) through map m,
  /// evaluated in float in the order a shader uses at gl_FragCoord.
  static void map_to_old(const std::array<float, 6>& m, int x, int y, float& sx, float& sy) {
    const float fx = float(x) + 0.5f, fy = float(y) + 0.5f;
    const float t0 = m[0] * fx, t1 = m[1] * fy, t2 = m[3] * fx, t3 = m[4] * fy;
    sx = (t0 + t1) + m[2];
    sy = (t2 + t3) + m[5];
  }

private:
  struct Affine {
    double m[2][3];
  };
  std::vector<std::array<UV2, 3>> old_src_, old_proj_;
  std::vector<Affine> pm_inv_;
};

}  // namespace internal

/// Per-collapse resampling of an Index_texture (CPU backend; see the file comment). Models the
/// IndexTextureResampler concept: constructible from an Index_texture&, called with every
/// Collapse_record, and synchronize() leaves the Index_texture up to date (a no-op here: this
/// backend writes it in place).
///
/// §3.6 reads the old region from a copy. This backend reads the index texture itself, clamped to
/// the wedge's region as a copy of that region would be, and holds the collapse's new values
/// back until every new triangle is resampled: the same values as reading a copy, without
/// copying the region (the bounding rectangle of the old star, many times the texels written)
/// or looking up the chart of every copied value.
/// It also keeps, per texel, the chart of the stored index value (Index_texture::chart_of), set
/// at construction and with every value it writes: the chart-aware lookup then reads the charts of
/// its four texels beside their values instead of looking each up in the chart map. So nothing
/// else may write the Index_texture while the resampler lives.
/// Memory: 4 bytes per texel besides the Index_texture.
class Index_texture_resampler {
public:
  explicit Index_texture_resampler(Index_texture& it)
      : it_(&it), value_chart_(std::size_t(it.width()) * std::size_t(it.height())) {
    internal::parallel_rows(it.height(), [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < it.width(); ++x) value_chart_[texel(x, y)] = it.chart_of(it.at(x, y)[0], it.at(x, y)[1]);
    });
  }

  void operator()(const Collapse_record& rec) {
    Index_texture& it = *it_;
    const int W = it.width(), H = it.height();
    plan_.build(rec, it.domain(), W, H);
    const std::size_t n = plan_.added.size();
    // Work items: blocks of `rows_per_task` texel rows of each new triangle, in triangle order
    // then upwards (the order in which one rasterisation after the other visits the texels).
    items_.clear();
    double box_texels = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const auto& d = plan_.added[k].dst;
      const double x0 = (std::min)({d[0][0], d[1][0], d[2][0]}), x1 = (std::max)({d[0][0], d[1][0], d[2][0]});
      const double y0 = (std::min)({d[0][1], d[1][1], d[2][1]}), y1 = (std::max)({d[0][1], d[1][1], d[2][1]});
      if (!(y1 >= y0) || !(x1 >= x0)) continue;  // not finite: rasterize_triangle draws nothing
      box_texels += (x1 - x0) * (y1 - y0);
      // every row the rasteriser may cover (texel centres y + 0.5 in [y0, y1]), clipped to [0, H)
      const double fr = std::floor(y0 - 0.5) - 1.0, lr = std::ceil(y1 - 0.5) + 1.0;
      if (lr < 0.0 || fr > double(H - 1)) continue;
      const int first = int((std::max)(fr, 0.0)), last = int((std::min)(lr, double(H - 1)));
      for (int r = first; r <= last; r += rows_per_task)
        items_.push_back({k, r, (std::min)(r + rows_per_task, last + 1)});
    }
    if (pending_.size() < items_.size()) pending_.resize(items_.size());
    auto resample_item = [&](std::size_t i) {
      const Item& item = items_[i];
      const std::size_t k = item.triangle;
      std::vector<Pending>& out = pending_[i];
      out.clear();
      rasterize_triangle(plan_.added[k].dst, W, H, item.y_begin, item.y_end, [&](int x, int y) {
        const std::size_t j = plan_.select_old_triangle(k, x, y);
        if (j == plan_.old.size()) return;
        float sx, sy;
        internal::Resampling_plan::map_to_old(plan_.map(k, j), x, y, sx, sy);
        Pending p;
        if (!sample(plan_.old[j].wedge, sx, sy, p.value)) return;
        p.x = x;
        p.y = y;
        out.push_back(p);
      });
    };
    // Every value depends on the old index texture only, and they are written once all are
    // computed, in item order: the same writes whether the items are resampled in turn or by
    // several threads, which pays off for collapses covering many texels (large textures).
    ++collapses_;
    if (items_.size() > 1 && box_texels >= parallel_box_texels) {
      ++parallel_collapses_;
      tbb::parallel_for(std::size_t(0), items_.size(), resample_item);
    } else {
      for (std::size_t i = 0; i < items_.size(); ++i) resample_item(i);
    }
    for (std::size_t i = 0; i < items_.size(); ++i)
      for (const Pending& p : pending_[i]) {
        float* out = it.at(p.x, p.y);
        out[0] = p.value[0];
        out[1] = p.value[1];
        value_chart_[texel(p.x, p.y)] = it.chart_of(out[0], out[1]);
      }
  }

  /// Nothing to do: the index texture is written in place.
  void synchronize() {}

  /// Collapses resampled so far, and how many of them as parallel tasks (blocks of rows of the
  /// new triangles).
  std::size_t collapses() const { return collapses_; }
  std::size_t parallel_collapses() const { return parallel_collapses_; }

private:
  struct Pending {
    int x, y;
    float value[2];
  };
  struct Item {
    std::size_t triangle;
    int y_begin, y_end;
  };
  static constexpr int rows_per_task = 8;
  std::size_t texel(int x, int y) const { return std::size_t(y) * std::size_t(it_->width()) + std::size_t(x); }

  /// Chart-aware bilinear lookup (§3.6) of the old index texture at (sx, sy) (texel units),
  /// confined to wedge w's region: only the four nearest texels whose stored index lies in the
  /// chart of the nearest one's are blended. False when the wedge reads nothing (empty region).
  bool sample(int w, float sx, float sy, float* out) const {
    const auto& r = plan_.rects[w];
    if (r.empty()) return false;
    const Index_texture& it = *it_;
    // stay inside the region (the source point is inside an old triangle, up to rounding)
    sx = (std::min)((std::max)(sx, float(r.x0)), float(r.x1) + 1.f);
    sy = (std::min)((std::max)(sy, float(r.y0)), float(r.y1) + 1.f);
    const int nx = int(std::floor(sx)), ny = int(std::floor(sy));
    const float px = sx - 0.5f, py = sy - 0.5f;
    const float flx = std::floor(px), fly = std::floor(py);
    const float fx = px - flx, fy = py - fly;
    const int ix = int(flx), iy = int(fly);
    // the four texels, clamped to the region; the nearest one (also clamped) is among them
    auto clamp_x = [&](int x) { return (std::min)((std::max)(x, r.x0), r.x1); };
    auto clamp_y = [&](int y) { return (std::min)((std::max)(y, r.y0), r.y1); };
    const int cnx = clamp_x(nx), cny = clamp_y(ny);
    const float* q[4];
    std::uint32_t cq[4];
    std::uint32_t cn = 0u;
    const float* an = nullptr;
    for (int k = 0; k < 4; ++k) {
      const int qx = clamp_x(ix + (k & 1)), qy = clamp_y(iy + (k >> 1));
      q[k] = it.at(qx, qy);
      cq[k] = value_chart_[texel(qx, qy)];
      if (qx == cnx && qy == cny) {
        an = q[k];
        cn = cq[k];
      }
    }
    float a0 = 0.f, a1 = 0.f, ws = 0.f;
    if (cn != 0u) {
      for (int k = 0; k < 4; ++k) {
        const int ox = k & 1, oy = k >> 1;
        const float wt = (ox ? fx : 1.f - fx) * (oy ? fy : 1.f - fy);
        if (cq[k] == cn) {
          a0 += wt * q[k][0];
          a1 += wt * q[k][1];
          ws += wt;
        }
      }
    }
    if (ws > 0.f) {
      out[0] = a0 / ws;
      out[1] = a1 / ws;
    } else {
      out[0] = an[0];
      out[1] = an[1];
    }
    return true;
  }

  /// Sum of the new triangles' bounding boxes (texels) from which a collapse is resampled in
  /// parallel (below it, task hand-over costs more than it saves).
  static constexpr double parallel_box_texels = 2048;

  Index_texture* it_;
  std::vector<std::uint32_t> value_chart_;  ///< chart_of() of each texel's stored value
  internal::Resampling_plan plan_;
  std::vector<Item> items_;
  std::vector<std::vector<Pending>> pending_;  ///< per item, reused across collapses
  std::size_t collapses_ = 0, parallel_collapses_ = 0;
};

/// Chart-aware bilinear lookup of `original` (any size; UVs outside [0,1] repeat) at the
/// original-atlas position `a` (texel units of the chart map `it`, an Index_texture's or one of
/// its own); channel values in [0,1].
/// With `chart` (chart id + 1, as Chart_map::chart() gives) the lookup keeps to that chart's
/// texels instead of the chart found at `a`. When none of the four taps is in it, the taps in any
/// chart are used (charts sharing texels: mirrored halves), else the nearest texel of the chart
/// within 4 rings (a chart too small to cover a texel centre), else all four taps.
inline void sample_original(const Chart_map& it, const Image& original, float ax, float ay, float* out,
                            std::uint32_t chart) {
  const Texture_domain& dom = it.domain();
  const int W0 = original.width(), H0 = original.height(), C = original.channels();
  const UV2 uv = dom.from_texel(ax, ay);
  const std::uint32_t cn = chart;
  // image row 0 is the top row (v = 1)
  const double px = uv[0] * W0 - 0.5, py = (1.0 - uv[1]) * H0 - 0.5;
  const double flx = std::floor(px), fly = std::floor(py);
  const double fx = px - flx, fy = py - fly;
  double acc[4] = {0, 0, 0, 0}, ws = 0;
  double acc_all[4] = {0, 0, 0, 0}, acc_any[4] = {0, 0, 0, 0}, ws_any = 0;
  // the two columns and two rows of the four taps: wrapped image texel, and the index-texture
  // texel coordinate of the tap's centre in the (unwrapped) domain (for its chart)
  int wxs[2], wys[2];
  float ctx[2], cty[2];
  for (int o = 0; o < 2; ++o) {
    const long long ix = (long long)flx + o, iy = (long long)fly + o;
    // (inside the image, the usual case, without the divisions of the wrap)
    wxs[o] = ix >= 0 && ix < W0 ? int(ix) : int(((ix % W0) + W0) % W0);
    wys[o] = iy >= 0 && iy < H0 ? int(iy) : int(((iy % H0) + H0) % H0);
    const UV2 ct = dom.to_texel(UV2{{(double(ix) + 0.5) / W0, 1.0 - (double(iy) + 0.5) / H0}});
    ctx[o] = float(ct[0]);
    cty[o] = float(ct[1]);
  }
  std::uint32_t tap_chart[4];
  for (int k = 0; k < 4; ++k) tap_chart[k] = it.chart_of(ctx[k & 1], cty[k >> 1]);
  if (cn == 0u || (tap_chart[0] == cn && tap_chart[1] == cn && tap_chart[2] == cn && tap_chart[3] == cn)) {
    // every tap in the chart (a texel inside it, the usual case): the plain bilinear lookup, the
    // same sums as below
    for (int k = 0; k < 4; ++k) {
      const int ox = k & 1, oy = k >> 1;
      const double wt = (ox ? fx : 1 - fx) * (oy ? fy : 1 - fy);
      for (int c = 0; c < C; ++c) acc[c] += wt * original.value(wxs[ox], wys[oy], c);
      ws += wt;
    }
    for (int c = 0; c < C; ++c) out[c] = float(ws > 0 ? acc[c] / ws : acc[c]);
    return;
  }
  for (int k = 0; k < 4; ++k) {
    const int ox = k & 1, oy = k >> 1;
    const int wx = wxs[ox], wy = wys[oy];
    const double wt = (ox ? fx : 1 - fx) * (oy ? fy : 1 - fy);
    const bool same = tap_chart[k] == cn;
    for (int c = 0; c < C; ++c) {
      const double v = original.value(wx, wy, c);
      acc_all[c] += wt * v;
      if (same) acc[c] += wt * v;
      if (tap_chart[k] != 0u) acc_any[c] += wt * v;
    }
    if (same) ws += wt;
    if (tap_chart[k] != 0u) ws_any += wt;
  }
  if (ws == 0 && ws_any > 0) {
    for (int c = 0; c < C; ++c) out[c] = float(acc_any[c] / ws_any);
    return;
  }
  if (ws == 0 && cn != 0u && std::isfinite(ax) && std::isfinite(ay)) {
    // no tap inside any chart: the texel of the point's own chart nearest to it within 4 rings
    // (chessboard distance), else of any chart within 8 (a face whose UVs lie in a gutter, outside
    // every texel its chart covers: the gutter's colour is no colour of the model)
    const int cx = int(std::floor(ax)), cy = int(std::floor(ay));
    int other_x = -1, other_y = -1;
    bool own = false;
    for (int r = 1; r <= 8 && !own; ++r) {
      for (int dy = -r; dy <= r && !own; ++dy)
        for (int dx = -r; dx <= r && !own; ++dx) {
          if ((std::max)(std::abs(dx), std::abs(dy)) != r) continue;
          const int x = cx + dx, y = cy + dy;
          if (x < 0 || y < 0 || x >= it.width() || y >= it.height()) continue;
          const std::uint32_t k = it.chart(x, y);
          own = k == cn && r <= 4;
          if (own || (k != 0u && other_x < 0)) {
            other_x = x;
            other_y = y;
          }
        }
      if (other_x >= 0 && r >= 4) break;  // none of its own chart within 4: the nearest of another
    }
    if (other_x >= 0) {
      const UV2 q = dom.from_texel(other_x + 0.5, other_y + 0.5);
      const long long ix = (long long)std::floor(q[0] * W0), iy = (long long)std::floor((1.0 - q[1]) * H0);
      const int wx = int(((ix % W0) + W0) % W0), wy = int(((iy % H0) + H0) % H0);
      for (int c = 0; c < C; ++c) out[c] = original.value(wx, wy, c);
      return;
    }
  }
  for (int c = 0; c < C; ++c) out[c] = float(ws > 0 ? acc[c] / ws : acc_all[c]);
}

/// The same, keeping to the chart found at `a` (the index texture only stores positions inside
/// charts).
inline void sample_original(const Chart_map& it, const Image& original, float ax, float ay, float* out) {
  sample_original(it, original, ax, ay, out, it.chart_of(ax, ay));
}

namespace internal {

/// The gutter dilation shared by every generated atlas: `dist` holds 0 on the covered texels
/// (whose `C` channel values are in `acc`, rows upwards) and 0xffffffff elsewhere. A texel at
/// chessboard distance d from the covered ones gets the average of its 8-neighbours at distance
/// d - 1 (the rings of a breadth-first growth), so every texel of the image ends up with a value;
/// returns the 8-bit image, row 0 at the top as in image files. The result does not depend on the
/// number of threads.
inline Image dilate_into_image(int W, int H, int C, std::vector<std::uint32_t>& dist, std::vector<float>& acc) {
  Image out(W, H, C, Image::Format::UInt8);
  constexpr std::uint32_t far = 0xffffffffu;
  // The distances come from an exact separable chessboard distance transform (Meijster, Roerdink
  // and Hesselink, "A general algorithm for computing distance transforms in linear time", 2000):
  // the distance along each column, then along each row the lower envelope of
  // max(|x - i|, g(i)); both passes run on all cores. The rings come from a counting sort by
  // distance; a ring only reads inner rings, so the order within a ring does not matter.
  const std::uint32_t inf = std::uint32_t(W) + std::uint32_t(H);  // above every finite distance
  constexpr int column_block = 256, row_block = 16;
  // columns: in place (0 stays 0 on the covered texels), a block of columns swept down then up
  tbb::parallel_for(tbb::blocked_range<int>(0, (W + column_block - 1) / column_block, 1),
                    [&](const tbb::blocked_range<int>& r) {
                      const int x0 = r.begin() * column_block, x1 = (std::min)(W, r.end() * column_block);
                      for (int x = x0; x < x1; ++x) dist[std::size_t(x)] = dist[std::size_t(x)] == 0 ? 0 : inf;
                      for (int y = 1; y < H; ++y) {
                        std::uint32_t* row = &dist[std::size_t(y) * W];
                        const std::uint32_t* below = row - W;
                        for (int x = x0; x < x1; ++x) row[x] = row[x] == 0 ? 0 : (below[x] == inf ? inf : below[x] + 1);
                      }
                      for (int y = H - 2; y >= 0; --y) {
                        std::uint32_t* row = &dist[std::size_t(y) * W];
                        const std::uint32_t* above = row + W;
                        for (int x = x0; x < x1; ++x)
                          if (above[x] != inf && above[x] + 1 < row[x]) row[x] = above[x] + 1;
                      }
                    });
  // rows: each row's distances from its columns' (g), through the lower envelope of the
  // functions x -> max(|x - i|, g(i)); the largest distance and the ring sizes counted per block
  const int row_blocks = (H + row_block - 1) / row_block;
  std::vector<std::uint32_t> block_max(std::size_t(row_blocks), 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, row_blocks, 1), [&](const tbb::blocked_range<int>& r) {
    const std::size_t w = std::size_t(W);
    std::vector<std::int64_t> g(w), s(w), t(w);
    for (int b = r.begin(); b < r.end(); ++b) {
      std::uint32_t m = 0;
      for (int y = b * row_block; y < (std::min)(H, (b + 1) * row_block); ++y) {
        std::uint32_t* row = &dist[std::size_t(y) * W];
        for (int x = 0; x < W; ++x) g[std::size_t(x)] = row[x];
        auto f = [&](std::int64_t x, std::int64_t i) { return (std::max)(x > i ? x - i : i - x, g[std::size_t(i)]); };
        auto sep = [&](std::int64_t i, std::int64_t u) {
          const std::int64_t gi = g[std::size_t(i)], gu = g[std::size_t(u)];
          return gi <= gu ? (std::max)(i + gu, (i + u) / 2) : (std::min)(u - gi, (i + u) / 2);
        };
        std::int64_t q = 0;
        s[0] = 0;
        t[0] = 0;
        for (std::int64_t u = 1; u < W; ++u) {
          while (q >= 0 && f(t[std::size_t(q)], s[std::size_t(q)]) > f(t[std::size_t(q)], u)) --q;
          if (q < 0) {
            q = 0;
            s[0] = u;
          } else {
            const std::int64_t w = 1 + sep(s[std::size_t(q)], u);
            if (w < W) {
              ++q;
              s[std::size_t(q)] = u;
              t[std::size_t(q)] = w;
            }
          }
        }
        for (std::int64_t u = W - 1; u >= 0; --u) {
          const std::int64_t d = f(u, s[std::size_t(q)]);
          row[u] = d >= std::int64_t(inf) ? far : std::uint32_t(d);
          if (row[u] != far) m = (std::max)(m, row[u]);
          if (u == t[std::size_t(q)]) --q;
        }
      }
      block_max[std::size_t(b)] = m;
    }
  });
  std::uint32_t max_d = 0;
  for (std::uint32_t m : block_max) max_d = (std::max)(max_d, m);
  // the rings: each block of rows counts its texels per distance, then writes them at its offsets
  const std::size_t rings = std::size_t(max_d) + 2;
  std::vector<std::size_t> count(std::size_t(row_blocks) * rings, 0);
  // fn(texel index, its distance) for the gutter texels of every block of rows, blocks on all cores
  auto for_gutter_texels = [&](const auto& fn) {
    tbb::parallel_for(tbb::blocked_range<int>(0, row_blocks, 1), [&](const tbb::blocked_range<int>& r) {
      for (int b = r.begin(); b < r.end(); ++b) {
        std::size_t* block_count = &count[std::size_t(b) * rings];
        const std::size_t i1 = std::size_t((std::min)(H, (b + 1) * row_block)) * W;
        for (std::size_t i = std::size_t(b) * row_block * W; i < i1; ++i)
          if (dist[i] != far && dist[i] > 0) fn(block_count, i, dist[i]);
      }
    });
  };
  for_gutter_texels([](std::size_t* block_count, std::size_t, std::uint32_t d) { ++block_count[d]; });
  // ring_start[d]: where ring d starts in by_ring; count[b * rings + d] becomes block b's start in it
  std::vector<std::size_t> ring_start(rings + 1, 0);
  {
    std::size_t at = 0;
    for (std::size_t d = 1; d < rings; ++d) {
      ring_start[d] = at;
      for (int b = 0; b < row_blocks; ++b) {
        const std::size_t c = count[std::size_t(b) * rings + d];
        count[std::size_t(b) * rings + d] = at;
        at += c;
      }
    }
    ring_start[rings] = at;
  }
  std::vector<std::uint32_t> by_ring = CMGeom::internal::filled_on_huge_pages(ring_start[rings], 0u);
  for_gutter_texels(
      [&](std::size_t* block_next, std::size_t i, std::uint32_t d) { by_ring[block_next[d]++] = std::uint32_t(i); });
  auto dilate = [&](std::uint32_t d, std::size_t r) {
    const std::size_t j = by_ring[r];
    const int x = int(j % std::size_t(W)), y = int(j / std::size_t(W));
    float s[4] = {0, 0, 0, 0};
    int cnt = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int qx = x + dx, qy = y + dy;
        if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
        const std::size_t k = std::size_t(qy) * W + qx;
        if (dist[k] >= d) continue;
        for (int c = 0; c < C; ++c) s[c] += acc[k * C + c];
        ++cnt;
      }
    for (int c = 0; c < C; ++c) acc[j * C + c] = cnt ? s[c] / float(cnt) : 0.f;
  };
  for (std::uint32_t d = 1; d <= max_d; ++d) {
    const std::size_t b = ring_start[d], e = ring_start[d + 1];
    if (e - b < 4096) {
      for (std::size_t r = b; r < e; ++r) dilate(d, r);
    } else {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(b, e, 1024), [&](const tbb::blocked_range<std::size_t>& rr) {
        for (std::size_t r = rr.begin(); r < rr.end(); ++r) dilate(d, r);
      });
    }
  }
  // (Image::set_value()'s rounding, a row at a time)
  std::uint8_t* const pixels = out.bytes();
  internal::parallel_rows(H, [&](int y0, int y1) {
    const std::size_t row = std::size_t(W) * std::size_t(C);
    for (int y = y0; y < y1; ++y) {
      const float* from = &acc[std::size_t(y) * row];
      std::uint8_t* to = pixels + out.index(0, H - 1 - y);
      for (std::size_t k = 0; k < row; ++k) {
        const float v = from[k] < 0.f ? 0.f : (from[k] > 1.f ? 1.f : from[k]);
        to[k] = std::uint8_t(v * 255.f + 0.5f);
      }
    }
  });
  return out;
}

}  // namespace internal

/// Output texture (same size as the index texture, covering the domain; row 0 at the top as in
/// image files): the original looked up through the index texture on every texel covered by
/// `final_triangles` (UVs in the domain), then dilated into the gutters.
/// Throws Invalid_input for an index texture of 2^32 texels or more (its texels are indexed in 32
/// bits; simplify_textured_mesh caps sides at 8192 by default).
inline Image generate_texture(const Index_texture& it, const Image& original,
                              const std::vector<std::array<UV2, 3>>& final_triangles) {
  const int W = it.width(), H = it.height(), C = original.channels();
  if (std::uint64_t(W) * std::uint64_t(H) >= (std::uint64_t(1) << 32))
    throw Invalid_input("generate_texture: " + std::to_string(W) + " x " + std::to_string(H) +
                        " texels is more than this function handles (2^32 - 1)");
  const std::size_t n = std::size_t(W) * std::size_t(H);
  // chessboard distance to the covered texels: 0 on them (set while they are looked up), the
  // rest from the distance transform below; `far` where no texel is covered at all
  constexpr std::uint32_t far = 0xffffffffu;
  std::vector<std::uint32_t> dist = CMGeom::internal::filled_on_huge_pages(n, far);
  std::vector<float> acc = CMGeom::internal::filled_on_huge_pages(n * std::size_t(C), 0.f);
  for (const auto& tri : final_triangles) {
    std::array<UV2, 3> t;
    for (int c = 0; c < 3; ++c) t[c] = it.domain().to_texel(tri[c]);
    rasterize_triangle(t, W, H, [&](int x, int y) { dist[std::size_t(y) * W + x] = 0; });
  }
  // a covered texel's value depends on its index only: looked up row by row, in parallel
  internal::parallel_rows(H, [&](int y0, int y1) {
    float v[4];
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const std::size_t i = std::size_t(y) * W + x;
        if (dist[i] != 0) continue;
        const float* a = it.at(x, y);
        sample_original(it, original, a[0], a[1], v);
        for (int c = 0; c < C; ++c) acc[i * C + c] = v[c];
      }
  });
  return internal::dilate_into_image(W, H, C, dist, acc);
}

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_INDEX_TEXTURE_H

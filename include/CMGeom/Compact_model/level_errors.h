// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// measure_level_errors(): the error control of §4.5.3 ("finding the foot points of the
// reconstructed mesh vertices and computing their fitting errors") run once at build time for
// every regular level 0..depth, and kept per base face in the model (Compact_model::level_errors)
// so that an adaptive reconstruction knows, without the input, where refining lowers the error
// against the input and where it does not (a CMGeom addition; the thesis measures to add points
// to the fits, not to guide reconstruction). Both directions are sampled, as Metro does: points
// of each reconstructed triangle measured against the input (attributed to the triangle's base
// face), and points of the input measured against the reconstruction (attributed to the base face
// of their closest point on the finest level, the same face at every level). Samples are
// area-uniform: per triangle a number proportional to its area (at least 1), laid out by a fixed
// low-discrepancy sequence, each weighted by the area it stands for: max(its triangles, 100 x the
// base faces) on a reconstruction, max(4 x its triangles, 200 x the base faces) on the input, plus
// the input's vertices for the largest distance (Metro's vertex samples). Deterministic whatever
// the thread count (per-triangle partial sums reduced in order; each fixed block of triangles or
// vertices searches from its previous result). Complexity per level:
// O((S + T) log T) for S samples and T triangles.
//
// Manual: doc/Compact_model/README.md, "Adaptive reconstruction to a vertex budget".
#ifndef CMGEOM_COMPACT_MODEL_LEVEL_ERRORS_H
#define CMGEOM_COMPACT_MODEL_LEVEL_ERRORS_H

#include <CMGeom/Compact_model/reconstruct.h>
#include <CMGeom/Error.h>
#include <CMGeom/Metrics/approximation_error.h>

#include <CGAL/Named_function_parameters.h>
#include <CGAL/boost/graph/named_params_helper.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace CMGeom {
namespace CM {

namespace internal {

/// Area-uniform samples of a triangle list (see the file comment): `offset[t]..offset[t + 1]`
/// are triangle t's, each standing for `weight[t]` of area.
struct Triangle_samples {
  std::vector<std::size_t> offset;
  std::vector<double> weight;
};

inline Triangle_samples plan_triangle_samples(const Metrics::internal::Flat_mesh& m, std::size_t target) {
  const std::size_t T = m.triangles.size();
  std::vector<double> area(T);
  double total = 0.;
  for (std::size_t t = 0; t < T; ++t) {
    const auto& tri = m.triangles[t];
    area[t] = Metrics::internal::triangle_area(m.points[tri[0]], m.points[tri[1]], m.points[tri[2]]);
    if (std::isfinite(area[t])) total += area[t];
  }
  Triangle_samples s;
  s.offset.assign(T + 1, 0);
  s.weight.assign(T, 0.);
  for (std::size_t t = 0; t < T; ++t) {
    const double share = total > 0. && std::isfinite(area[t]) ? double(target) * area[t] / total : 0.;
    const std::size_t k = std::max<std::size_t>(1, std::size_t(std::llround(share)));
    s.offset[t + 1] = s.offset[t] + k;
    s.weight[t] = std::isfinite(area[t]) ? area[t] / double(k) : 0.;
  }
  return s;
}

/// Sample j of k of triangle (a, b, c): the centroid for k = 1, otherwise point j of the R2
/// sequence folded into the triangle.
inline Metrics::internal::Distance_kernel::Point_3 triangle_sample(const std::array<double, 3>& a,
                                                                   const std::array<double, 3>& b,
                                                                   const std::array<double, 3>& c, std::size_t j,
                                                                   std::size_t k) {
  double u = 1. / 3., v = 1. / 3.;
  if (k > 1) {
    u = std::fmod(0.5 + 0.7548776662466927 * double(j), 1.);
    v = std::fmod(0.5 + 0.5698402909980532 * double(j), 1.);
    if (u + v > 1.) {
      u = 1. - u;
      v = 1. - v;
    }
  }
  const double w = 1. - u - v;
  return {w * a[0] + u * b[0] + v * c[0], w * a[1] + u * b[1] + v * c[1], w * a[2] + u * b[2] + v * c[2]};
}

}  // namespace internal

/// Measures the regular reconstructions of levels 0..`depth` of `m` against `input` and stores the
/// result in `m.level_errors` (see the file comment and Level_errors), replacing any table there.
/// `opt`: the reconstruction's options (its projection is the one the table is valid for; the
/// reconstruction an adaptive run will make); its progress hook is called after each level. `TriangleMesh`: a model of
/// `FaceListGraph` with triangle faces; named parameter `vertex_point_map` (default: the internal one). Throws
/// Invalid_input when `depth` is outside [0, 8], the model is invalid or has no face, or the input
/// has no face, a non-triangle face or a non-finite coordinate.
template <class TriangleMesh, class Traits = Quadric_surface_traits,
          class NP = CGAL::parameters::Default_named_parameters>
void measure_level_errors(Compact_model& m, const TriangleMesh& input, int depth,
                          const Reconstruction_options& opt = Reconstruction_options(), const Traits& traits = Traits(),
                          const NP& np = CGAL::parameters::default_values()) {
  using Flat_mesh = Metrics::internal::Flat_mesh;
  using Tree = Metrics::internal::Triangle_tree;
  using P3 = Metrics::internal::Distance_kernel::Point_3;
  using CGAL::parameters::choose_parameter;
  using CGAL::parameters::get_parameter;
  if (depth < 0 || depth > 8)
    throw Invalid_input("measure_level_errors: the depth must be in [0, 8], got " + std::to_string(depth));
  m.validate();
  if (m.faces.empty()) throw Invalid_input("measure_level_errors: the model has no face");
  auto vpm = choose_parameter(get_parameter(np, CGAL::internal_np::vertex_point),
                              get_const_property_map(CGAL::vertex_point, input));
  const Flat_mesh in = Metrics::internal::make_flat_mesh(input, vpm, "input mesh");
  const Tree in_tree(in);
  const std::size_t F = m.faces.size();
  const std::size_t n = std::size_t(depth + 1) * F;
  std::vector<double> rms(n, 0.), mx(n, 0.);
  Reconstruction_options ro = opt;
  ro.progress = Progress_callback();  // (reported per level below)
  double work = 0., done = 0.;        // a level's share of the work: its triangles, 4^level
  for (int level = 0; level <= depth; ++level) work += std::exp2(2. * level);
  constexpr std::size_t block = 256;

  // Input samples are attributed to base faces once, by the finest level (measured first), so that
  // a sample's error at every level counts against the same face.
  std::vector<std::uint32_t> face_of, vface_of;
  internal::Triangle_samples s_in;
  for (int step = 0; step <= depth; ++step) {
    const int level = step == 0 ? depth : step - 1;
    const Reconstruction r = reconstruct_regular(m, level, ro, traits);
    Flat_mesh rec;
    rec.points.resize(r.points.size());
    for (std::size_t i = 0; i < r.points.size(); ++i) rec.points[i] = {r.points[i].x, r.points[i].y, r.points[i].z};
    rec.triangles.assign(r.triangles.begin(), r.triangles.end());
    const Tree rec_tree(rec);
    const internal::Triangle_samples s_rec =
        internal::plan_triangle_samples(rec, std::max(rec.triangles.size(), 100 * F));
    if (step == 0) s_in = internal::plan_triangle_samples(in, std::max(4 * in.triangles.size(), 200 * F));

    // Reconstruction -> input, per reconstructed triangle: sum of w d^2, sum of w, max d.
    const std::size_t T = rec.triangles.size();
    std::vector<std::array<double, 3>> per_tri(T);
    // (Each block's searches start from the result before them: a reconstruction's triangles come
    // base face by base face, so the previous sample is near. The blocks are the same whatever the
    // thread count, simple_partitioner, and so are the results.)
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, T, block),
        [&](const tbb::blocked_range<std::size_t>& br) {
          P3 hint;
          bool have = false;
          for (std::size_t t = br.begin(); t != br.end(); ++t) {
            const auto& tri = rec.triangles[t];
            const std::size_t k = s_rec.offset[t + 1] - s_rec.offset[t];
            std::array<double, 3> acc{0., 0., 0.};
            for (std::size_t j = 0; j < k; ++j) {
              const P3 q = internal::triangle_sample(rec.points[tri[0]], rec.points[tri[1]], rec.points[tri[2]], j, k);
              hint = have ? in_tree.closest_point(q, hint) : in_tree.tree.closest_point(q);
              have = true;
              const double d = std::sqrt(CGAL::squared_distance(q, hint));
              acc[0] += s_rec.weight[t] * d * d;
              acc[1] += s_rec.weight[t];
              acc[2] = std::max(acc[2], d);
            }
            per_tri[t] = acc;
          }
        },
        tbb::simple_partitioner());
    std::vector<double> s2(F, 0.), w(F, 0.), dmax(F, 0.);
    for (std::size_t t = 0; t < T; ++t) {
      const std::uint32_t f = r.base_face[t];
      s2[f] += per_tri[t][0];
      w[f] += per_tri[t][1];
      dmax[f] = std::max(dmax[f], per_tri[t][2]);
    }
    // The closest point of the reconstruction and its triangle, searched from the previous result
    // unless `first`.
    auto closest_on_rec = [&rec_tree](const P3& q, bool first, const std::pair<P3, std::size_t>& previous) {
      return first ? rec_tree.closest_point_and_triangle(q)
                   : rec_tree.closest_point_and_triangle(q, previous.first, previous.second);
    };
    // Input -> reconstruction, per sample: its distance (and, at the finest level, the base face of
    // its closest point, which it is attributed to at every level).
    const std::size_t S = s_in.offset.back();
    std::vector<double> dist(S);
    if (step == 0) face_of.resize(S);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, in.triangles.size(), block),
        [&](const tbb::blocked_range<std::size_t>& br) {
          std::pair<P3, std::size_t> c;
          bool have = false;
          for (std::size_t t = br.begin(); t != br.end(); ++t) {
            const auto& tri = in.triangles[t];
            const std::size_t o = s_in.offset[t], k = s_in.offset[t + 1] - o;
            for (std::size_t j = 0; j < k; ++j) {
              const P3 q = internal::triangle_sample(in.points[tri[0]], in.points[tri[1]], in.points[tri[2]], j, k);
              c = closest_on_rec(q, !have, c);
              have = true;
              dist[o + j] = std::sqrt(CGAL::squared_distance(q, c.first));
              if (step == 0) face_of[o + j] = r.base_face[c.second];
            }
          }
        },
        tbb::simple_partitioner());
    // The input's vertices too (Metro's vertex samples: where a thin feature's tip is), for the
    // largest distance only.
    const std::size_t NV = in.points.size();
    std::vector<double> vdist(NV, 0.);
    if (step == 0) vface_of.assign(NV, 0);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, NV, block),
        [&](const tbb::blocked_range<std::size_t>& br) {
          std::pair<P3, std::size_t> c;
          bool have = false;
          for (std::size_t v = br.begin(); v != br.end(); ++v) {
            if (!in.used[v]) continue;
            const P3 q(in.points[v][0], in.points[v][1], in.points[v][2]);
            c = closest_on_rec(q, !have, c);
            if (step == 0) vface_of[v] = r.base_face[c.second];
            have = true;
            vdist[v] = std::sqrt(CGAL::squared_distance(q, c.first));
          }
        },
        tbb::simple_partitioner());
    for (std::size_t t = 0; t < in.triangles.size(); ++t)
      for (std::size_t i = s_in.offset[t]; i < s_in.offset[t + 1]; ++i) {
        const std::uint32_t f = face_of[i];
        s2[f] += s_in.weight[t] * dist[i] * dist[i];
        w[f] += s_in.weight[t];
        dmax[f] = std::max(dmax[f], dist[i]);
      }
    for (std::size_t v = 0; v < NV; ++v)
      if (in.used[v]) dmax[vface_of[v]] = std::max(dmax[vface_of[v]], vdist[v]);
    for (std::size_t f = 0; f < F; ++f) {
      rms[std::size_t(level) * F + f] = w[f] > 0. ? std::sqrt(s2[f] / w[f]) : 0.;
      mx[std::size_t(level) * F + f] = dmax[f];
    }
    done += std::exp2(2. * level);
    if (opt.progress) opt.progress(done / work);
  }

  // Codes: the largest distance gets the largest code.
  double top = 0.;
  for (std::size_t i = 0; i < n; ++i) top = std::max({top, rms[i], mx[i]});
  Level_errors le;
  le.depth = depth;
  {
    volatile float u = float(top > 0. && std::isfinite(top) ? top * std::exp2(-254. / 16.) : 1.);
    le.unit = double(u);
  }
  le.rms.resize(n);
  le.max.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    le.rms[i] = Level_errors::encode(rms[i], le.unit);
    le.max[i] = Level_errors::encode(mx[i], le.unit);
  }
  m.level_errors = std::move(le);
}

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_LEVEL_ERRORS_H

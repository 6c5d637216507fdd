// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// texture_deviation(): the largest 3D distance between points that carry the same texture
// coordinate (u, v) on two textured surfaces, where both are defined (Cohen, Olano and Manocha 1998;
// thesis §3.1 asks that the points of the same attribute on successive approximations stay close).
// Each surface is sampled in parameter space and each sample is located in the other surface's UV
// triangles (CGAL AABB_tree) and mapped to 3D. Key choices: an uncovered (u, v) is skipped; where
// atlases overlap the nearest preimage in 3D is taken; degenerate UV triangles are ignored, so a
// mesh against itself gives 0. Both directions, maximum reported; parallel and deterministic.
//
// Manual: doc/Metrics/README.md, "Texture deviation".
#ifndef CMGEOM_METRICS_TEXTURE_DEVIATION_H
#define CMGEOM_METRICS_TEXTURE_DEVIATION_H

#include <CMGeom/Error.h>
#include <CMGeom/Metrics/approximation_error.h>

#include <CGAL/boost/graph/helpers.h>

#include <array>
#include <vector>

namespace CMGeom {
namespace Metrics {

/// Result of texture_deviation().
struct Texture_deviation {
  double deviation = 0.;            ///< max over both directions / reference diagonal
  double absolute = 0.;             ///< same, absolute units
  double diagonal = 0.;             ///< reference bounding-box diagonal
  std::size_t samples = 0;          ///< samples of both surfaces that were tried
  std::size_t matched_samples = 0;  ///< samples whose (u,v) exists on the other surface
};

namespace internal {

/// A mesh in parameter space: per face the three corner UVs and 3D positions.
struct UV_flat_mesh {
  Flat_mesh geometry;
  std::vector<std::array<std::array<double, 2>, 3>> uvs;  // per face, per corner
};

template <class TriangleMesh, class VertexPointMap, class UVMap>
UV_flat_mesh make_uv_flat_mesh(const TriangleMesh& tm, VertexPointMap vpm, UVMap uv, const std::string& what) {
  UV_flat_mesh m;
  m.geometry = make_flat_mesh(tm, vpm, what);
  for (auto f : faces(tm)) {
    std::array<std::array<double, 2>, 3> t{};
    int k = 0;
    for (auto h : CGAL::halfedges_around_face(halfedge(f, tm), tm)) {
      const auto& p = get(uv, h);
      t[k++] = {{CGAL::to_double(p.x()), CGAL::to_double(p.y())}};
    }
    m.uvs.push_back(t);
  }
  return m;
}

struct UV_tree {
  using K = Error_kernel;
  using Iterator = std::vector<K::Triangle_3>::const_iterator;
  using Primitive = CGAL::AABB_triangle_primitive<K, Iterator>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
  std::vector<K::Triangle_3> triangles;
  Tree tree;
  explicit UV_tree(const UV_flat_mesh& m) {
    for (const auto& t : m.uvs)
      triangles.emplace_back(K::Point_3(t[0][0], t[0][1], 0), K::Point_3(t[1][0], t[1][1], 0),
                             K::Point_3(t[2][0], t[2][1], 0));
    tree.insert(triangles.begin(), triangles.end());
    tree.build();
  }
};

/// Max over samples of `from` of the distance to the same-(u,v) point of `to`.
inline double one_sided_texture_deviation(const UV_flat_mesh& from, const UV_flat_mesh& to, const UV_tree& to_tree,
                                          std::size_t target, std::uint64_t seed, std::size_t& tried,
                                          std::size_t& matched) {
  using K = Error_kernel;
  // Parameter-space samples: (face, barycentrics). Corners first, then face samples.
  struct S {
    std::uint32_t f;
    double b0, b1, b2;
  };
  // A face whose UV triangle has (almost) zero area maps no (u,v) to a unique point: not
  // sampled. "Almost": twice the area below 1e-14 (UV coordinates are O(1)), below which
  // rounding makes barycentric coordinates meaningless.
  auto uv_degenerate = [&](std::size_t f) {
    const auto& q = from.uvs[f];
    return std::abs((q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1])) <= 1e-14;
  };
  std::vector<S> samples;
  for (std::uint32_t f = 0; f < from.uvs.size(); ++f) {
    if (uv_degenerate(f)) continue;
    samples.push_back({f, 1, 0, 0});
    samples.push_back({f, 0, 1, 0});
    samples.push_back({f, 0, 0, 1});
  }
  Sampling_plan plan = metro_plan(from.geometry, target, false, false, true);
  sample_surface(
      from.geometry, plan, seed, [](std::size_t) {}, [](std::size_t, double) {},
      [&](std::size_t f, double b0, double b1, double b2) {
        if (!uv_degenerate(f)) samples.push_back({std::uint32_t(f), b0, b1, b2});
      });
  constexpr std::size_t block = 1024;
  const std::size_t nblocks = (samples.size() + block - 1) / block;
  std::vector<double> block_max(nblocks, 0.);
  std::vector<std::size_t> block_matched(nblocks, 0);
  const auto& fp = from.geometry.points;
  const auto& tp = to.geometry.points;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nblocks), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<UV_tree::Tree::Primitive_id> hits;
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      const std::size_t i1 = std::min(samples.size(), (b + 1) * block);
      for (std::size_t i = b * block; i < i1; ++i) {
        const S& s = samples[i];
        const auto& t = from.uvs[s.f];
        const auto& tri = from.geometry.triangles[s.f];
        const double u = s.b0 * t[0][0] + s.b1 * t[1][0] + s.b2 * t[2][0];
        const double v = s.b0 * t[0][1] + s.b1 * t[1][1] + s.b2 * t[2][1];
        double x[3];
        for (int k = 0; k < 3; ++k) x[k] = s.b0 * fp[tri[0]][k] + s.b1 * fp[tri[1]][k] + s.b2 * fp[tri[2]][k];
        // A tiny box rather than the exact point: a sample on an edge of a thin UV triangle may
        // land a rounding error outside its own triangle, and with overlapping charts the only
        // exact hit would then be another chart. Barycentric coordinates below -1e-6 (a box
        // hit that does not contain (u,v)) are rejected.
        hits.clear();
        to_tree.tree.all_intersected_primitives(CGAL::Bbox_3(u - 1e-9, v - 1e-9, -1., u + 1e-9, v + 1e-9, 1.),
                                                std::back_inserter(hits));
        double best = HUGE_VAL;
        for (auto id : hits) {
          const std::size_t g = std::size_t(id - to_tree.triangles.begin());
          const auto& q = to.uvs[g];
          // Barycentric coordinates of (u,v) in the UV triangle q.
          const double d = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
          if (std::abs(d) <= 1e-14) continue;  // degenerate UV triangle: no unique preimage
          const double l1 = ((u - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (v - q[0][1])) / d;
          const double l2 = ((q[1][0] - q[0][0]) * (v - q[0][1]) - (u - q[0][0]) * (q[1][1] - q[0][1])) / d;
          const double l0 = 1. - l1 - l2;
          if (l0 < -1e-6 || l1 < -1e-6 || l2 < -1e-6) continue;
          const auto& gt = to.geometry.triangles[g];
          double dist2 = 0.;
          for (int k = 0; k < 3; ++k) {
            const double y = l0 * tp[gt[0]][k] + l1 * tp[gt[1]][k] + l2 * tp[gt[2]][k];
            dist2 += (x[k] - y) * (x[k] - y);
          }
          best = std::min(best, dist2);
        }
        if (best < HUGE_VAL) {
          ++block_matched[b];
          block_max[b] = std::max(block_max[b], std::sqrt(best));
        }
      }
    }
  });
  double m = 0.;
  for (std::size_t b = 0; b < nblocks; ++b) {
    m = std::max(m, block_max[b]);
    matched += block_matched[b];
  }
  tried += samples.size();
  return m;
}

inline Texture_deviation texture_deviation_flat(const UV_flat_mesh& a, const UV_flat_mesh& b,
                                                const Error_options& options) {
  Texture_deviation r;
  r.diagonal = a.geometry.diagonal();
  if (!(r.diagonal > 0.)) throw Invalid_input("texture_deviation: the reference mesh has a zero-size bounding box");
  const std::size_t target = options.samples ? options.samples : 10 * std::max(a.uvs.size(), b.uvs.size());
  auto run = [&] {
    UV_tree ta(a), tb(b);
    const double d1 = one_sided_texture_deviation(a, b, tb, target, options.seed, r.samples, r.matched_samples);
    const double d2 =
        one_sided_texture_deviation(b, a, ta, target, options.seed ^ 0x5bd1e995ull, r.samples, r.matched_samples);
    r.absolute = std::max(d1, d2);
  };
  if (options.threads > 0) {
    tbb::task_arena arena(options.threads);
    arena.execute(run);
  } else {
    run();
  }
  r.deviation = r.absolute / r.diagonal;
  return r;
}

}  // namespace internal

/// Texture deviation between two textured triangle meshes (see the file comment).
/// `uv1`, `uv2`: readable property maps from halfedge_descriptor to a 2D point (the texture
/// coordinate of target(h) as seen from face(h)). `options.samples`, `options.seed` and
/// `options.threads` are used as in approximation_error().
template <class TriangleMesh1, class UVMap1, class TriangleMesh2, class UVMap2,
          class NP1 = CGAL::parameters::Default_named_parameters,
          class NP2 = CGAL::parameters::Default_named_parameters>
Texture_deviation texture_deviation(const TriangleMesh1& reference, UVMap1 uv1, const TriangleMesh2& approximation,
                                    UVMap2 uv2, const Error_options& options = Error_options(),
                                    const NP1& np1 = CGAL::parameters::default_values(),
                                    const NP2& np2 = CGAL::parameters::default_values()) {
  using CGAL::parameters::choose_parameter;
  using CGAL::parameters::get_parameter;
  auto vpm1 = choose_parameter(get_parameter(np1, CGAL::internal_np::vertex_point),
                               get_const_property_map(CGAL::vertex_point, reference));
  auto vpm2 = choose_parameter(get_parameter(np2, CGAL::internal_np::vertex_point),
                               get_const_property_map(CGAL::vertex_point, approximation));
  const auto a = internal::make_uv_flat_mesh(reference, vpm1, uv1, "reference mesh");
  const auto b = internal::make_uv_flat_mesh(approximation, vpm2, uv2, "approximation mesh");
  return internal::texture_deviation_flat(a, b, options);
}

}  // namespace Metrics
}  // namespace CMGeom

#endif  // CMGEOM_METRICS_TEXTURE_DEVIATION_H

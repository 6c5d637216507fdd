// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// approximation_error(): the geometric error between a reference mesh and an approximation, in
// the Metro convention (thesis §2.3.2.2, eqs. 2.4-2.9; Cignoni, Rocchini and Scopigno 1998). Both
// surfaces are sampled (vertices, edges, similar-triangle face samples), every sample is measured
// against the other surface with a CGAL AABB_tree, and the two sides give the Hausdorff distance
// (eq. 2.7), the mean and the RMS, as fractions of the reference's bounding-box diagonal (as the
// thesis' Tables 4.2-4.3) plus absolute one-sided values. Key choice where the thesis is open: the
// symmetric mean pools both sample sets (eq. 2.8). Default: 10 x max(F1, F2) samples per
// direction. Bit-identical for a given seed whatever the thread count (TBB, fixed blocks).
// Error_reference prepares the reference's side once (tree, samples) for measuring several
// approximations of it (a level-of-detail chain, the snapshots of a run) with the same numbers.
//
// Manual: doc/Metrics/README.md, "Geometric error in the Metro convention".
#ifndef CMGEOM_METRICS_APPROXIMATION_ERROR_H
#define CMGEOM_METRICS_APPROXIMATION_ERROR_H

#include <CMGeom/Compact_model/internal/Vec3.h>
#include <CMGeom/Error.h>
#include <CMGeom/Metrics/internal/surface_sampling.h>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Named_function_parameters.h>
#include <CGAL/boost/graph/named_params_helper.h>
#include <CGAL/hilbert_sort.h>
#include <CGAL/property_map.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Spatial_sort_traits_adapter_3.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <numeric>
#include <vector>

namespace CMGeom {
namespace Metrics {

/// Options of approximation_error().
struct Error_options {
  /// Samples per direction; 0 means 10 x max(number of faces of the two meshes) (Metro).
  std::size_t samples = 0;
  /// Seed of the face-sampling draws (same seed, same samples, same numbers).
  std::uint64_t seed = 20110101;
  /// Worker threads; 0 lets TBB choose (all cores). The result does not depend on it.
  int threads = 0;
  bool sample_vertices = true;
  bool sample_edges = true;
  bool sample_faces = true;
  /// Fill Approximation_error::reference_vertex_error / approximation_vertex_error.
  bool vertex_field = true;
};

/// One direction: samples of one surface measured against the other (absolute units).
struct One_sided_error {
  double max = 0., mean = 0., rms = 0.;
  std::size_t samples = 0;
  std::size_t vertex_samples = 0, edge_samples = 0, face_samples = 0;
};

/// Result of approximation_error().
struct Approximation_error {
  double hausdorff = 0.;                       ///< symmetric Hausdorff / diagonal
  double mean = 0.;                            ///< pooled mean distance / diagonal
  double rms = 0.;                             ///< pooled RMS distance / diagonal
  double diagonal = 0.;                        ///< bounding-box diagonal of the reference (absolute)
  std::size_t samples = 0;                     ///< samples of both directions together
  One_sided_error reference_to_approximation;  ///< samples on the reference, absolute units
  One_sided_error approximation_to_reference;  ///< samples on the approximation, absolute units
  /// Distance of every vertex of the reference (order of vertices(reference)) to the
  /// approximation, absolute units; 0 for vertices no face uses. Empty unless vertex_field.
  std::vector<double> reference_vertex_error;
  /// Same for the vertices of the approximation, measured against the reference.
  std::vector<double> approximation_vertex_error;
};

namespace internal {

using Error_kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
/// The kernel of the distance queries: plain doubles. A closest-point query only compares
/// squared distances and box distances, which no exact predicate decides (Epick's filters cost
/// a third of a query and change no result beyond round-off).
using Distance_kernel = CGAL::Simple_cartesian<double>;

/// An AABB tree over the triangles of a Flat_mesh (the primitive id is an iterator into
/// `triangles`, so `id - triangles.begin()` is the face index).
struct Triangle_tree {
  using K = Distance_kernel;
  using Iterator = std::vector<K::Triangle_3>::const_iterator;
  using Primitive = CGAL::AABB_triangle_primitive<K, Iterator>;
  using Traits = CGAL::AABB_traits<K, Primitive>;
  using Tree = CGAL::AABB_tree<Traits>;

  std::vector<K::Triangle_3> triangles;
  Tree tree;

  explicit Triangle_tree(const Flat_mesh& m) {
    triangles.reserve(m.triangles.size());
    auto P = [&](std::uint32_t i) { return K::Point_3(m.points[i][0], m.points[i][1], m.points[i][2]); };
    for (const auto& t : m.triangles) triangles.emplace_back(P(t[0]), P(t[1]), P(t[2]));
    tree.insert(triangles.begin(), triangles.end());
    tree.build();
    // Builds the internal search tree for the hint-less queries (block starts) up front: the
    // lazy construction is not thread-safe.
    tree.accelerate_distance_queries();
    tree.closest_point(triangles.front().vertex(0));
  }

  /// The point of the surface closest to `q`, searched from `hint` (a point of the surface: the
  /// search keeps only boxes nearer than it). The same tree as CGAL's closest_point(q, hint), the
  /// nearer child box visited first (traversal_with_priority) and each triangle's closest point
  /// by Ericson's region tests (CM::internal::closest_on_triangle): the same point up to round-off,
  /// with a whole error 1.6-1.7x faster (doc/Metrics/README.md, "Performance").
  K::Point_3 closest_point(const K::Point_3& q, const K::Point_3& hint) const {
    Closest_point_traits traits(q, hint);
    tree.traversal_with_priority(q, traits);
    return traits.closest();
  }

  /// The closest point and the index of its triangle, searched without a hint (as CGAL's
  /// closest_point_and_primitive()).
  std::pair<K::Point_3, std::size_t> closest_point_and_triangle(const K::Point_3& q) const {
    const auto pp = tree.closest_point_and_primitive(q);
    return {pp.first, std::size_t(pp.second - triangles.begin())};
  }

  /// The same search, also giving the index of the triangle of the closest point; `hint` is a
  /// point of triangle `hint_triangle` (the result of a previous query serves).
  std::pair<K::Point_3, std::size_t> closest_point_and_triangle(const K::Point_3& q, const K::Point_3& hint,
                                                                std::size_t hint_triangle) const {
    Closest_point_traits traits(q, hint, triangles.begin(), hint_triangle);
    tree.traversal_with_priority(q, traits);
    return {traits.closest(), traits.closest_triangle()};
  }

private:
  using Vec3 = CM::internal::Vec3;
  static Vec3 vec(const K::Point_3& p) { return Vec3(p.x(), p.y(), p.z()); }

  class Closest_point_traits {
  public:
    using Priority = double;  // (the nearer box has the higher priority: minus its distance)
    Closest_point_traits(const K::Point_3& q, const K::Point_3& hint, Iterator first = Iterator(),
                         std::size_t hint_triangle = 0)
        : q_(vec(q)),
          best_(vec(hint)),
          best_sq_(CM::internal::squared_length(best_ - q_)),
          first_(first),
          best_id_(hint_triangle) {}
    bool go_further() const { return true; }
    void intersection(const K::Point_3&, const Primitive& p) {
      const K::Triangle_3& t = *p.id();
      const Vec3 x = CM::internal::closest_on_triangle(q_, vec(t.vertex(0)), vec(t.vertex(1)), vec(t.vertex(2)));
      const double d = CM::internal::squared_length(x - q_);
      if (d < best_sq_) {
        best_sq_ = d;
        best_ = x;
        best_id_ = std::size_t(p.id() - first_);
      }
    }
    template <class Node>
    bool do_intersect(const K::Point_3&, const Node& node) const {
      return CM::internal::squared_distance_to_box(q_, node.bbox()) < best_sq_;
    }
    template <class Node>
    std::pair<bool, Priority> do_intersect_with_priority(const K::Point_3&, const Node& node) const {
      const double d = CM::internal::squared_distance_to_box(q_, node.bbox());
      return {d < best_sq_, -d};
    }
    K::Point_3 closest() const { return K::Point_3(best_.x, best_.y, best_.z); }
    std::size_t closest_triangle() const { return best_id_; }

  private:
    Vec3 q_, best_;
    double best_sq_;
    Iterator first_;  // (triangles.begin(), for the index; unused by closest_point())
    std::size_t best_id_;
  };
};

/// Samples of one surface, as points, with the counts per kind.
struct Sample_set {
  std::vector<Distance_kernel::Point_3> points;
  std::vector<std::uint32_t> vertex_of_sample;  ///< for the first `vertex_samples` points
  std::size_t vertex_samples = 0, edge_samples = 0, face_samples = 0;
  std::vector<std::size_t> order;  ///< visiting order of the points (see hilbert_order())
};

/// Orders the samples along a Hilbert curve, so that consecutive samples are close and the
/// previous closest point is an excellent hint (it bounds the search ball from the start).
/// Files do not always list faces in a coherent order: on the armadillo this is 15x faster
/// than file order. CGAL's Hilbert sort is deterministic: the middle policy halves each box at
/// its centre, with no random choice and no median search.
inline void hilbert_order(Sample_set& s) {
  s.order.resize(s.points.size());
  std::iota(s.order.begin(), s.order.end(), std::size_t(0));  // size_t: Pointer_property_map's key
  using Sort_traits =
      CGAL::Spatial_sort_traits_adapter_3<Distance_kernel,
                                          CGAL::Pointer_property_map<Distance_kernel::Point_3>::const_type>;
  const std::vector<Distance_kernel::Point_3>& points = s.points;
  CGAL::hilbert_sort(s.order.begin(), s.order.end(), Sort_traits(CGAL::make_property_map(points)),
                     CGAL::Hilbert_sort_middle_policy());
}

inline Sample_set make_samples(const Flat_mesh& m, const Sampling_plan& plan, std::uint64_t seed) {
  Sample_set s;
  using P3 = Distance_kernel::Point_3;
  const auto& pts = m.points;
  sample_surface(
      m, plan, seed,
      [&](std::size_t v) {
        s.points.emplace_back(pts[v][0], pts[v][1], pts[v][2]);
        s.vertex_of_sample.push_back(std::uint32_t(v));
        ++s.vertex_samples;
      },
      [&](std::size_t e, double t) {
        const auto& a = pts[m.edges[e][0]];
        const auto& b = pts[m.edges[e][1]];
        s.points.push_back(P3(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])));
        ++s.edge_samples;
      },
      [&](std::size_t f, double b0, double b1, double b2) {
        const auto& a = pts[m.triangles[f][0]];
        const auto& b = pts[m.triangles[f][1]];
        const auto& c = pts[m.triangles[f][2]];
        s.points.push_back(P3(b0 * a[0] + b1 * b[0] + b2 * c[0], b0 * a[1] + b1 * b[1] + b2 * c[1],
                              b0 * a[2] + b1 * b[2] + b2 * c[2]));
        ++s.face_samples;
      });
  return s;
}

/// Measures every sample against `tree`; fills `field[vertex]` for vertex samples when non-null.
/// With `stride` > 1, only every stride-th sample in visiting order (a subset: its max is at most
/// the whole set's, up to the round-off by which a closest point depends on the search's hint);
/// `samples` then counts those measured, the counts per kind stay the set's.
inline One_sided_error measure(const Sample_set& s, const Triangle_tree& target, std::vector<double>* field,
                               std::size_t stride = 1) {
  const std::size_t n = (s.points.size() + stride - 1) / stride;  // positions 0, stride, ...
  const std::vector<std::size_t>& order = s.order;
  // Fixed block size: partial results per block, reduced in block order => deterministic
  // whatever the number of threads.
  constexpr std::size_t block = 1024;
  const std::size_t nblocks = (n + block - 1) / block;
  struct Partial {
    double max = 0., sum = 0., sum2 = 0.;
  };
  std::vector<Partial> partial(nblocks);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nblocks), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      const std::size_t i0 = b * block, i1 = std::min(n, i0 + block);
      auto hint = target.tree.closest_point(s.points[order[i0 * stride]]);
      Partial p;
      for (std::size_t i = i0; i < i1; ++i) {
        const std::size_t k = order[i * stride];
        hint = target.closest_point(s.points[k], hint);
        const double d = std::sqrt(CGAL::squared_distance(s.points[k], hint));
        p.max = std::max(p.max, d);
        p.sum += d;
        p.sum2 += d * d;
        if (field && k < s.vertex_samples) (*field)[s.vertex_of_sample[k]] = d;
      }
      partial[b] = p;
    }
  });
  One_sided_error e;
  double sum = 0., sum2 = 0.;
  for (const Partial& p : partial) {
    e.max = std::max(e.max, p.max);
    sum += p.sum;
    sum2 += p.sum2;
  }
  e.samples = n;
  e.vertex_samples = s.vertex_samples;
  e.edge_samples = s.edge_samples;
  e.face_samples = s.face_samples;
  if (n) {
    e.mean = sum / double(n);
    e.rms = std::sqrt(sum2 / double(n));
  }
  return e;
}

/// The samples a direction's plan gives, in their visiting order.
inline Sample_set ordered_samples(const Flat_mesh& m, const Sampling_plan& plan, std::uint64_t seed) {
  Sample_set s = make_samples(m, plan, seed);
  hilbert_order(s);
  return s;
}

/// Samples per direction for a pair of meshes (see Error_options::samples).
inline std::size_t sample_target(const Flat_mesh& ref, const Flat_mesh& app, const Error_options& o) {
  return o.samples ? o.samples : 10 * std::max(ref.triangles.size(), app.triangles.size());
}

inline Sampling_plan plan_of(const Flat_mesh& m, std::size_t target, const Error_options& o) {
  return metro_plan(m, target, o.sample_vertices, o.sample_edges, o.sample_faces);
}

inline std::uint64_t approximation_seed(const Error_options& o) { return o.seed ^ 0x5bd1e995ull; }

/// Runs `f` on `o.threads` workers (all cores when 0).
template <class F>
void run_with_threads(const Error_options& o, const F& f) {
  if (o.threads > 0) {
    tbb::task_arena arena(o.threads);
    arena.execute(f);
  } else {
    f();
  }
}

/// Both directions measured, pooled into the result (fields of `r` already set: diagonal).
inline void measure_both(Approximation_error& r, const Flat_mesh& ref, const Sample_set& s_ref,
                         const Triangle_tree& tree_ref, const Flat_mesh& app, const Sample_set& s_app,
                         const Triangle_tree& tree_app, const Error_options& o) {
  if (o.vertex_field) {
    r.reference_vertex_error.assign(ref.points.size(), 0.);
    r.approximation_vertex_error.assign(app.points.size(), 0.);
  }
  r.reference_to_approximation = measure(s_ref, tree_app, o.vertex_field ? &r.reference_vertex_error : nullptr);
  r.approximation_to_reference = measure(s_app, tree_ref, o.vertex_field ? &r.approximation_vertex_error : nullptr);
  const One_sided_error& a = r.reference_to_approximation;
  const One_sided_error& b = r.approximation_to_reference;
  r.samples = a.samples + b.samples;
  r.hausdorff = std::max(a.max, b.max) / r.diagonal;
  if (r.samples) {
    const double sum = a.mean * double(a.samples) + b.mean * double(b.samples);
    const double sum2 = a.rms * a.rms * double(a.samples) + b.rms * b.rms * double(b.samples);
    r.mean = sum / double(r.samples) / r.diagonal;
    r.rms = std::sqrt(sum2 / double(r.samples)) / r.diagonal;
  }
}

inline double reference_diagonal(const Flat_mesh& ref) {
  const double d = ref.diagonal();
  if (!(d > 0.)) throw Invalid_input("approximation_error: the reference mesh has a zero-size bounding box");
  return d;
}

inline Approximation_error approximation_error_flat(const Flat_mesh& ref, const Flat_mesh& app,
                                                    const Error_options& o) {
  Approximation_error r;
  r.diagonal = reference_diagonal(ref);
  const std::size_t target = sample_target(ref, app, o);
  const Sampling_plan plan_ref = plan_of(ref, target, o), plan_app = plan_of(app, target, o);
  run_with_threads(o, [&] {
    // The serial parts (tree construction, sampling, sorting) of the two directions are
    // independent: run them side by side.
    std::unique_ptr<Triangle_tree> tree_ref, tree_app;
    Sample_set s_ref, s_app;
    tbb::parallel_invoke([&] { tree_ref = std::make_unique<Triangle_tree>(ref); },
                         [&] { tree_app = std::make_unique<Triangle_tree>(app); },
                         [&] { s_ref = ordered_samples(ref, plan_ref, o.seed); },
                         [&] { s_app = ordered_samples(app, plan_app, approximation_seed(o)); });
    measure_both(r, ref, s_ref, *tree_ref, app, s_app, *tree_app, o);
  });
  return r;
}

}  // namespace internal

/// Metro-style symmetric error between `reference` and `approximation` (see the file comment).
///
/// `TriangleMesh1`, `TriangleMesh2`: models of `FaceListGraph` and `EdgeListGraph` whose faces are
/// triangles. Named parameters `np1`, `np2`: `vertex_point_map` of each mesh (default: the
/// internal `vertex_point` property). Throws Invalid_input if a mesh has no face, a non-triangle
/// face, a non-finite coordinate, or if the reference has an empty bounding box.
template <class TriangleMesh1, class TriangleMesh2, class NP1 = CGAL::parameters::Default_named_parameters,
          class NP2 = CGAL::parameters::Default_named_parameters>
Approximation_error approximation_error(const TriangleMesh1& reference, const TriangleMesh2& approximation,
                                        const Error_options& options = Error_options(),
                                        const NP1& np1 = CGAL::parameters::default_values(),
                                        const NP2& np2 = CGAL::parameters::default_values()) {
  using CGAL::parameters::choose_parameter;
  using CGAL::parameters::get_parameter;
  auto vpm1 = choose_parameter(get_parameter(np1, CGAL::internal_np::vertex_point),
                               get_const_property_map(CGAL::vertex_point, reference));
  auto vpm2 = choose_parameter(get_parameter(np2, CGAL::internal_np::vertex_point),
                               get_const_property_map(CGAL::vertex_point, approximation));
  const internal::Flat_mesh ref = internal::make_flat_mesh(reference, vpm1, "reference mesh");
  const internal::Flat_mesh app = internal::make_flat_mesh(approximation, vpm2, "approximation mesh");
  return internal::approximation_error_flat(ref, app, options);
}

/// The reference side of approximation_error() prepared once (its copy, its AABB tree, its
/// samples) for measuring several approximations of one reference: the levels of a chain, the
/// snapshots of a run. `error(approximation)` returns exactly what
/// `approximation_error(reference, approximation, options)` returns (same samples, same numbers);
/// only the approximation's side is built for each call. When `options.samples` is 0 and an
/// approximation has more faces than the reference, the reference's samples of that call are
/// drawn again (their number depends on both meshes). `error()` may be called from several threads
/// at once.
class Error_reference {
public:
  /// `reference`, `np`: as approximation_error()'s first mesh and its named parameters. Throws
  /// Invalid_input as approximation_error() does for the reference.
  template <class TriangleMesh, class NP = CGAL::parameters::Default_named_parameters>
  explicit Error_reference(const TriangleMesh& reference, const Error_options& options = Error_options(),
                           const NP& np = CGAL::parameters::default_values())
      : options_(options) {
    using CGAL::parameters::choose_parameter;
    using CGAL::parameters::get_parameter;
    auto vpm = choose_parameter(get_parameter(np, CGAL::internal_np::vertex_point),
                                get_const_property_map(CGAL::vertex_point, reference));
    ref_ = internal::make_flat_mesh(reference, vpm, "reference mesh");
    diagonal_ = internal::reference_diagonal(ref_);
    // (the samples for any approximation with at most as many faces)
    target_ = internal::sample_target(ref_, ref_, options_);
    const internal::Sampling_plan plan = internal::plan_of(ref_, target_, options_);
    internal::run_with_threads(options_, [&] {
      tbb::parallel_invoke([&] { tree_ = std::make_unique<internal::Triangle_tree>(ref_); },
                           [&] { samples_ = internal::ordered_samples(ref_, plan, options_.seed); });
    });
  }

  /// The error of `approximation` (named parameters `np`: its `vertex_point_map`).
  template <class TriangleMesh, class NP = CGAL::parameters::Default_named_parameters>
  Approximation_error error(const TriangleMesh& approximation,
                            const NP& np = CGAL::parameters::default_values()) const {
    using CGAL::parameters::choose_parameter;
    using CGAL::parameters::get_parameter;
    auto vpm = choose_parameter(get_parameter(np, CGAL::internal_np::vertex_point),
                                get_const_property_map(CGAL::vertex_point, approximation));
    return error_flat(internal::make_flat_mesh(approximation, vpm, "approximation mesh"));
  }

  /// The same for an approximation already copied into flat arrays.
  Approximation_error error_flat(const internal::Flat_mesh& app) const {
    Approximation_error r;
    r.diagonal = diagonal_;
    const std::size_t target = internal::sample_target(ref_, app, options_);
    const internal::Sampling_plan plan_app = internal::plan_of(app, target, options_);
    internal::run_with_threads(options_, [&] {
      std::unique_ptr<internal::Triangle_tree> tree_app;
      internal::Sample_set s_app, s_ref_own;
      tbb::parallel_invoke(
          [&] { tree_app = std::make_unique<internal::Triangle_tree>(app); },
          [&] { s_app = internal::ordered_samples(app, plan_app, internal::approximation_seed(options_)); },
          [&] {
            if (target != target_)
              s_ref_own = internal::ordered_samples(ref_, internal::plan_of(ref_, target, options_), options_.seed);
          });
      const internal::Sample_set& s_ref = target != target_ ? s_ref_own : samples_;
      internal::measure_both(r, ref_, s_ref, *tree_, app, s_app, *tree_app, options_);
    });
    return r;
  }

  /// A lower bound of error(approximation).hausdorff, for a small part of its cost: the largest
  /// distance (as a fraction of the diagonal) over every `stride`-th sample of the reference, in
  /// their visiting order, measured against the approximation, and over every `stride`-th vertex
  /// of the approximation measured against the reference. Both are subsets of the samples error()
  /// measures (its reference samples are the same set, and it samples every vertex of the
  /// approximation when `sample_vertices` is on; off, only the reference side counts), so the
  /// bound is at most error()'s Hausdorff distance, up to the round-off by which a closest point
  /// depends on where its search starts. For searches that measure many candidates and need the
  /// full measure only of the few they keep (simplify_to_levels() by error bounds). `stride` >= 1;
  /// 1 measures every reference sample and every vertex. O((samples + vertices) / stride x log
  /// faces), plus building the approximation's tree.
  template <class TriangleMesh, class NP = CGAL::parameters::Default_named_parameters>
  double hausdorff_lower_bound(const TriangleMesh& approximation, std::size_t stride,
                               const NP& np = CGAL::parameters::default_values()) const {
    using CGAL::parameters::choose_parameter;
    using CGAL::parameters::get_parameter;
    auto vpm = choose_parameter(get_parameter(np, CGAL::internal_np::vertex_point),
                                get_const_property_map(CGAL::vertex_point, approximation));
    return hausdorff_lower_bound_flat(internal::make_flat_mesh(approximation, vpm, "approximation mesh"), stride);
  }

  /// The same for an approximation already copied into flat arrays.
  double hausdorff_lower_bound_flat(const internal::Flat_mesh& app, std::size_t stride) const {
    if (stride == 0) throw Invalid_input("Error_reference::hausdorff_lower_bound: the stride must be at least 1");
    // (another sample count than the prepared one: error() samples the reference again, and so
    // does this, with the same plan and seed)
    const std::size_t target = internal::sample_target(ref_, app, options_);
    double far = 0.;
    internal::run_with_threads(options_, [&] {
      std::unique_ptr<internal::Triangle_tree> tree_app;
      internal::Sample_set s_vertices, s_ref_own;
      tbb::parallel_invoke([&] { tree_app = std::make_unique<internal::Triangle_tree>(app); },
                           [&] {
                             if (!options_.sample_vertices) return;
                             internal::Sampling_plan plan;  // the vertices alone
                             plan.vertices = true;
                             plan.edges = plan.faces = false;
                             s_vertices = internal::ordered_samples(app, plan, 0);
                           },
                           [&] {
                             if (target != target_)
                               s_ref_own = internal::ordered_samples(ref_, internal::plan_of(ref_, target, options_),
                                                                     options_.seed);
                           });
      const internal::Sample_set& s_ref = target != target_ ? s_ref_own : samples_;
      far = internal::measure(s_ref, *tree_app, nullptr, stride).max;
      far = std::max(far, internal::measure(s_vertices, *tree_, nullptr, stride).max);
    });
    return far / diagonal_;
  }

  const Error_options& options() const { return options_; }

private:
  Error_options options_;
  internal::Flat_mesh ref_;
  double diagonal_ = 0.;
  std::size_t target_ = 0;
  std::unique_ptr<internal::Triangle_tree> tree_;
  internal::Sample_set samples_;
};

}  // namespace Metrics
}  // namespace CMGeom

#endif  // CMGEOM_METRICS_APPROXIMATION_ERROR_H

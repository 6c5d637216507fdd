// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Error-driven adaptive reconstruction of a Compact Model (a CMGeom addition to §4.5.2):
// Chord_error_criterion, chord_deviation() and reconstruct_to_vertex_budget(). The criteria of
// §4.5.2 say where to refine, not how far the output is from the surface; here an edge (p1, p2)
// is halved when its chord's midpoint is estimated farther than `tolerance` from the blended
// surface Phi, by |(d . n2) n2 - (d . n1) n1| / 8 (d the chord, n1, n2 the blended end normals:
// the cubic Hermite curve with the projected chord as end tangents), which is first order in the
// turning angle, 0 on a plane, and needs no evaluation at the midpoint.
// reconstruct_to_vertex_budget() bisects log(tolerance) and returns the largest output within a
// vertex budget. The error is measured against Phi, not the input (which the CM no longer has).
// When the model carries a level error table (Compact_model::level_errors, level_errors.h: the
// input's error of every regular level per base face, measured at build time),
// reconstruct_to_vertex_budget() uses it instead: face_levels_for_budget() gives every base face
// a level, minimising the estimated squared error (sum over faces of area x RMS^2) within the
// budget, with no face's estimated largest error above the largest of the regular level that
// fits the budget, and never an estimate worse than that regular level's (which it returns
// then); Face_level_criterion realises the levels (an edge is split to the finer level of its
// faces). Refining is not always better: where the local surfaces stray from the input, a coarse
// chord can be closer than Phi, and only the measured table knows it.
//
// Manual: doc/Compact_model/README.md, "Error-driven adaptive reconstruction (CMGeom addition to §4.5.2)".
#ifndef CMGEOM_COMPACT_MODEL_ERROR_CRITERION_H
#define CMGEOM_COMPACT_MODEL_ERROR_CRITERION_H

#include <CMGeom/Compact_model/reconstruct.h>
#include <CMGeom/Error.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace CM {

/// Estimated distance between the midpoint of the chord (a.point, b.point) and the surface,
/// from the end points and their unit normals (see the file comment).
inline double chord_deviation(const Sample& a, const Sample& b) {
  const Vec3 d = b.point - a.point;
  const Vec3 dev = internal::dot(d, b.normal) * b.normal - internal::dot(d, a.normal) * a.normal;
  const double e = internal::length(dev) / 8.;
  return std::isfinite(e) ? e : 0.;
}

/// Adaptive criterion (§4.5.2 interface): halve an edge whose chord is estimated farther than
/// `tolerance` from the surface (absolute, in model units).
struct Chord_error_criterion {
  double tolerance;
  bool operator()(const Sample& a, const Sample& b) const { return chord_deviation(a, b) > tolerance; }
};

/// Adaptive criterion from per-base-face levels (see the file comment): an edge is split while
/// its number of halvings is below the level of its face, or the larger of its two faces' levels
/// on a base edge. `levels` (one per base face) must outlive the criterion.
struct Face_level_criterion {
  const std::vector<std::uint8_t>* levels;
  bool operator()(const Sample&, const Sample&, const Split_site& s) const {
    return s.level < int(std::max((*levels)[s.face[0]], (*levels)[s.face[1]]));
  }
};

/// Levels chosen by face_levels_for_budget().
struct Face_levels {
  std::vector<std::uint8_t> levels;  ///< one per base face
  std::size_t vertices = 0;          ///< output points of reconstruct_face_levels() with them
  int regular_level = -1;            ///< the finest regular level within the budget (-1: none)
  bool regular = false;              ///< true when the result is that regular level
  double estimated_rms = 0.;         ///< area-weighted, from the table (model units)
  double estimated_max = 0.;         ///< largest face's error from the table (model units)
  double regular_estimated_rms = 0., regular_estimated_max = 0.;  ///< the same for regular_level
};

namespace internal {

/// Base edges as the faces beside them (a border edge repeats its face), and each face's edges.
struct Face_level_topology {
  std::vector<std::array<std::uint32_t, 2>> edge_faces;
  std::vector<std::array<std::uint32_t, 3>> face_edges;
  explicit Face_level_topology(const Compact_model& m) {
    Base_topology topo(m);  // (the reconstruction's own edge numbering)
    edge_faces.reserve(topo.edges.size());
    for (const auto& e : topo.edges)
      edge_faces.push_back({e.face[0], e.face[1] == Base_topology::npos ? e.face[0] : e.face[1]});
    face_edges = std::move(topo.face_edges);
  }
  static std::size_t interior_points(int l) {
    const std::size_t n = std::size_t(1) << l;
    return (n - 1) * (n - 2) / 2;
  }
  /// Output points of reconstruct_face_levels(m, levels).
  std::size_t count(std::size_t V, const std::vector<std::uint8_t>& levels) const {
    std::size_t c = V;
    for (const auto& ef : edge_faces) c += (std::size_t(1) << std::max(levels[ef[0]], levels[ef[1]])) - 1;
    for (std::uint8_t l : levels) c += interior_points(l);
    return c;
  }
};

}  // namespace internal

/// Per-face levels for an output of at most `max_vertices` points, at most `max_level` (and the
/// table's depth) halvings, from the model's level error table (see the file comment). Throws
/// Invalid_input when the model has no table or the budget is 0.
inline Face_levels face_levels_for_budget(const Compact_model& m, std::size_t max_vertices, int max_level) {
  if (m.level_errors.empty()) throw Invalid_input("face_levels_for_budget: the model has no level error table");
  if (max_vertices == 0) throw Invalid_input("face_levels_for_budget: the budget must be at least 1 vertex");
  m.validate();
  const std::size_t F = m.faces.size(), V = m.vertices.size();
  const int D = std::max(0, std::min(max_level, m.level_errors.depth));
  const internal::Face_level_topology topo(m);
  // Weights: base face areas (the share of the surface each face's RMS stands for).
  std::vector<double> area(F);
  double total_area = 0.;
  for (std::size_t f = 0; f < F; ++f) {
    const Vec3 &a = m.vertices[m.faces[f][0].vertex], &b = m.vertices[m.faces[f][1].vertex],
               &c = m.vertices[m.faces[f][2].vertex];
    area[f] = 0.5 * internal::length(internal::cross(b - a, c - a));
    total_area += area[f];
  }
  if (!(total_area > 0.)) {
    std::fill(area.begin(), area.end(), 1.);
    total_area = double(F);
  }
  const Level_errors& le = m.level_errors;
  auto e = [&](std::size_t f, int l) {
    const double r = le.rms_at(l, f, F);
    return area[f] * r * r;
  };
  auto cost = [](int l) {  // a face's share of the points of its level
    const double n = double(std::size_t(1) << l);
    return (n - 1.) * (n - 2.) / 2. + 1.5 * (n - 1.);
  };
  Face_levels out;
  auto finish = [&](std::vector<std::uint8_t> levels) {
    double s = 0., mx = 0.;
    for (std::size_t f = 0; f < F; ++f) {
      s += e(f, levels[f]);
      mx = std::max(mx, le.max_at(levels[f], f, F));
    }
    out.estimated_rms = std::sqrt(s / total_area);
    out.estimated_max = mx;
    out.vertices = topo.count(V, levels);
    out.levels = std::move(levels);
  };
  // The finest regular level within the budget.
  int L = -1;
  for (int l = 0; l <= D; ++l)
    if (topo.count(V, std::vector<std::uint8_t>(F, std::uint8_t(l))) <= max_vertices) L = l;
  out.regular_level = L;
  if (L < 0 || L == D) {  // nothing coarser than the base, or the finest the table knows fits
    out.regular = true;
    finish(std::vector<std::uint8_t>(F, std::uint8_t(std::max(L, 0))));
    out.regular_estimated_rms = out.estimated_rms;
    out.regular_estimated_max = out.estimated_max;
    return out;
  }
  double reg_sum = 0., cap = 0.;
  for (std::size_t f = 0; f < F; ++f) {
    reg_sum += e(f, L);
    cap = std::max(cap, le.max_at(L, f, F));
  }
  out.regular_estimated_rms = std::sqrt(reg_sum / total_area);
  out.regular_estimated_max = cap;
  auto admissible = [&](std::size_t f, int l) { return l == L || le.max_at(l, f, F) <= cap; };
  // Lagrangian relaxation: level of f = argmin over admissible l of e(f, l) + lambda cost(l).
  auto assign = [&](double lambda) {
    std::vector<std::uint8_t> lv(F);
    for (std::size_t f = 0; f < F; ++f) {
      int best = L;
      double bv = e(f, L) + lambda * cost(L);
      for (int l = 0; l <= D; ++l)
        if (l != L && admissible(f, l)) {
          const double v = e(f, l) + lambda * cost(l);
          if (v < bv || (v == bv && l < best)) {
            best = l;
            bv = v;
          }
        }
      lv[f] = std::uint8_t(best);
    }
    return lv;
  };
  double lo = HUGE_VAL, hi = 0.;  // range of the slopes between a face's levels
  for (std::size_t f = 0; f < F; ++f)
    for (int l = 0; l < D; ++l) {
      const double slope = std::abs(e(f, l) - e(f, l + 1)) / (cost(l + 1) - cost(l));
      if (slope > 0.) {
        lo = std::min(lo, slope);
        hi = std::max(hi, slope);
      }
    }
  std::vector<std::uint8_t> best;
  if (hi > 0.) {
    lo /= 4.;
    hi *= 4.;
    std::vector<std::uint8_t> lv = assign(hi);
    if (topo.count(V, lv) <= max_vertices) {
      best = std::move(lv);
      for (int i = 0; i < 64 && hi / lo > 1.0001; ++i) {  // smallest lambda within the budget
        const double mid = std::sqrt(lo * hi);
        lv = assign(mid);
        if (topo.count(V, lv) <= max_vertices) {
          hi = mid;
          best = std::move(lv);
        } else {
          lo = mid;
        }
      }
    }
  }
  if (!best.empty()) {
    // Greedy fill of what the budget has left: one upgrade per face, best error drop per point.
    std::size_t used = topo.count(V, best);
    struct Up {
      double ratio;
      std::uint32_t f;
      int l;
    };
    std::vector<Up> ups;
    for (std::size_t f = 0; f < F; ++f) {
      Up u{0., std::uint32_t(f), -1};
      for (int l = best[f] + 1; l <= D; ++l)
        if (admissible(f, l) && e(f, l) < e(f, best[f])) {
          const double r = (e(f, best[f]) - e(f, l)) / (cost(l) - cost(best[f]));
          if (r > u.ratio) u = Up{r, std::uint32_t(f), l};
        }
      if (u.l >= 0) ups.push_back(u);
    }
    std::sort(ups.begin(), ups.end(),
              [](const Up& a, const Up& b) { return a.ratio > b.ratio || (a.ratio == b.ratio && a.f < b.f); });
    for (const Up& u : ups) {
      const int from = best[u.f];
      std::size_t add =
          internal::Face_level_topology::interior_points(u.l) - internal::Face_level_topology::interior_points(from);
      for (int k = 0; k < 3; ++k) {
        const auto& ef = topo.edge_faces[topo.face_edges[u.f][k]];
        const int other = int(best[ef[0] == u.f ? ef[1] : ef[0]]);
        add += (std::size_t(1) << std::max(u.l, other)) - (std::size_t(1) << std::max(from, other));
      }
      if (used + add > max_vertices) continue;
      best[u.f] = std::uint8_t(u.l);
      used += add;
    }
    double sum = 0.;
    for (std::size_t f = 0; f < F; ++f) sum += e(f, best[f]);
    if (sum < reg_sum) {
      finish(std::move(best));
      return out;
    }
  }
  out.regular = true;
  finish(std::vector<std::uint8_t>(F, std::uint8_t(L)));
  return out;
}

/// Adaptive reconstruction with a level per base face (Face_level_criterion).
template <class Traits = Quadric_surface_traits>
Reconstruction reconstruct_face_levels(const Compact_model& m, const std::vector<std::uint8_t>& levels,
                                       const Reconstruction_options& opt = Reconstruction_options(),
                                       const Traits& traits = Traits()) {
  if (levels.size() != m.faces.size())
    throw Invalid_input("reconstruct_face_levels: " + std::to_string(levels.size()) + " levels for " +
                        std::to_string(m.faces.size()) + " faces");
  const int top = levels.empty() ? 0 : int(*std::max_element(levels.begin(), levels.end()));
  return reconstruct_adaptive(m, Face_level_criterion{&levels}, top, opt, traits);
}

/// What reconstruct_to_vertex_budget() found.
struct Vertex_budget_result {
  Reconstruction reconstruction;
  double tolerance = 0.;      ///< the Chord_error_criterion tolerance of `reconstruction` (0 with the table)
  int reconstructions = 0;    ///< adaptive reconstructions run
  bool level_errors = false;  ///< true when the model's level error table chose the levels
  Face_levels face_levels;    ///< what the table chose (when level_errors)
};

/// Adaptive reconstruction with Chord_error_criterion whose tolerance is chosen so that the
/// output has at most `max_vertices` points, as many as `iterations` bisection steps on
/// log(tolerance) find (see the file comment). `max_level` bounds the halvings of a base edge.
/// When even the base mesh exceeds the budget, the result is the base (level 0). Throws
/// Invalid_input for a budget of 0 or fewer than 1 iteration. A model with a level error table
/// is reconstructed with the levels of face_levels_for_budget() instead (see the file comment; one
/// reconstruction, `iterations` unused); clear `m.level_errors` in a copy for the chord criterion.
template <class Traits = Quadric_surface_traits>
Vertex_budget_result reconstruct_to_vertex_budget(const Compact_model& m, std::size_t max_vertices, int max_level,
                                                  const Reconstruction_options& opt = Reconstruction_options(),
                                                  const Traits& traits = Traits(), int iterations = 24) {
  if (max_vertices == 0) throw Invalid_input("reconstruct_to_vertex_budget: the budget must be at least 1 vertex");
  if (iterations < 1) throw Invalid_input("reconstruct_to_vertex_budget: at least 1 iteration");
  if (!m.level_errors.empty()) {
    Vertex_budget_result r;
    r.face_levels = face_levels_for_budget(m, max_vertices, max_level);
    r.reconstruction = reconstruct_face_levels(m, r.face_levels.levels, opt, traits);
    r.reconstructions = 1;
    r.level_errors = true;
    return r;
  }
  // Scale of the model: the diagonal of its base vertices' box.
  Vec3 lo = m.vertices.empty() ? Vec3() : m.vertices[0], hi = lo;
  for (const Vec3& v : m.vertices) {
    lo = Vec3(std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z));
    hi = Vec3(std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z));
  }
  const double scale = std::max(internal::length(hi - lo), 1e-300);
  Vertex_budget_result best;
  bool have = false;
  int runs = 0;
  auto run = [&](double tol) {
    Reconstruction r = reconstruct_adaptive(m, Chord_error_criterion{tol}, max_level, opt, traits);
    ++runs;
    const bool fits = r.points.size() <= max_vertices;
    if (fits && (!have || r.points.size() > best.reconstruction.points.size() ||
                 (r.points.size() == best.reconstruction.points.size() && tol < best.tolerance))) {
      best.reconstruction = std::move(r);
      best.tolerance = tol;
      have = true;
    }
    return fits;
  };
  // Bracket: lo_t over the budget, hi_t within it.
  double lo_t = 1e-7 * scale, hi_t = scale;
  if (run(lo_t)) {  // even the finest tolerance fits the budget
    best.reconstructions = runs;
    return best;
  }
  if (!run(hi_t)) {
    // Only a base with more vertices than the budget gets here (a tolerance of the model's size
    // splits almost nothing): give the base itself.
    best.reconstruction = reconstruct_adaptive(m, Chord_error_criterion{hi_t}, 0, opt, traits);
    best.tolerance = hi_t;
    best.reconstructions = runs + 1;
    return best;
  }
  for (int i = 2; i < iterations; ++i) {
    const double mid = std::sqrt(lo_t * hi_t);
    if (run(mid))
      hi_t = mid;
    else
      lo_t = mid;
    if (hi_t / lo_t < 1.0005) break;
  }
  best.reconstructions = runs;
  return best;
}

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_ERROR_CRITERION_H

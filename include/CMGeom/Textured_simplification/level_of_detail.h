// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// simplify_to_levels(): a level-of-detail chain from ONE simplification run. The collapses of
// simplify_mesh() run down to the smallest target and the mesh is copied each time the face count
// reaches a level's target, so every level is the same collapse sequence stopped earlier. Levels
// may also be asked by error bound (`max_errors`, snapshots every `error_step`; a sampled
// measure, not a guarantee). Texture: an atlas per level baked from the input (default), or one
// shared texture, the coarsest level's atlas, which every finer level addresses (the thesis' future
// work of levels sharing one texture, §7.1). Each level's geometric error is measured unless
// `measure_error` is false.
//
// Manual: doc/Textured_simplification/README.md, "Levels of detail from one run, and one texture for all of them".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_LEVEL_OF_DETAIL_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_LEVEL_OF_DETAIL_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>
#include <CMGeom/Mesh_IO/charts.h>
#include <CMGeom/Metrics/approximation_error.h>
#include <CMGeom/Textured_simplification/Edge_collapse_visitor_base.h>
#include <CMGeom/Textured_simplification/rebuild_atlas.h>
#include <CMGeom/Textured_simplification/simplify_mesh.h>

#include <CGAL/boost/graph/copy_face_graph.h>

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <unordered_map>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {

/// Options of simplify_to_levels().
struct Level_of_detail_options {
  /// Face targets of the levels, strictly decreasing (a target >= the input's face count is the
  /// input itself).
  std::vector<std::size_t> target_faces;
  /// Instead of face targets: error bounds, strictly increasing, >= 0, as fractions of the input's
  /// bounding-box diagonal. Each level is the smallest snapshot of the run whose measured error
  /// (symmetric Hausdorff, Metrics::approximation_error with `error_samples`) is at most its bound;
  /// snapshots are taken and measured each time the face count falls to `error_step` times the
  /// previous snapshot's, and the run stops at the first one above the largest bound. A bound no
  /// snapshot meets gives the input itself. Ignored when empty.
  std::vector<double> max_errors;
  /// See max_errors; in (0, 1).
  double error_step = 0.8;
  /// Cost and placement (plain Garland-Heckbert by default, as simplify_mesh).
  Quadric_options quadric = Quadric_options{false};
  bool surface_memory = true;
  bool flips = false;
  /// Textured input: one atlas for every level (see the file comment) instead of one per level.
  bool shared_texture = false;
  /// The atlas (per-level atlases, or the shared one).
  Atlas_options atlas;
  /// Shared texture: a corner past its chart's border is extended over it by at most this
  /// fraction of the coarse face it is projected on (barycentric coordinates >= -this).
  double max_extrapolation = 0.5;
  /// Measure every level's error against the input (Metrics::approximation_error).
  bool measure_error = true;
  /// Samples per direction of that measure; 0: 2 x the input's face count.
  std::size_t error_samples = 0;
};

/// One level of the chain.
struct Level_of_detail {
  Textured_mesh mesh;
  std::size_t target_faces = 0;
  bool is_input = false;  ///< the input itself (target >= its face count)
  double hausdorff = -1;  ///< symmetric Hausdorff / bounding-box diagonal (-1: not measured)
  double rms = -1;        ///< RMS distance / diagonal (-1: not measured)
  Atlas_result atlas;     ///< its atlas (per-level mode), or the shared one (coarsest level)
};

struct Level_of_detail_result {
  std::vector<Level_of_detail> levels;
  double seconds_collapse = 0;  ///< the collapse run, snapshots included
  double seconds_texture = 0;   ///< atlas extraction, baking, mapping through the shared atlas
  double seconds_error = 0;     ///< the error measures
  /// Shared texture: the fraction of the original's texels in the atlas that another part of the
  /// original took (parts that fold onto one place of the coarsest level, e.g. a label over a
  /// bottle on a 45-face bottle); those parts show the other part's colours at every level.
  double shared_texture_hidden = 0;
  double seconds = 0;
};

namespace internal {

/// Copies the live part of `from` (a mesh that may hold garbage) into a new garbage-free mesh.
inline Surface_mesh compact_copy(const Surface_mesh& from) {
  Surface_mesh to;
  CGAL::copy_face_graph(from, to);
  return to;
}

/// Forwards every engine call to the caller's visitor; the snapshot visitors below derive from it
/// and add to OnCollapsed.
template <class Visitor>
struct Forwarding_visitor {
  Visitor visitor;
  template <class TM>
  void OnStarted(TM& tm) const {
    visitor.OnStarted(tm);
  }
  template <class TM>
  void OnFinished(TM& tm) const {
    visitor.OnFinished(tm);
  }
  template <class P>
  void OnStopConditionReached(const P& p) const {
    visitor.OnStopConditionReached(p);
  }
  template <class P, class C>
  void OnCollected(const P& p, const C& c) const {
    visitor.OnCollected(p, c);
  }
  template <class P, class C, class S>
  void OnSelected(const P& p, const C& c, S i, S n) const {
    visitor.OnSelected(p, c, i, n);
  }
  template <class P, class Pl>
  void OnCollapsing(const P& p, const Pl& pl) const {
    visitor.OnCollapsing(p, pl);
  }
  template <class P, class V>
  void OnCollapsed(const P& p, const V& v) const {
    visitor.OnCollapsed(p, v);
  }
  template <class P>
  void OnNonCollapsable(const P& p) const {
    visitor.OnNonCollapsable(p);
  }
  template <class TM, class H>
  void OnFlipped(const TM& tm, const H& h) const {
    visitor.OnFlipped(tm, h);
  }
};

/// Visitor that copies the mesh each time the face count reaches the next level's target, and
/// forwards every call to the caller's visitor.
template <class Visitor>
struct Snapshot_visitor : Forwarding_visitor<Visitor> {
  struct State {
    const std::vector<std::size_t>* targets;  // the collapsed levels' targets, decreasing
    std::size_t next = 0;
    std::vector<Surface_mesh> snapshots;
  };
  State* state;
  Snapshot_visitor(State* s, const Visitor& v) : Forwarding_visitor<Visitor>{v}, state(s) {}

  template <class P, class V>
  void OnCollapsed(const P& p, const V& v) const {
    this->visitor.OnCollapsed(p, v);
    const auto& mesh = p.surface_mesh();
    // (the last target is the run's stop: the mesh left at the end is that level)
    while (state->next + 1 < state->targets->size() && mesh.number_of_faces() <= (*state->targets)[state->next]) {
      state->snapshots.push_back(compact_copy(mesh));
      ++state->next;
    }
  }
};

/// Visitor of the error-bound mode: each time the face count falls to the next threshold it copies
/// the mesh, measures its error against the input, keeps it, and asks the run to stop once an error
/// exceeds the largest bound.
template <class Visitor>
struct Error_snapshot_visitor : Forwarding_visitor<Visitor> {
  struct Candidate {
    Surface_mesh mesh;
    double hausdorff, rms;
  };
  struct State {
    const Surface_mesh* input;
    Metrics::Error_options error_options;
    double step, largest_bound;
    double next;  // face count of the next snapshot
    bool stop = false;
    std::vector<Candidate> candidates;
  };
  State* state;
  Error_snapshot_visitor(State* s, const Visitor& v) : Forwarding_visitor<Visitor>{v}, state(s) {}

  template <class P, class V>
  void OnCollapsed(const P& p, const V& v) const {
    this->visitor.OnCollapsed(p, v);
    const auto& mesh = p.surface_mesh();
    if (state->stop || double(mesh.number_of_faces()) > state->next) return;
    Surface_mesh copy = compact_copy(mesh);
    const Metrics::Approximation_error e = Metrics::approximation_error(*state->input, copy, state->error_options);
    if (e.hausdorff > state->largest_bound) {
      state->stop = true;
      return;
    }
    state->candidates.push_back({std::move(copy), e.hausdorff, e.rms});
    state->next = double(mesh.number_of_faces()) * state->step;
  }
};

/// Stops at a face count or when a flag is raised (the error-bound mode's run).
template <class Mesh>
struct Face_count_or_flag_stop {
  Face_count_stop_predicate<Mesh> count;
  const bool* flag;
  template <class FT, class Profile>
  bool operator()(const FT& c, const Profile& p, std::size_t initial, std::size_t current) const {
    return *flag || count(c, p, initial, current);
  }
};

/// Gives `fine` texture coordinates in the atlas of `coarse` (see the file comment) and the
/// coarse mesh's materials. When given, `chart_of_face` receives the coarse chart each fine face
/// was put in and `depth_of_face` the distance from its centroid to the coarse surface.
inline void map_through_atlas(const Textured_mesh& coarse, Textured_mesh& fine, double max_extrapolation,
                              std::vector<int>* chart_of_face = nullptr, std::vector<double>* depth_of_face = nullptr) {
  using SC = Facing_closest_point::SC;
  using Face = Surface_mesh::Face_index;
  using Vertex = Surface_mesh::Vertex_index;
  const Surface_mesh& cm = coarse.mesh();
  Surface_mesh& fm = fine.mesh();
  // the coarse faces: triangles, normals, UVs, charts
  auto chart_map = get(CGAL::dynamic_face_property_t<int>(), cm);
  compute_chart_ids(cm, coarse.uv_map(), chart_map);
  const std::size_t nc = cm.number_of_faces();
  Facing_closest_point::Triangles tris;
  std::vector<Vector_3> normals;
  std::vector<std::array<Point_2, 3>> uvs;
  std::vector<int> chart;
  tris.reserve(nc);
  int charts = 0;
  for (Face f : cm.faces()) {
    std::array<Point_3, 3> p;
    std::array<Point_2, 3> t;
    int k = 0;
    for (auto h : CGAL::halfedges_around_face(cm.halfedge(f), cm)) {
      p[std::size_t(k)] = cm.point(cm.target(h));
      t[std::size_t(k)] = coarse.uv(h);
      ++k;
    }
    tris.emplace_back(SC::Point_3(p[0].x(), p[0].y(), p[0].z()), SC::Point_3(p[1].x(), p[1].y(), p[1].z()),
                      SC::Point_3(p[2].x(), p[2].y(), p[2].z()));
    normals.push_back(internal::unit_or_zero(CGAL::cross_product(p[1] - p[0], p[2] - p[0])));
    uvs.push_back(t);
    chart.push_back(get(chart_map, f));
    charts = std::max(charts, get(chart_map, f) + 1);
  }
  std::vector<std::vector<std::size_t>> chart_faces(static_cast<std::size_t>(charts));
  for (std::size_t i = 0; i < nc; ++i) chart_faces[std::size_t(chart[i])].push_back(i);
  const Facing_closest_point finder(tris, normals, std::vector<char>(nc, 1));

  // the fine mesh's face normals, vertex normals, and each face's chart
  const std::size_t nf = fm.number_of_faces(), nv = fm.number_of_vertices();
  std::vector<Vector_3> vertex_normal(nv, CGAL::NULL_VECTOR);
  std::vector<Vector_3> face_normal(nf);
  std::vector<Point_3> centroid(nf);
  for (Face f : fm.faces()) {
    const auto h = fm.halfedge(f);
    const Point_3 &a = fm.point(fm.source(h)), &b = fm.point(fm.target(h)), &c = fm.point(fm.target(fm.next(h)));
    const Vector_3 n = CGAL::cross_product(b - a, c - a);
    face_normal[std::size_t(f)] = internal::unit_or_zero(n);
    centroid[std::size_t(f)] = CGAL::centroid(a, b, c);
    for (auto g : CGAL::halfedges_around_face(h, fm)) vertex_normal[std::size_t(fm.target(g))] += n;
  }
  for (auto& n : vertex_normal) n = internal::unit_or_zero(n);
  auto nearest = [&](const Point_3& p, const Vector_3& n) {
    const double q[3] = {p.x(), p.y(), p.z()};
    Facing_closest_point::Hit hit;
    finder.search(q, n, hit);
    if (!hit.found()) finder.search(q, CGAL::NULL_VECTOR, hit);
    return hit;
  };
  std::vector<int> face_chart(nf, 0);
  std::vector<double> face_depth(nf, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const Facing_closest_point::Hit hit = nearest(centroid[i], face_normal[i]);
      face_chart[i] = chart[hit.face];
      face_depth[i] = std::sqrt(hit.squared_distance);
    }
  });

  // one texture coordinate per (vertex, chart) used
  struct Key_hash {
    std::size_t operator()(const std::pair<std::uint32_t, int>& k) const {
      return std::size_t(k.first) * 0x9E3779B97F4A7C15ull ^ std::size_t(k.second);
    }
  };
  std::unordered_map<std::pair<std::uint32_t, int>, std::size_t, Key_hash> slot;
  std::vector<std::pair<std::uint32_t, int>> keys;
  for (Face f : fm.faces())
    for (auto h : CGAL::halfedges_around_face(fm.halfedge(f), fm)) {
      const std::pair<std::uint32_t, int> k{std::uint32_t(fm.target(h)), face_chart[std::size_t(f)]};
      if (slot.emplace(k, keys.size()).second) keys.push_back(k);
    }
  std::vector<Point_2> uv_of(keys.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, keys.size()), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const Vertex v(keys[i].first);
      const int k = keys[i].second;
      const Point_3& p = fm.point(v);
      const Vector_3& n = vertex_normal[std::size_t(v)];
      Facing_closest_point::Hit hit = nearest(p, n);
      if (chart[hit.face] != k) {  // the nearest point of the face's chart, facing first
        const double q[3] = {p.x(), p.y(), p.z()};
        Facing_closest_point::Hit in_chart;
        for (std::size_t f : chart_faces[std::size_t(k)]) finder.test(f, q, n, in_chart);
        if (!in_chart.found())
          for (std::size_t f : chart_faces[std::size_t(k)]) finder.test(f, q, CGAL::NULL_VECTOR, in_chart);
        hit = in_chart;
      }
      // barycentric coordinates of p's projection on the face's plane, clamped, renormalised
      const auto& t = tris[hit.face];
      const Vector_3 e1(t[1].x() - t[0].x(), t[1].y() - t[0].y(), t[1].z() - t[0].z());
      const Vector_3 e2(t[2].x() - t[0].x(), t[2].y() - t[0].y(), t[2].z() - t[0].z());
      const Vector_3 d(p.x() - t[0].x(), p.y() - t[0].y(), p.z() - t[0].z());
      const double a11 = e1 * e1, a12 = e1 * e2, a22 = e2 * e2, b1 = d * e1, b2 = d * e2;
      const double det = a11 * a22 - a12 * a12;
      std::array<double, 3> w{{1.0 / 3, 1.0 / 3, 1.0 / 3}};
      if (det > 0 && std::isfinite(det)) {
        const double s = (a22 * b1 - a12 * b2) / det, u = (a11 * b2 - a12 * b1) / det;
        w = {{1 - s - u, s, u}};
        double sum = 0;
        for (double& x : w) {
          x = std::max(x, -max_extrapolation);
          sum += x;
        }
        for (double& x : w) x /= sum;
      }
      const auto& c = uvs[hit.face];
      uv_of[i] = Point_2(w[0] * c[0].x() + w[1] * c[1].x() + w[2] * c[2].x(),
                         w[0] * c[0].y() + w[1] * c[1].y() + w[2] * c[2].y());
    }
  });
  for (Face f : fm.faces())
    for (auto h : CGAL::halfedges_around_face(fm.halfedge(f), fm))
      fine.set_uv(h, uv_of[slot.at({std::uint32_t(fm.target(h)), face_chart[std::size_t(f)]})]);
  fine.materials() = coarse.materials();
  for (Face f : fm.faces()) fine.material_map()[f] = 0;
  fine.set_has_uvs(true);
  if (chart_of_face) *chart_of_face = std::move(face_chart);
  if (depth_of_face) *depth_of_face = std::move(face_depth);
}

/// Paints the shared atlas `image` (made for `coarse`) from the original itself: every original
/// face, at the texture coordinates map_through_atlas() gave it (`original_mapped`, the original's
/// faces in order), is rasterised into the atlas and each texel it covers takes the original's
/// colour at that point of the face (Atlas_source::colour_at). A texel keeps the colour of the
/// original face nearest to the coarse surface among those covering it, and is written only by
/// faces of the chart it belongs to (texels outside every chart, the gutters, by any). Texels no
/// original face covers keep the coarse bake. So the finest level reads the original's colours
/// almost exactly, and a coarser level, whose points map to the same atlas points as the original
/// points they stand for, reads those colours too. Rows are painted in parallel bands. Returns
/// the fraction of the texels the original's faces cover that went to another face (hidden:
/// parts of the original that fold onto the same place of the coarse surface).
inline double paint_atlas_from_original(const Atlas_source& source, const Textured_mesh& coarse,
                                        const Textured_mesh& original_mapped, const std::vector<int>& chart_of_face,
                                        const std::vector<double>& depth_of_face, Image& image) {
  using Face = Surface_mesh::Face_index;
  const int W = image.width(), H = image.height(), C = image.channels();
  if (W <= 0 || H <= 0 || C != source.colour_channels()) return 0.0;
  // the chart of every texel of the coarse atlas (-1: none)
  const Surface_mesh& cm = coarse.mesh();
  auto chart_map = get(CGAL::dynamic_face_property_t<int>(), cm);
  compute_chart_ids(cm, coarse.uv_map(), chart_map);
  std::vector<int> owner(std::size_t(W) * std::size_t(H), -1);
  auto texel_triangle = [&](const Textured_mesh& tm, Face f) {
    std::array<UV2, 3> t;
    int k = 0;
    for (auto h : CGAL::halfedges_around_face(tm.mesh().halfedge(f), tm.mesh())) {
      const Point_2 p = tm.uv(h);
      t[std::size_t(k++)] = {{p.x() * W, p.y() * H}};
    }
    return t;
  };
  for (Face f : cm.faces()) {
    const int c = get(chart_map, f);
    rasterize_triangle(texel_triangle(coarse, f), W, H,
                       [&](int x, int y) { owner[std::size_t(y) * std::size_t(W) + std::size_t(x)] = c; });
  }
  const Surface_mesh& om = original_mapped.mesh();
  const std::size_t nf = om.number_of_faces();
  std::vector<std::array<UV2, 3>> tri(nf);
  std::vector<std::pair<int, int>> rows(nf);
  for (Face f : om.faces()) {
    const std::size_t i = std::size_t(f);
    tri[i] = texel_triangle(original_mapped, f);
    double lo = tri[i][0][1], hi = lo;
    for (const auto& p : tri[i]) {
      lo = (std::min)(lo, p[1]);
      hi = (std::max)(hi, p[1]);
    }
    rows[i] = {int(std::floor(lo)) - 1, int(std::ceil(hi)) + 1};
  }
  const int band = 16;
  std::atomic<std::size_t> covered{0}, won{0};
  tbb::parallel_for(0, (H + band - 1) / band, [&](int b) {
    const int y0 = b * band, y1 = (std::min)(H, y0 + band);
    const std::size_t texels = std::size_t(y1 - y0) * std::size_t(W);
    std::vector<double> best(texels, std::numeric_limits<double>::infinity());
    std::vector<std::size_t> winner(texels, std::size_t(-1));
    std::size_t band_covered = 0;
    for (std::size_t i = 0; i < nf; ++i) {
      if (rows[i].second < y0 || rows[i].first >= y1) continue;
      const int k = chart_of_face[i];
      const double depth = depth_of_face[i];
      rasterize_triangle(tri[i], W, H, y0, y1, [&](int x, int y) {
        const std::size_t at = std::size_t(y) * std::size_t(W) + std::size_t(x);
        if (owner[at] != -1 && owner[at] != k) return;
        ++band_covered;
        const std::size_t j = std::size_t(y - y0) * std::size_t(W) + std::size_t(x);
        if (depth >= best[j]) return;
        best[j] = depth;
        winner[j] = i;
      });
    }
    std::size_t band_won = 0;
    float c[4];
    for (std::size_t j = 0; j < texels; ++j) {
      const std::size_t i = winner[j];
      if (i == std::size_t(-1)) continue;
      ++band_won;
      const auto& t = tri[i];
      const int x = int(j % std::size_t(W)), y = y0 + int(j / std::size_t(W));
      const double det = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]);
      const double cx = x + 0.5, cy = y + 0.5;
      const double b1 = ((cx - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (cy - t[0][1])) / det;
      const double b2 = ((t[1][0] - t[0][0]) * (cy - t[0][1]) - (cx - t[0][0]) * (t[1][1] - t[0][1])) / det;
      source.colour_at(i, 1 - b1 - b2, b1, b2, c);
      for (int ch = 0; ch < C; ++ch) image.set_value(x, H - 1 - y, ch, c[ch]);  // image rows run down
    }
    covered += band_covered;
    won += band_won;
  });
  return covered > 0 ? 1.0 - double(won) / double(covered) : 0.0;
}

inline double seconds_since_lod(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace internal

/// Builds the level-of-detail chain of `input` (see the file comment). `input` is not changed.
/// `visitor` receives the collapse engine's calls (progress). Throws Invalid_input for targets
/// that are not strictly decreasing or are 0, error bounds that are not strictly increasing or
/// are negative, or a non-triangle mesh.
template <class Visitor = Edge_collapse_visitor_base>
Level_of_detail_result simplify_to_levels(const Textured_mesh& input, const Level_of_detail_options& options,
                                          Visitor visitor = Visitor()) {
  using Clock = std::chrono::steady_clock;
  const auto t_start = Clock::now();
  const bool by_error = !options.max_errors.empty();
  std::vector<std::size_t> targets = options.target_faces;
  if (by_error) {
    const auto& b = options.max_errors;
    for (std::size_t i = 0; i < b.size(); ++i) {
      if (!(b[i] >= 0) || !std::isfinite(b[i]))
        throw Invalid_input("simplify_to_levels: an error bound is negative or not finite");
      if (i > 0 && b[i] <= b[i - 1])
        throw Invalid_input("simplify_to_levels: the error bounds must be strictly increasing");
    }
    if (!(options.error_step > 0 && options.error_step < 1))
      throw Invalid_input("simplify_to_levels: error_step must be in (0, 1)");
  } else {
    if (targets.empty()) throw Invalid_input("simplify_to_levels: no level asked for");
    for (std::size_t i = 0; i < targets.size(); ++i) {
      if (targets[i] == 0) throw Invalid_input("simplify_to_levels: a level's target is 0 faces");
      if (i > 0 && targets[i] >= targets[i - 1])
        throw Invalid_input("simplify_to_levels: the levels' targets must be strictly decreasing");
    }
  }
  if (!CGAL::is_triangle_mesh(input.mesh())) throw Invalid_input("simplify_to_levels: not a triangle mesh");
  if (input.mesh().has_garbage()) throw Invalid_input("simplify_to_levels: the input must be garbage-free");
  bool has_image = false;
  for (const Material& m : input.materials()) has_image |= !m.diffuse_image.empty() || !m.normal_image.empty();
  const bool textured = input.has_uvs() && has_image;

  Level_of_detail_result res;
  const std::size_t faces_in = input.mesh().number_of_faces();
  Metrics::Error_options eo;
  eo.samples = options.error_samples > 0 ? options.error_samples : 2 * faces_in;
  eo.vertex_field = false;

  // error-bound mode: one run snapshots and measures, each bound takes the smallest snapshot it allows
  std::vector<Surface_mesh> meshes;
  std::vector<std::pair<double, double>> measured;  // (hausdorff, rms) of the collapsed levels
  const auto t_collapse = Clock::now();
  if (by_error) {
    Surface_mesh work = input.mesh();
    auto uv = work.property_map<Surface_mesh::Halfedge_index, Point_2>("h:uv");
    if (uv.second) work.remove_property_map(uv.first);
    using EV = internal::Error_snapshot_visitor<Visitor>;
    typename EV::State state{&input.mesh(), eo, options.error_step, options.max_errors.back(),
                             double(faces_in) * options.error_step};
    {
      using Mesh = Surface_mesh;
      using VPM = typename Mesh::template Property_map<typename Mesh::Vertex_index, Point_3>;
      Area_weighted_quadric_policies<Mesh> policy(work, options.quadric);
      std::optional<Surface_memory<Mesh, VPM>> memory;
      if (options.surface_memory) memory.emplace(work, work.points(), Surface_memory_options());
      Surface_memory<Mesh, VPM>* m = memory ? &*memory : nullptr;
      internal::Face_count_or_flag_stop<Mesh> stop{Face_count_stop_predicate<Mesh>(work, 1), &state.stop};
      internal::collapse_with_placement(policy, false, [&](const auto& placement) {
        edge_collapse(work, stop,
                      CMGeom::parameters::surface_memory(
                          m, CMGeom::parameters::edge_flips(
                                 options.flips, CGAL::parameters::get_cost(policy).get_placement(placement).visitor(
                                                    EV{&state, visitor}))));
      });
    }
    targets.clear();
    for (double bound : options.max_errors) {
      std::size_t best = std::size_t(-1);
      for (std::size_t c = 0; c < state.candidates.size(); ++c)
        if (state.candidates[c].hausdorff <= bound) best = c;  // the later, the fewer faces
      if (best == std::size_t(-1)) {
        targets.push_back(faces_in);
      } else {
        targets.push_back(state.candidates[best].mesh.number_of_faces());
        meshes.push_back(state.candidates[best].mesh);
        measured.emplace_back(state.candidates[best].hausdorff, state.candidates[best].rms);
      }
    }
  }
  // the levels that are the input itself, then the collapsed ones
  std::vector<std::size_t> collapsed;
  for (std::size_t t : targets)
    if (t < faces_in) collapsed.push_back(t);
  const std::size_t kept = targets.size() - collapsed.size();

  // the atlas source, taken and prepared beside the collapses
  Atlas_options ao = options.atlas;
  if (options.shared_texture) ao.gutter_texels = std::max(ao.gutter_texels, 8);
  std::optional<Atlas_source> source;
  tbb::task_group prepare;
  if (textured && !collapsed.empty()) {
    const auto t0 = Clock::now();
    source.emplace(input, ao);
    res.seconds_texture += internal::seconds_since_lod(t0);
    prepare.run([&source] { source->prepare(); });
  }

  try {
    if (!collapsed.empty() && !by_error) {
      // a copy with the input's element order (the collapse order depends on it: the chain's levels
      // are then those of simplify_mesh() run on the input to each level's target)
      Surface_mesh work = input.mesh();
      auto uv = work.property_map<Surface_mesh::Halfedge_index, Point_2>("h:uv");
      if (uv.second) work.remove_property_map(uv.first);
      typename internal::Snapshot_visitor<Visitor>::State state{&collapsed, 0, {}};
      Mesh_simplification_options so;
      so.quadric = options.quadric;
      so.surface_memory = options.surface_memory;
      so.flips = options.flips;
      so.parts_min_faces = 0;  // snapshots need the whole mesh at every collapse
      simplify_mesh(work, collapsed.back(), so, internal::Snapshot_visitor<Visitor>{&state, visitor});
      meshes = std::move(state.snapshots);
      // levels the run never reached (no collapse left) are the mesh it ended with
      while (meshes.size() < collapsed.size()) meshes.push_back(internal::compact_copy(work));
    }
  } catch (...) {
    prepare.wait();
    throw;
  }
  res.seconds_collapse = internal::seconds_since_lod(t_collapse);

  res.levels.resize(targets.size());
  for (std::size_t i = 0; i < targets.size(); ++i) {
    Level_of_detail& l = res.levels[i];
    l.target_faces = targets[i];
    if (i < kept) {
      l.mesh = input;
      l.is_input = true;
    } else {
      l.mesh = Textured_mesh(std::move(meshes[i - kept]));
    }
  }

  const auto t_texture = Clock::now();
  prepare.wait();
  if (textured && !collapsed.empty()) {
    if (options.shared_texture) {
      Level_of_detail& coarsest = res.levels.back();
      coarsest.atlas = rebuild_atlas(*source, coarsest.mesh, ao);
      // the original mapped into the atlas paints it; then every finer level is mapped into it
      std::optional<Textured_mesh> original_copy;
      if (kept == 0) original_copy.emplace(input);
      Textured_mesh& original = kept > 0 ? res.levels.front().mesh : *original_copy;
      std::vector<int> chart_of_face;
      std::vector<double> depth_of_face;
      internal::map_through_atlas(coarsest.mesh, original, options.max_extrapolation, &chart_of_face, &depth_of_face);
      res.shared_texture_hidden =
          internal::paint_atlas_from_original(*source, coarsest.mesh, original, chart_of_face, depth_of_face,
                                              coarsest.mesh.materials().front().diffuse_image);
      original.materials() = coarsest.mesh.materials();
      for (std::size_t i = 1; i < kept; ++i) res.levels[i].mesh = original;
      tbb::parallel_for(kept, res.levels.size() - 1, [&](std::size_t i) {
        internal::map_through_atlas(coarsest.mesh, res.levels[i].mesh, options.max_extrapolation);
      });
      for (std::size_t i = 0; i + 1 < res.levels.size(); ++i) res.levels[i].atlas = coarsest.atlas;
    } else {
      for (std::size_t i = kept; i < res.levels.size(); ++i)
        res.levels[i].atlas = rebuild_atlas(*source, res.levels[i].mesh, ao);
    }
  } else if (!textured) {
    for (auto& l : res.levels)
      if (!l.is_input) {
        l.mesh.set_has_uvs(false);
        l.mesh.materials() = input.materials();
      }
  }
  res.seconds_texture += internal::seconds_since_lod(t_texture);

  if (by_error) {  // measured already, in the run
    for (std::size_t i = 0; i < res.levels.size(); ++i) {
      auto& l = res.levels[i];
      l.hausdorff = l.is_input ? 0 : measured[i - kept].first;
      l.rms = l.is_input ? 0 : measured[i - kept].second;
    }
  } else if (options.measure_error) {
    const auto t_error = Clock::now();
    for (auto& l : res.levels) {
      if (l.is_input) {
        l.hausdorff = l.rms = 0;
        continue;
      }
      const Metrics::Approximation_error e = Metrics::approximation_error(input.mesh(), l.mesh.mesh(), eo);
      l.hausdorff = e.hausdorff;
      l.rms = e.rms;
    }
    res.seconds_error = internal::seconds_since_lod(t_error);
  }
  res.seconds = internal::seconds_since_lod(t_start);
  return res;
}

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_LEVEL_OF_DETAIL_H

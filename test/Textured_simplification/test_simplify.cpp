// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// simplify_mesh(mesh, options), the one call of geometric simplification: a ratio target is the
// face count target_faces_for_ratio() gives (the same mesh, bit for bit, as that count), on both
// engines and with parts; a cost bound stops where every collapse left costs more than it
// (costs recomputed here from the input's planes); invalid options throw before the mesh changes.
#include <CMGeom/Textured_simplification.h>

#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/helpers.h>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "cmgeom_test_surface_meshes.h"

#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace TS = CMGeom::Textured_simplification;
using Mesh = CMGeom::Surface_mesh;
using Point_3 = CMGeom::Point_3;

// A closed torus with a ripple: n x m quads, each split in two.
Mesh ripple_torus(int n, int m) { return cmgeom_test::rippled_torus(n, m, 0.3, 0.03, 5, 3); }

// A wavy square sheet on an n x n grid (one border loop).
Mesh wavy_sheet(int n) {
  return cmgeom_test::height_field(n, [](double x, double y) { return 0.04 * std::sin(8 * x) * std::sin(6 * y); });
}

// Every bit of the mesh that a writer would see: points (exact) and faces, in index order.
std::string bytes_of(const Mesh& m) {
  std::ostringstream s;
  s << std::hexfloat;
  for (auto v : m.vertices()) s << m.point(v) << '\n';
  for (auto f : m.faces()) {
    for (auto w : CGAL::vertices_around_face(m.halfedge(f), m)) s << std::size_t(w) << ' ';
    s << '\n';
  }
  return s.str();
}

}  // namespace

TEST(SimplifyOneCall, RatioRuleRoundsHalvesUp) {
  EXPECT_EQ(TS::target_faces_for_ratio(10, 0.25), 3u);  // 2.5
  EXPECT_EQ(TS::target_faces_for_ratio(6, 0.25), 2u);   // 1.5
  EXPECT_EQ(TS::target_faces_for_ratio(2, 0.25), 1u);   // 0.5
  EXPECT_EQ(TS::target_faces_for_ratio(3, 0.125), 0u);  // 0.375
  EXPECT_EQ(TS::target_faces_for_ratio(9, 0.125), 1u);  // 1.125
  EXPECT_EQ(TS::target_faces_for_ratio(7, 1.0), 7u);
  EXPECT_EQ(TS::target_faces_for_ratio(2400, 0.1), 240u);
  for (double bad : {0.0, -0.25, 1.0000001, std::numeric_limits<double>::quiet_NaN()})
    EXPECT_THROW(TS::target_faces_for_ratio(10, bad), std::invalid_argument) << bad;
}

// A ratio is its count: the same result and the same mesh, on both engines, with and without
// the memoryful cost, with parts, and with the ratio stop predicate under the engine directly.
TEST(SimplifyOneCall, RatioGivesTheMeshOfItsCount) {
  struct Case {
    Mesh mesh;
    double ratio;
    TS::Simplification_engine engine;
    bool memory;
    bool parts;
  };
  std::vector<Case> cases = {
      {ripple_torus(40, 30), 0.1, TS::Simplification_engine::cmgeom, true, false},
      {ripple_torus(40, 30), 0.0625, TS::Simplification_engine::cgal, false, false},
      {wavy_sheet(30), 0.25, TS::Simplification_engine::cmgeom, false, false},  // 450: an exact count
      {wavy_sheet(31), 0.3, TS::Simplification_engine::cgal, false, false},
      {wavy_sheet(25), 0.01, TS::Simplification_engine::cmgeom, true, false},  // 12.5 -> 13
      {ripple_torus(80, 60), 0.05, TS::Simplification_engine::cmgeom, true, true},
  };
  for (const Case& c : cases) {
    const std::size_t faces = c.mesh.number_of_faces();
    const std::size_t count = TS::target_faces_for_ratio(faces, c.ratio);
    EXPECT_EQ(count, std::size_t(std::floor(c.ratio * double(faces) + 0.5)));
    TS::Mesh_simplification_options o;
    o.engine = c.engine;
    o.surface_memory = c.memory;
    if (c.parts) {
      o.parts_min_faces = 4000;
      o.part_faces = 1500;
    }
    Mesh by_ratio = c.mesh, by_count = c.mesh, by_old_call = c.mesh;
    TS::Mesh_simplification_options ro = o, co = o;
    ro.target_ratio = c.ratio;
    co.target_faces = count;
    const TS::Mesh_simplification_result r = TS::simplify_mesh(by_ratio, ro);
    const TS::Mesh_simplification_result k = TS::simplify_mesh(by_count, co);
    const TS::Mesh_simplification_result old = TS::simplify_mesh(by_old_call, count, o);
    SCOPED_TRACE("faces " + std::to_string(faces) + ", ratio " + std::to_string(c.ratio));
    EXPECT_EQ(r.faces_in, faces);
    EXPECT_EQ(r.target_faces, count);
    EXPECT_EQ(k.target_faces, count);
    EXPECT_EQ(r.faces_out, k.faces_out);
    EXPECT_EQ(r.faces_out, old.faces_out);
    EXPECT_EQ(r.parts, k.parts);
    EXPECT_EQ(r.parts > 0, c.parts);
    EXPECT_EQ(r.stopped_by, TS::Stop_reason::target);
    // a closed mesh loses two faces a collapse: an odd count is reached one below
    EXPECT_LE(r.faces_out, count);
    EXPECT_GE(r.faces_out + 1, count);
    EXPECT_EQ(bytes_of(by_ratio), bytes_of(by_count));
    EXPECT_EQ(bytes_of(by_ratio), bytes_of(by_old_call));
  }
  // the stop predicate of a hand-made run follows the same rule
  const Mesh sheet = wavy_sheet(25);  // 1250 faces
  for (double ratio : {0.01, 0.3}) {
    Mesh a = sheet, b = sheet;
    TS::edge_collapse(a, TS::Face_count_ratio_stop_predicate<Mesh>(a, ratio));
    TS::edge_collapse(b, TS::Face_count_stop_predicate<Mesh>(b, TS::target_faces_for_ratio(1250, ratio)));
    a.collect_garbage();
    b.collect_garbage();
    EXPECT_EQ(a.number_of_faces(), b.number_of_faces());
    EXPECT_EQ(bytes_of(a), bytes_of(b));
  }
}

namespace {

// Remembers, for every vertex (by its index during the run), the input vertices merged into it,
// and checks that every collapse made cost at most the bound.
struct Merge_recorder : TS::Edge_collapse_visitor_base {
  struct State {
    std::vector<std::vector<std::size_t>> merged;
    double last_cost = 0, bound = 0;
    std::size_t collapses = 0, over_bound = 0;
  };
  State* s;
  template <class Profile, class Cost>
  void OnSelected(const Profile&, const Cost& c, std::size_t, std::size_t) const {
    s->last_cost = c ? CGAL::to_double(*c) : std::numeric_limits<double>::infinity();
  }
  template <class Profile, class V>
  void OnCollapsed(const Profile& p, const V& kept) const {
    ++s->collapses;
    if (s->last_cost > s->bound) ++s->over_bound;
    const std::size_t a = std::size_t(p.v0()), b = std::size_t(p.v1()), k = std::size_t(kept);
    std::vector<std::size_t> u = s->merged[a];
    u.insert(u.end(), s->merged[b].begin(), s->merged[b].end());
    s->merged[a].clear();
    s->merged[b].clear();
    s->merged[k] = std::move(u);
  }
};

using Q4 = Eigen::Matrix4d;

// The cost of collapsing an edge whose endpoints carry the plane quadric q, recomputed here: the
// quadric's minimum where it is defined and no further than the edge's length from its midpoint,
// else its minimum on the edge. Returns the cost and the point.
std::pair<double, Eigen::Vector3d> edge_cost(const Q4& q, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1) {
  auto value = [&](const Eigen::Vector3d& x) {
    const Eigen::Vector4d h(x[0], x[1], x[2], 1.0);
    return double(h.dot(q * h));
  };
  const Eigen::Matrix3d A = q.topLeftCorner<3, 3>();
  const Eigen::Vector3d b = q.topRightCorner<3, 1>();
  const Eigen::Vector3d d = p1 - p0, mid = 0.5 * (p0 + p1);
  Eigen::FullPivLU<Eigen::Matrix3d> lu(A);
  lu.setThreshold(1e-12);
  if (lu.isInvertible()) {
    const Eigen::Vector3d x = lu.solve(-b);
    if ((x - mid).norm() <= 2.0 * d.norm()) return {std::max(0.0, value(x)), x};
  }
  // Q(p0 + t d) is a quadratic in t: its least value on [0, 1]
  const double a2 = d.dot(A * d), a1 = 2.0 * (d.dot(A * p0) + d.dot(b));
  double best_t = value(p0) <= value(p1) ? 0.0 : 1.0;
  if (a2 > 0) {
    const double t = std::clamp(-a1 / (2.0 * a2), 0.0, 1.0);
    if (value(p0 + t * d) < value(p0 + best_t * d)) best_t = t;
  }
  const Eigen::Vector3d x = p0 + best_t * d;
  return {std::max(0.0, value(x)), x};
}

Eigen::Vector3d vec(const Point_3& p) { return Eigen::Vector3d(p.x(), p.y(), p.z()); }

// True when moving both ends of h to x turns some surviving triangle of their stars over (or
// flattens it): the collapse is not allowed then.
bool flips(const Mesh& m, Mesh::Halfedge_index h, const Eigen::Vector3d& x) {
  const auto v0 = m.source(h), v1 = m.target(h);
  for (auto v : {v0, v1})
    for (auto f : CGAL::faces_around_target(m.halfedge(v), m)) {
      if (f == Mesh::null_face()) continue;
      std::array<Eigen::Vector3d, 3> before, after;
      int i = 0, ends = 0;
      for (auto w : CGAL::vertices_around_face(m.halfedge(f), m)) {
        before[std::size_t(i)] = vec(m.point(w));
        const bool end = w == v0 || w == v1;
        ends += end;
        after[std::size_t(i++)] = end ? x : vec(m.point(w));
      }
      if (ends == 2) continue;  // removed by the collapse
      const Eigen::Vector3d n0 = (before[1] - before[0]).cross(before[2] - before[0]);
      const Eigen::Vector3d n1 = (after[1] - after[0]).cross(after[2] - after[0]);
      if (!(n0.dot(n1) > 0)) return true;
    }
  return false;
}

}  // namespace

// A cost bound stops the collapses where every collapse left costs more than the bound: each edge
// of the result is either dearer (its cost recomputed from the input's face planes and the input
// vertices merged into its ends) or not collapsible (link condition, fold-over); and no collapse
// made cost more than the bound.
TEST(SimplifyOneCall, MaxCostLeavesOnlyDearerCollapses) {
  const Mesh input = ripple_torus(48, 32);
  // the input's plane quadrics: area x squared distance to each face's plane
  std::vector<Q4> vertex_q(input.num_vertices(), Q4::Zero());
  for (auto f : input.faces()) {
    std::array<Eigen::Vector3d, 3> p;
    std::array<std::size_t, 3> id;
    int i = 0;
    for (auto w : CGAL::vertices_around_face(input.halfedge(f), input)) {
      p[std::size_t(i)] = vec(input.point(w));
      id[std::size_t(i++)] = std::size_t(w);
    }
    const Eigen::Vector3d c = (p[1] - p[0]).cross(p[2] - p[0]);
    const Eigen::Vector3d n = c.normalized();
    const Eigen::Vector4d plane(n[0], n[1], n[2], -n.dot(p[0]));
    const Q4 q = 0.5 * c.norm() * plane * plane.transpose();
    for (std::size_t k : id) vertex_q[k] += q;
  }
  for (const auto engine : {TS::Simplification_engine::cmgeom, TS::Simplification_engine::cgal})
    for (double bound : {2e-6, 2e-5}) {
      SCOPED_TRACE(std::string(engine == TS::Simplification_engine::cgal ? "cgal" : "cmgeom") + ", bound " +
                   std::to_string(bound * 1e6) + "e-6");
      Mesh m = input;
      auto id = m.add_property_map<Mesh::Vertex_index, std::size_t>("v:run_index", 0).first;
      for (auto v : m.vertices()) id[v] = std::size_t(v);
      Merge_recorder::State state;
      state.bound = bound;
      state.merged.resize(m.num_vertices());
      for (std::size_t i = 0; i < state.merged.size(); ++i) state.merged[i] = {i};
      TS::Mesh_simplification_options o;
      o.quadric.weighted = false;  // plain quadrics: a vertex's quadric is the sum of its input vertices'
      o.surface_memory = false;
      o.engine = engine;
      o.max_cost = bound;
      const TS::Mesh_simplification_result r = TS::simplify_mesh(m, o, Merge_recorder{{}, &state});
      EXPECT_EQ(r.stopped_by, TS::Stop_reason::max_cost);
      EXPECT_EQ(r.target_faces, 0u);
      EXPECT_EQ(r.faces_out, m.number_of_faces());
      EXPECT_LT(r.faces_out, r.faces_in / 2);  // the bound lets many collapses through
      EXPECT_GT(r.faces_out, 100u);            // and stops them well before the end
      EXPECT_EQ(state.collapses, (r.faces_in - r.faces_out) / 2);
      EXPECT_EQ(state.over_bound, 0u);
      std::size_t dearer = 0, blocked = 0, cheaper_and_free = 0;
      for (auto e : m.edges()) {
        const auto h = m.halfedge(e);
        const std::size_t a = id[m.source(h)], b = id[m.target(h)];
        Q4 q = Q4::Zero();
        for (std::size_t k : state.merged[a]) q += vertex_q[k];
        for (std::size_t k : state.merged[b]) q += vertex_q[k];
        const auto [cost, x] = edge_cost(q, vec(m.point(m.source(h))), vec(m.point(m.target(h))));
        if (cost > bound * (1 + 1e-9))
          ++dearer;
        else if (!CGAL::Euler::does_satisfy_link_condition(e, m) || flips(m, h, x))
          ++blocked;
        else
          ++cheaper_and_free;
      }
      EXPECT_EQ(cheaper_and_free, 0u) << dearer << " dearer, " << blocked << " blocked";
      EXPECT_GT(dearer, 0u);
    }
  // with a face target too, whichever comes first: the loose bound lets the count stop it
  Mesh m = input;
  TS::Mesh_simplification_options o;
  o.surface_memory = false;
  o.max_cost = 1.0;
  o.target_faces = 500;
  EXPECT_EQ(TS::simplify_mesh(m, o).stopped_by, TS::Stop_reason::target);
  EXPECT_EQ(m.number_of_faces(), 500u);
  // and a bound of 0 on a mesh with no free collapse leaves it as it is
  Mesh t = input;
  o.target_faces.reset();
  o.max_cost = 0.0;
  const TS::Mesh_simplification_result r0 = TS::simplify_mesh(t, o);
  EXPECT_EQ(r0.stopped_by, TS::Stop_reason::max_cost);
  EXPECT_EQ(r0.faces_out, input.number_of_faces());
}

TEST(SimplifyOneCall, StopsWhenNoCollapseIsLeft) {
  Mesh t;
  const auto a = t.add_vertex(Point_3(0, 0, 0)), b = t.add_vertex(Point_3(1, 0, 0)), c = t.add_vertex(Point_3(0, 1, 0)),
             d = t.add_vertex(Point_3(0, 0, 1));
  t.add_face(a, c, b);
  t.add_face(a, b, d);
  t.add_face(b, c, d);
  t.add_face(c, a, d);
  TS::Mesh_simplification_options o;
  o.target_faces = 1;
  const TS::Mesh_simplification_result r = TS::simplify_mesh(t, o);
  EXPECT_EQ(r.stopped_by, TS::Stop_reason::no_collapse);
  EXPECT_EQ(r.faces_out, 4u);
  EXPECT_STREQ(TS::to_string(r.stopped_by), "no_collapse");
  // a target at or above the input's count: nothing to do, the target is met
  o.target_faces = 4;
  EXPECT_EQ(TS::simplify_mesh(t, o).stopped_by, TS::Stop_reason::target);
}

TEST(SimplifyOneCall, InvalidOptionsThrowAndLeaveTheMesh) {
  const Mesh input = wavy_sheet(10);
  auto expect_throw = [&](const TS::Mesh_simplification_options& o, const char* what) {
    Mesh m = input;
    EXPECT_THROW(TS::simplify_mesh(m, o), std::invalid_argument) << what;
    EXPECT_EQ(bytes_of(m), bytes_of(input)) << what;
  };
  TS::Mesh_simplification_options none;
  expect_throw(none, "no target");
  TS::Mesh_simplification_options both;
  both.target_faces = 10;
  both.target_ratio = 0.5;
  expect_throw(both, "count and ratio");
  for (double bad : {0.0, -1.0, 2.0, std::numeric_limits<double>::quiet_NaN()}) {
    TS::Mesh_simplification_options o;
    o.target_ratio = bad;
    expect_throw(o, "ratio out of (0, 1]");
  }
  for (double bad : {-1e-9, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    TS::Mesh_simplification_options o;
    o.max_cost = bad;
    expect_throw(o, "max_cost");
  }
  TS::Mesh_simplification_options cgal;
  cgal.target_faces = 10;
  cgal.engine = TS::Simplification_engine::cgal;
  expect_throw(cgal, "CGAL's engine with the memoryful cost (on by default)");
  cgal.surface_memory = false;
  cgal.flips = true;
  expect_throw(cgal, "CGAL's engine with flips");
  TS::Mesh_simplification_options factor;
  factor.target_faces = 10;
  factor.parts_stop_factor = 0.5;
  expect_throw(factor, "parts_stop_factor");
  factor.parts_stop_factor = 1.0;
  factor.parts_tail_per_cut_vertex = -1.0;
  expect_throw(factor, "parts_tail_per_cut_vertex");
  factor.parts_tail_per_cut_vertex = 3.0;
  factor.parts_whole_levels = 0;
  expect_throw(factor, "parts_whole_levels");
  Mesh m = input;
  EXPECT_THROW(TS::Face_count_ratio_stop_predicate<Mesh>(m, 0.0), std::invalid_argument);
  // a quad mesh is not simplified
  Mesh quad;
  std::vector<Mesh::Vertex_index> v;
  for (int i = 0; i < 4; ++i) v.push_back(quad.add_vertex(Point_3(i & 1, i >> 1, 0)));
  quad.add_face(v[0], v[1], v[3], v[2]);
  TS::Mesh_simplification_options o;
  o.target_ratio = 0.5;
  EXPECT_THROW(TS::simplify_mesh(quad, o), CMGeom::Invalid_input);
}

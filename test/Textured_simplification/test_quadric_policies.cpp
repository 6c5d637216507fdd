// Tests of the quadric policies of Textured_simplification (thesis §3.4): weights, options, the
// CGAL engine, the plain (Garland-Heckbert) policy.
#include "textured_simplification_test_util.h"

#include <algorithm>
#include <array>
#include <random>
#include <vector>

// ------------------------------------------------------------------------- policies

TEST(TexturedSimplificationPolicy, FlatGridHasClampedWeightsAndStaysPlanar) {
  Mesh m = make_flat_grid(20);
  Policy policy(m);
  policy.initialize(m, get(CGAL::vertex_point, m));
  // interior vertices are flat (weight 0, clamped); border vertices carry boundary quadrics,
  // whose planes are orthogonal to the normal, hence large weights
  for (vertex_descriptor v : m.vertices()) {
    if (m.is_border(v))
      EXPECT_GT(policy.weight(v), 0.5);
    else
      EXPECT_DOUBLE_EQ(policy.weight(v), policy.options().min_weight);
  }
  TS::Face_count_stop_predicate<Mesh> stop(m, 100);
  TS::edge_collapse(m, stop, CGAL::parameters::get_cost(policy).get_placement(policy));
  m.collect_garbage();
  EXPECT_EQ(m.number_of_faces(), 100u);
  for (vertex_descriptor v : m.vertices()) {
    EXPECT_NEAR(m.point(v).z(), 0.0, 1e-12);
    EXPECT_GE(m.point(v).x(), -1e-12);
    EXPECT_LE(m.point(v).x(), 1 + 1e-12);
  }
  // boundary quadrics keep the square: its area is unchanged
  EXPECT_NEAR(PMP::area(m), 1.0, 1e-9);
}

TEST(TexturedSimplificationPolicy, RejectsOutOfRangeOptions) {
  Mesh m = make_flat_grid(4);
  const double bad_floor[] = {0.0, -1e-3, 1.5, std::numeric_limits<double>::quiet_NaN(),
                              std::numeric_limits<double>::infinity()};
  for (double mw : bad_floor) {
    TS::Quadric_options o;
    o.min_weight = mw;
    EXPECT_THROW(Policy(m, o), std::invalid_argument) << "min_weight " << mw;
  }
  const double bad_boundary[] = {-1.0, std::numeric_limits<double>::quiet_NaN(),
                                 std::numeric_limits<double>::infinity()};
  for (double bw : bad_boundary) {
    TS::Quadric_options o;
    o.boundary_weight = bw;
    EXPECT_THROW(Policy(m, o), std::invalid_argument) << "boundary_weight " << bw;
  }
  // the ends of the valid ranges are accepted, and a floor of 1 makes every weight 1
  TS::Quadric_options o;
  o.min_weight = 1.0;
  o.boundary_weight = 0.0;
  Policy p(m, o);
  p.initialize(m, get(CGAL::vertex_point, m));
  for (vertex_descriptor v : m.vertices()) EXPECT_EQ(p.weight(v), 1.0);
}

TEST(TexturedSimplificationPolicy, RunsUnderCgalEngineWithUpdateHook) {
  Mesh m;
  if (!read_mesh(data_dir() + "/classic/bunny.off", m)) GTEST_SKIP() << "shared data not found: " << data_dir();
  const Mesh original = m;
  const long chi = euler_characteristic(m);
  Counting_policy::Counts counts;
  Counting_policy policy(m, &counts);
  Checking_visitor::Stats stats;
  TS::Face_count_stop_predicate<Mesh> stop(m, 1000);
  const int removed = SMS::edge_collapse(m, stop,
                                         CGAL::parameters::get_cost(policy)
                                             .get_placement(policy)
                                             .filter(TS::No_normal_flip_filter<>())
                                             .visitor(Checking_visitor(&stats)));
  EXPECT_EQ(counts.init, 1u);
  EXPECT_EQ(counts.update, stats.collapsed);
  EXPECT_EQ(std::size_t(removed), 3 * stats.collapsed);  // CGAL counts removed edges
  EXPECT_EQ(stats.flipped_faces, 0u);
  EXPECT_EQ(live_faces(m), 1000u);
  EXPECT_EQ(stop.current_face_count(), 1000u);
  EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
  EXPECT_EQ(euler_characteristic(m), chi);
  m.collect_garbage();
  const Error_stats e = surface_error(original, m);
  EXPECT_LT(e.hausdorff, 0.02 * bbox_diagonal(original));
}

TEST(TexturedSimplificationPolicy, PlainPolicyIsGarlandHeckbert) {
  // With weighting off the policy is the plane QEM: on the same mesh, same engine (CGAL's) and
  // the same face count its error matches CGAL's GarlandHeckbert_plane_policies closely (CGAL's
  // planes are not area-weighted, so the results are close, not identical).
  Mesh m;
  if (!read_mesh(data_dir() + "/classic/bunny.off", m)) GTEST_SKIP() << "shared data not found: " << data_dir();
  const Mesh original = m;
  Mesh ours = m, cgal = m;
  TS::Quadric_options plain;
  plain.weighted = false;
  Policy policy(ours, plain);
  SMS::edge_collapse(ours, TS::Face_count_stop_predicate<Mesh>(ours, 700),
                     CGAL::parameters::get_cost(policy).get_placement(policy).filter(TS::No_normal_flip_filter<>()));
  SMS::GarlandHeckbert_plane_policies<Mesh, K> gh(cgal);
  SMS::edge_collapse(cgal, TS::Face_count_stop_predicate<Mesh>(cgal, 700),
                     CGAL::parameters::get_cost(gh.get_cost()).get_placement(gh.get_placement()));
  ours.collect_garbage();
  cgal.collect_garbage();
  for (vertex_descriptor v : ours.vertices()) ASSERT_DOUBLE_EQ(policy.weight(v), 1.0);
  const Error_stats eo = surface_error(original, ours), eg = surface_error(original, cgal);
  EXPECT_LT(eo.rms, 1.15 * eg.rms);
  EXPECT_LT(eo.hausdorff, 1.5 * eg.hausdorff);
}

TEST(TexturedSimplificationPolicy, StarDataIsWhatInitializeGives) {
  // star_vertex_data() (simplify_mesh() takes the data of its parts' border vertices from it)
  // gives every vertex the very numbers initialize() gives it, in both modes: a rippled sheet
  // whose faces are added in a shuffled order (so that a vertex's star is not in index order),
  // with one border loop and a zero-area face
  const int n = 32;  // a power of two: the grid coordinates are exact
  std::vector<Point> points;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double x = double(i) / n, y = double(j) / n;
      points.emplace_back(x, y, 0.1 * std::sin(7 * x) * std::cos(5 * y) + 0.03 * x * y);
    }
  // triangle (3, 4), (4, 4), (4, 5) of the grid has no area: its middle corner is moved between the others
  points[std::size_t(3 * (n + 1) + 4)] = Point(3.0 / n, 4.0 / n, 0.0);
  points[std::size_t(4 * (n + 1) + 5)] = Point(4.0 / n, 5.0 / n, 0.0);
  points[std::size_t(4 * (n + 1) + 4)] = Point(3.5 / n, 4.5 / n, 0.0);
  std::vector<std::array<std::size_t, 3>> triangles;
  auto at = [&](int i, int j) { return std::size_t(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  std::shuffle(triangles.begin(), triangles.end(), std::mt19937(7));
  Mesh m;
  for (const Point& p : points) m.add_vertex(p);
  for (const auto& t : triangles)
    ASSERT_NE(m.add_face(vertex_descriptor(Mesh::size_type(t[0])), vertex_descriptor(Mesh::size_type(t[1])),
                         vertex_descriptor(Mesh::size_type(t[2]))),
              Mesh::null_face());
  std::size_t flat = 0;
  for (auto f : m.faces()) {
    const auto h = m.halfedge(f);
    flat += CGAL::collinear(m.point(m.source(h)), m.point(m.target(h)), m.point(m.target(m.next(h)))) ? 1 : 0;
  }
  ASSERT_GE(flat, 1u);
  for (bool weighted : {false, true}) {
    TS::Quadric_options o;
    o.weighted = weighted;
    Policy policy(m, o);
    policy.initialize(m, m.points());
    std::size_t border = 0, not_one = 0;
    for (vertex_descriptor v : m.vertices()) {
      const auto [q, w] = policy.star_vertex_data(m, m.points(), v);
      const auto& r = policy.quadric(v);
      const std::array<double, 10> a{q.a00, q.a01, q.a02, q.a11, q.a12, q.a22, q.b0, q.b1, q.b2, q.c},
          b{r.a00, r.a01, r.a02, r.a11, r.a12, r.a22, r.b0, r.b1, r.b2, r.c};
      ASSERT_EQ(a, b) << "vertex " << v << (weighted ? ", weighted" : ", plain");  // bit for bit
      ASSERT_EQ(w, policy.weight(v)) << "vertex " << v;
      border += m.is_border(v) ? 1 : 0;
      not_one += w != 1.0 ? 1 : 0;
    }
    EXPECT_EQ(border, std::size_t(4 * n));
    EXPECT_EQ(not_one > 0, weighted);
  }
}

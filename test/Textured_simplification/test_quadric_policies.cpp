// Tests of the quadric policies of Textured_simplification (thesis §3.4): weights, options, the
// CGAL engine, the plain (Garland-Heckbert) policy.
#include "textured_simplification_test_util.h"

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

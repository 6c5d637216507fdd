// Tests of the edge-collapse engine of Textured_simplification: the normal hint of the policy,
// the weighted metric, edge flips, other face graphs, constrained edges.
#include "textured_simplification_test_util.h"

// The policy without the engine's normal shortcut: hiding the four-argument
// update_after_collapse makes the engine call the three-argument one, which walks the star.
struct Policy_without_normal_hint : Policy {
  using Policy::Policy;
  template <class Profile>
  void update_after_collapse(const Profile& p, vertex_descriptor v, const Collapse_token& t) const {
    Policy::update_after_collapse(p, v, t);
  }
};

static_assert(TS::internal::has_normal_hint<Policy, Engine_profile, vertex_descriptor, Policy::Collapse_token>::value,
              "the policy takes the engine's normal");
static_assert(!TS::internal::has_normal_hint<Policy_without_normal_hint, Engine_profile, vertex_descriptor,
                                             Policy::Collapse_token>::value,
              "the wrapper hides it");

TEST(TexturedSimplificationEngine, NormalFromFoldOverTestGivesTheSameCollapses) {
  // CMGeom's engine hands the policy the kept vertex's normal summed by its fold-over test; the
  // policy would otherwise sum it over the star after the collapse. Same weights, so the same
  // simplified mesh, point for point.
  Mesh m;
  if (!read_mesh(data_dir() + "/classic/bunny.off", m)) GTEST_SKIP() << "shared data not found: " << data_dir();
  Mesh a = m, b = m;
  Policy pa(a);
  Policy_without_normal_hint pb(b);
  TS::edge_collapse(a, TS::Face_count_stop_predicate<Mesh>(a, 2000), CGAL::parameters::get_cost(pa).get_placement(pa));
  TS::edge_collapse(b, TS::Face_count_stop_predicate<Mesh>(b, 2000), CGAL::parameters::get_cost(pb).get_placement(pb));
  ASSERT_EQ(a.number_of_vertices(), b.number_of_vertices());
  ASSERT_EQ(live_faces(a), 2000u);
  // before garbage collection the indices are the input's, which the policies' records use
  for (vertex_descriptor v : a.vertices()) {
    ASSERT_FALSE(b.is_removed(v)) << "vertex " << v;
    ASSERT_EQ(a.point(v), b.point(v)) << "vertex " << v;
    ASSERT_EQ(pa.weight(v), pb.weight(v)) << "vertex " << v;
  }
}

TEST(TexturedSimplificationEngine, WeightedMetricKeepsThinCurvedHorn) {
  // A unit sphere with a thin curved horn (height 1, base radius ~0.06). The thesis' claim
  // (§3.4, Fig. 3.1-3.3): plain QEM erases such features, the weighted metric keeps them. We
  // measure the distance from the original horn (points above the sphere) to each result.
  const Mesh original = make_sphere_with_horn(1.0);
  std::vector<Point> horn;
  for (const Point& p : sample_surface(original, 40000))
    if (std::sqrt(CGAL::square(p.x()) + CGAL::square(p.y()) + CGAL::square(p.z())) > 1.3) horn.push_back(p);
  ASSERT_GT(horn.size(), 50u);
  auto horn_error = [&](bool weighted, std::size_t target = 300) {
    Mesh m = original;
    TS::Quadric_options o;
    o.weighted = weighted;
    Policy p(m, o);
    TS::edge_collapse(m, TS::Face_count_stop_predicate<Mesh>(m, target),
                      CGAL::parameters::get_cost(p).get_placement(p));
    m.collect_garbage();
    Distance_to_mesh d(m);
    double mx = 0;
    for (const Point& q : horn) mx = std::max(mx, d(q));
    return mx;
  };
  // At every level the weighted result is closer to the horn, and clearly so on average (the
  // geometric mean of the ratios); at the coarsest level plain QEM has cut the horn short.
  double log_sum = 0;
  int levels = 0;
  for (std::size_t target : {60, 150, 300, 1000}) {
    const double plain = horn_error(false, target), weighted = horn_error(true, target);
    std::cout << "faces " << target << ": horn max distance plain " << plain << ", weighted " << weighted << std::endl;
    EXPECT_LT(weighted, plain) << target << " faces";
    log_sum += std::log(weighted / plain);
    ++levels;
    if (target == 60) {
      EXPECT_GT(plain, 0.1);  // a tenth of the horn's length is gone
      EXPECT_LT(weighted, 0.5 * plain);
    }
  }
  EXPECT_LT(std::exp(log_sum / levels), 0.6);
}

TEST(TexturedSimplificationEngine, FlipsKeepValidityAndHappen) {
  Mesh m;
  if (!read_mesh(data_dir() + "/classic/bunny.off", m)) GTEST_SKIP() << "shared data not found: " << data_dir();
  const Mesh original = m;
  const long chi = euler_characteristic(m);
  Checking_visitor::Stats stats;
  TS::Face_count_stop_predicate<Mesh> stop(m, 1000);
  TS::edge_collapse(m, stop, CMGeom::parameters::edge_flips(true, CGAL::parameters::visitor(Checking_visitor(&stats))));
  EXPECT_GT(stats.flips, 0u);
  EXPECT_EQ(stats.flipped_faces, 0u);
  EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
  EXPECT_EQ(euler_characteristic(m), chi);
  EXPECT_EQ(live_faces(m), 1000u);
  m.collect_garbage();
  const Error_stats e = surface_error(original, m);
  EXPECT_LT(e.hausdorff, 0.02 * bbox_diagonal(original));
}

TEST(TexturedSimplificationEngine, FlipsImproveTriangleShapeOnFlatRegions) {
  // §3.5.1: flips "create well-shaped triangles in flat regions". On a flat grid the quadric
  // error is zero everywhere, so shape is all that changes: the mean of the smallest angle of
  // the triangles must not get worse with flips, and no triangle may be flipped or lost.
  auto mean_min_angle = [](const Mesh& m) {
    double sum = 0;
    std::size_t n = 0;
    for (face_descriptor f : m.faces()) {
      const halfedge_descriptor h = m.halfedge(f);
      const Point p[3] = {m.point(m.source(h)), m.point(m.target(h)), m.point(m.target(m.next(h)))};
      double mn = CGAL_PI;
      for (int i = 0; i < 3; ++i) {
        const Vector a = p[(i + 1) % 3] - p[i], b = p[(i + 2) % 3] - p[i];
        mn = std::min(mn, std::acos(std::clamp(a * b / std::sqrt(a.squared_length() * b.squared_length()), -1.0, 1.0)));
      }
      sum += mn;
      ++n;
    }
    return sum / double(n);
  };
  double angle[2];
  for (int flips = 0; flips < 2; ++flips) {
    Mesh m = make_flat_grid(30);
    Checking_visitor::Stats stats;
    TS::edge_collapse(m, TS::Face_count_stop_predicate<Mesh>(m, 300),
                      CMGeom::parameters::edge_flips(flips == 1, CGAL::parameters::visitor(Checking_visitor(&stats))));
    m.collect_garbage();
    EXPECT_EQ(stats.flipped_faces, 0u);
    EXPECT_GE(m.number_of_faces(), 299u);  // open mesh: the last collapse may remove 2 faces
    EXPECT_LE(m.number_of_faces(), 300u);
    EXPECT_NEAR(PMP::area(m), 1.0, 1e-9);
    if (flips == 1) EXPECT_GT(stats.flips, 0u);
    angle[flips] = mean_min_angle(m);
  }
  std::cout << "mean smallest angle: without flips " << angle[0] * 180 / CGAL_PI << " deg, with flips "
            << angle[1] * 180 / CGAL_PI << " deg" << std::endl;
  EXPECT_GE(angle[1], angle[0]);
}

TEST(TexturedSimplificationEngine, GenericOverFaceGraphs) {
  // The engine and the policy only use the BGL interface: run them on a Polyhedron_3 (with ids,
  // which CGAL's get_initialized_*_index_map need for this graph type).
  using Polyhedron = CGAL::Polyhedron_3<K, CGAL::Polyhedron_items_with_id_3>;
  const Mesh sm = make_sphere_with_horn(0.5, 30, 30);
  Polyhedron poly;
  CGAL::copy_face_graph(sm, poly);
  const long chi = long(poly.size_of_vertices()) - long(poly.size_of_halfedges() / 2) + long(poly.size_of_facets());
  TS::Area_weighted_quadric_policies<Polyhedron> policy(poly);
  TS::edge_collapse(poly, TS::Face_count_stop_predicate<Polyhedron>(poly, 200),
                    CGAL::parameters::get_cost(policy).get_placement(policy));
  EXPECT_TRUE(CGAL::is_valid_polygon_mesh(poly));
  EXPECT_EQ(poly.size_of_facets(), 200u);
  EXPECT_EQ(long(poly.size_of_vertices()) - long(poly.size_of_halfedges() / 2) + long(poly.size_of_facets()), chi);
}

TEST(TexturedSimplificationEngine, ConstrainedEdgesSurvive) {
  // edge_is_constrained_map: constrained edges are never collapsed nor removed
  Mesh m = make_flat_grid(20);
  auto ecm = m.add_property_map<Mesh::Edge_index, bool>("e:constrained", false).first;
  std::size_t constrained = 0;
  for (Mesh::Edge_index e : m.edges()) {
    // the border and one interior line x = 0.5
    const Point a = m.point(m.vertex(e, 0)), b = m.point(m.vertex(e, 1));
    if (m.is_border(e) || (std::abs(a.x() - 0.5) < 1e-12 && std::abs(b.x() - 0.5) < 1e-12)) {
      ecm[e] = true;
      ++constrained;
    }
  }
  TS::edge_collapse(m, TS::Face_count_stop_predicate<Mesh>(m, 100), CGAL::parameters::edge_is_constrained_map(ecm));
  EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
  std::size_t still = 0;
  for (Mesh::Edge_index e : m.edges()) still += ecm[e];
  EXPECT_EQ(still, constrained);
  EXPECT_NEAR(PMP::area(m), 1.0, 1e-9);
}

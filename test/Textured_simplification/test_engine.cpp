// Tests of the edge-collapse engine of Textured_simplification: invariants, topology, profiles,
// CGAL policies on the engine, open meshes, quality and results against CGAL's engine.
#include "textured_simplification_test_util.h"

#include <CGAL/boost/graph/Euler_operations.h>

// ------------------------------------------------------------------------- engine

TEST(TexturedSimplificationEngine, InvariantsOnClosedClassicMeshes) {
  const auto files = closed_classic_meshes();
  if (files.empty()) GTEST_SKIP() << "shared data not found: " << data_dir();
  std::size_t tested = 0;
  for (const std::string& f : files) {
    Mesh m;
    if (!read_mesh(f, m)) continue;
    if (!CGAL::is_valid_polygon_mesh(m) || !CGAL::is_triangle_mesh(m) || !CGAL::is_closed(m)) continue;
    ++tested;
    const std::size_t target = 2 * std::max<std::size_t>(m.number_of_faces() / 20, 8);  // ~10 %, even
    check_simplification_invariants(fs::path(f).filename().string(), m, target,
                                    [](Mesh& mesh, std::size_t t, Checking_visitor vis) {
                                      TS::Face_count_stop_predicate<Mesh> stop(mesh, t);
                                      TS::edge_collapse(mesh, stop, CGAL::parameters::visitor(vis));
                                    });
  }
  EXPECT_GE(tested, 10u) << "expected most classic meshes to be closed and manifold";
}

TEST(TexturedSimplificationEngine, ExtremeTargetKeepsTopology) {
  Mesh m;
  if (!read_mesh(data_dir() + "/classic/knot_orig.ply", m)) GTEST_SKIP() << "shared data not found: " << data_dir();
  // genus 1: the smallest torus has 7 vertices / 14 faces; ask for less and check we stop sanely
  check_simplification_invariants("knot", m, 64, [](Mesh& mesh, std::size_t t, Checking_visitor vis) {
    TS::Face_count_stop_predicate<Mesh> stop(mesh, t);
    TS::edge_collapse(mesh, stop, CGAL::parameters::visitor(vis));
  });
}

// A valid CGAL::Surface_mesh may hold pockets: a vertex p with two faces, (a, p, b) and (b, p, a),
// and two edges joining a and b (triangulating two quads that share two edges makes one; the
// shared suzanne.obj, read by CGAL and triangulated, has one). The engine never collapses an edge
// whose two faces have the same apex nor one of two edges joining the same vertices: both would
// leave an edge from a vertex to itself. Each pocket is put in a noisy sphere by splitting an edge
// (a, b) at p, lifted off the surface, then splitting both quads along a second edge (a, b).
TEST(TexturedSimplificationEngine, PocketsAndDoubledEdgesNeverBecomeLoops) {
  Mesh m = make_noisy_sphere(24, 7, 0.02);
  const std::size_t pockets = 6;
  std::vector<halfedge_descriptor> picked;
  std::set<vertex_descriptor> used;
  for (halfedge_descriptor h : m.halfedges()) {  // edges far apart: no two share a face's vertex
    if (picked.size() == pockets) break;
    const std::array<vertex_descriptor, 4> around{m.source(h), m.target(h), m.target(m.next(h)),
                                                  m.target(m.next(m.opposite(h)))};
    bool near = false;
    for (vertex_descriptor v : around)
      for (halfedge_descriptor g : CGAL::halfedges_around_target(v, m)) near = near || used.count(m.source(g));
    if (near) continue;
    for (vertex_descriptor v : around) used.insert(v);
    picked.push_back(h);
  }
  ASSERT_EQ(picked.size(), pockets);
  for (halfedge_descriptor h : picked) {
    const vertex_descriptor a = m.source(h), b = m.target(h);
    const Point pa = m.point(a), pb = m.point(b);
    const halfedge_descriptor to_p = CGAL::Euler::split_edge(h, m);  // a -> p, then p -> b is h
    const vertex_descriptor p = m.target(to_p);
    m.point(p) = CGAL::midpoint(pa, pb) + 0.2 * (CGAL::midpoint(pa, pb) - CGAL::ORIGIN);
    // each side is now a quad (a, p, b, apex): split it between a and b
    for (halfedge_descriptor side : {to_p, m.opposite(h)}) {
      halfedge_descriptor ha = side, hb = side;
      while (m.target(ha) != a) ha = m.next(ha);
      while (m.target(hb) != b) hb = m.next(hb);
      CGAL::Euler::split_face(ha, hb, m);
    }
    std::size_t ab = 0;
    for (halfedge_descriptor g : CGAL::halfedges_around_target(a, m)) ab += m.source(g) == b;
    ASSERT_EQ(ab, 2u) << "the pocket's two edges between a and b";
  }
  ASSERT_TRUE(CGAL::is_valid_polygon_mesh(m));
  ASSERT_TRUE(CGAL::is_triangle_mesh(m));
  const std::size_t faces_in = m.number_of_faces();
  auto no_loop_or_pinched_face = [](const Mesh& mesh, const std::string& what) {
    for (halfedge_descriptor g : mesh.halfedges()) ASSERT_NE(mesh.source(g), mesh.target(g)) << what;
    for (face_descriptor f : mesh.faces()) {
      const halfedge_descriptor g = mesh.halfedge(f);
      const vertex_descriptor x = mesh.target(g), y = mesh.target(mesh.next(g)), z = mesh.source(g);
      ASSERT_TRUE(x != y && y != z && z != x) << what;
    }
  };
  for (double ratio : {0.1, 0.02}) {
    Mesh engine_only = m;
    TS::Face_count_stop_predicate<Mesh> stop(engine_only, std::size_t(ratio * double(faces_in)));
    TS::edge_collapse(engine_only, stop);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(engine_only)) << ratio;
    no_loop_or_pinched_face(engine_only, "edge_collapse");
    EXPECT_LE(engine_only.number_of_faces(), std::size_t(ratio * double(faces_in)) + 4 * pockets) << ratio;

    Mesh whole = m;  // simplify_mesh's defaults: the memoryful cost and the fit
    TS::Mesh_simplification_options o;
    o.quadric.weighted = false;
    o.target_ratio = ratio;
    TS::simplify_mesh(whole, o);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(whole)) << ratio;
    EXPECT_TRUE(CGAL::is_triangle_mesh(whole)) << ratio;
    no_loop_or_pinched_face(whole, "simplify_mesh");
    EXPECT_LE(whole.number_of_faces(), std::size_t(ratio * double(faces_in)) + 4 * pockets) << ratio;
  }
  // CGAL's engine does not handle them (CGAL 5.5.1 loops or fails an assertion): refused up front
  Mesh on_cgal = m;
  TS::Mesh_simplification_options o;
  o.engine = TS::Simplification_engine::cgal;
  o.surface_memory = false;
  o.target_ratio = 0.1;
  try {
    TS::simplify_mesh(on_cgal, o);
    FAIL() << "expected CMGeom::Invalid_input";
  } catch (const CMGeom::Invalid_input& e) {
    EXPECT_NE(std::string(e.what()).find("joined by two edges"), std::string::npos) << e.what();
  }
  EXPECT_EQ(on_cgal.number_of_faces(), faces_in) << "the refused mesh is left as it was";
}

// CMGeom's profile gives the same neighbourhood as CGAL's Edge_profile (triangles with the same
// orientation, link vertices, border edges), compared as sets on every halfedge of an open mesh.
TEST(TexturedSimplificationEngine, ProfileNeighbourhoodMatchesCgalEdgeProfile) {
  Mesh m;
  if (!read_mesh(data_dir() + "/classic/mech-holes-shark.off", m))
    GTEST_SKIP() << "shared data not found: " << data_dir();
  ASSERT_FALSE(CGAL::is_closed(m));
  using VPM = Mesh::Property_map<vertex_descriptor, Point>;
  using Ours = TS::Collapse_profile<Mesh, VPM, K>;
  using Theirs = SMS::Edge_profile<Mesh, VPM, K>;
  const K gt;
  // A triangle as its cyclic order starting from the smallest vertex (orientation kept).
  auto key = [](vertex_descriptor a, vertex_descriptor b, vertex_descriptor c) {
    while (!(a < b && a < c)) std::tie(a, b, c) = std::make_tuple(b, c, a);
    return std::array<std::size_t, 3>{std::size_t(a), std::size_t(b), std::size_t(c)};
  };
  std::size_t checked = 0, with_border = 0;
  for (halfedge_descriptor h : halfedges(m)) {
    if (is_border(h, m) && is_border(opposite(h, m), m)) continue;
    const Ours ours(h, m, m.points(), gt);
    const Theirs theirs(h, m, gt, get(CGAL::vertex_index, m), m.points(), get(CGAL::halfedge_index, m), true);
    std::set<std::array<std::size_t, 3>> t1, t2;
    for (const auto& t : ours.triangles()) t1.insert(key(t.v0, t.v1, t.v2));
    for (const auto& t : theirs.triangles()) t2.insert(key(t.v0, t.v1, t.v2));
    ASSERT_EQ(t1, t2) << "halfedge " << h;
    EXPECT_EQ(ours.triangles().size(), theirs.triangles().size());
    const std::set<vertex_descriptor> l1(ours.link().begin(), ours.link().end()),
        l2(theirs.link().begin(), theirs.link().end());
    ASSERT_EQ(l1, l2) << "halfedge " << h;
    const std::set<halfedge_descriptor> b1(ours.border_edges().begin(), ours.border_edges().end()),
        b2(theirs.border_edges().begin(), theirs.border_edges().end());
    ASSERT_EQ(b1, b2) << "halfedge " << h;
    with_border += !b1.empty();
    ++checked;
  }
  EXPECT_GT(checked, 1000u);
  EXPECT_GT(with_border, 10u);
}

// Policies written for CGAL's engine run unchanged on CMGeom's: CGAL's Lindstrom-Turk cost and
// placement (which read triangles(), link() and border_edges()) and its Garland-Heckbert
// policies reach the target and leave a valid mesh of the same topology close to the input.
TEST(TexturedSimplificationEngine, CgalPoliciesRunOnTheEngine) {
  Mesh input;
  if (!read_mesh(data_dir() + "/classic/mech-holes-shark.off", input))
    GTEST_SKIP() << "shared data not found: " << data_dir();
  const long chi = euler_characteristic(input);
  const std::size_t target = live_faces(input) / 5;
  Mesh lt = input;
  TS::edge_collapse(
      lt, TS::Face_count_stop_predicate<Mesh>(lt, target),
      CGAL::parameters::get_cost(SMS::LindstromTurk_cost<Mesh>()).get_placement(SMS::LindstromTurk_placement<Mesh>()));
  Mesh gh = input;
  SMS::GarlandHeckbert_plane_policies<Mesh, K> policies(gh);
  TS::edge_collapse(gh, TS::Face_count_stop_predicate<Mesh>(gh, target),
                    CGAL::parameters::get_cost(policies.get_cost()).get_placement(policies.get_placement()));
  // The same Lindstrom-Turk run on CGAL's engine, for the distance comparison.
  Mesh lt_cgal = input;
  SMS::edge_collapse(lt_cgal, TS::Face_count_stop_predicate<Mesh>(lt_cgal, target));
  const double diag = bbox_diagonal(input);
  for (const Mesh* m : {&lt, &gh}) {
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(*m));
    EXPECT_LE(live_faces(*m), target);
    EXPECT_GE(live_faces(*m), target - 2);
    EXPECT_EQ(euler_characteristic(*m), chi);
  }
  // Lindstrom-Turk on either engine: every vertex of the input stays as close to the result.
  auto worst = [&](const Mesh& m) {
    CGAL::AABB_tree<CGAL::AABB_traits<K, CGAL::AABB_face_graph_triangle_primitive<Mesh>>> tree(faces(m).first,
                                                                                               faces(m).second, m);
    double d = 0;
    for (auto v : vertices(input)) d = std::max(d, std::sqrt(tree.squared_distance(input.point(v))));
    return d / diag;
  };
  const double ours = worst(lt), theirs = worst(lt_cgal);
  EXPECT_LT(ours, 1.5 * theirs + 1e-3) << "ours " << ours << ", CGAL's engine " << theirs;
}

TEST(TexturedSimplificationEngine, OpenMeshBoundaryAndExactCounts) {
  Mesh m;
  if (!read_mesh(data_dir() + "/classic/mech-holes-shark.off", m))
    GTEST_SKIP() << "shared data not found: " << data_dir();
  ASSERT_FALSE(CGAL::is_closed(m));
  const long chi = euler_characteristic(m);
  // odd target on an open mesh: boundary collapses remove one face, so it is reachable exactly
  TS::Face_count_stop_predicate<Mesh> stop(m, 1001);
  TS::edge_collapse(m, stop);
  EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
  EXPECT_EQ(euler_characteristic(m), chi);
  EXPECT_LE(live_faces(m), 1001u);
  EXPECT_GE(live_faces(m), 1000u);
  EXPECT_EQ(stop.current_face_count(), live_faces(m));  // the O(1) counter is exact
  // vertex-count predicate
  Mesh m2;
  read_mesh(data_dir() + "/classic/mech-holes-shark.off", m2);
  TS::Vertex_count_stop_predicate<Mesh> vstop(m2, 700);
  TS::edge_collapse(m2, vstop);
  EXPECT_EQ(m2.number_of_vertices(), 700u);
  // ratio predicate, and two predicates combined (the first to fire wins)
  Mesh m3;
  read_mesh(data_dir() + "/classic/mech-holes-shark.off", m3);
  const std::size_t f3 = live_faces(m3);
  TS::edge_collapse(m3, TS::Face_count_ratio_stop_predicate<Mesh>(m3, 0.25));
  EXPECT_LE(live_faces(m3), f3 / 4);
  EXPECT_GE(live_faces(m3), f3 / 4 - 1);
  Mesh m4;
  read_mesh(data_dir() + "/classic/mech-holes-shark.off", m4);
  TS::edge_collapse(m4,
                    TS::Stop_if_any<TS::Face_count_stop_predicate<Mesh>, TS::Vertex_count_stop_predicate<Mesh>>(
                        TS::Face_count_stop_predicate<Mesh>(m4, 10), TS::Vertex_count_stop_predicate<Mesh>(m4, 2000)));
  EXPECT_EQ(m4.number_of_vertices(), 2000u);
}

TEST(TexturedSimplificationEngine, SameQualityAsCgalEngine) {
  Mesh m;
  if (!read_mesh(data_dir() + "/classic/bunny.off", m)) GTEST_SKIP() << "shared data not found: " << data_dir();
  const Mesh original = m;
  for (bool weighted : {true, false}) {
    TS::Quadric_options o;
    o.weighted = weighted;
    Mesh a = m, b = m;
    Policy pa(a, o), pb(b, o);
    TS::edge_collapse(a, TS::Face_count_stop_predicate<Mesh>(a, 800), CGAL::parameters::get_cost(pa).get_placement(pa));
    SMS::edge_collapse(b, TS::Face_count_stop_predicate<Mesh>(b, 800),
                       CGAL::parameters::get_cost(pb).get_placement(pb).filter(TS::No_normal_flip_filter<>()));
    EXPECT_EQ(live_faces(a), live_faces(b));
    a.collect_garbage();
    b.collect_garbage();
    const Error_stats ea = surface_error(original, a), eb = surface_error(original, b);
    const double diag = bbox_diagonal(original);
    // same policy, same order of magnitude of error, and the two results close to each other
    EXPECT_LT(ea.rms, 1.1 * eb.rms) << "weighted=" << weighted;
    EXPECT_LT(ea.hausdorff, 1.3 * eb.hausdorff) << "weighted=" << weighted;
    const Error_stats eab = surface_error(a, b);
    EXPECT_LT(eab.hausdorff, 0.01 * diag) << "weighted=" << weighted;
  }
}

TEST(TexturedSimplificationEngine, IdenticalToCgalEngineOnASmallMesh) {
  // Both engines run the same policy, pop edges by cost and refuse the same fold-overs, so on a
  // small smooth mesh with distinct costs (a sphere with random radial noise: no ties) they make
  // the same collapses: same vertex positions, same connectivity size.
  const Mesh m = make_noisy_sphere(24, 3, 0.01);
  for (bool weighted : {true, false}) {
    TS::Quadric_options o;
    o.weighted = weighted;
    Mesh a = m, b = m;
    Policy pa(a, o), pb(b, o);
    TS::edge_collapse(a, TS::Face_count_stop_predicate<Mesh>(a, 300), CGAL::parameters::get_cost(pa).get_placement(pa));
    SMS::edge_collapse(b, TS::Face_count_stop_predicate<Mesh>(b, 300),
                       CGAL::parameters::get_cost(pb).get_placement(pb).filter(TS::No_normal_flip_filter<>()));
    a.collect_garbage();
    b.collect_garbage();
    ASSERT_EQ(a.number_of_faces(), b.number_of_faces());
    const auto pa_pts = sorted_points(a), pb_pts = sorted_points(b);
    std::size_t same = 0;
    for (const auto& p : pa_pts) same += std::binary_search(pb_pts.begin(), pb_pts.end(), p);
    std::cout << (weighted ? "weighted" : "plain") << ": " << same << " of " << pa_pts.size() << " vertices identical"
              << std::endl;
    EXPECT_EQ(same, pa_pts.size()) << "weighted=" << weighted;
  }
}

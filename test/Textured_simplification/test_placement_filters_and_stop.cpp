// Tests of the edge-collapse engine of Textured_simplification with placement filters (greedy
// order at the filtered placement, fold-over test) and the maximum-cost stop.
#include "textured_simplification_test_util.h"

// The test filters below move the placement of the edges whose lower-index endpoint has an even
// index (a rule that depends on the edge only, not on its orientation). True for such an edge,
// with its endpoints' points, lower index first.
template <class Profile>
bool is_even_edge(const Profile& p, Point& low, Point& high) {
  const bool v0_low = p.v0() < p.v1();
  if (std::size_t(v0_low ? p.v0() : p.v1()) % 2 != 0) return false;
  low = v0_low ? p.p0() : p.p1();
  high = v0_low ? p.p1() : p.p0();
  return true;
}

// Half-edge collapses, as the chart constraints make onto a chart boundary: the kept vertex goes
// to the lower-index endpoint.
struct Snap_to_even_endpoint_filter {
  template <class Profile, class Placement>
  Placement operator()(const Profile& p, const Placement& pl) const {
    Point low, high;
    if (!pl || !is_even_edge(p, low, high)) return pl;
    return Placement(low);
  }
};

using Mesh_vpm = Mesh::Property_map<vertex_descriptor, Point>;

// For every collapse, checks against every other edge of the mesh before it: the collapse's cost
// at the placement it is made with must not exceed any other collapsible edge's cost at the
// placement it would be made with (the filter's). Collapsible: the link condition holds and the
// policy's placement flips no face (the engine's own tests, in the engine's order).
struct Greedy_order_checker : TS::Edge_collapse_visitor_base {
  const Policy* policy = nullptr;
  std::size_t* collapses = nullptr;
  std::size_t* moved = nullptr;
  std::size_t* not_cheapest_by_queue_cost = nullptr;
  std::size_t* folding = nullptr;
  std::vector<std::string>* failures = nullptr;

  template <class Profile, class OP>
  void OnCollapsing(const Profile& p, const OP& placement) const {
    const Mesh& m = p.surface_mesh();
    const double cost = CGAL::to_double(*(*policy)(p, placement));
    ++*collapses;
    // the engine's fold-over guarantee holds at the placement used, moved or not
    if (TS::internal::collapse_flips_a_face(m, get(CGAL::vertex_point, m), p.v0_v1(),
                                            TS::internal::to_vec3(*placement)))
      ++*folding;
    const auto own = (*policy)(p);
    if (*own != *placement) ++*moved;
    double best_real = std::numeric_limits<double>::infinity(), best_queue = best_real;
    std::vector<unsigned> mark(m.number_of_vertices() + m.number_of_removed_vertices(), 0u);
    unsigned stamp = 0;
    const auto vim = get(CGAL::vertex_index, m);
    for (auto e : m.edges()) {
      const halfedge_descriptor h = m.halfedge(e);
      if (e == m.edge(p.v0_v1())) continue;
      if (!TS::internal::is_collapse_topologically_valid(m, vim, h, mark, stamp)) continue;
      const Engine_profile q(h, m, get(CGAL::vertex_point, m), K());
      const auto x = (*policy)(q);
      if (TS::internal::collapse_flips_a_face(m, get(CGAL::vertex_point, m), h, TS::internal::to_vec3(*x))) continue;
      best_queue = (std::min)(best_queue, CGAL::to_double(*(*policy)(q, x)));
      const auto y = Snap_to_even_endpoint_filter()(q, x);
      if (TS::internal::collapse_flips_a_face(m, get(CGAL::vertex_point, m), h, TS::internal::to_vec3(*y))) continue;
      best_real = (std::min)(best_real, CGAL::to_double(*(*policy)(q, y)));
    }
    if (cost > best_real) {
      std::ostringstream msg;
      msg << "collapse " << *collapses << ": cost " << cost << " at its placement, another edge " << best_real;
      failures->push_back(msg.str());
    }
    if (cost > best_queue) ++*not_cheapest_by_queue_cost;
  }
};

TEST(TexturedSimplificationEngine, CollapsesInOrderOfTheCostAtTheFilteredPlacement) {
  // A filter may move the placement (the chart constraints' half-edge collapses do). The queue
  // holds costs at the policy's placement; the engine re-costs an edge whose placement the filter
  // moved, and collapses it only if it is still the cheapest. So every collapse is the cheapest
  // one at the placement actually used, checked here against all edges, brute force.
  const Mesh m = make_noisy_sphere(16, 5, 0.02);
  for (bool weighted : {true, false}) {
    TS::Quadric_options o;
    o.weighted = weighted;
    Mesh a = m;
    Policy policy(a, o);
    std::size_t collapses = 0, moved = 0, reordered = 0, folding = 0;
    std::vector<std::string> failures;
    Greedy_order_checker checker;
    checker.policy = &policy;
    checker.collapses = &collapses;
    checker.moved = &moved;
    checker.not_cheapest_by_queue_cost = &reordered;
    checker.folding = &folding;
    checker.failures = &failures;
    const std::size_t target = live_faces(a) / 3;
    TS::edge_collapse(a, TS::Face_count_stop_predicate<Mesh>(a, target),
                      CGAL::parameters::get_cost(policy)
                          .get_placement(policy)
                          .filter(Snap_to_even_endpoint_filter())
                          .visitor(checker));
    EXPECT_EQ(live_faces(a), target);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(a));
    EXPECT_TRUE(failures.empty()) << failures.size() << " collapses out of order, first: " << failures.front();
    EXPECT_EQ(folding, 0u) << "collapses that fold a face at the placement used, weighted=" << weighted;
    // not vacuous: placements were moved, and the order differs from the queue costs' order
    EXPECT_GT(moved, collapses / 4) << "weighted=" << weighted;
    EXPECT_GT(reordered, 0u) << "weighted=" << weighted;
  }
}

// The kept vertex one edge length beyond the higher-index endpoint (on a flat grid this folds the
// faces on that side).
struct Overshoot_filter {
  template <class Profile, class Placement>
  Placement operator()(const Profile& p, const Placement& pl) const {
    Point low, high;
    if (!pl || !is_even_edge(p, low, high)) return pl;
    return Placement(high + (high - low));
  }
};

TEST(TexturedSimplificationEngine, FoldOverTestAppliesToThePlacementTheFilterReturns) {
  // The fold-over test runs at the policy's placement; when the filter moves it, the engine tests
  // the new one too. On a flat grid in the z = 0 plane (normals +z) every face must keep a
  // positive z normal, whatever the filter does.
  Mesh m = make_flat_grid(16);
  const std::size_t before = live_faces(m);
  Policy policy(m);
  TS::edge_collapse(m, TS::Face_count_stop_predicate<Mesh>(m, before / 4),
                    CGAL::parameters::get_cost(policy).get_placement(policy).filter(Overshoot_filter()));
  m.collect_garbage();
  EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
  EXPECT_LT(live_faces(m), before / 2);  // collapses happened
  std::size_t flipped = 0;
  for (face_descriptor f : m.faces()) {
    const halfedge_descriptor h = m.halfedge(f);
    const Vector n = CGAL::cross_product(m.point(m.target(h)) - m.point(m.source(h)),
                                         m.point(m.target(m.next(h))) - m.point(m.source(h)));
    flipped += !(n.z() > 0);
  }
  EXPECT_EQ(flipped, 0u) << "faces folded over";
}

// Records the cost of every collapsed edge and the cost at which the stop predicate fired.
struct Cost_recorder : TS::Edge_collapse_visitor_base {
  struct State {
    double last = -1, stop_cost = -1;
    std::vector<double> collapsed;
  };
  State* s;
  explicit Cost_recorder(State* st) : s(st) {}
  template <class Profile, class OFT, class S>
  void OnSelected(const Profile&, const OFT& cost, S, S) const {
    s->last = cost ? CGAL::to_double(*cost) : -1;
  }
  template <class Profile, class OP>
  void OnCollapsing(const Profile&, const OP&) const {
    s->collapsed.push_back(s->last);
  }
  template <class Profile>
  void OnStopConditionReached(const Profile&) const {
    s->stop_cost = s->last;
  }
};

TEST(TexturedSimplificationEngine, MaxCostStopsAtTheFirstEdgeAboveTheThreshold) {
  // A reference run without the predicate gives the sequence of collapse costs (the engine is
  // deterministic); the threshold is the 100th of them. The run with Max_cost_stop_predicate must
  // then make exactly the collapses of the sequence up to the first cost above the threshold, each
  // at most the threshold, and stop on a cost above it.
  const Mesh base = make_sphere_with_horn(0.0, 30, 30);
  Cost_recorder::State ref;
  {
    Mesh m = base;
    TS::edge_collapse(m, TS::Face_count_stop_predicate<Mesh>(m, live_faces(base) / 4),
                      CGAL::parameters::visitor(Cost_recorder(&ref)));
  }
  ASSERT_GT(ref.collapsed.size(), 200u);
  const double threshold = ref.collapsed[99];
  std::size_t expected = 0;
  while (expected < ref.collapsed.size() && ref.collapsed[expected] <= threshold) ++expected;
  ASSERT_GE(expected, 100u);
  ASSERT_LT(expected, ref.collapsed.size()) << "the threshold must stop the run before the reference's end";
  Cost_recorder::State run;
  Mesh m = base;
  TS::edge_collapse(m, TS::Max_cost_stop_predicate(threshold), CGAL::parameters::visitor(Cost_recorder(&run)));
  EXPECT_EQ(run.collapsed.size(), expected);
  for (double c : run.collapsed) EXPECT_LE(c, threshold);
  EXPECT_GT(run.stop_cost, threshold);
  EXPECT_EQ(live_faces(m), live_faces(base) - 2 * expected);  // a closed mesh: two faces per collapse
  // and the other side: a threshold below every cost (the sphere has no zero-cost collapse) stops at once
  Mesh untouched = base;
  TS::edge_collapse(untouched, TS::Max_cost_stop_predicate(0.0));
  EXPECT_EQ(live_faces(untouched), live_faces(base));
}

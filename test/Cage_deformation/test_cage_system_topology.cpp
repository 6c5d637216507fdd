// Tests of the structure of a *Cages system: grid borders and join cages, the multi-level
// propagation (§5.3.4), parent links of hand-made descriptions.
#include "cage_system_test_util.h"

// ------------------------------------------------------------------ structure
TEST(Cage_system, grid_structure_borders_and_join_cages) {
  const Cage_system s(make_grid_cage_system({0, 0, 0}, {2, 2, 1}, 2, 2, 1));
  ASSERT_EQ(s.leaf_cages().size(), 4u);
  EXPECT_EQ(s.leaf_vertices().size(), 18u);  // 3 x 3 x 2 lattice
  for (std::size_t c = 0; c < 4; ++c) {
    EXPECT_EQ(s.neighbours(c).size(), 2u);  // diagonal cells touch along an edge only
    for (std::size_t o : s.neighbours(c)) EXPECT_EQ(s.border_size(c, o), 2u);
    EXPECT_EQ(s.boundary_vertices(c).size(), 6u);
  }
  // Classes: the central edge (2 vertices, 4 cages) and 4 face-middle edges (2 vertices, 2 cages).
  ASSERT_EQ(s.number_of_join_cages(), 5u);
  std::size_t total = 0;
  for (std::size_t k = 0; k < s.number_of_join_cages(); ++k) {
    total += s.join_class(k).size();
    EXPECT_EQ(s.join_class(k).size(), 2u);
    Triangle_cage jc = s.join_cage(k);
    EXPECT_FALSE(validate_cage(jc, "join cage", Cage_orientation::require_outward));
    EXPECT_NEAR(jc.signed_volume(), double(s.join_class_cages(k).size()), 1e-12);
  }
  EXPECT_EQ(total, 10u);
  Triangle_cage u = s.union_cage();
  EXPECT_FALSE(validate_cage(u, "union", Cage_orientation::require_outward));
  EXPECT_NEAR(u.signed_volume(), 4.0, 1e-12);
  // Overlapping cages are rejected.
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {1, 1, 1}, 1, 1, 1);
  d.cages.push_back(d.cages[0]);
  EXPECT_THROW(Cage_system{d}, CMGeom::Invalid_input);
}

// ------------------------------------------------------------------ multi-level (§5.3.4)
TEST(Cage_system, moving_an_internal_cage_moves_only_its_descendants) {
  // Leaves: 3 cells in a row. Internal P owns every vertex of cell 2; top Q owns every vertex of P.
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {3, 1, 1}, 3, 1, 1);
  Cage_description P = make_grid_cage_system({1.6, -0.5, -0.5}, {3.5, 1.5, 1.5}, 1, 1, 1).cages[0];
  Cage_description Q = make_grid_cage_system({1.4, -1, -1}, {4, 2, 2}, 1, 1, 1).cages[0];
  P.name = "P";
  Q.name = "Q";
  d.cages.push_back(P);  // 3
  d.cages.push_back(Q);  // 4
  d.cages[2].parents.push_back({3, {0, 1, 2, 3, 4, 5, 6, 7}});
  d.cages[3].parents.push_back({4, {0, 1, 2, 3, 4, 5, 6, 7}});
  const Cage_system s(d);
  EXPECT_EQ(s.leaf_cages(), (std::vector<std::size_t>{0, 1, 2}));
  const std::vector<Vec3> rest = s.leaf_vertices();
  auto poses = [&]() {
    std::vector<std::vector<Vec3>> p;
    for (const auto& c : d.cages) p.push_back(c.rest.vertices);
    return p;
  };
  std::set<std::uint32_t> desc(s.global_vertices(2).begin(), s.global_vertices(2).end());
  // Translate Q: its descendants (P, then cell 2's vertices) translate; nothing else moves.
  const Vec3 shift{0.3, -0.2, 0.5};
  auto pose = poses();
  for (Vec3& v : pose[4]) v = add(v, shift);
  std::vector<Vec3> moved = s.deformed_leaf_vertices(pose);
  for (std::uint32_t v = 0; v < rest.size(); ++v) {
    if (desc.count(v))
      EXPECT_LT(norm(sub(moved[v], add(rest[v], shift))), 1e-12);
    else
      EXPECT_EQ(moved[v], rest[v]);
  }
  // Moving a leaf vertex directly does not move its parents; moving P afterwards keeps the
  // vertex's offset (rotation about P's centre: the offset rotates with it).
  pose = poses();
  const std::uint32_t k = 7;  // corner (3,1,1) of cell 2
  const Vec3 t{0.1, 0.05, -0.02};
  pose[2][k] = add(pose[2][k], t);
  moved = s.deformed_leaf_vertices(pose);
  EXPECT_LT(norm(sub(moved[s.global_vertices(2)[k]], add(rest[s.global_vertices(2)[k]], t))), 1e-12);
  const Vec3 ctr{2.55, 0.5, 0.5};
  auto rot = [&](const Vec3& p) {
    const Vec3 q = sub(p, ctr);
    return add(ctr, Vec3{-q[1], q[0], q[2]});  // 90° about z
  };
  for (Vec3& v : pose[3]) v = rot(v);
  moved = s.deformed_leaf_vertices(pose);
  for (std::uint32_t v = 0; v < rest.size(); ++v) {
    if (!desc.count(v)) {
      EXPECT_EQ(moved[v], rest[v]);
      continue;
    }
    const Vec3 expect = v == s.global_vertices(2)[k] ? rot(add(rest[v], t)) : rot(rest[v]);
    EXPECT_LT(norm(sub(moved[v], expect)), 1e-12);
  }
}

// A hand-made description (not read from a file, so not checked by the reader) with a bad
// parent link is refused before anything indexes with it.
TEST(Cage_system, bad_parent_links_of_a_hand_made_description_are_refused) {
  const Cage_system_description base = [] {
    Cage_system_description d = make_grid_cage_system({0, 0, 0}, {2, 1, 1}, 2, 1, 1);
    d.cages.push_back(make_grid_cage_system({-0.5, -0.5, -0.5}, {2.5, 1.5, 1.5}, 1, 1, 1).cages[0]);
    return d;
  }();
  auto refused = [](const Cage_system_description& d, const std::string& what) {
    try {
      const Cage_system s(d);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const CMGeom::Invalid_input& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  Cage_system_description d = base;
  d.cages[0].parents.push_back({7, {0, 1}});
  refused(d, "bad parent link to cage 7");
  d = base;
  d.cages[1].parents.push_back({1, {0}});
  refused(d, "bad parent link to cage 1");
  d = base;
  d.cages[0].parents.push_back({2, {0, 1, 100000}});
  refused(d, "owns vertex 100000");
  d = base;  // a valid link still builds
  d.cages[0].parents.push_back({2, {0, 1, 2, 3, 4, 5, 6, 7}});
  EXPECT_NO_THROW(Cage_system s(d));
}

// Tests of the evaluation of a *Cages system: C¹ continuity of S across every border (and the jump
// of piecewise MVC), heterogeneous coordinates, S = T_i where d_i = 1, h per border (§5.5), one
// cage = plain coordinates, affine reproduction, harmonic parents.
#include "cage_system_test_util.h"

// ------------------------------------------------------------------ C¹ across borders
TEST(Cage_system, C1_across_every_border_and_jump_of_piecewise_mvc) {
  std::mt19937 rng(7);
  for (const std::array<int, 3> g :
       {std::array<int, 3>{2, 1, 1}, std::array<int, 3>{2, 2, 1}, std::array<int, 3>{1, 1, 3},
        std::array<int, 3>{2, 2, 2}, std::array<int, 3>{3, 3, 3}}) {
    Cage_system_description d =
        make_grid_cage_system({-1, -0.8, -0.6}, {1.1, 0.9, 0.7}, g[0], g[1], g[2], Coordinate_type::mean_value, 0.6);
    deform_all(d, bend);
    const Cage_system s(d);
    const std::vector<Vec3> B = s.basis(s.deformed_leaf_vertices());
    const Border_result star = probe_borders(s, B, Sine_h_smoothing(), rng);
    EXPECT_GT(star.probes, 0);
    EXPECT_LT(star.max_rel_jump, 1e-6) << g[0] << "x" << g[1] << "x" << g[2];
    EXPECT_LT(star.max_value_gap, 1e-12);
    const Border_result piecewise = probe_borders(s, B, Piecewise_smoothing(), rng);
    std::cout << g[0] << "x" << g[1] << "x" << g[2] << ": " << star.probes << " probes, Jacobian jump *Cages "
              << star.max_rel_jump << ", piecewise MVC " << piecewise.max_rel_jump << "\n";
    EXPECT_GT(piecewise.max_rel_jump, 1e-2) << "piecewise MVC should show a Jacobian jump";
    EXPECT_LT(piecewise.max_value_gap, 1e-12) << "piecewise MVC is C0";
  }
}

TEST(Cage_system, heterogeneous_coordinates_stay_C1) {
  std::mt19937 rng(11);
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {3, 1, 1}, 3, 1, 1, Coordinate_type::mean_value, 0.6);
  d.cages[1].coordinates = Coordinate_type::green;
  d.cages[2].coordinates = Coordinate_type::harmonic;
  d.cages[2].harmonic.resolution = 24;
  deform_all(d, bend);
  const Cage_system s(d);
  const std::vector<Vec3> B = s.basis(s.deformed_leaf_vertices());
  const Border_result r = probe_borders(s, B, Sine_h_smoothing(), rng);
  EXPECT_EQ(r.probes, 2 * 2 * 2);
  EXPECT_LT(r.max_rel_jump, 1e-6);
  EXPECT_LT(r.max_value_gap, 1e-12);
  // Without the join, the Green cage is discontinuous across its faces.
  const Border_result p = probe_borders(s, B, Piecewise_smoothing(), rng);
  std::cout << "MVC+Green+harmonic: Jacobian jump " << r.max_rel_jump << ", value gap without join " << p.max_value_gap
            << "\n";
  EXPECT_GT(p.max_value_gap, 1e-4);
}

// ------------------------------------------------------------------ reductions
TEST(Cage_system, S_equals_T_where_d_is_one) {
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {2, 1, 1}, 2, 1, 1, Coordinate_type::mean_value, 0.2);
  deform_all(d, bend);
  const Cage_system s(d);
  const std::vector<Vec3> leaf = s.deformed_leaf_vertices();
  const std::vector<Vec3> B = s.basis(leaf);
  std::mt19937 rng(3);
  int with_d1 = 0;
  for (const Vec3& p : random_points(rng, {0, 0, 0}, {2, 1, 1}, 400)) {
    const auto [c, inside] = s.locate(p);
    ASSERT_TRUE(inside);
    EXPECT_EQ(c, p[0] < 1 ? 0u : 1u);
    if (s.distance(p, c) < 1) continue;
    ++with_d1;
    Mean_value_coordinates_3 mvc(d.cages[c].rest);
    std::vector<double> w(8);
    mvc(p, w.begin());
    Vec3 t{0, 0, 0};
    for (int k = 0; k < 8; ++k) t = add(t, mul(w[k], leaf[s.global_vertices(c)[k]]));
    EXPECT_LT(norm(sub(s.evaluate(p, c, B), t)), 1e-14);
    EXPECT_EQ(s.row(p, c).entries.size(), 8u) << "no join data where d = 1";
  }
  EXPECT_GT(with_d1, 100);
}

// ------------------------------------------------------------------ h per border (§5.5)
TEST(Cage_system, h_per_border_is_C1_and_acts_near_its_border_only) {
  std::mt19937 rng(13);
  // Three cells along x; the middle cell (1) has borders with 0 (x = 1) and 2 (x = 2).
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {3, 1, 1}, 3, 1, 1, Coordinate_type::mean_value, 0.5);
  deform_all(d, bend);
  const Cage_system plain(d);
  d.cages[1].border_h.push_back({0, 0.1});
  d.cages[0].border_h.push_back({1, 0.3});  // the other side of the same border, its own value
  const Cage_system own(d);
  EXPECT_EQ(own.border_h(1, 0), 0.1);
  EXPECT_EQ(own.border_h(1, 2), 0.5);
  EXPECT_EQ(own.border_h(0, 1), 0.3);
  // Reference: d_1 = f_0.5(1 − w_12) · f_0.1(1 − w_10), with w_1j the mean value coordinates of
  // cage 1 summed over the 4 vertices of the shared face (computed here from the rest cage).
  Mean_value_coordinates_3 mvc(d.cages[1].rest);
  const Sine_h_smoothing fh;
  int near0_plain = 0, near0_own = 0, near2_plain = 0, near2_own = 0;
  for (const Vec3& p : random_points(rng, {1.02, 0.02, 0.02}, {1.98, 0.98, 0.98}, 2000)) {
    std::vector<double> w(8);
    mvc(p, w.begin());
    double w10 = 0, w12 = 0;
    for (int k = 0; k < 8; ++k) (d.cages[1].rest.vertices[k][0] < 1.5 ? w10 : w12) += w[k];
    const double ref = fh(1 - w12, 0.5) * fh(1 - w10, 0.1);
    EXPECT_NEAR(own.distance(p, 1), ref, 1e-12);
    EXPECT_NEAR(plain.distance(p, 1), fh((1 - w10) * (1 - w12), 0.5), 1e-12);
    const bool near0 = p[0] < 1.5;
    (near0 ? near0_plain : near2_plain) += plain.distance(p, 1) < 1;
    (near0 ? near0_own : near2_own) += own.distance(p, 1) < 1;
  }
  // A small h on the border with cage 0 frees most of that half from join data; the half near
  // cage 2 keeps its transition zone.
  std::cout << "points with d < 1, half near cage 0: " << near0_plain << " -> " << near0_own
            << ", half near cage 2: " << near2_plain << " -> " << near2_own << "\n";
  EXPECT_GT(near0_plain, 800);
  EXPECT_LT(near0_own, near0_plain / 2);
  EXPECT_GT(near2_own, near2_plain * 8 / 10);
  // d = 0 on the borders and S stays C¹ across every border (both sides with their own h).
  const std::vector<Vec3> B = own.basis(own.deformed_leaf_vertices());
  const Border_result r = probe_borders(own, B, Sine_h_smoothing(), rng);
  EXPECT_GT(r.probes, 0);
  EXPECT_LT(r.max_rel_jump, 1e-6);
  EXPECT_LT(r.max_value_gap, 1e-12);
  EXPECT_NEAR(own.distance({1.0 + 1e-12, 0.5, 0.5}, 1), 0.0, 1e-9);
  // A border h naming a cage that is no neighbour is refused.
  Cage_system_description bad = d;
  bad.cages[0].border_h = {{2, 0.5}};
  EXPECT_THROW(Cage_system{bad}, CMGeom::Invalid_input);
  bad.cages[0].border_h = {{1, 0.0}};
  EXPECT_THROW(Cage_system{bad}, CMGeom::Invalid_input);
  // Errors name the file the description came from.
  bad.source = "system.json";
  try {
    Cage_system{bad};
    ADD_FAILURE() << "a border h of 0 was accepted";
  } catch (const CMGeom::Invalid_input& e) {
    EXPECT_EQ(std::string(e.what()), "system.json: cage 0: border h for cage 1: h must be in (0, 1]");
  }
}

TEST(Cage_system, one_cage_is_the_plain_coordinates) {
  std::mt19937 rng(5);
  for (Coordinate_type type : {Coordinate_type::mean_value, Coordinate_type::green}) {
    Cage_system_description d = make_grid_cage_system({0, 0, 0}, {1, 2, 1}, 1, 1, 1, type, 0.5);
    deform_all(d, bend);
    const Cage_system s(d);
    EXPECT_EQ(s.number_of_join_cages(), 0u);
    const std::vector<Vec3> pts = random_points(rng, {-0.2, -0.2, -0.2}, {1.2, 2.2, 1.2}, 300);
    const Cage_system_binding<double> b = s.bind(pts);
    std::vector<Vec3> out;
    b.deform(s.basis(s.deformed_leaf_vertices()), out);
    const Any_cage_coordinates plain = make_cage_coordinates(type, d.cages[0].rest);
    const Cage_binding<double> pb = bind_points(plain, pts);
    std::vector<Vec3> ref;
    pb.deform(plain.deformation_rule(), d.cages[0].deformed, ref);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      EXPECT_EQ(b.influence()[i], 1.0f);
      EXPECT_LT(norm(sub(out[i], ref[i])), 1e-13) << to_string(type);
    }
  }
}

TEST(Cage_system, global_affine_map_is_reproduced) {
  std::mt19937 rng(9);
  const double A[3][4] = {{1.1, 0.3, -0.2, 0.5}, {-0.1, 0.9, 0.4, -1}, {0.2, 0.1, 1.3, 2}};
  auto affine = [&](const Vec3& p) {
    Vec3 r;
    for (int a = 0; a < 3; ++a) r[a] = A[a][0] * p[0] + A[a][1] * p[1] + A[a][2] * p[2] + A[a][3];
    return r;
  };
  for (const std::array<int, 3> g :
       {std::array<int, 3>{2, 1, 1}, std::array<int, 3>{2, 2, 1}, std::array<int, 3>{3, 3, 3}}) {
    Cage_system_description d =
        make_grid_cage_system({0, 0, 0}, {2, 1.5, 1}, g[0], g[1], g[2], Coordinate_type::mean_value, 0.6);
    for (auto& c : d.cages)
      for (std::size_t k = 0; k < 8; ++k) c.deformed[k] = affine(c.rest.vertices[k]);
    const Cage_system s(d);
    const std::vector<Vec3> pts = random_points(rng, {0, 0, 0}, {2, 1.5, 1}, 500);
    const Cage_system_binding<double> b = s.bind(pts);
    EXPECT_EQ(b.outside(), 0u);
    EXPECT_GT(b.joined_points(), 0u);
    std::vector<Vec3> out;
    b.deform(s.basis(s.deformed_leaf_vertices()), out);
    for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_LT(norm(sub(out[i], affine(pts[i]))), 1e-9);
  }
}

TEST(Cage_system, harmonic_parent_uses_the_lambda_rule_outside) {
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {1, 1, 1}, 1, 1, 1);
  Cage_description P =
      make_grid_cage_system({-0.25, -0.25, -0.25}, {1.25, 1.25, 1.25}, 1, 1, 1, Coordinate_type::harmonic).cages[0];
  P.harmonic.resolution = 16;
  d.cages.push_back(P);
  d.cages[0].parents.push_back({1, {0, 1, 2, 3, 4, 5, 6, 7}});
  const Cage_system s(d);
  std::vector<std::vector<Vec3>> pose{d.cages[0].rest.vertices, d.cages[1].rest.vertices};
  const Vec3 t{0.6, 0.4, 0.5}, shift{1, 2, 3};
  pose[0][7] = add(pose[0][7], t);  // (1,1,1) + t is outside P: harmonic coordinates undefined
  for (Vec3& v : pose[1]) v = add(v, shift);
  const std::vector<Vec3> moved = s.deformed_leaf_vertices(pose);
  const std::uint32_t g = s.global_vertices(0)[7];
  EXPECT_LT(norm(sub(moved[g], add(add(s.leaf_vertices()[g], t), shift))), 1e-9);
  EXPECT_LT(norm(sub(moved[s.global_vertices(0)[0]], add(s.leaf_vertices()[s.global_vertices(0)[0]], shift))), 1e-9);
}

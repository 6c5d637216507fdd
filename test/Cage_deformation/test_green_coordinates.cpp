// Tests of the Green coordinates: rest pose, precision under similarities (not under shear), the
// stretch factor, boundary probes and the continuity of the exterior extension.
#include "cage_coordinates_test_util.h"

// ================================================================== Green coordinates
TEST(CAGE_SUITE(Cage_Green), rest_pose_and_sum_of_vertex_terms) {
  std::mt19937 rng(21);
  for (const Triangle_cage& cage : {cube_cage(), l_cage()}) {
    Green_coordinates_3 gc(cage);
    const double L = cage.bbox_diagonal();
    const std::size_t n = cage.vertices.size();
    std::vector<Vec3> B = basis_of(gc.deformation_rule(), cage.vertices);
    for (const Vec3& x : random_points(rng, {-1, -1, -1}, {3, 3, 2}, 2000)) {
      Coordinate_status st;
      std::vector<double> w = coordinates(gc, x, &st);
      ASSERT_TRUE(all_finite(w));
      // interior: the integrals alone; exterior: with the exit-face continuation
      EXPECT_LT(norm(sub(combine(w, B), x)), 1e-9 * L);
      EXPECT_NEAR(sum_of(w, n), 1.0, 1e-9);
      const double wind = gc.winding_number(x);
      EXPECT_TRUE(std::abs(wind) < 1e-9 || std::abs(wind - 1) < 1e-9) << wind;
      EXPECT_EQ(st, wind > 0.5 ? Coordinate_status::regular : Coordinate_status::extended);
    }
  }
}

TEST(CAGE_SUITE(Cage_Green), exact_under_similarities_not_under_shear) {
  std::mt19937 rng(23);
  Triangle_cage cage = l_cage();
  Green_coordinates_3 gc(cage);
  const double L = cage.bbox_diagonal();
  std::vector<Vec3> pts = random_points(rng, {-0.7, -0.7, -0.7}, {2.7, 2.7, 1.7}, 400);
  Cage_binding<double> b = bind_points(gc, pts);
  for (double scale : {1.0, 1.5, 0.3}) {
    Affine a = random_similarity(rng, scale);
    std::vector<Vec3> out;
    b.deform(gc.deformation_rule(), transformed(cage.vertices, a), out);
    for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_LT(norm(sub(out[i], a(pts[i]))), 1e-9 * L * scale);
  }
  // A non-uniform scale is not reproduced (Green coordinates are quasi-conformal).
  Affine s{{{2, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0, 0, 0}};
  std::vector<Vec3> out;
  b.deform(gc.deformation_rule(), transformed(cage.vertices, s), out);
  double emax = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) emax = std::max(emax, norm(sub(out[i], s(pts[i]))));
  EXPECT_GT(emax, 1e-3);
}

TEST(CAGE_SUITE(Cage_Green), stretch_factor) {
  Triangle_cage cage = cube_cage();
  Green_rule rule(cage);
  std::vector<Vec3> B = basis_of(rule, cage.vertices);
  const std::size_t n = cage.vertices.size();
  for (std::size_t j = 0; j < cage.triangles.size(); ++j) EXPECT_NEAR(norm(B[n + j]), 1.0, 1e-15);
  std::vector<Vec3> scaled;
  for (const Vec3& p : cage.vertices) scaled.push_back(mul(2.5, p));
  B = basis_of(rule, scaled);
  for (std::size_t j = 0; j < cage.triangles.size(); ++j) EXPECT_NEAR(norm(B[n + j]), 2.5, 1e-14);
}

TEST(CAGE_SUITE(Cage_Green), boundary_probes_finite_and_reproducing) {
  Triangle_cage cage = l_cage();
  Green_coordinates_3 gc(cage);
  const double L = cage.bbox_diagonal();
  const std::size_t n = cage.vertices.size();
  std::vector<Vec3> B = basis_of(gc.deformation_rule(), cage.vertices);
  std::vector<Vec3> probes = cage.vertices;
  for (const auto& t : cage.triangles) {
    probes.push_back(mul(0.5, add(cage.vertices[t[0]], cage.vertices[t[1]])));
    probes.push_back(mul(1.0 / 3, add(add(cage.vertices[t[0]], cage.vertices[t[1]]), cage.vertices[t[2]])));
  }
  probes.push_back({0.5, 1, 0.5});  // interior point in a face plane
  probes.push_back({2.5, 1, 0.5});  // exterior point in a face plane
  // exterior points on the lines of cage edges (the edge integral's two forms meet there)
  probes.push_back({3, 0, 0});
  probes.push_back({-1, 0, 0});
  probes.push_back({0, 0, -1.5});
  probes.push_back({2, 2, 2});
  for (const Vec3& x : probes) {
    Coordinate_status st;
    std::vector<double> w = coordinates(gc, x, &st);
    ASSERT_TRUE(all_finite(w));
    EXPECT_LT(norm(sub(combine(w, B), x)), 1e-9 * L);
    EXPECT_NEAR(sum_of(w, n), 1.0, 1e-8);
  }
}

TEST(CAGE_SUITE(Cage_Green), exterior_extension_continuous_across_face) {
  std::mt19937 rng(29);
  Triangle_cage cage = l_cage();
  Green_coordinates_3 gc(cage);
  // A deformation that is not a similarity, so continuity is a real property.
  std::vector<Vec3> def = cage.vertices;
  std::uniform_real_distribution<double> U(-0.2, 0.2);
  for (Vec3& p : def)
    for (double& c : p) c += U(rng);
  std::vector<Vec3> B = basis_of(gc.deformation_rule(), def);
  for (std::size_t t = 0; t < cage.triangles.size(); ++t) {
    const auto& tr = cage.triangles[t];
    const Vec3 c = mul(1.0 / 3, add(add(cage.vertices[tr[0]], cage.vertices[tr[1]]), cage.vertices[tr[2]]));
    internal::Cage_geometry geom(cage);
    const Vec3 nrm = geom.normal[t];
    const Vec3 on = combine(coordinates(gc, c), B);
    double prev = 1e300;
    for (double eps : {1e-2, 1e-3, 1e-4, 1e-6}) {
      Coordinate_status si, so;
      const Vec3 in = combine(coordinates(gc, sub(c, mul(eps, nrm)), &si), B);
      const Vec3 out = combine(coordinates(gc, add(c, mul(eps, nrm)), &so), B);
      EXPECT_EQ(si, Coordinate_status::regular);
      EXPECT_EQ(so, Coordinate_status::extended);
      const double jump = norm(sub(in, out));
      EXPECT_LT(jump, 20 * eps) << "face " << t << " eps " << eps;
      EXPECT_LT(norm(sub(on, out)), 20 * eps);
      EXPECT_LE(jump, prev * 1.01 + 1e-12);
      prev = jump;
    }
  }
}

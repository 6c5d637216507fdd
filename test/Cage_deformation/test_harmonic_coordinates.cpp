// Tests of the harmonic coordinates: rest pose, affine maps, partition of unity, non-negativity,
// interpolation of the closest-point values, flagging of outside points, the C¹ tricubic lookup.
#include "cage_coordinates_test_util.h"

// ================================================================== harmonic coordinates
namespace {
Harmonic_options harmonic_options(int R, Harmonic_interpolation interp,
                                  Harmonic_boundary_values bv = Harmonic_boundary_values::mean_value) {
  Harmonic_options o;
  o.resolution = R;
  o.interpolation = interp;
  o.boundary_values = bv;
  return o;
}
}  // namespace

TEST(CAGE_SUITE(Cage_Harmonic), rest_pose_affine_maps_partition_of_unity) {
  std::mt19937 rng(41);
  // A rotated L so that the cage is not aligned with the grid: points near the cage then have
  // stencils that leave the domain (status approximate) and must still reproduce affine maps.
  const Affine rot = random_similarity(rng, 1.0);
  Triangle_cage cage = l_cage();
  cage.vertices = transformed(cage.vertices, rot);
  const double L = cage.bbox_diagonal();
  for (auto interp : {Harmonic_interpolation::trilinear, Harmonic_interpolation::tricubic}) {
    Harmonic_coordinates_3 hc(cage, harmonic_options(24, interp));
    EXPECT_LT(hc.solver_residual(), 1e-11);
    std::vector<Vec3> pts;
    for (const Vec3& p : random_points(rng, {0, 0, 0}, {2, 2, 1}, 3000))
      if (!(p[0] > 1 && p[1] > 1)) pts.push_back(rot(p));
    Cage_binding<double> b = bind_points(hc, pts);
    EXPECT_GT(b.count(Coordinate_status::approximate), 10u);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      ASSERT_NE(b.status()[i], Coordinate_status::undefined);
      double s = 0;
      for (std::size_t k = 0; k < b.number_of_coordinates(); ++k) s += b.weight(i, k);
      EXPECT_NEAR(s, 1.0, 1e-9);
    }
    for (int trial = 0; trial < 3; ++trial) {
      Affine a = trial == 0 ? Affine{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0, 0, 0}} : random_affine(rng);
      std::vector<Vec3> out;
      b.deform(hc.deformation_rule(), transformed(cage.vertices, a), out);
      double emax = 0;
      for (std::size_t i = 0; i < pts.size(); ++i) emax = std::max(emax, norm(sub(out[i], a(pts[i]))));
      EXPECT_LT(emax, 1e-9 * L) << "trial " << trial;
    }
  }
}

TEST(CAGE_SUITE(Cage_Harmonic), non_negative_and_interpolating_with_closest_point_values) {
  std::mt19937 rng(43);
  Triangle_cage cage = l_cage();
  Harmonic_coordinates_3 hc(
      cage, harmonic_options(32, Harmonic_interpolation::trilinear, Harmonic_boundary_values::closest_point));
  const double h = hc.spacing();
  double worst_repro = 0;
  for (const Vec3& x : random_points(rng, {0, 0, 0}, {2, 2, 1}, 2000)) {
    if (x[0] > 1 && x[1] > 1) continue;
    Coordinate_status st;
    std::vector<double> w = coordinates(hc, x, &st);
    ASSERT_NE(st, Coordinate_status::undefined);
    for (double v : w) {
      EXPECT_GE(v, -1e-12);
      EXPECT_LE(v, 1 + 1e-12);
    }
    EXPECT_NEAR(sum_of(w, w.size()), 1.0, 1e-9);
    worst_repro = std::max(worst_repro, norm(sub(combine(w, cage.vertices), x)));
  }
  // linear precision only up to the discretisation: O(h)
  EXPECT_LT(worst_repro, h);
  // close to a cage vertex the coordinate of that vertex dominates
  std::vector<double> w = coordinates(hc, Vec3{0.02, 0.02, 0.02});
  EXPECT_GT(w[0], 0.8);
}

TEST(CAGE_SUITE(Cage_Harmonic), outside_points_flagged) {
  Triangle_cage cage = l_cage();
  Harmonic_coordinates_3 hc(cage, harmonic_options(16, Harmonic_interpolation::tricubic));
  Coordinate_status st;
  for (Vec3 x : {Vec3{1.5, 1.5, 0.5}, Vec3{-0.3, 0.5, 0.5}, Vec3{5, 5, 5}, Vec3{0.5, 0.5, 1.01}}) {
    std::vector<double> w = coordinates(hc, x, &st);
    EXPECT_EQ(st, Coordinate_status::undefined);
    for (double v : w) EXPECT_EQ(v, 0.0);
  }
  // just inside a face: the tricubic stencil reaches exterior nodes
  std::vector<double> w = coordinates(hc, Vec3{0.5, 0.5, 0.99}, &st);
  EXPECT_EQ(st, Coordinate_status::approximate);
  EXPECT_NEAR(sum_of(w, w.size()), 1.0, 1e-9);
  w = coordinates(hc, Vec3{0.5, 0.5, 0.5}, &st);
  EXPECT_EQ(st, Coordinate_status::regular);
  // on the cage: the hat functions exactly (vertices, edge midpoints)
  for (std::size_t i = 0; i < cage.vertices.size(); ++i) {
    w = coordinates(hc, cage.vertices[i], &st);
    EXPECT_EQ(st, Coordinate_status::on_boundary);
    for (std::size_t k = 0; k < w.size(); ++k) EXPECT_EQ(w[k], k == i ? 1.0 : 0.0);
  }
  const auto& t = cage.triangles[5];
  w = coordinates(hc, mul(0.5, add(cage.vertices[t[0]], cage.vertices[t[2]])), &st);
  EXPECT_EQ(st, Coordinate_status::on_boundary);
  EXPECT_NEAR(w[t[0]], 0.5, 1e-14);
  EXPECT_NEAR(w[t[2]], 0.5, 1e-14);
}

// Harmonic_outside::mean_value: a point outside takes the cage's mean value coordinates (the same
// numbers as Mean_value_coordinates_3 gives), status extended; inside nothing changes; across a
// face the weights jump by little (both sides tend to the hat functions), where the default's
// zeros jump by the weights themselves.
TEST(CAGE_SUITE(Cage_Harmonic), outside_points_take_mean_value_coordinates_when_asked) {
  std::mt19937 rng(47);
  Triangle_cage cage = l_cage();
  Harmonic_options o = harmonic_options(16, Harmonic_interpolation::tricubic);
  const Harmonic_coordinates_3 strict(cage, o);
  o.outside = Harmonic_outside::mean_value;
  const Harmonic_coordinates_3 hc(cage, o);
  const Mean_value_coordinates_3 mvc(cage);
  Coordinate_status st;
  for (Vec3 x : {Vec3{1.5, 1.5, 0.5}, Vec3{-0.3, 0.5, 0.5}, Vec3{5, 5, 5}, Vec3{0.5, 0.5, 1.01}}) {
    const std::vector<double> w = coordinates(hc, x, &st);
    EXPECT_EQ(st, Coordinate_status::extended);
    EXPECT_EQ(w, coordinates(mvc, x));
    EXPECT_NEAR(sum_of(w, w.size()), 1.0, 1e-9);
    EXPECT_LT(norm(sub(combine(w, cage.vertices), x)), 1e-9);  // linear precision outside too
  }
  // inside (and on the cage): the same numbers and status as without the option
  for (const Vec3& x : random_points(rng, {0, 0, 0}, {2, 2, 1}, 300)) {
    if (x[0] > 1 && x[1] > 1) continue;
    Coordinate_status a, b;
    EXPECT_EQ(coordinates(hc, x, &a), coordinates(strict, x, &b));
    EXPECT_EQ(a, b);
  }
  // across the top face z = 1: the weights jump by the grid's error near the cage, which shrinks as
  // the grid gets finer (the default's zeros outside jump by the weights themselves)
  auto jump_across_top = [&](const Harmonic_coordinates_3& c, double& largest) {
    double jump = 0;
    largest = 0;
    for (const Vec3& p : {Vec3{0.37, 0.41, 1}, Vec3{1.3, 0.6, 1}, Vec3{0.55, 1.45, 1}}) {
      const std::vector<double> in = coordinates(c, Vec3{p[0], p[1], 1 - 1e-6}, &st);
      EXPECT_NE(st, Coordinate_status::extended);
      const std::vector<double> out = coordinates(c, Vec3{p[0], p[1], 1 + 1e-6}, &st);
      EXPECT_EQ(st, Coordinate_status::extended);
      for (std::size_t k = 0; k < in.size(); ++k) {
        jump = std::max(jump, std::abs(in[k] - out[k]));
        largest = std::max(largest, std::abs(in[k]));
      }
    }
    return jump;
  };
  std::vector<double> jumps;
  for (int R : {16, 32, 48}) {
    Harmonic_options r = o;
    r.resolution = R;
    double largest = 0;
    jumps.push_back(jump_across_top(Harmonic_coordinates_3(cage, r), largest));
    EXPECT_LT(jumps.back(), 0.1 * largest) << "resolution " << R;
  }
  EXPECT_LT(jumps[1], 0.8 * jumps[0]);
  EXPECT_LT(jumps[2], 0.8 * jumps[1]);
}

TEST(CAGE_SUITE(Cage_Harmonic), tricubic_lookup_is_C1) {
  // Gradient (central differences) on both sides of a grid plane: continuous for the cubic
  // B-spline lookup, jumping for the trilinear one.
  Triangle_cage cage = cube_cage();
  Harmonic_coordinates_3 cub(cage, harmonic_options(16, Harmonic_interpolation::tricubic));
  Harmonic_coordinates_3 lin(cage, harmonic_options(16, Harmonic_interpolation::trilinear));
  const double h = cub.spacing();
  // find a grid plane x = origin + i h near the middle: origin = -3 h
  const double plane = -3 * h + 11 * h;
  const double d = 1e-4 * h;
  auto grad_x = [&](const Harmonic_coordinates_3& hc, double x0, std::size_t k) {
    std::vector<double> a = coordinates(hc, Vec3{x0 + d, 0.43, 0.37});
    std::vector<double> b = coordinates(hc, Vec3{x0 - d, 0.43, 0.37});
    return (a[k] - b[k]) / (2 * d);
  };
  double jump_cub = 0, jump_lin = 0;
  for (std::size_t k = 0; k < 8; ++k) {
    jump_cub = std::max(jump_cub, std::abs(grad_x(cub, plane + 3 * d, k) - grad_x(cub, plane - 3 * d, k)));
    jump_lin = std::max(jump_lin, std::abs(grad_x(lin, plane + 3 * d, k) - grad_x(lin, plane - 3 * d, k)));
  }
  EXPECT_LT(jump_cub, 1e-3);
  EXPECT_GT(jump_lin, 10 * jump_cub);
}

// Tests of the mean value coordinates: reproduction, partition of unity, positivity in a convex
// cage, linear precision under affine maps, degenerate probes, scale invariance, continuity across
// face planes, and an independent quadrature on the shared cages.
#include "cage_coordinates_test_util.h"

namespace {

std::string data_dir() { return CMGEOM_DATA_DIR; }

struct Model {
  std::string name, mesh, cage;
};
std::vector<Model> data_models() {
  const std::string d = data_dir() + "/cages/";
  return {{"hand", d + "pgc/hand/hand.obj", d + "pgc/hand/cage.obj"},
          {"armadilloman", d + "pgc/armadilloman/armadilloman.obj", d + "pgc/armadilloman/cage.obj"},
          {"octopus", d + "pgc/octopus/octupus.obj", d + "pgc/octopus/cage.obj"},
          {"elephant", d + "pgc/elephant/elephant.obj", d + "pgc/elephant/cage.obj"},
          {"Ogre", d + "qmvc/Ogre.obj", d + "qmvc/Ogre_Cage.obj"},
          {"ManHead", d + "qmvc/ManHead.obj", d + "qmvc/ManHead_Cage.obj"},
          {"Beast", d + "qmvc/Beast.obj", d + "qmvc/Beast_Cage.obj"},
          {"giraffe", d + "pgc/giraffe/giraffe.obj", d + "pgc/giraffe/cage.obj"}};
}

}  // namespace

// ================================================================== mean value coordinates
TEST(CAGE_SUITE(Cage_MVC), rest_pose_and_partition_of_unity) {
  std::mt19937 rng(7);
  for (const Triangle_cage& cage : {cube_cage(), l_cage()}) {
    Mean_value_coordinates_3 mvc(cage);
    const double L = cage.bbox_diagonal();
    // Inside and outside the cage (MVC are defined everywhere).
    for (const Vec3& x : random_points(rng, {-1, -1, -1}, {3, 3, 2}, 3000)) {
      std::vector<double> w = coordinates(mvc, x);
      ASSERT_TRUE(all_finite(w));
      EXPECT_NEAR(sum_of(w, w.size()), 1.0, 1e-12);
      EXPECT_LT(norm(sub(combine(w, cage.vertices), x)), 1e-9 * L) << x[0] << " " << x[1] << " " << x[2];
    }
  }
}

TEST(CAGE_SUITE(Cage_MVC), positive_inside_convex_cage) {
  std::mt19937 rng(3);
  Mean_value_coordinates_3 mvc(cube_cage());
  for (const Vec3& x : random_points(rng, {0.01, 0.01, 0.01}, {0.99, 0.99, 0.99}, 500))
    for (double w : coordinates(mvc, x)) EXPECT_GT(w, 0.0);
}

TEST(CAGE_SUITE(Cage_MVC), linear_precision_under_random_affine_maps) {
  std::mt19937 rng(11);
  Triangle_cage cage = l_cage();
  Mean_value_coordinates_3 mvc(cage);
  std::vector<Vec3> pts = random_points(rng, {-0.5, -0.5, -0.5}, {2.5, 2.5, 1.5}, 500);
  Cage_binding<double> b = bind_points(mvc, pts);
  for (int trial = 0; trial < 5; ++trial) {
    Affine a = random_affine(rng);
    std::vector<Vec3> def = transformed(cage.vertices, a), out;
    b.deform(mvc.deformation_rule(), def, out);
    for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_LT(norm(sub(out[i], a(pts[i]))), 1e-9 * cage.bbox_diagonal());
  }
}

TEST(CAGE_SUITE(Cage_MVC), exact_on_vertices_edges_faces) {
  Triangle_cage cage = l_cage();
  Mean_value_coordinates_3 mvc(cage);
  const std::size_t n = cage.vertices.size();
  Coordinate_status st;
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double> w = coordinates(mvc, cage.vertices[i], &st);
    EXPECT_EQ(st, Coordinate_status::on_boundary);
    for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(w[k], k == i ? 1.0 : 0.0);
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0.05, 0.95);
  for (const auto& t : cage.triangles) {
    // edge midpoint: 1/2, 1/2
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k], b = t[(k + 1) % 3];
      std::vector<double> w = coordinates(mvc, mul(0.5, add(cage.vertices[a], cage.vertices[b])), &st);
      EXPECT_EQ(st, Coordinate_status::on_boundary);
      EXPECT_NEAR(w[a], 0.5, 1e-14);
      EXPECT_NEAR(w[b], 0.5, 1e-14);
      EXPECT_NEAR(sum_of(w, n), 1.0, 1e-14);
    }
    // random point on the face: its barycentric coordinates
    double b0 = U(rng), b1 = U(rng) * (1 - b0), b2 = 1 - b0 - b1;
    Vec3 x = add(add(mul(b0, cage.vertices[t[0]]), mul(b1, cage.vertices[t[1]])), mul(b2, cage.vertices[t[2]]));
    std::vector<double> w = coordinates(mvc, x, &st);
    EXPECT_EQ(st, Coordinate_status::on_boundary);
    EXPECT_NEAR(w[t[0]], b0, 1e-12);
    EXPECT_NEAR(w[t[1]], b1, 1e-12);
    EXPECT_NEAR(w[t[2]], b2, 1e-12);
  }
}

TEST(CAGE_SUITE(Cage_MVC), face_planes_and_continuity) {
  Triangle_cage cage = l_cage();
  Mean_value_coordinates_3 mvc(cage);
  const double L = cage.bbox_diagonal();
  // (0.5, 1, 0.5) is inside the cage, in the plane y = 1 of the top face of cube (1,0,0);
  // (2.5, 1, 0.5) is outside, in the same plane; (1.5, 1, 0.5) is on that face.
  for (Vec3 x :
       {Vec3{0.5, 1, 0.5}, Vec3{2.5, 1, 0.5}, Vec3{1.5, 1, 0.5}, Vec3{1, 1, 0.5}, Vec3{3, 1, 1}, Vec3{1, 3, 0}}) {
    std::vector<double> w0 = coordinates(mvc, x);
    ASSERT_TRUE(all_finite(w0));
    EXPECT_LT(norm(sub(combine(w0, cage.vertices), x)), 1e-9 * L);
    // approaching from both sides of the plane: values converge to the value in the plane
    for (double eps : {1e-3, 1e-5, 1e-7, 1e-10, 1e-12}) {
      for (double sgn : {-1.0, 1.0}) {
        std::vector<double> w = coordinates(mvc, add(x, {0, sgn * eps, 0}));
        ASSERT_TRUE(all_finite(w));
        double diff = 0;
        for (std::size_t k = 0; k < w.size(); ++k) diff = std::max(diff, std::abs(w[k] - w0[k]));
        EXPECT_LT(diff, 50 * eps + 1e-7) << "eps " << eps << " at " << x[0] << "," << x[2];
      }
    }
  }
}

TEST(CAGE_SUITE(Cage_MVC), scale_invariance) {
  std::mt19937 rng(9);
  Triangle_cage c1 = l_cage();
  std::vector<Vec3> pts = random_points(rng, {-0.5, -0.5, -0.5}, {2.5, 2.5, 1.5}, 200);
  // some points on the cage too
  pts.push_back({1.5, 1, 0.5});
  pts.push_back({1, 1, 0.5});
  pts.push_back({0.5, 1, 0.5});
  Mean_value_coordinates_3 m1(c1);
  Green_coordinates_3 g1(c1);
  for (double s : {1e-3, 1e3}) {
    const Vec3 off{7 * s, -3 * s, 2 * s};
    Triangle_cage cs = l_cage(s, off);
    Mean_value_coordinates_3 ms(cs);
    Green_coordinates_3 gs(cs);
    for (const Vec3& x : pts) {
      const Vec3 xs = add(mul(s, x), off);
      std::vector<double> a = coordinates(m1, x), b = coordinates(ms, xs);
      for (std::size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(a[k], b[k], 1e-9);
      std::vector<double> ga = coordinates(g1, x), gb = coordinates(gs, xs);
      // vertex terms are scale free, face terms scale like a length
      for (std::size_t k = 0; k < ga.size(); ++k) EXPECT_NEAR(ga[k], k < c1.vertices.size() ? gb[k] : gb[k] / s, 1e-8);
    }
  }
}

TEST(CAGE_SUITE(Cage_MVC), permuting_vertices_permutes_weights) {
  Triangle_cage c = l_cage();
  const std::size_t n = c.vertices.size();
  std::vector<std::uint32_t> perm(n);
  for (std::size_t i = 0; i < n; ++i) perm[i] = std::uint32_t((i * 7 + 3) % n);
  Triangle_cage p;
  p.vertices.resize(n);
  for (std::size_t i = 0; i < n; ++i) p.vertices[perm[i]] = c.vertices[i];
  for (auto t : c.triangles) p.triangles.push_back({perm[t[0]], perm[t[1]], perm[t[2]]});
  Mean_value_coordinates_3 a(c), b(p);
  Vec3 x{0.4, 0.7, 0.3};
  std::vector<double> wa = coordinates(a, x), wb = coordinates(b, x);
  for (std::size_t i = 0; i < n; ++i) EXPECT_NEAR(wa[i], wb[perm[i]], 1e-14);
}

// Independent slow reference: w_i(x) = integral over the cage of hat_i(xi) n.(xi - x)/|xi - x|^4
// (the mean value definition of Ju et al. written over the surface instead of the unit sphere;
// the signed solid-angle element handles rays that cross the cage several times), by a degree-5
// Dunavant rule on a 32 x 32 subdivision of every triangle.
std::vector<double> mvc_quadrature(const Triangle_cage& cage, const Vec3& x) {
  static const double W[7] = {0.225,
                              0.132394152788506,
                              0.132394152788506,
                              0.132394152788506,
                              0.125939180544827,
                              0.125939180544827,
                              0.125939180544827};
  const double a1 = 0.059715871789770, b1 = 0.470142064105115;
  const double a2 = 0.797426985353087, b2 = 0.101286507323456;
  const double P[7][3] = {
      {1. / 3, 1. / 3, 1. / 3}, {a1, b1, b1}, {b1, a1, b1}, {b1, b1, a1}, {a2, b2, b2}, {b2, a2, b2}, {b2, b2, a2}};
  const int S = 32;
  std::vector<double> w(cage.vertices.size(), 0.0);
  for (const auto& t : cage.triangles) {
    const Vec3 &A = cage.vertices[t[0]], &B = cage.vertices[t[1]], &C = cage.vertices[t[2]];
    const Vec3 nn = cross(sub(B, A), sub(C, A));
    const double area = 0.5 * norm(nn) / (S * S);
    const Vec3 n = mul(1.0 / norm(nn), nn);
    // sub-triangles in barycentric (i, j) grid, both orientations
    for (int i = 0; i < S; ++i)
      for (int j = 0; i + j < S; ++j)
        for (int up = 0; up < 2; ++up) {
          if (up && i + j + 1 >= S) continue;
          std::array<std::array<double, 2>, 3> c;  // (beta1, beta2) corners
          if (!up)
            c = {{{double(i), double(j)}, {double(i + 1), double(j)}, {double(i), double(j + 1)}}};
          else
            c = {{{double(i + 1), double(j)}, {double(i + 1), double(j + 1)}, {double(i), double(j + 1)}}};
          for (int q = 0; q < 7; ++q) {
            const double b1q = (P[q][0] * c[0][0] + P[q][1] * c[1][0] + P[q][2] * c[2][0]) / S;
            const double b2q = (P[q][0] * c[0][1] + P[q][1] * c[1][1] + P[q][2] * c[2][1]) / S;
            const double b0q = 1 - b1q - b2q;
            const Vec3 xi = add(add(mul(b0q, A), mul(b1q, B)), mul(b2q, C));
            const Vec3 d = sub(xi, x);
            const double r2 = dot(d, d);
            const double f = W[q] * area * dot(n, d) / (r2 * r2);
            w[t[0]] += f * b0q;
            w[t[1]] += f * b1q;
            w[t[2]] += f * b2q;
          }
        }
  }
  double s = 0;
  for (double v : w) s += v;
  for (double& v : w) v /= s;
  return w;
}

TEST(CAGE_SUITE(Cage_MVC), matches_independent_quadrature_on_shared_cages) {
  if (!std::filesystem::exists(data_dir() + "/cages"))
    GTEST_SKIP() << "shared data not found: " << data_dir() << "/cages";
  int checked = 0;
  for (const Model& m : data_models()) {
    std::vector<Vec3> cp, mp;
    std::vector<std::vector<std::size_t>> cf, mf;
    ASSERT_TRUE(read_soup(m.cage, cp, cf)) << m.cage;
    ASSERT_TRUE(read_soup(m.mesh, mp, mf)) << m.mesh;
    Triangle_cage cage = make_triangle_cage(cp, cf);
    validate_cage(cage, m.cage);
    Mean_value_coordinates_3 mvc(cage);
    internal::Cage_geometry geom(cage);
    const double L = cage.bbox_diagonal();
    int used = 0;
    for (std::size_t v = 0; v < mp.size() && used < 6; v += mp.size() / 97 + 1) {
      double dmin = 1e300;
      for (std::size_t t = 0; t < geom.m; ++t) dmin = std::min(dmin, geom.distance_to_triangle(t, mp[v]));
      if (dmin < 0.015 * L) continue;  // the quadrature needs a smooth integrand
      std::vector<double> w = coordinates(mvc, mp[v]);
      std::vector<double> ref = mvc_quadrature(cage, mp[v]);
      double wmax = 0;
      for (double x : ref) wmax = std::max(wmax, std::abs(x));
      for (std::size_t k = 0; k < w.size(); ++k)
        EXPECT_NEAR(w[k], ref[k], 1e-6 * wmax) << m.name << " vertex " << v << " coord " << k;
      ++used;
      ++checked;
    }
    EXPECT_GT(used, 0) << m.name;
  }
  EXPECT_GT(checked, 10);
}

TEST(CAGE_SUITE(Cage_MVC), rest_pose_on_shared_models) {
  if (!std::filesystem::exists(data_dir() + "/cages"))
    GTEST_SKIP() << "shared data not found: " << data_dir() << "/cages";
  for (const Model& m : data_models()) {
    std::vector<Vec3> cp, mp;
    std::vector<std::vector<std::size_t>> cf, mf;
    ASSERT_TRUE(read_soup(m.cage, cp, cf));
    ASSERT_TRUE(read_soup(m.mesh, mp, mf));
    Triangle_cage cage = make_triangle_cage(cp, cf);
    validate_cage(cage, m.cage);
    const double L = cage.bbox_diagonal();
    std::vector<Vec3> pts;
    for (std::size_t v = 0; v < mp.size(); v += 7) pts.push_back(mp[v]);
    Mean_value_coordinates_3 mvc(cage);
    Green_coordinates_3 gc(cage);
    Cage_binding<double> bm = bind_points(mvc, pts);
    Cage_binding<double> bg = bind_points(gc, pts);
    std::vector<Vec3> om, og;
    bm.deform(mvc.deformation_rule(), cage.vertices, om);
    bg.deform(gc.deformation_rule(), cage.vertices, og);
    double em = 0, eg = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      em = std::max(em, norm(sub(om[i], pts[i])));
      if (bg.status()[i] == Coordinate_status::regular) eg = std::max(eg, norm(sub(og[i], pts[i])));
    }
    EXPECT_LT(em, 1e-9 * L) << m.name;
    EXPECT_LT(eg, 1e-9 * L) << m.name;
    EXPECT_GT(bg.count(Coordinate_status::regular), pts.size() * 9 / 10) << m.name;
  }
}

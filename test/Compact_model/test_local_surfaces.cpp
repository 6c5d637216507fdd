// Tests of the local surface models of a Compact Model: analytic reproduction (quadric, cone,
// cubic), the local frame, rank-deficient fits, Newton projections, sharp-edge points.
#include "compact_model_test_util.h"

namespace {

// ------------------------------------------------------------------ local surfaces
TEST(CompactModelSurfaces, QuadricReproducesParaboloidInAnyFrame) {
  std::mt19937 rng(7);
  const Local_frame f(Vec3(0.3, -0.2, 1.1), Vec3(0.4, -0.7, 0.6));
  const double a = 0.7, b = -0.3, c = 1.2, d = 0.25, e = -0.4;
  auto h = [&](double x, double y) { return a * x * x + b * x * y + c * y * y + d * x + e * y; };
  const auto pts = sample_local(f, rng, 60, 0.5, h);
  const Fit_result r = fit_quadric(pts);
  ASSERT_TRUE(r.ok);
  EXPECT_NEAR(r.surface.c[0], a, 1e-9);
  EXPECT_NEAR(r.surface.c[1], b, 1e-9);
  EXPECT_NEAR(r.surface.c[2], c, 1e-9);
  EXPECT_NEAR(r.surface.c[3], d, 1e-9);
  EXPECT_NEAR(r.surface.c[4], e, 1e-9);
  EXPECT_LT(r.error, 1e-9);
  for (const Vec3& p : pts) EXPECT_NEAR(evaluate_height(r.surface, p.x, p.y), p.z, 1e-9);
  // Normal at the origin: NS = N - dU - eV (§4.4.1).
  const Vec3 ns = surface_normal(f, r.surface, 0, 0);
  const Vec3 expect = CMGeom::CM::internal::normalized(f.N - d * f.U - e * f.V);
  EXPECT_NEAR(CMGeom::CM::internal::length(ns - expect), 0., 1e-9);
}

TEST(CompactModelSurfaces, FrameFollowsThesisFormula) {
  const Local_frame f(Vec3(), Vec3(1, 2, 2));
  EXPECT_NEAR(f.U.x, 2 / std::sqrt(5.), 1e-15);
  EXPECT_NEAR(f.U.y, -1 / std::sqrt(5.), 1e-15);
  EXPECT_EQ(f.U.z, 0.);
  const Local_frame z(Vec3(), Vec3(0, 0, 3));
  EXPECT_EQ(z.U, Vec3(1, 0, 0));
  EXPECT_EQ(z.V, Vec3(0, 1, 0));
}

TEST(CompactModelSurfaces, ConeModelReproducesCone) {
  std::mt19937 rng(11);
  // Circular cone with its apex at the frame origin and axis -N (points below the apex).
  const Local_frame f(Vec3(1, 2, 3), Vec3(-0.2, 0.5, 0.8));
  const double k = 1.7;
  auto h = [&](double x, double y) { return -k * std::sqrt(x * x + y * y); };
  const auto pts = sample_local(f, rng, 80, 1.0, h);
  const Fit_result cone = fit_cone(pts);
  ASSERT_TRUE(cone.ok);
  EXPECT_LT(cone.error, 1e-9);
  for (const Vec3& p : pts) EXPECT_NEAR(evaluate_height(cone.surface, p.x, p.y), p.z, 1e-9);
  // The quadric cannot: the build would pick the cone (cone-type vertex, §4.4.3).
  EXPECT_GT(fit_quadric(pts).error, 1e-3);
}

TEST(CompactModelSurfaces, ConeModelReproducesCylinderThroughOrigin) {
  // Cylinder of radius r, axis parallel to V, through the origin with N tangent to it:
  // (x - r)^2 + z^2 = r^2  <=>  z^2 = -x^2 + 2 r x, the conical model with a = -1, d = 2r.
  std::mt19937 rng(12);
  const Local_frame f(Vec3(0.5, 0, 0), Vec3(0, 0.3, 1));
  const double r = 0.8;
  auto h = [&](double x, double) { return std::sqrt(std::max(0., -x * x + 2 * r * x)); };
  const auto pts = sample_local(f, rng, 80, 2 * r * 0.999, h, true);
  const Fit_result cone = fit_cone(pts);
  ASSERT_TRUE(cone.ok);
  EXPECT_NEAR(cone.surface.c[0], -1, 1e-9);
  EXPECT_NEAR(cone.surface.c[3], 2 * r, 1e-9);
  for (const Vec3& p : pts) EXPECT_NEAR(evaluate_height(cone.surface, p.x, p.y), p.z, 1e-9);
}

TEST(CompactModelSurfaces, CubicReproducesCubicAndBeatsQuadric) {
  std::mt19937 rng(13);
  const Local_frame f(Vec3(), Vec3(0.1, 0.2, 1));
  auto h = [](double x, double y) { return 0.5 * x * x - 0.2 * y * y + 0.3 * x - 0.7 * x * x * x + 0.4 * x * y * y; };
  const auto pts = sample_local(f, rng, 100, 0.8, h);
  const Fit_result cubic = Cubic_surface_traits().fit(pts);
  ASSERT_TRUE(cubic.ok);
  EXPECT_EQ(cubic.surface.model, CUBIC_MODEL);
  EXPECT_LT(cubic.error, 1e-9);
  for (const Vec3& p : pts) EXPECT_NEAR(evaluate_height(cubic.surface, p.x, p.y), p.z, 1e-9);
  EXPECT_GT(Quadric_surface_traits().fit(pts).error, 1e-3);
}

TEST(CompactModelSurfaces, RankDeficientFitsGiveFiniteSurfaces) {
  std::vector<Vec3> pts = {Vec3(0.1, 0.1, 0.01), Vec3(0.2, 0.2, 0.04)};  // collinear, 2 points
  const Fit_result r = fit_quadric(pts);
  ASSERT_TRUE(r.ok);
  for (double c : r.surface.c) EXPECT_TRUE(std::isfinite(c));
  EXPECT_LT(r.error, 1e-12);  // minimum-norm solution still interpolates
  EXPECT_FALSE(fit_quadric({}).ok);
}

TEST(CompactModelSurfaces, ClosestPointNewtonIsOrthogonalAndCloser) {
  const Local_frame f(Vec3(0.2, 0.1, -0.3), Vec3(0.3, 0.1, 1));
  Local_surface s;
  s.c = {0.9, 0.2, -0.6, 0.1, 0.3, 0, 0, 0, 0};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  for (int i = 0; i < 50; ++i) {
    const Vec3 p = f.to_world(u(rng), u(rng), u(rng));
    double uv[2];
    const Vec3 q = closest_point(f, s, p, Quadric_surface_traits(), uv);
    // q on S, p - q parallel to the normal at q, and no farther than the projection along N.
    EXPECT_NEAR(f.to_local(q).z, evaluate_height(s, uv[0], uv[1]), 1e-12);
    const Vec3 n = surface_normal(f, s, uv[0], uv[1]);
    const Vec3 d = p - q;
    EXPECT_NEAR(CMGeom::CM::internal::length(CMGeom::CM::internal::cross(d, n)), 0., 1e-9);
    EXPECT_LE(CMGeom::CM::internal::length(d), CMGeom::CM::internal::length(p - project_along_normal(f, s, p)) + 1e-12);
  }
}

TEST(CompactModelSurfaces, SharpEdgePointLiesOnBothSurfacesInThePlane) {
  // Two tilted paraboloid pieces meeting at a crease near the x axis.
  const Local_frame f1(Vec3(0, 0, 0), Vec3(0, -0.7, 1)), f2(Vec3(0, 0, 0), Vec3(0, 0.7, 1));
  Local_surface s1, s2;
  s1.c = {0.2, 0, 0.1, 0, 0, 0, 0, 0, 0};
  s2.c = {0.3, 0.05, -0.1, 0, 0, 0, 0, 0, 0};
  const Vec3 t(1, 0, 0);
  for (double x : {-0.4, -0.1, 0.2, 0.5}) {
    const Vec3 p(x, 0.01, 0.02);
    bool ok = false;
    const Vec3 q = sharp_edge_point(f1, s1, f2, s2, p, t, Quadric_surface_traits(), &ok);
    ASSERT_TRUE(ok);
    const Vec3 l1 = f1.to_local(q), l2 = f2.to_local(q);
    EXPECT_NEAR(l1.z, evaluate_height(s1, l1.x, l1.y), 1e-10);
    EXPECT_NEAR(l2.z, evaluate_height(s2, l2.x, l2.y), 1e-10);
    EXPECT_NEAR(CMGeom::CM::internal::dot(q - p, t), 0., 1e-12);
  }
}

// Two surfaces through the vertex (the origin) that bend away from the edge (the x axis) and meet
// far from it: h1 = 3 x^2 and h2 = 3.6 x^2 + k y. In the plane x = 0.1 they intersect at
// y = -0.006 / k, while the edge point p = (0.1, 0, 0) is 0.1 from the vertex. Newton converges
// there, but that point is a spike; the guard returns the start (the mean of the projections
// along N) beyond two reaches, blends between one and two, and is continuous in k.
TEST(CompactModelSurfaces, SharpEdgePointFarFromTheEdgeFallsBackToTheStart) {
  using CMGeom::CM::internal::length;
  const Local_frame f(Vec3(0, 0, 0), Vec3(0, 0, 1));
  const Vec3 p(0.1, 0, 0), t(1, 0, 0);
  auto surfaces = [](double k) {
    Local_surface s1, s2;
    s1.c = {3, 0, 0, 0, 0, 0, 0, 0, 0};
    s2.c = {3.6, 0, 0, 0, k, 0, 0, 0, 0};
    return std::make_pair(s1, s2);
  };
  const Vec3 start(0.1, 0, 0.5 * (0.03 + 0.036));  // both projections along N, averaged
  const double reach = length(p) + length(start - p);
  for (double k : {0.02, 0.025}) {
    const auto [s1, s2] = surfaces(k);
    const Vec3 intersection(0.1, -0.006 / k, 0.03);
    bool ok = false;
    const Vec3 q = sharp_edge_point(f, s1, f, s2, p, t, Quadric_surface_traits(), &ok);
    EXPECT_TRUE(ok);  // Newton converged; the guard, not the old far-jump test, decides
    EXPECT_GT(length(intersection - p), reach);
    EXPECT_LE(length(q - p), 1.25 * reach + 1e-12);
    const double r = length(intersection - p) / reach;
    const double lambda = std::max(0., 2. - r);
    const Vec3 expected = lambda * intersection + (1. - lambda) * start;
    EXPECT_NEAR(length(q - expected), 0., 1e-9) << "k = " << k << ", r = " << r;
  }
  // Continuity: from an intersection within one reach (k = 0.1: 0.06 from p) to one beyond two
  // (k = 0.015), consecutive results move by a small multiple of what the intersection moves (the
  // blend adds |q - start| / reach, at most 2.3, times it); a switch without the blend would jump
  // by |q - start| (0.13 to 0.27) once.
  Vec3 previous = sharp_edge_point(f, surfaces(0.1).first, f, surfaces(0.1).second, p, t);
  EXPECT_NEAR(length(previous - Vec3(0.1, -0.06, 0.03)), 0., 1e-9);  // within reach: unchanged
  for (double k = 0.1 - 1e-4; k > 0.015; k -= 1e-4) {
    const auto [s1, s2] = surfaces(k);
    const Vec3 q = sharp_edge_point(f, s1, f, s2, p, t);
    const double moved = 0.006 / (k * k) * 1e-4;  // |d intersection / dk| times the step
    EXPECT_LE(length(q - previous), 4. * moved + 1e-9) << "k = " << k;
    previous = q;
  }
}

}  // namespace

// Tests of the quadric algebra of Textured_simplification (thesis §3.4): plane quadrics, minimisers,
// singular quadrics, the area distortion.
#include "textured_simplification_test_util.h"

// ------------------------------------------------------------------------- quadric algebra

TEST(TexturedSimplificationQuadric, PlaneQuadricIsSquaredDistance) {
  const TS::internal::Vec3 n{0.0, 0.6, 0.8};
  const double d = -2.0;  // plane 0.6 y + 0.8 z = 2
  const Quadric q = Quadric::plane(n, d, 3.0);
  const TS::internal::Vec3 u{1.5, -1.0, 4.0};
  const double dist = 0.6 * u[1] + 0.8 * u[2] + d;
  EXPECT_NEAR(q(u), 3.0 * dist * dist, 1e-12);
}

TEST(TexturedSimplificationQuadric, MinimiserOfThreePlanesIsTheirIntersection) {
  Quadric q = Quadric::plane({1, 0, 0}, -1.0, 1.0);  // x = 1
  q += Quadric::plane({0, 1, 0}, -2.0, 2.0);         // y = 2
  q += Quadric::plane({0, 0, 1}, 3.0, 0.5);          // z = -3
  const auto u = q.minimiser_on_edge({0, 0, 0}, {1, 2, -2});
  EXPECT_NEAR(u[0], 1.0, 1e-12);
  EXPECT_NEAR(u[1], 2.0, 1e-12);
  EXPECT_NEAR(u[2], -3.0, 1e-12);
  EXPECT_NEAR(q(u), 0.0, 1e-12);
}

TEST(TexturedSimplificationQuadric, SingularQuadricFallsBackToTheSegment) {
  // one plane (rank 1): the free minimiser is undefined; the best point of the segment is used
  const Quadric q = Quadric::plane({0, 0, 1}, 0.0, 1.0);  // z = 0
  const auto u = q.minimiser_on_edge({0, 0, 1}, {2, 0, -3});
  // z(t) = 1 - 4t = 0 at t = 0.25
  EXPECT_NEAR(u[0], 0.5, 1e-12);
  EXPECT_NEAR(u[2], 0.0, 1e-12);
  // constant along the segment (segment inside the plane): the midpoint
  const auto m = q.minimiser_on_edge({0, 0, 0}, {2, 4, 0});
  EXPECT_NEAR(m[0], 1.0, 1e-12);
  EXPECT_NEAR(m[1], 2.0, 1e-12);
  // zero quadric: no NaN
  const auto z = Quadric().minimiser_on_edge({0, 0, 0}, {1, 1, 1});
  EXPECT_TRUE(std::isfinite(z[0]) && std::isfinite(z[1]) && std::isfinite(z[2]));
}

TEST(TexturedSimplificationQuadric, AreaDistortionMatchesThesisFormula) {
  // §3.4.1: for A = diag(a11, a22, a33) in the frame (e1, e2, n), the measure is
  // (a11 + a22) / (a11 + a22 + 2 a33).
  const double a11 = 0.3, a22 = 0.1, a33 = 2.0;
  // rotate the frame so the test does not depend on the axes
  const double c = std::cos(0.7), s = std::sin(0.7);
  const TS::internal::Vec3 e1{c, s, 0}, e2{-s * 0.6, c * 0.6, 0.8}, n = TS::internal::cross(e1, e2);
  Quadric q = Quadric::plane(e1, 0, a11);
  q += Quadric::plane(e2, 0, a22);
  q += Quadric::plane(n, 0, a33);
  EXPECT_NEAR(q.area_distortion(n), (a11 + a22) / (a11 + a22 + 2 * a33), 1e-12);
  // flat neighbourhood: A = area n n^T gives 0
  EXPECT_NEAR(Quadric::plane(n, 1.0, 5.0).area_distortion(n), 0.0, 1e-12);
}

TEST(TexturedSimplificationQuadric, AreaDistortionMatchesAnIterativeEigenDecomposition) {
  // Reference: Eigen's iterative (QR) solver, eigenvector closest to the normal picked by the
  // largest |cosine| -- an algorithm independent of the closed-form eigenvalues and projectors
  // area_distortion() uses. Random positive semi-definite A (sums of 1 to 6 area-weighted
  // planes, from flat to isotropic) and normals near or far from the dominant direction.
  std::mt19937 rng(20261123);
  std::uniform_real_distribution<double> u(-1.0, 1.0), area(1e-3, 2.0);
  int compared = 0, near_ties = 0, repeated = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    Quadric q;
    const int planes = 1 + trial % 6;
    for (int k = 0; k < planes; ++k) {
      TS::internal::Vec3 n{u(rng), u(rng), u(rng)};
      const double l = TS::internal::norm(n);
      if (!(l > 1e-3)) continue;
      q += Quadric::plane(TS::internal::scale(n, 1.0 / l), u(rng), area(rng));
    }
    const TS::internal::Vec3 normal{u(rng), u(rng), u(rng)};
    Eigen::Matrix3d A;
    A << q.a00, q.a01, q.a02, q.a01, q.a11, q.a12, q.a02, q.a12, q.a22;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(A);
    const Eigen::Vector3d nv(normal[0], normal[1], normal[2]);
    double cos_abs[3];
    for (int i = 0; i < 3; ++i) cos_abs[i] = std::abs(es.eigenvectors().col(i).dot(nv)) / nv.norm();
    const int best = int(std::max_element(cos_abs, cos_abs + 3) - cos_abs);
    double second = 0;
    for (int i = 0; i < 3; ++i)
      if (i != best) second = std::max(second, cos_abs[i]);
    const double t = A.trace();
    const double lambda = std::clamp(es.eigenvalues()(best), 0.0, t);
    const double expected = (t - lambda) / (t + lambda);
    const double w = q.area_distortion(normal);
    ASSERT_TRUE(std::isfinite(w));
    ASSERT_GE(w, 0.0);
    ASSERT_LE(w, 1.0);
    const Eigen::Vector3d& l = es.eigenvalues();
    if (std::min(l(1) - l(0), l(2) - l(1)) < 1e-6 * t) {  // repeated eigenvalue: no unique eigenvectors
      ++repeated;
      continue;
    }
    if (cos_abs[best] - second < 1e-6) {  // two eigenvectors equally close: either is right
      ++near_ties;
      continue;
    }
    ++compared;
    // the closed-form eigenvalues are accurate to ~1e-8 of the trace (near-zero eigenvalues of
    // rank-deficient A differ most); a wrong eigenvector would change w by far more
    ASSERT_NEAR(w, expected, 1e-7) << "trial " << trial;
  }
  // one plane in six gives a rank-1 A (a double zero eigenvalue)
  EXPECT_GT(compared, 15000);
  EXPECT_LT(near_ties, 100);
  EXPECT_LT(repeated, 4000);
}

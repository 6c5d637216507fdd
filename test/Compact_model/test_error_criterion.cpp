// Tests of the error-driven adaptive reconstruction (error_criterion.h): the chord estimate,
// vertex budgets, the tolerance on every output edge.
#include "compact_model_test_util.h"

namespace {

// ------------------------------------------------------------------ error-driven adaptive
// The chord estimate of error_criterion.h from two samples of the unit sphere theta apart: the
// distance between the chord's midpoint and the sphere is 1 - cos(theta / 2); the estimate is
// first order in theta, so it agrees within a few percent for small theta, and is 0 on a plane.
TEST(CompactModelAdaptive, ChordDeviationMatchesTheSagitta) {
  for (double theta : {0.05, 0.2, 0.4}) {
    const Vec3 a(1, 0, 0), b(std::cos(theta), std::sin(theta), 0);
    const double sagitta = 1 - std::cos(theta / 2);
    const double e = chord_deviation(Sample{a, a}, Sample{b, b});
    EXPECT_NEAR(e, sagitta, 0.03 * sagitta) << theta;
  }
  const Vec3 up(0, 0, 1);
  EXPECT_EQ(chord_deviation(Sample{Vec3(0, 0, 0), up}, Sample{Vec3(3, 1, 0), up}), 0.);
  EXPECT_FALSE(Chord_error_criterion{1e-9}(Sample{Vec3(0, 0, 0), up}, Sample{Vec3(3, 1, 0), up}));
}

// The budget driver stays within the budget, fills most of it, and a larger budget gets a
// smaller tolerance; the output is crack-free with shared vertices like every adaptive one.
TEST(CompactModelAdaptive, VertexBudgetIsMetAndFilled) {
  const Compact_model& m = sphere_model();
  double previous = std::numeric_limits<double>::infinity();
  for (std::size_t budget : {1500u, 4000u, 12000u}) {
    const Vertex_budget_result r = reconstruct_to_vertex_budget(m, budget, 7);
    EXPECT_LE(r.reconstruction.points.size(), budget);
    EXPECT_GE(r.reconstruction.points.size(), std::size_t(0.9 * double(budget)));
    EXPECT_LT(r.tolerance, previous);
    previous = r.tolerance;
    std::string why;
    EXPECT_TRUE(is_closed_and_shared(r.reconstruction, &why)) << why;
  }
  // A budget below the base's vertex count gives the base.
  const Vertex_budget_result base = reconstruct_to_vertex_budget(m, 3, 5);
  EXPECT_EQ(base.reconstruction.points.size(), m.vertices.size());
  EXPECT_THROW(reconstruct_to_vertex_budget(m, 0, 5), CMGeom::Invalid_input);
}

// Every edge of a chord-error adaptive output satisfies the criterion (no edge reached the level
// bound here): its estimated chord deviation is within the tolerance.
TEST(CompactModelAdaptive, EveryOutputEdgeMeetsTheTolerance) {
  const Compact_model& m = sphere_model();
  for (double tol : {1e-3, 2e-4}) {
    const Reconstruction r = reconstruct_adaptive(m, Chord_error_criterion{tol}, 12);
    double worst = 0.;
    for (const auto& t : r.triangles)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = t[k], b = t[(k + 1) % 3];
        worst = std::max(worst, chord_deviation(Sample{r.points[a], r.normals[a]}, Sample{r.points[b], r.normals[b]}));
      }
    EXPECT_LE(worst, tol);
    EXPECT_GT(r.points.size(), m.vertices.size());
  }
}

// A plane joined to a parabolic fillet (as in JointFitLowersTheErrorAcrossAFillet): at the vertex
// count of regular level 2, the chord-error output puts more than three times as many points on
// the curved half (x > 0.1) as on the flat half (x < -0.1). (The simplified base already leans the
// same way: it has few faces on the flat half.)
TEST(CompactModelAdaptive, ChordErrorRefinesWhereTheSurfaceBends) {
  const Surface_mesh grid = plane_and_fillet(60);
  const Compact_model m = build_compact_model(grid, 60);
  const Reconstruction reg = reconstruct_regular(m, 2);
  const Vertex_budget_result ad = reconstruct_to_vertex_budget(m, reg.points.size(), 5);
  auto count = [](const Reconstruction& r, bool curved) {
    return std::count_if(r.points.begin(), r.points.end(),
                         [&](const Vec3& p) { return curved ? p.x > 0.1 : p.x < -0.1; });
  };
  EXPECT_LE(ad.reconstruction.points.size(), reg.points.size());
  EXPECT_GT(count(ad.reconstruction, true), 3 * count(ad.reconstruction, false));
}

}  // namespace

// Tests of the joint refit (Build_options::joint_fit) and of the error control of the build.
#include "compact_model_test_util.h"

namespace {

// Build options with the joint refit on, and a model of the shared data.
Build_options joint_fit_options() {
  Build_options o;
  o.joint_fit = true;
  return o;
}
CMGeom::Textured_mesh shared_model(const std::string& name) {
  CMGeom::Textured_mesh tm;
  CMGeom::IO::read_mesh(cmgeom_test::shared_data(name), tm);
  return tm;
}

// A plane joined to a parabolic fillet (z = 0 for x < 0, 0.8 x^2 beyond: tangent-continuous, with
// a jump in curvature, as on Fandisk): one quadric per corner cannot follow both sides, and the
// joint refit (Build_options::joint_fit), which fits the blend rather than each corner surface,
// must lower the RMS distance to the input.
TEST(CompactModelBuild, JointFitLowersTheErrorAcrossAFillet) {
  const Surface_mesh grid = plane_and_fillet(60);
  Build_statistics st;
  const Compact_model a = build_compact_model(grid, 100);
  const Compact_model b =
      build_compact_model(grid, 100, joint_fit_options(), Quadric_surface_traits(), Weighted_quadric_simplifier(), &st);
  EXPECT_TRUE(st.joint_fit);
  EXPECT_EQ(a.faces, b.faces);  // same base and sectors, other coefficients
  for (int level = 2; level <= 3; ++level) {
    const double ea = symmetric_vertex_rms(grid, to_surface_mesh(reconstruct_regular(a, level)));
    const double eb = symmetric_vertex_rms(grid, to_surface_mesh(reconstruct_regular(b, level)));
    EXPECT_LT(eb, 0.7 * ea) << "level " << level;
  }
}

// On Fandisk (planes, fillets and creases) the joint refit roughly halves the RMS distance; the
// reconstruction stays closed, with shared vertices.
TEST(CompactModelBuild, JointFitLowersTheFandiskError) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const CMGeom::Textured_mesh tm = shared_model("classic/fandisk.obj");
  const Reconstruction ra = reconstruct_regular(build_compact_model(tm.mesh(), 250), 2);
  const Reconstruction rb = reconstruct_regular(build_compact_model(tm.mesh(), 250, joint_fit_options()), 2);
  std::string why;
  EXPECT_TRUE(is_closed_and_shared(rb, &why)) << why;
  const double ea = symmetric_vertex_rms(tm.mesh(), to_surface_mesh(ra));
  const double eb = symmetric_vertex_rms(tm.mesh(), to_surface_mesh(rb));
  EXPECT_LT(eb, 0.7 * ea);
}

// Error control (§4.5.3) must not make a model worse: with the thesis' fits on Fandisk, a bound
// of 0.01 once raised the level-2 Hausdorff error (0.81 -> 1.16 % of the diagonal); rounds that
// do not lower the largest distance are now undone. Since sharp-edge points far from their edge
// fall back to their start, that Fandisk round lowers the error; on the CAD block (86 base faces,
// bound 0.2 % of the diagonal; the same from 80 to 86 faces and bounds of 0.1 to 0.4 %) the one
// round still raises it, so it is undone.
TEST(CompactModelBuild, ErrorControlNeverRaisesTheMaximumError) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const CMGeom::Textured_mesh tm = shared_model("classic/block.off");
  Build_options controlled;
  controlled.error_bound = 0.002 * bbox_diagonal(tm.mesh());
  Build_statistics st;
  const Compact_model a = build_compact_model(tm.mesh(), 86);
  const Compact_model b =
      build_compact_model(tm.mesh(), 86, controlled, Quadric_surface_traits(), Weighted_quadric_simplifier(), &st);
  CMGeom::Metrics::Error_options eo;
  eo.samples = 100000;
  eo.vertex_field = false;
  const auto ea = CMGeom::Metrics::approximation_error(tm.mesh(), to_surface_mesh(reconstruct_regular(a, 2)), eo);
  const auto eb = CMGeom::Metrics::approximation_error(tm.mesh(), to_surface_mesh(reconstruct_regular(b, 2)), eo);
  EXPECT_LE(eb.hausdorff, ea.hausdorff * (1 + 1e-9));
  // What was undone is counted, and the points of undone rounds are not.
  EXPECT_GE(st.error_control_rejected_rounds, 1u);
  if (b.surfaces == a.surfaces) EXPECT_EQ(st.error_control_points, 0u);
}

// With the joint refit, error control's points enter its least squares (as extra points of a
// sector they weighed 1e-4 of a sample and changed nothing: same Hausdorff error with and without
// control). Fandisk, cubic surfaces, bound 0.3 % of the diagonal measured at level 3: the level-3
// Hausdorff error falls from about 0.49 % to about 0.30 %.
TEST(CompactModelBuild, ErrorControlWithTheJointRefitLowersTheFandiskMaximum) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const CMGeom::Textured_mesh tm = shared_model("classic/fandisk.obj");
  const double diagonal = bbox_diagonal(tm.mesh());
  Build_options controlled = joint_fit_options();
  controlled.error_bound = 0.003 * diagonal;
  controlled.error_control_level = 3;
  controlled.error_control_rounds = 4;
  Build_statistics st;
  const Compact_model a = build_compact_model(tm.mesh(), 250, joint_fit_options(), Cubic_surface_traits());
  const Compact_model b =
      build_compact_model(tm.mesh(), 250, controlled, Cubic_surface_traits(), Weighted_quadric_simplifier(), &st);
  EXPECT_GT(st.error_control_points, 0u);
  CMGeom::Metrics::Error_options eo;
  eo.samples = 100000;
  eo.vertex_field = false;
  const Reconstruction rb = reconstruct_regular(b, 3, Reconstruction_options(), Cubic_surface_traits());
  std::string why;
  EXPECT_TRUE(is_closed_and_shared(rb, &why)) << why;
  const auto ea = CMGeom::Metrics::approximation_error(
      tm.mesh(), to_surface_mesh(reconstruct_regular(a, 3, Reconstruction_options(), Cubic_surface_traits())), eo);
  const auto eb = CMGeom::Metrics::approximation_error(tm.mesh(), to_surface_mesh(rb), eo);
  EXPECT_LT(eb.hausdorff, 0.8 * ea.hausdorff);
  EXPECT_LT(eb.rms, 1.1 * ea.rms);
}

// The trim-star has 387 sharp base edges, whose points are intersections of two sector surfaces
// that the joint refit's least squares do not see. Without the refit's sharp-edge guard its
// level-3 Hausdorff error rose above the thesis fits' (measured 2.97 % against 2.57 % of the
// diagonal); with it, it must not.
TEST(CompactModelBuild, JointFitKeepsSharpEdgesOnTheTrimStar) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const CMGeom::Textured_mesh tm = shared_model("classic/trim-star.off");
  CMGeom::Metrics::Error_options eo;
  eo.samples = 200000;
  eo.vertex_field = false;
  const Surface_mesh ra = to_surface_mesh(reconstruct_regular(build_compact_model(tm.mesh(), 1000), 3));
  const Surface_mesh rb =
      to_surface_mesh(reconstruct_regular(build_compact_model(tm.mesh(), 1000, joint_fit_options()), 3));
  const auto ea = CMGeom::Metrics::approximation_error(tm.mesh(), ra, eo);
  const auto eb = CMGeom::Metrics::approximation_error(tm.mesh(), rb, eo);
  EXPECT_LT(eb.hausdorff, ea.hausdorff);
  EXPECT_LT(eb.rms, ea.rms);
}

TEST(CompactModelBuild, RejectsBadErrorControlOptions) {
  const Surface_mesh s = make_sphere(2);
  auto refused = [&](void (*set)(Build_options&)) {
    Build_options o;
    o.error_bound = 1e-3;
    set(o);
    try {
      build_compact_model(s, 40, o);
    } catch (const CMGeom::Invalid_input& e) {
      return std::string(e.what()).find("error_control") != std::string::npos;
    }
    return false;
  };
  EXPECT_TRUE(refused([](Build_options& o) { o.error_bound = -1.; }));
  EXPECT_TRUE(refused([](Build_options& o) { o.error_bound = std::nan(""); }));
  EXPECT_TRUE(refused([](Build_options& o) { o.error_control_rounds = -1; }));
  EXPECT_TRUE(refused([](Build_options& o) { o.error_control_level = 9; }));
  EXPECT_TRUE(refused([](Build_options& o) { o.error_control_level = -1; }));
  EXPECT_TRUE(refused([](Build_options& o) { o.error_control_weight = 0.; }));
  EXPECT_TRUE(refused([](Build_options& o) { o.error_control_weight = std::numeric_limits<double>::infinity(); }));
  // the range ends are accepted
  EXPECT_FALSE(refused([](Build_options& o) { o.error_control_level = 0; }));
  EXPECT_FALSE(refused([](Build_options& o) { o.error_control_rounds = 0; }));
}

TEST(CompactModelBuild, ErrorControlLowersTheMaximumError) {
  const Surface_mesh s = make_sphere(4);
  Build_options plain, controlled;
  controlled.error_bound = 1e-4;
  controlled.error_control_level = 2;
  const Compact_model a = build_compact_model(s, 40, plain);
  const Compact_model b = build_compact_model(s, 40, controlled);
  EXPECT_EQ(a.faces, b.faces);  // same base, refitted surfaces
  const double ea = max_radius_error(reconstruct_regular(a, 2)), eb = max_radius_error(reconstruct_regular(b, 2));
  EXPECT_LT(eb, ea);
}

}  // namespace

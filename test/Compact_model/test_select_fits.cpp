// Tests of build_selected_compact_model() (select_compact_model.h): the model returned is the
// candidate of lowest measured error, measured independently here, and equals that candidate
// built alone; bad arguments are refused; the progress hook rises to 1.
#include "compact_model_test_util.h"

#include <CMGeom/Compact_model/select_compact_model.h>

namespace {

// The candidate configuration built on its own, as build_selected_compact_model() builds it.
Compact_model build_alone(const Surface_mesh& input, std::size_t faces, const Fit_configuration& c) {
  Build_options o;
  o.joint_fit = c.joint_fit;
  if (c.sharp_angle > 0.) o.sharp_angle = c.sharp_angle;
  Weighted_quadric_simplifier s;
  s.optimal_placement = c.optimal_placement;
  return c.cubic ? build_compact_model(input, faces, o, Cubic_surface_traits(), s)
                 : build_compact_model(input, faces, o, Quadric_surface_traits(), s);
}

// The symmetric Hausdorff distance and RMS of a model's level-`level` reconstruction, measured by
// approximation_error() itself (not the selection's prepared reference), fractions of the diagonal.
std::pair<double, double> measured(const Surface_mesh& input, const Compact_model& m, int level, std::size_t samples) {
  CMGeom::Metrics::Error_options eo;
  eo.samples = samples;
  eo.vertex_field = false;
  const auto e = CMGeom::Metrics::approximation_error(input, to_surface_mesh(reconstruct_regular(m, level)), eo);
  return {e.hausdorff, e.rms};
}

// Checks the selection on `input`: every candidate's recorded error is the independent measure of
// that candidate built alone, the chosen one has the lowest Hausdorff distance, the model returned
// is that candidate, and no candidate beats the thesis' build in Hausdorff distance by being
// skipped. Returns the result.
Selection_result check_selection(const Surface_mesh& input, std::size_t faces, int level) {
  Selection_options so;
  so.level = level;
  so.samples = 50000;
  Selection_result res;
  Build_statistics st;
  const Compact_model chosen = build_selected_compact_model(input, faces, Build_options(), so, &res, &st);
  EXPECT_EQ(res.candidates.size(), so.candidates.size());
  double lowest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < res.candidates.size(); ++i) {
    const auto& c = res.candidates[i];
    const Compact_model alone = build_alone(input, faces, c.configuration);
    const auto [h, rms] = measured(input, alone, level, so.samples);
    EXPECT_DOUBLE_EQ(c.hausdorff, h) << c.configuration.name;
    EXPECT_DOUBLE_EQ(c.rms, rms) << c.configuration.name;
    EXPECT_GT(c.seconds, 0.) << c.configuration.name;
    lowest = std::min(lowest, h);
    if (i == res.chosen) EXPECT_TRUE(alone == chosen) << "the model returned is not candidate " << c.configuration.name;
    EXPECT_TRUE(build_configured_compact_model(input, faces, Build_options(), c.configuration) == alone)
        << "build_configured_compact_model() is not candidate " << c.configuration.name << " built alone";
  }
  EXPECT_EQ(res.candidates[res.chosen].hausdorff, lowest);
  EXPECT_EQ(st.base_faces, chosen.faces.size());
  EXPECT_EQ(st.joint_fit, res.candidates[res.chosen].configuration.joint_fit);
  return res;
}

}  // namespace

// A plane joined to a parabolic fillet (no shared data needed).
TEST(CompactModelSelection, ChoosesTheCandidateOfLowestMeasuredError) {
  const Surface_mesh grid = plane_and_fillet(40);
  const Selection_result res = check_selection(grid, 120, 2);
  // the thesis' build is the first default candidate: the choice is never worse than it
  ASSERT_EQ(res.candidates[0].configuration.name, "thesis");
  EXPECT_LE(res.candidates[res.chosen].hausdorff, res.candidates[0].hausdorff);
}

// Fandisk with a 250-face base (127 base vertices), level 3: the thesis' figures (Table 4.3:
// Hausdorff 0.208 %, RMS 0.027 % of the diagonal) set the targets 0.3 % and 0.03 %, measured
// Metro-style (10 x the faces' samples per direction). The thesis' build gives 0.844 % and 0.083 %;
// the selection picks the joint refit at 25 degrees, 0.298 % and 0.019 %.
TEST(CompactModelSelection, FandiskReachesTheThesisTargets) {
  CMGEOM_REQUIRE_SHARED_DATA();
  CMGeom::Textured_mesh tm;
  CMGeom::IO::read_mesh(cmgeom_test::shared_data("classic/fandisk.obj"), tm);
  const Selection_result res = check_selection(tm.mesh(), 250, 3);
  const auto& best = res.candidates[res.chosen];
  EXPECT_NE(best.configuration.name, "thesis");
  const Compact_model m = build_alone(tm.mesh(), 250, best.configuration);
  EXPECT_LE(m.vertices.size(), 130u);
  const auto e = CMGeom::Metrics::approximation_error(tm.mesh(), to_surface_mesh(reconstruct_regular(m, 3)));
  EXPECT_LE(e.hausdorff, 0.003);
  EXPECT_LE(e.rms, 0.0003);
}

TEST(CompactModelSelection, RefusesBadArguments) {
  const Surface_mesh sphere = make_sphere(2);
  Selection_options none;
  none.candidates.clear();
  EXPECT_THROW(build_selected_compact_model(sphere, 40, Build_options(), none), CMGeom::Invalid_input);
  for (int level : {0, 7}) {
    Selection_options so;
    so.level = level;
    EXPECT_THROW(build_selected_compact_model(sphere, 40, Build_options(), so), CMGeom::Invalid_input) << level;
  }
  EXPECT_THROW(build_selected_compact_model(sphere, 0), CMGeom::Invalid_input);
}

TEST(CompactModelSelection, ProgressRisesToOne) {
  const Surface_mesh sphere = make_sphere(3);
  std::vector<double> seen;
  Selection_options so;
  so.samples = 20000;
  so.progress = [&](double f) { seen.push_back(f); };
  build_selected_compact_model(sphere, 60, Build_options(), so);
  ASSERT_GE(seen.size(), 2u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_GE(seen.front(), 0.);
  EXPECT_DOUBLE_EQ(seen.back(), 1.);
}

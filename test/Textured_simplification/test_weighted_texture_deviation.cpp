// Tests of the texture deviation (Metrics) of the weighted policy against plain quadrics.
#include "textured_part_test_util.h"

namespace {

// Texture deviation (Metrics) of the weighted policy against plain quadrics, charts kept (the
// thesis' path, where UVs keep their meaning), default merge, equal face counts. The weighting does
// not lower it in general: measured at 20 % and 30 % on the eight shared textured models, weighted is
// lower in 5 of 16 cases and plain in 11 (doc/Textured_simplification/README.md). The test pins one
// model on each side with a margin of more than 15 %: bob (weighted 0.0247 vs 0.0303 at 30 %) and
// Spot (plain 0.0610 vs 0.0840), so a change of either policy that moves the balance is noticed.
TEST(TexturedSimplification, WeightedPolicyTextureDeviationDependsOnTheModel) {
  for (const char* dir : {"bob", "spot"}) {
    SCOPED_TRACE(dir);
    Model m{};
    for (const Model& k : kModels)
      if (std::string(k.dir) == dir) m = k;
    CMGeom::Textured_mesh base;
    if (!read_model(m, base, false)) GTEST_SKIP() << "shared data not found: " << model_path(m);
    double dev[2];
    std::size_t faces[2];
    for (int weighted = 0; weighted < 2; ++weighted) {
      CMGeom::Textured_mesh tm = base;
      TS::Textured_simplification_options o;
      o.target_faces = base.mesh().number_of_faces() * 3 / 10;
      o.keep_charts = true;
      o.resample_textures = false;
      o.quadric.weighted = weighted == 1;
      TS::simplify_textured_mesh(tm, o);
      CMGeom::Metrics::Error_options eo;
      eo.threads = 1;
      dev[weighted] =
          CMGeom::Metrics::texture_deviation(base.mesh(), base.uv_map(), tm.mesh(), tm.uv_map(), eo).deviation;
      faces[weighted] = tm.mesh().number_of_faces();
    }
    ASSERT_EQ(faces[0], faces[1]) << "compare at equal face counts";
    if (std::string(dir) == "bob")
      EXPECT_LT(dev[1], 0.9 * dev[0]) << "texture deviation: plain " << dev[0] << ", weighted " << dev[1];
    else
      EXPECT_LT(dev[0], 0.9 * dev[1]) << "texture deviation: plain " << dev[0] << ", weighted " << dev[1];
  }
}

}  // namespace

// Tests of `cmgeom info --json` on the shared models (SOURCES.md values).
#include "mesh_io_test_util.h"

TEST(Mesh_IO_cli, InfoJsonReportsSourcesValues) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  const auto r = cmgeom_test::run_cli("info --json '" + shared_data("textured/fuze/fuze.obj") + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["vertices"], 502);
  EXPECT_EQ(j["faces"], 1000);
  EXPECT_EQ(j["charts"], 8);
  EXPECT_EQ(j["closed"], true);
  EXPECT_EQ(j["manifold"], true);
  EXPECT_EQ(j["genus"], 0);
  EXPECT_EQ(j["components"], 1);
  EXPECT_EQ(j["materials"][0]["diffuse_texture"]["width"], 1024);  // "fuze uv.jpg": a space in the name
}

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

// `cmgeom info --repair`: the topology of the mesh as the repairing readers (simplify, lod, cm
// build) build it, beside that of the file. Reference values counted by hand: two tetrahedra
// sharing one vertex (a non-manifold vertex) read as two closed genus-0 surfaces, the shared
// vertex duplicated: 8 vertices, 12 edges, 8 faces, Euler characteristic 4.
TEST(Mesh_IO_cli, InfoRepairReportsTheMeshTheReadersBuild) {
  const std::string dir = scratch_dir();
  const std::string pinched = write_text(dir, "pinched.obj",
                                         "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                         "v -1 0 0\nv 0 -1 0\nv 0 0 -1\n"
                                         "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
                                         "f 1 5 6\nf 1 7 5\nf 1 6 7\nf 5 7 6\n");
  const auto plain = cmgeom_test::run_cli("info --json '" + pinched + "'", dir);
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const auto p = nlohmann::json::parse(plain.out);
  EXPECT_EQ(p["manifold"], false);
  EXPECT_TRUE(p["genus"].is_null());
  EXPECT_EQ(p["non_manifold_vertices"], 1);
  EXPECT_FALSE(p.contains("repaired"));

  const auto fixed = cmgeom_test::run_cli("info --json --repair '" + pinched + "'", dir);
  ASSERT_EQ(fixed.exit_code, 0) << fixed.err;
  EXPECT_NE(fixed.err.find("repaired: 1 non-manifold vertex duplicated"), std::string::npos) << fixed.err;
  const auto r = nlohmann::json::parse(fixed.out)["repaired"];
  EXPECT_EQ(r["vertices"], 8);
  EXPECT_EQ(r["faces"], 8);
  EXPECT_EQ(r["manifold"], true);
  EXPECT_EQ(r["oriented"], true);
  EXPECT_EQ(r["closed"], true);
  EXPECT_EQ(r["components"], 2);
  EXPECT_EQ(r["boundary_loops"], 0);
  EXPECT_EQ(r["euler_characteristic"], 4);
  EXPECT_EQ(r["genus"], 0);
  // the file's own figures are unchanged by --repair
  EXPECT_EQ(nlohmann::json::parse(fixed.out)["manifold"], false);

  // a zero-area face: --repair builds the mesh as the readers do, so it is refused in one line
  // naming the option that keeps it, and accepted with that option
  const std::string flat = write_text(dir, "flat.obj",
                                      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n"
                                      "f 1 2 3\nf 1 4 2\n");
  const auto refused = cmgeom_test::run_cli("info --repair '" + flat + "'", dir);
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.err.find("--allow-degenerate"), std::string::npos) << refused.err;
  EXPECT_EQ(refused.out, "");
  const auto kept = cmgeom_test::run_cli("info --json --repair --allow-degenerate '" + flat + "'", dir);
  ASSERT_EQ(kept.exit_code, 0) << kept.err;
  EXPECT_EQ(nlohmann::json::parse(kept.out)["repaired"]["faces"], 2);
}

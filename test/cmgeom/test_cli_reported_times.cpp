// The reconstruction time that cmgeom cm reconstruct and cmgeom deform report lies within the
// command's time.
#include "cli_test_util.h"

// cm reconstruct and cm deform report the library's reconstruction time alone
// (reconstruct_seconds) beside the whole command's (seconds: reading, deforming, writing
// included), and the size of what they wrote.
TEST(cmgeom_cli, CmReconstructAndDeformReportReconstructionTimeWithinTheCommandTime) {
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string spot = "'" + std::string(CMGEOM_SOURCE_DIR) + "/data/spot/spot.obj'";
  const std::string cm = "'" + dir + "/spot.cm'";
  const auto b = cmgeom_test::run_cli("cm build " + spot + " -o " + cm + " --ratio 0.1", dir);
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const std::vector<std::pair<std::string, std::string>> commands = {
      {"reconstruct regular", "cm reconstruct " + cm + " -o '" + dir + "/r.ply' --level 2 --json"},
      {"reconstruct along N", "cm reconstruct " + cm + " -o '" + dir + "/n.ply' --level 2 --projection normal --json"},
      {"reconstruct adaptive",
       "cm reconstruct " + cm + " -o '" + dir + "/a.ply' --edge-length 0.05 --max-level 3 --json"},
      {"deform", "cm deform " + cm + " --affine 1,0.2,0,0,0,1,0,0,0,0,1.5,0 -o '" + dir + "/d.ply' --level 2 --json"}};
  for (const auto& [name, args] : commands) {
    SCOPED_TRACE(name);
    const auto r = cmgeom_test::run_cli(args, dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_TRUE(j.contains("reconstruct_seconds") && j.contains("seconds") && j.contains("vertices")) << r.out;
    const double rec = j["reconstruct_seconds"].get<double>(), all = j["seconds"].get<double>();
    EXPECT_GE(rec, 0.);
    EXPECT_LE(rec, all);
    const std::size_t V = j["base_vertices"].get<std::size_t>(), F = j["base_faces"].get<std::size_t>();
    const std::size_t vertices = j["vertices"].get<std::size_t>(), faces = j["faces"].get<std::size_t>();
    EXPECT_GT(vertices, V);
    if (name != "reconstruct adaptive") {
      // Level 2 of a closed base: 16 triangles per base face, 3 points per base edge (E = 3F/2),
      // 3 interior points per base face.
      EXPECT_EQ(faces, 16 * F);
      EXPECT_EQ(vertices, V + 3 * (3 * F / 2) + 3 * F);
    }
  }
}

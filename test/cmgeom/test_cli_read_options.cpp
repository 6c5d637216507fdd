// Reading options every mesh-reading command shares: zero-area faces are refused with the option
// that keeps them named in the message, and that option keeps them.
#include "cli_test_util.h"

namespace {

// icosphere(2) with one zero-area face: face 0 (a, b, c) becomes (a, m, c), (m, b, c) and the flat
// (b, m, a), m the midpoint of ab (a closed oriented manifold still: V + 1, E + 3, F + 2).
std::string sphere_with_a_flat_face_off() {
  std::vector<std::array<double, 3>> p;
  std::vector<std::array<std::size_t, 3>> f;
  cmgeom_test::icosphere(2, p, f);
  const auto [a, b, c] = f[0];
  const std::size_t m = p.size();
  p.push_back({0.5 * (p[a][0] + p[b][0]), 0.5 * (p[a][1] + p[b][1]), 0.5 * (p[a][2] + p[b][2])});
  f[0] = {a, m, c};
  f.push_back({m, b, c});
  f.push_back({b, m, a});
  return off_text(p, f);
}

std::size_t off_face_count(const std::string& path) {
  std::ifstream in(path);
  std::string magic;
  std::size_t nv = 0, nf = 0;
  in >> magic >> nv >> nf;
  return nf;
}

}  // namespace

TEST(cmgeom_cli, ZeroAreaFacesAreRefusedNamingTheOptionThatKeepsThemAndTheOptionKeepsThem) {
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string in = cmgeom_test::write_text(dir, "flat.off", sphere_with_a_flat_face_off());
  const std::size_t faces_in = off_face_count(in);
  ASSERT_EQ(faces_in, 322u);
  const std::string simplify = "simplify '" + in + "' -o '" + dir + "/s.off' --faces 100";
  const std::string lod = "lod '" + in + "' -o '" + dir + "/l.glb' --faces 200,100 --no-error";
  for (const std::string& cmd : {simplify, lod}) {
    SCOPED_TRACE(cmd);
    const auto refused = cmgeom_test::run_cli(cmd, dir);
    EXPECT_EQ(refused.exit_code, 1);
    EXPECT_NE(refused.err.find("flat.off:"), std::string::npos) << refused.err;  // the file and line
    EXPECT_NE(refused.err.find("1 zero-area face"), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find("--allow-degenerate"), std::string::npos) << refused.err;
    EXPECT_EQ(cmgeom_test::count_files(dir), 1u);  // nothing written beside the input
  }
  const auto kept = cmgeom_test::run_cli(simplify + " --allow-degenerate", dir);
  ASSERT_EQ(kept.exit_code, 0) << kept.err;
  EXPECT_EQ(off_face_count(dir + "/s.off"), 100u);
  const auto chain = cmgeom_test::run_cli(lod + " --allow-degenerate", dir);
  ASSERT_EQ(chain.exit_code, 0) << chain.err;
  EXPECT_TRUE(fs::is_regular_file(dir + "/l.glb"));
}

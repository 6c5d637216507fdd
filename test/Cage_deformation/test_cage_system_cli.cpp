// Tests of `cmgeom deform` and `cmgeom influence` with a two-cage system.
#include "cage_system_test_util.h"

// ------------------------------------------------------------------ command line
namespace {
int run_cli(const std::string& args, std::string* out, std::string* err) {
  const std::string o = tmp("cli_stdout.txt"), e = tmp("cli_stderr.txt");
  const int rc = std::system((std::string(CMGEOM_CMGEOM_EXE) + " " + args + " > " + o + " 2> " + e).c_str());
  auto slurp = [](const std::string& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  if (out) *out = slurp(o);
  if (err) *err = slurp(e);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}
}  // namespace

TEST(Cage_system_cli, deform_and_influence_of_a_two_cage_system) {
  if (!std::filesystem::exists(CMGEOM_CMGEOM_EXE)) GTEST_SKIP() << "cmgeom not built";
  // An octahedron straddling the border of a 2x1x1 system whose cages move by one affine map.
  const std::vector<Vec3> mv = {{1.0, 0.5, 0.9}, {0.3, 0.5, 0.5}, {1.0, 0.1, 0.5},
                                {1.7, 0.5, 0.5}, {1.0, 0.9, 0.5}, {1.0, 0.5, 0.1}};
  {
    std::ofstream o(tmp("octa.obj"));
    o.precision(17);
    for (const Vec3& p : mv) o << "v " << p[0] << " " << p[1] << " " << p[2] << "\n";
    o << "f 1 2 3\nf 1 3 4\nf 1 4 5\nf 1 5 2\nf 6 3 2\nf 6 4 3\nf 6 5 4\nf 6 2 5\n";
  }
  auto affine = [](const Vec3& p) {
    return Vec3{1.2 * p[0] + 0.3 * p[2] + 1, 0.9 * p[1] - 0.2 * p[0], 1.1 * p[2] + 0.1 * p[1] - 2};
  };
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {2, 1, 1}, 2, 1, 1, Coordinate_type::mean_value, 0.6);
  for (auto& c : d.cages)
    for (std::size_t k = 0; k < 8; ++k) c.deformed[k] = affine(c.rest.vertices[k]);
  write_cage_system(tmp("two.json"), d);
  std::string so, se;
  ASSERT_EQ(
      run_cli("deform " + tmp("octa.obj") + " --cages " + tmp("two.json") + " -o " + tmp("two_out.obj") + " --json",
              &so, &se),
      0)
      << se;
  EXPECT_NE(so.find("\"joined_vertices\""), std::string::npos) << so;
  std::vector<Vec3> pts;
  std::vector<std::vector<std::uint32_t>> polys;
  read_polygons(tmp("two_out.obj"), pts, polys);
  ASSERT_EQ(pts.size(), mv.size());
  for (std::size_t i = 0; i < mv.size(); ++i) EXPECT_LT(norm(sub(pts[i], affine(mv[i]))), 1e-9) << i;
  // Influence values: the library's d_i, in vertex order.
  ASSERT_EQ(
      run_cli("influence " + tmp("octa.obj") + " --cages " + tmp("two.json") + " --values " + tmp("d.txt"), &so, &se),
      0)
      << se;
  const Cage_system s(read_cage_system(tmp("two.json")));
  const Cage_system_binding<float> b = s.bind<float>(mv);
  std::ifstream in(tmp("d.txt"));
  for (std::size_t i = 0; i < mv.size(); ++i) {
    double x = -1;
    ASSERT_TRUE(in >> x);
    EXPECT_NEAR(x, b.influence()[i], 1e-7);
    EXPECT_GE(x, 0);
    EXPECT_LE(x, 1);
  }
  EXPECT_LT(b.influence()[0], 0.01);  // (1, 0.5, 0.9) is on the border: d = 0
  // --grid --write-cages writes an editable system that reads back with the same cages.
  ASSERT_EQ(run_cli("deform " + tmp("octa.obj") + " --grid 2,2,1 --h 0.5 --write-cages " + tmp("grid.json"), &so, &se),
            0)
      << se;
  const Cage_system_description g = read_cage_system(tmp("grid.json"));
  EXPECT_EQ(g.cages.size(), 4u);
  EXPECT_EQ(g.cages[3].h, 0.5);
  // Errors: one line, exit code 1, no output file.
  Cage_system_description bad = d;
  bad.cages.push_back(bad.cages[0]);  // overlapping cages
  bad.cages.back().name = "copy";
  write_cage_system(tmp("bad.json"), bad);
  std::filesystem::remove(tmp("bad_out.obj"));
  EXPECT_EQ(
      run_cli("deform " + tmp("octa.obj") + " --cages " + tmp("bad.json") + " -o " + tmp("bad_out.obj"), &so, &se), 1);
  EXPECT_NE(se.find("overlap"), std::string::npos) << se;
  EXPECT_EQ(std::count(se.begin(), se.end(), '\n'), 1) << se;
  EXPECT_FALSE(std::filesystem::exists(tmp("bad_out.obj")));
  EXPECT_EQ(run_cli("deform " + tmp("octa.obj") + " --grid 2,x,1 -o " + tmp("bad_out.obj"), &so, &se), 1);
  EXPECT_NE(se.find("--grid"), std::string::npos) << se;
}

// Tests of `cmgeom deform`: vertex order and reproduction of affine maps, one-line errors that
// leave no output.
#include "cage_coordinates_test_util.h"

// ================================================================== cmgeom deform
namespace {
// One directory per test and per executable, so that `ctest -j` may run them concurrently.
std::string cli_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string d = std::string(CMGEOM_TEST_TMP_DIR) + "/" + info->test_suite_name() + "_" + info->name();
  std::filesystem::create_directories(d + "/cages");
  return d;
}
void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }
std::string cube_obj(const Affine& a) {
  std::ostringstream s;
  s.precision(17);
  const Vec3 c[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (const Vec3& p : c) {
    const Vec3 q = a(p);
    s << "v " << q[0] << " " << q[1] << " " << q[2] << "\n";
  }
  s << "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  return s.str();
}
int run(const std::string& cmd, std::string* out = nullptr, std::string* err = nullptr) {
  const std::string d = cli_dir();
  const int rc = std::system((cmd + " > " + d + "/stdout.txt 2> " + d + "/stderr.txt").c_str());
  auto slurp = [](const std::string& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  if (out) *out = slurp(d + "/stdout.txt");
  if (err) *err = slurp(d + "/stderr.txt");
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}
}  // namespace

TEST(CAGE_SUITE(Cage_cli), deform_keeps_vertex_order_and_reproduces_maps) {
  if (!std::filesystem::exists(CMGEOM_CMGEOM_EXE)) GTEST_SKIP() << "cmgeom not built";
  const std::string d = cli_dir();
  std::mt19937 rng(51);
  const Affine id{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0, 0, 0}};
  // a mesh inside the cube: an octahedron around (0.4, 0.5, 0.55), vertex order scrambled
  std::vector<Vec3> mv = {{0.4, 0.5, 0.85}, {0.1, 0.5, 0.55}, {0.4, 0.2, 0.55},
                          {0.7, 0.5, 0.55}, {0.4, 0.8, 0.55}, {0.4, 0.5, 0.25}};
  {
    std::ostringstream s;
    s.precision(17);
    for (const Vec3& p : mv) s << "v " << p[0] << " " << p[1] << " " << p[2] << "\n";
    s << "f 1 2 3\nf 1 3 4\nf 1 4 5\nf 1 5 2\nf 6 3 2\nf 6 4 3\nf 6 5 4\nf 6 2 5\n";
    write_text(d + "/mesh.obj", s.str());
  }
  write_text(d + "/cages/rest.obj", cube_obj(id));
  struct Case {
    std::string coords;
    Affine map;
    std::string extra;
  };
  std::vector<Case> cases = {{"mean_value", random_affine(rng), ""},
                             {"harmonic", random_affine(rng), ", \"harmonic\": {\"resolution\": 16}"},
                             {"green", random_similarity(rng, 1.3), ""}};
  for (const Case& c : cases) {
    write_text(d + "/cages/deformed.obj", cube_obj(c.map));
    write_text(d + "/system.json",
               "{\"cages\": [{\"rest\": \"cages/rest.obj\", \"deformed\": "
               "\"cages/deformed.obj\", \"coordinates\": \"" +
                   c.coords + "\"" + c.extra + "}]}");
    const std::string out = d + "/out_" + c.coords + ".obj";
    std::string so, se;
    ASSERT_EQ(run(std::string(CMGEOM_CMGEOM_EXE) + " deform " + d + "/mesh.obj --cages " + d + "/system.json -o " +
                      out + " --json",
                  &so, &se),
              0)
        << se;
    for (const char* key : {"\"bind_seconds\"", "\"deform_seconds\"", "\"weights_bytes\""})
      EXPECT_NE(so.find(key), std::string::npos) << key;
    std::vector<Vec3> pts;
    std::vector<std::vector<std::size_t>> polys;
    ASSERT_TRUE(read_soup(out, pts, polys));
    ASSERT_EQ(pts.size(), mv.size());
    for (std::size_t i = 0; i < mv.size(); ++i)
      EXPECT_LT(norm(sub(pts[i], c.map(mv[i]))), 1e-9) << c.coords << " vertex " << i;
  }
  // A deformed cage whose file lists other faces (here: triangles, in another order) is accepted:
  // only its vertex positions are used, with the rest cage's triangles.
  const Affine a = random_affine(rng);
  std::string obj = cube_obj(a);
  obj = obj.substr(0, obj.find("f "));
  obj +=
      "f 2 3 7\nf 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 7 6\nf 3 4 8\n"
      "f 3 8 7\nf 4 1 5\nf 4 5 8\n";
  write_text(d + "/cages/deformed.obj", obj);
  write_text(d + "/system.json",
             "{\"cages\": [{\"rest\": \"cages/rest.obj\", \"deformed\": "
             "\"cages/deformed.obj\"}]}");
  std::string se;
  ASSERT_EQ(run(std::string(CMGEOM_CMGEOM_EXE) + " deform " + d + "/mesh.obj --cages " + d + "/system.json -o " + d +
                    "/out_faces.obj",
                nullptr, &se),
            0)
      << se;
  EXPECT_NE(se.find("faces differ"), std::string::npos) << se;
  std::vector<Vec3> pts;
  std::vector<std::vector<std::size_t>> polys;
  ASSERT_TRUE(read_soup(d + "/out_faces.obj", pts, polys));
  ASSERT_EQ(pts.size(), mv.size());
  for (std::size_t i = 0; i < mv.size(); ++i) EXPECT_LT(norm(sub(pts[i], a(mv[i]))), 1e-9);
}

TEST(CAGE_SUITE(Cage_cli), errors_are_one_line_and_leave_no_output) {
  if (!std::filesystem::exists(CMGEOM_CMGEOM_EXE)) GTEST_SKIP() << "cmgeom not built";
  const std::string d = cli_dir();
  const Affine id{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0, 0, 0}};
  write_text(d + "/cages/rest.obj", cube_obj(id));
  write_text(d + "/cages/other.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n");
  write_text(d + "/outside.obj", "v 0.5 0.5 0.5\nv 2 0.5 0.5\nv 0.5 0.6 0.5\nf 1 2 3\n");
  if (!std::filesystem::exists(d + "/mesh.obj"))
    write_text(d + "/mesh.obj", "v 0.5 0.5 0.5\nv 0.6 0.5 0.5\nv 0.5 0.6 0.5\nf 1 2 3\n");
  struct Bad {
    std::string json, mesh, expect;
  };
  const std::vector<Bad> bad = {
      {"{\"cages\": [", "mesh.obj", "invalid JSON"},
      {"{\"cages\": [{\"deformed\": \"cages/rest.obj\"}]}", "mesh.obj", "/cages/0/rest: missing"},
      {"{\"cages\": [{\"rest\": \"cages/rest.obj\", \"deformed\": \"cages/missing.obj\"}]}", "mesh.obj", "missing.obj"},
      {"{\"cages\": [{\"rest\": \"cages/rest.obj\", \"deformed\": \"cages/other.obj\"}]}", "mesh.obj", "same vertices"},
      {"{\"cages\": [{\"rest\": \"cages/rest.obj\", \"deformed\": \"cages/rest.obj\", \"coordinates\": \"bogus\"}]}",
       "mesh.obj", "unknown coordinates"},
      {"{\"cages\": [{\"rest\": \"cages/rest.obj\", \"deformed\": \"cages/rest.obj\", \"coordinates\": \"harmonic\", "
       "\"harmonic\": {\"resolution\": 16}}]}",
       "outside.obj", "outside the cage"}};
  for (const Bad& b : bad) {
    write_text(d + "/bad.json", b.json);
    const std::string out = d + "/bad_out.obj";
    std::filesystem::remove(out);
    std::string se;
    EXPECT_EQ(
        run(std::string(CMGEOM_CMGEOM_EXE) + " deform " + d + "/" + b.mesh + " --cages " + d + "/bad.json -o " + out,
            nullptr, &se),
        1)
        << b.json;
    EXPECT_NE(se.find(b.expect), std::string::npos) << se;
    EXPECT_EQ(std::count(se.begin(), se.end(), '\n'), 1) << se;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}

// Tests of `cmgeom simplify`: the JSON report and errors.
#include "textured_simplification_test_util.h"

#include "cmgeom_test_support.h"

#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Metrics/approximation_error.h>

// ------------------------------------------------------------------------- command line

namespace {
// Runs a shell command, returns (exit code, stdout).
std::pair<int, std::string> run(const std::string& cmd) {
  std::string out;
  FILE* p = popen((cmd + " 2>/dev/null").c_str(), "r");
  if (!p) return {-1, out};
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}
}  // namespace

TEST(TexturedSimplificationCli, SimplifyJsonAndErrors) {
  const std::string exe = CMGEOM_CMGEOM_EXE;
  if (!fs::exists(exe)) GTEST_SKIP() << "cmgeom not built: " << exe;
  const std::string in = data_dir() + "/classic/bunny.off";
  if (!fs::exists(in)) GTEST_SKIP() << "shared data not found: " << data_dir();
  const std::string out = std::string(CMGEOM_TEST_TMP_DIR) + "/ts_cli_bunny.off";
  fs::remove(out);
  for (const std::string engine : {"cmgeom", "cgal"}) {
    const auto [code, text] =
        run("'" + exe + "' simplify '" + in + "' -o '" + out + "' --faces 1000 --json --engine " + engine);
    ASSERT_EQ(code, 0) << text;
    const auto j = nlohmann::json::parse(text);
    EXPECT_EQ(j["faces_in"].get<std::size_t>(), 6966u);
    EXPECT_EQ(j["faces_out"].get<std::size_t>(), 1000u);
    EXPECT_GE(j["seconds"].get<double>(), 0.0);
    Mesh m;
    ASSERT_TRUE(CGAL::IO::read_polygon_mesh(out, m));
    EXPECT_EQ(m.number_of_faces(), 1000u);
  }
  {
    // the fit of the vertices: reported, on by default; --fit-rounds 0 leaves the collapsed
    // positions (the same connectivity, other points), with a higher RMS error
    double rms[2] = {0, 0};
    std::vector<Point> points[2];
    for (int rounds : {0, 3}) {
      const std::string o = std::string(CMGEOM_TEST_TMP_DIR) + "/ts_cli_fit" + std::to_string(rounds) + ".off";
      const auto [code, text] = run("'" + exe + "' simplify '" + in + "' -o '" + o + "' --faces 1000 --json" +
                                    (rounds == 0 ? " --fit-rounds 0" : ""));
      ASSERT_EQ(code, 0) << text;
      const auto j = nlohmann::json::parse(text);
      EXPECT_EQ(j["fit_rounds"].get<int>(), rounds);
      EXPECT_EQ(j["fit_moves"].get<std::size_t>() > 0, rounds > 0);
      Mesh input, output;
      ASSERT_TRUE(CGAL::IO::read_polygon_mesh(in, input));
      ASSERT_TRUE(CGAL::IO::read_polygon_mesh(o, output));
      EXPECT_EQ(output.number_of_faces(), 1000u);
      for (auto v : output.vertices()) points[rounds > 0].push_back(output.point(v));
      rms[rounds > 0] = CMGeom::Metrics::approximation_error(input, output).rms;
    }
    EXPECT_EQ(points[0].size(), points[1].size());
    EXPECT_NE(points[0], points[1]);
    EXPECT_LT(rms[1], rms[0]);
    const std::string never = std::string(CMGEOM_TEST_TMP_DIR) + "/ts_cli_never_fitted.off";
    fs::remove(never);
    EXPECT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + never + "' --faces 1000 --fit-rounds -1").first,
              2);  // a usage error
    EXPECT_FALSE(fs::exists(never));
    // the fit is made with at least --fit-min-points input points per output face (default 3):
    // bunny's 3,485 vertices on 1,000 faces are 3.485 per face, fitted above, not with 4
    const std::string few = std::string(CMGEOM_TEST_TMP_DIR) + "/ts_cli_fit_min_points.off";
    const auto [code, text] =
        run("'" + exe + "' simplify '" + in + "' -o '" + few + "' --faces 1000 --json --fit-min-points 4");
    ASSERT_EQ(code, 0) << text;
    const auto j = nlohmann::json::parse(text);
    EXPECT_EQ(j["fit_min_points"].get<double>(), 4.0);
    EXPECT_EQ(j["fit_moves"].get<std::size_t>(), 0u);
    Mesh unfitted;
    ASSERT_TRUE(CGAL::IO::read_polygon_mesh(few, unfitted));
    std::vector<Point> p;
    for (auto v : unfitted.vertices()) p.push_back(unfitted.point(v));
    EXPECT_EQ(p, points[0]);                              // the --fit-rounds 0 output
    for (const char* bad : {"-1", "nan", "inf", "3x"}) {  // usage errors, nothing written
      const auto [bad_code, bad_text] =
          run("{ '" + exe + "' simplify '" + in + "' -o '" + never + "' --faces 1000 --fit-min-points " + bad +
              " 2>&1; }");  // (the message on stdout)
      EXPECT_EQ(bad_code, 2) << bad;
      EXPECT_NE(bad_text.find("--fit-min-points: expected a finite number >= 0"), std::string::npos) << bad_text;
      EXPECT_FALSE(fs::exists(never)) << bad;
    }
  }
  {
    // --memory-points N: at most N of the input's vertices as points (reported; 0 = all, the
    // default); with 1,000 of bunny's 3,485 the pricing waits for 2,008 faces, so the collapses
    // differ; refused without the memoryful term, writing nothing
    std::vector<Point> points[2];
    for (int capped : {0, 1}) {
      const std::string o = std::string(CMGEOM_TEST_TMP_DIR) + "/ts_cli_points" + std::to_string(capped) + ".off";
      const auto [code, text] = run("'" + exe + "' simplify '" + in + "' -o '" + o + "' --faces 1000 --json" +
                                    (capped ? " --memory-points 1000" : ""));
      ASSERT_EQ(code, 0) << text;
      EXPECT_EQ(nlohmann::json::parse(text)["memory_points"].get<std::size_t>(), capped ? 1000u : 0u);
      Mesh output;
      ASSERT_TRUE(CGAL::IO::read_polygon_mesh(o, output));
      EXPECT_EQ(output.number_of_faces(), 1000u);
      for (auto v : output.vertices()) points[capped].push_back(output.point(v));
    }
    EXPECT_NE(points[0], points[1]);
    const std::string never = std::string(CMGEOM_TEST_TMP_DIR) + "/ts_cli_points_memoryless.off";
    fs::remove(never);
    EXPECT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + never + "' --faces 1000 --memoryless --memory-points 10")
                  .first,
              1);
    EXPECT_FALSE(fs::exists(never));
    // a negative count is a usage error (not read as a huge unsigned cap)
    EXPECT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + never + "' --faces 1000 --memory-points -5").first, 2);
    EXPECT_FALSE(fs::exists(never));
  }
  {
    // plain quadrics always sum, whatever --merge says; the report says what was used
    const auto [code, text] =
        run("'" + exe + "' simplify '" + in + "' -o '" + out + "' --faces 1000 --json --policy plain --merge thesis");
    ASSERT_EQ(code, 0) << text;
    const auto j = nlohmann::json::parse(text);
    EXPECT_EQ(j["policy"].get<std::string>(), "plain");
    EXPECT_EQ(j["merge"].get<std::string>(), "sum");
    EXPECT_EQ(j["faces_out"].get<std::size_t>(), 1000u);
  }
  // bad input: exit code 1, one line on stderr, no output written
  const std::string bad = std::string(CMGEOM_TEST_TMP_DIR) + "/ts_cli_bad.obj";
  {
    std::ofstream f(bad);
    f << "v 0 0 0\nv 1 0 0\nf 1 2 7\n";
  }
  const std::string out2 = std::string(CMGEOM_TEST_TMP_DIR) + "/ts_cli_never.obj";
  fs::remove(out2);
  EXPECT_EQ(run("'" + exe + "' simplify '" + bad + "' -o '" + out2 + "' --ratio 0.5").first, 1);
  EXPECT_FALSE(fs::exists(out2));
  EXPECT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + out2 + "' --ratio 1.5").first, 1);
  EXPECT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + out2 + "'").first, 1);
  EXPECT_FALSE(fs::exists(out2));
}

TEST(TexturedSimplificationCli, SimplifyMeshDefaultsGiveTheCommandsOutput) {
  // simplify_mesh() with default options (a face target alone) is `cmgeom simplify` without
  // options: the same points, bit for bit (the OFF writer prints the shortest form that reads back
  // to the same double). Mesh_simplification_options once left the quadrics weighted where the
  // command and the manual use plain ones.
  const std::string exe = CMGEOM_CMGEOM_EXE;
  if (!fs::exists(exe)) GTEST_SKIP() << "cmgeom not built: " << exe;
  const std::string in = data_dir() + "/classic/bunny.off";
  if (!fs::exists(in)) GTEST_SKIP() << "shared data not found: " << data_dir();
  const std::string out = std::string(CMGEOM_TEST_TMP_DIR) + "/ts_cli_defaults.off";
  fs::remove(out);
  ASSERT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + out + "' --faces 700").first, 0);
  Mesh by_command, by_call;
  ASSERT_TRUE(CGAL::IO::read_polygon_mesh(out, by_command));
  ASSERT_TRUE(CGAL::IO::read_polygon_mesh(in, by_call));
  const TS::Mesh_simplification_result r = TS::simplify_mesh(by_call, 700, TS::Mesh_simplification_options());
  EXPECT_EQ(r.faces_out, 700u);
  ASSERT_EQ(by_call.number_of_faces(), by_command.number_of_faces());
  EXPECT_TRUE(sorted_points(by_call) == sorted_points(by_command));
  // and the thesis' weighted quadrics, asked for, give another mesh
  Mesh weighted;
  ASSERT_TRUE(CGAL::IO::read_polygon_mesh(in, weighted));
  TS::Mesh_simplification_options w;
  w.quadric.weighted = true;
  TS::simplify_mesh(weighted, 700, w);
  EXPECT_FALSE(sorted_points(weighted) == sorted_points(by_command));
}

TEST(TexturedSimplificationCli, GeometryOnlyNoteNamesTextureCoordinatesTheFacesUse) {
  // "texture coordinates are dropped" is said when the faces carry texture coordinates (here with
  // --no-texture), not for a file whose `vt` lines no face uses; both run as geometry
  const std::string exe = CMGEOM_CMGEOM_EXE;
  if (!fs::exists(exe)) GTEST_SKIP() << "cmgeom not built: " << exe;
  const std::string dir = CMGEOM_TEST_TMP_DIR;
  for (bool faces_use_them : {true, false}) {
    const std::string in = dir + "/ts_cli_vt" + std::to_string(faces_use_them) + ".obj";
    const std::string out = dir + "/ts_cli_vt_out" + std::to_string(faces_use_them) + ".obj";
    const std::string err = dir + "/ts_cli_vt_err" + std::to_string(faces_use_them) + ".txt";
    {
      std::ofstream f(in);
      const int n = 12;
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) f << "v " << i << ' ' << j << ' ' << (i * j) % 3 << "\n";
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) f << "vt " << double(i) / n << ' ' << double(j) / n << "\n";
      auto at = [&](int i, int j) { return std::to_string(i * (n + 1) + j + 1); };
      auto corner = [&](int i, int j) { return faces_use_them ? at(i, j) + "/" + at(i, j) : at(i, j); };
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          f << "f " << corner(i, j) << ' ' << corner(i + 1, j) << ' ' << corner(i + 1, j + 1) << "\n";
          f << "f " << corner(i, j) << ' ' << corner(i + 1, j + 1) << ' ' << corner(i, j + 1) << "\n";
        }
    }
    fs::remove(out);
    const auto [code, text] =
        run("{ '" + exe + "' simplify '" + in + "' -o '" + out + "' --ratio 0.5 --no-texture 2>'" + err + "'; }");
    ASSERT_EQ(code, 0) << text;
    EXPECT_TRUE(fs::exists(out));
    std::ifstream e(err);
    const std::string said((std::istreambuf_iterator<char>(e)), std::istreambuf_iterator<char>());
    EXPECT_EQ(said.find("texture coordinates are dropped") != std::string::npos, faces_use_them) << said;
  }
}

// `cmgeom simplify --max-error E`: the report says what stopped it and the bound kept, and the
// output's Hausdorff distance to the input, measured by dense sampling here, is within E; a bound
// that is not > 0 is refused with no output written. With --keep-charts the bound holds too, the
// charts are kept, and the end is said to come from both.
TEST(TexturedSimplificationCli, MaxErrorReportAndBound) {
  const std::string exe = CMGEOM_CMGEOM_EXE;
  if (!fs::exists(exe)) GTEST_SKIP() << "cmgeom not built: " << exe;
  const std::string in = data_dir() + "/classic/bunny.off";
  if (!fs::exists(in)) GTEST_SKIP() << "shared data not found: " << data_dir();
  const std::string out = std::string(CMGEOM_TEST_TMP_DIR) + "/ts_cli_bunny_bounded.off";
  fs::remove(out);
  const auto [code, text] = run("'" + exe + "' simplify '" + in + "' -o '" + out + "' --max-error 0.01 --json");
  ASSERT_EQ(code, 0) << text;
  const auto j = nlohmann::json::parse(text);
  EXPECT_EQ(j["stopped_by"].get<std::string>(), "max_error");
  EXPECT_DOUBLE_EQ(j["max_error"].get<double>(), 0.01);
  EXPECT_LE(j["error_bound"].get<double>(), 0.01);
  EXPECT_FALSE(j.contains("target_faces"));
  EXPECT_LT(j["faces_out"].get<std::size_t>(), 6966u / 4);
  Mesh input, output;
  ASSERT_TRUE(CGAL::IO::read_polygon_mesh(in, input));
  ASSERT_TRUE(CGAL::IO::read_polygon_mesh(out, output));
  EXPECT_EQ(output.number_of_faces(), j["faces_out"].get<std::size_t>());
  CMGeom::Metrics::Error_options eo;
  eo.samples = 20 * input.number_of_faces();
  // measured on the file as written (its coordinates as stored)
  EXPECT_LE(CMGeom::Metrics::approximation_error(input, output, eo).hausdorff, 0.01);
  const std::string never = std::string(CMGEOM_TEST_TMP_DIR) + "/ts_cli_never_bounded.off";
  fs::remove(never);
  EXPECT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + never + "' --max-error 0").first, 1);
  EXPECT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + never + "' --max-error -0.5").first, 1);
  EXPECT_FALSE(fs::exists(never));
  // a textured input bounded alone: stopping at the bound is where the run ends, not a target
  // missed (the command used to say "stopped at N faces for a target of 1")
  const std::string textured = data_dir() + "/textured/fuze/fuze.obj";
  ASSERT_TRUE(fs::exists(textured)) << textured;
  // (stdout and stderr apart: cmgeom_test::run_cli)
  const std::string dir = cmgeom_test::scratch_dir();
  const auto t =
      cmgeom_test::run_cli("simplify '" + textured + "' -o '" + dir + "/fuze.obj' --max-error 0.01 --json", dir);
  ASSERT_EQ(t.exit_code, 0) << t.err;
  const auto tj = nlohmann::json::parse(t.out);
  EXPECT_EQ(tj["stopped_by"].get<std::string>(), "max_error");
  EXPECT_LE(tj["error_bound"].get<double>(), 0.01);
  EXPECT_EQ(t.err.find("for a target of"), std::string::npos) << t.err;
  // the input's charts kept under the bound
  const std::string kout = dir + "/fuze_kept.obj";
  const auto k = cmgeom_test::run_cli(
      "simplify '" + textured + "' -o '" + kout + "' --keep-charts --max-error 0.01 --faces 10 --json", dir);
  ASSERT_EQ(k.exit_code, 0) << k.err;
  const auto kj = nlohmann::json::parse(k.out);
  EXPECT_EQ(kj["charts"].get<std::string>(), "kept");
  EXPECT_EQ(kj["charts_out"], kj["charts_in"]);
  EXPECT_EQ(kj["stopped_by"].get<std::string>(), "max_error");
  EXPECT_GT(kj["error_bound"].get<double>(), 0.);
  EXPECT_LE(kj["error_bound"].get<double>(), 0.01);
  EXPECT_LT(kj["faces_out"].get<std::size_t>(), kj["faces_in"].get<std::size_t>() / 2);
  EXPECT_NE(k.err.find("keeps both the input's charts and --max-error"), std::string::npos) << k.err;
  Mesh fuze, kept;
  CMGeom::IO::read_mesh(textured, fuze);
  CMGeom::IO::read_mesh(kout, kept);
  EXPECT_EQ(kept.number_of_faces(), kj["faces_out"].get<std::size_t>());
  CMGeom::Metrics::Error_options keo;
  keo.samples = 20 * fuze.number_of_faces();
  EXPECT_LE(CMGeom::Metrics::approximation_error(fuze, kept, keo).hausdorff, 0.01);
}

TEST(TexturedSimplificationCli, StopAboveTargetNamesTheComponentsAndPrune) {
  // three closed tetrahedra: no collapse is valid (each would leave a doubled face), so a target
  // below 12 faces cannot be reached; `simplify` and `lod` say why, with the component count, and
  // point at --prune unless it was given (with it, whole tetrahedra go)
  const std::string exe = CMGEOM_CMGEOM_EXE;
  if (!fs::exists(exe)) GTEST_SKIP() << "cmgeom not built: " << exe;
  const std::string dir = CMGEOM_TEST_TMP_DIR;
  const std::string in = dir + "/ts_cli_tets.obj";
  {
    std::ofstream f(in);
    for (int k = 0; k < 3; ++k)
      f << "v " << 3 * k << " 0 0\nv " << 3 * k + 1 << " 0 0\nv " << 3 * k << " 1 0\nv " << 3 * k << " 0 1\n";
    for (int k = 0; k < 3; ++k) {
      const int b = 4 * k + 1;
      f << "f " << b << ' ' << b + 2 << ' ' << b + 1 << "\nf " << b << ' ' << b + 1 << ' ' << b + 3 << "\nf " << b
        << ' ' << b + 3 << ' ' << b + 2 << "\nf " << b + 1 << ' ' << b + 2 << ' ' << b + 3 << "\n";
    }
  }
  auto said = [&](const std::string& args, int& code) {
    const std::string err = dir + "/ts_cli_tets_err.txt";
    code = run("{ '" + exe + "' " + args + " 2>'" + err + "'; }").first;
    std::ifstream e(err);
    return std::string((std::istreambuf_iterator<char>(e)), std::istreambuf_iterator<char>());
  };
  int code = -1;
  const std::string out = dir + "/ts_cli_tets_out.obj";
  std::string text = said("simplify '" + in + "' -o '" + out + "' --faces 4", code);
  EXPECT_EQ(code, 0) << text;
  EXPECT_NE(text.find("stopped at 12 faces for a target of 4"), std::string::npos) << text;
  EXPECT_NE(text.find("each of the 3 connected components"), std::string::npos) << text;
  EXPECT_NE(text.find("--prune removes whole components"), std::string::npos) << text;
  text = said("simplify '" + in + "' -o '" + out + "' --faces 4 --prune", code);
  EXPECT_EQ(code, 0) << text;
  EXPECT_EQ(text.find("--prune removes"), std::string::npos) << text;
  Mesh pruned;
  ASSERT_TRUE(CGAL::IO::read_polygon_mesh(out, pruned));
  EXPECT_EQ(pruned.number_of_faces(), 4u);
  text = said("lod '" + in + "' -o '" + dir + "/ts_cli_tets.glb' --faces 12,4 --no-error", code);
  EXPECT_EQ(code, 0) << text;
  EXPECT_NE(text.find("level 1 stopped at 12 faces for a target of 4"), std::string::npos) << text;
  EXPECT_NE(text.find("--prune removes whole components"), std::string::npos) << text;
}

// The level-of-detail chains of cmgeom lod: GLB nodes listed by MSFT_lod, refusals, OBJ copies.
#include "cli_test_util.h"

// ------------------------------------------------------------------ levels of detail
// cmgeom lod writes a level-of-detail chain as one glTF node per level (doc/CLI.md): the report
// on stdout, the nodes of the GLB (read back from its JSON chunk), the images each level draws,
// the refusals (nothing written), the OBJ copies of --obj-prefix.
namespace {

// Everything in `dir` (files and folders), for the checks that a refused command wrote nothing.
std::vector<std::string> entries_of(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// icosphere(level) as OFF text: a mesh without texture coordinates.
std::string icosphere_off(int level) {
  std::vector<std::array<double, 3>> p;
  std::vector<std::array<std::size_t, 3>> f;
  cmgeom_test::icosphere(level, p, f);
  return off_text(p, f);
}

}  // namespace

TEST(cmgeom_cli, LodWritesOneGlbNodePerLevelListedByMsftLod) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string duck = cmgeom_test::shared_data("textured/Duck/Duck.obj");
  const std::string validator_missing = gltf_validator_missing();
  if (!validator_missing.empty()) std::cout << "validator not run: " << validator_missing << "\n";
  for (const bool shared : {false, true}) {
    SCOPED_TRACE(shared ? "--shared-texture" : "an atlas per level");
    const auto duck_info = cmgeom_test::run_cli("info " + quoted(duck) + " --json", dir);
    ASSERT_EQ(duck_info.exit_code, 0) << duck_info.err;
    const auto input_charts = nlohmann::json::parse(duck_info.out)["charts"];
    ASSERT_GT(input_charts.get<int>(), 0);
    const std::string glb = (fs::path(dir) / (shared ? "shared.glb" : "levels.glb")).string();
    const auto r = cmgeom_test::run_cli("--quiet lod " + quoted(duck) + " -o " + quoted(glb) +
                                            " --ratios 1,0.25,0.05 --json" + (shared ? " --shared-texture" : ""),
                                        dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    const nlohmann::json report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["textured"], true);
    EXPECT_EQ(report["shared_texture"], shared);
    const auto& levels = report["levels"];
    ASSERT_EQ(levels.size(), 3u);
    const std::size_t faces_in = report["faces_in"].get<std::size_t>();
    const double ratios[3] = {1, 0.25, 0.05};
    std::vector<std::size_t> faces;
    for (std::size_t i = 0; i < 3; ++i) {
      SCOPED_TRACE("level " + std::to_string(i));
      const auto& l = levels[i];
      EXPECT_EQ(l["level"], i);
      EXPECT_EQ(l["is_input"], i == 0);
      EXPECT_EQ(l["target_faces"], std::size_t(std::llround(ratios[i] * double(faces_in))));
      faces.push_back(l["faces"].get<std::size_t>());
      // a snapshot is taken at the first collapse that reaches the target (one collapse removes
      // at most two faces)
      EXPECT_LE(faces[i], l["target_faces"].get<std::size_t>());
      EXPECT_GE(faces[i] + 2, l["target_faces"].get<std::size_t>());
      if (i > 0) EXPECT_LT(faces[i], faces[i - 1]);
      // every level reports its texture: level 0 the input's own (its image and its charts, as
      // `cmgeom info` counts them) unless one atlas serves all levels
      EXPECT_GT(l["texture_width"].get<int>(), 0) << l;
      EXPECT_GT(l["texture_height"].get<int>(), 0) << l;
      if (i == 0 && !shared) EXPECT_EQ(l["charts"], input_charts) << l;
      // one atlas: every level reports its size, the strip of overflow charts included
      if (shared) EXPECT_EQ(l["texture_height"], levels[2]["texture_height"]) << l;
      // the making of an atlas is reported on the level it was made for: every simplified level,
      // or the coarsest only when one atlas serves all; painted texels are a part of those in charts
      const bool made_here = shared ? i == 2 : i > 0;
      EXPECT_EQ(l.contains("seconds_bake"), made_here) << l;
      if (made_here) {
        EXPECT_GT(l["texels_in_charts"].get<std::size_t>(), 0u);
        EXPECT_LE(l["texels_painted"].get<std::size_t>(), l["texels_in_charts"].get<std::size_t>());
        for (const char* k : {"seconds_charts", "seconds_paint", "seconds_bake"}) EXPECT_GE(l[k].get<double>(), 0.0);
      }
    }
    if (shared) {
      // the strip's share of the atlas, and the share of the input's area given charts there
      const double overflow = report["shared_texture_overflow"].get<double>();
      EXPECT_GE(overflow, 0.0);
      EXPECT_LE(overflow, 0.5);
      EXPECT_GE(report["shared_texture_relocated"].get<double>(), 0.0);
      EXPECT_LE(report["shared_texture_relocated"].get<double>(), 1.0);
    }
    EXPECT_EQ(faces[0], faces_in);

    // the GLB: three nodes, the first in the scene listing the other two by MSFT_lod
    const nlohmann::json j = glb_json(glb);
    ASSERT_TRUE(j.is_object());
    ASSERT_EQ(j["nodes"].size(), 3u);
    EXPECT_EQ(j["nodes"][0]["extensions"]["MSFT_lod"]["ids"], nlohmann::json::array({1, 2}));
    for (const std::size_t i : {std::size_t(1), std::size_t(2)})
      EXPECT_FALSE(j["nodes"][i].contains("extensions")) << i;
    ASSERT_EQ(j["scenes"].size(), 1u);
    EXPECT_EQ(j["scene"], 0);
    EXPECT_EQ(j["scenes"][0]["nodes"], nlohmann::json::array({0}));
    EXPECT_NE(std::find(j["extensionsUsed"].begin(), j["extensionsUsed"].end(), "MSFT_lod"), j["extensionsUsed"].end());
    // each node: the level's faces (in its extras and in its mesh) and its error, growing with the level
    double previous_error = -1;
    for (std::size_t i = 0; i < 3; ++i) {
      SCOPED_TRACE("node " + std::to_string(i));
      const auto& extras = j["nodes"][i]["extras"];
      EXPECT_EQ(extras["level"], i);
      EXPECT_EQ(extras["faces"].get<std::size_t>(), faces[i]);
      EXPECT_EQ(triangles_of_node(j, i), faces[i]);
      ASSERT_TRUE(extras.contains("error"));
      const double error = extras["error"].get<double>();
      EXPECT_DOUBLE_EQ(error, levels[i]["hausdorff"].get<double>());
      EXPECT_GE(error, 0.0);
      if (i == 0)
        EXPECT_EQ(error, 0.0);  // the input itself
      else
        EXPECT_GT(error, previous_error);
      previous_error = error;
    }
    // the images: one shared atlas, or the input's texture and an atlas per simplified level
    ASSERT_TRUE(j.contains("images"));
    std::vector<std::set<int>> drawn;
    for (std::size_t i = 0; i < 3; ++i) drawn.push_back(images_of_node(j, i));
    if (shared) {
      EXPECT_EQ(j["images"].size(), 1u);
      for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(drawn[i], std::set<int>({0})) << "node " << i;
    } else {
      EXPECT_EQ(j["images"].size(), 3u);
      for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(drawn[i].size(), 1u) << "node " << i;
      EXPECT_EQ((std::set<int>{*drawn[0].begin(), *drawn[1].begin(), *drawn[2].begin()}).size(), 3u)
          << "two levels draw the same image";
    }
    for (const auto& image : j["images"]) {
      EXPECT_TRUE(image.contains("bufferView")) << image;  // embedded, not a file beside the GLB
      EXPECT_EQ(image["mimeType"], "image/png") << image;
    }
    // a reader without MSFT_lod (cmgeom's own) sees the finest level
    const auto info = cmgeom_test::run_cli("info " + quoted(glb) + " --json", dir);
    ASSERT_EQ(info.exit_code, 0) << info.err;
    EXPECT_EQ(nlohmann::json::parse(info.out)["faces"].get<std::size_t>(), faces[0]);
    if (validator_missing.empty()) {
      const Validation v = validate_gltf(glb);
      EXPECT_EQ(v.errors, 0) << v.report;
      EXPECT_EQ(v.warnings, 0) << v.report;
    }
  }
}

// Refused chains: exit code 1 (2 for a usage error), one line on stderr naming the problem, and
// nothing in the output directory.
TEST(cmgeom_cli, LodRefusalsNameTheProblemAndWriteNothing) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string duck = cmgeom_test::shared_data("textured/Duck/Duck.obj");
  const std::string inputs = (fs::path(dir) / "inputs").string();
  fs::create_directories(inputs);
  const std::string sphere = cmgeom_test::write_text(inputs, "sphere.off", icosphere_off(2));
  struct Refusal {
    std::string input, args;  // args: "{out}" = the case's output directory
    int exit_code;
    std::string named;  // what the error line must say
  };
  const std::vector<Refusal> refusals = {
      {duck, "-o {out}/x.glb --ratios 1,1", 1, "the levels must decrease strictly (in faces: 4212 then 4212)"},
      {duck, "-o {out}/x.glb --ratios 0.5,0.7", 1, "the levels must decrease strictly (in faces: 2106 then 2948)"},
      {duck, "-o {out}/x.glb --ratios 0", 1, "--ratios: every ratio must be in (0, 1]"},
      {duck, "-o {out}/x.glb --ratios 1,0.5,-0.1", 1, "--ratios: every ratio must be in (0, 1]"},
      {duck, "-o {out}/x.glb --ratios 1,half", 1, "--ratios: 'half' is not a number"},
      {duck, "-o {out}/x.glb --faces 1000,0", 1, "--faces: every face count must be at least 1"},
      {duck, "-o {out}/x.obj --ratios 1,0.25", 1, "x.obj: a level-of-detail chain is written as .glb or .gltf"},
      {duck, "-o {out}/x --ratios 1,0.25", 1, "a level-of-detail chain is written as .glb or .gltf"},
      {duck, "-o {out}/x.glb", 1, "one of --ratios, --faces or --max-errors is required"},
      {duck, "-o {out}/x.glb --max-errors 0.01,0.01", 1, "--max-errors: the bounds must increase strictly"},
      {duck, "-o {out}/x.glb --max-errors 0,0.01 --prune", 1, "--prune cannot be combined with --max-errors"},
      {duck, "-o {out}/x.glb --ratios 1,0.25 --faces 1000", 2, "--ratios excludes --faces"},
      {sphere, "-o {out}/x.glb --ratios 1,0.25 --shared-texture", 1, "--shared-texture needs a textured input"},
      {duck, "-o {out}/x.glb --ratios 1,0.25 --no-overflow-charts", 1,
       "--no-overflow-charts applies to --shared-texture only"},
      {duck, "-o {out}/x.glb --ratios 1,0.25 --overflow-colour-tolerance 0.1", 1,
       "--overflow-colour-tolerance applies to --shared-texture with overflow charts only"},
      {duck, "-o {out}/x.glb --ratios 1,0.25 --shared-texture --no-overflow-charts --overflow-colour-tolerance 0.1", 1,
       "--overflow-colour-tolerance applies to --shared-texture with overflow charts only"},
      {duck, "-o {out}/x.glb --ratios 1,0.25 --shared-texture --overflow-colour-tolerance 1.5", 2,
       "--overflow-colour-tolerance"},
      // every file is written or none: an --obj-prefix in a missing folder leaves no GLB behind
      {duck, "-o {out}/x.glb --ratios 1,0.25 --obj-prefix {out}/missing/P", 1, "does not exist"},
  };
  for (std::size_t k = 0; k < refusals.size(); ++k) {
    const Refusal& c = refusals[k];
    const std::string out = (fs::path(dir) / ("case" + std::to_string(k))).string();
    fs::create_directories(out);
    std::string args = c.args;
    for (std::size_t p; (p = args.find("{out}")) != std::string::npos;) args.replace(p, 5, out);
    SCOPED_TRACE("lod " + fs::path(c.input).filename().string() + " " + args);
    // --quiet: a progress line would be a second line on stderr
    const auto r = cmgeom_test::run_cli("--quiet lod " + quoted(c.input) + " " + args, dir);
    EXPECT_EQ(r.exit_code, c.exit_code) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.compare(0, c.exit_code == 2 ? 21 : 19,
                            c.exit_code == 2 ? "cmgeom: usage error: " : "cmgeom lod: error: "),
              0)
        << r.err;
    EXPECT_NE(r.err.find(c.named), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_TRUE(entries_of(out).empty()) << "left behind: " << ::testing::PrintToString(entries_of(out));
  }
  // the same sphere without --shared-texture is a valid chain (the refusal is about the texture)
  const auto ok = cmgeom_test::run_cli(
      "--quiet lod " + quoted(sphere) + " -o " + quoted(dir + "/sphere.glb") + " --ratios 1,0.25 --json", dir);
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  const nlohmann::json ok_report = nlohmann::json::parse(ok.out);
  EXPECT_EQ(ok_report["textured"], false);
  // the times of the three stages, as simplify reports them
  for (const char* key : {"seconds_read", "seconds", "seconds_write"}) {
    ASSERT_TRUE(ok_report.contains(key)) << key;
    EXPECT_GE(ok_report[key].get<double>(), 0.0) << key;
  }
  // a refused run keeps an existing output as it was
  const std::string kept = cmgeom_test::write_text(dir, "kept.glb", "not replaced");
  const auto r = cmgeom_test::run_cli("--quiet lod " + quoted(duck) + " -o " + quoted(kept) +
                                          " --ratios 1,0.25 --obj-prefix " + quoted(dir + "/missing/P"),
                                      dir);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(bytes_of(kept), "not replaced");
}

TEST(cmgeom_cli, LodObjPrefixWritesEveryLevelAsObj) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string duck = cmgeom_test::shared_data("textured/Duck/Duck.obj");
  const std::string prefix = (fs::path(dir) / "duck").string();
  const auto r = cmgeom_test::run_cli("--quiet lod " + quoted(duck) + " -o " + quoted(dir + "/duck.glb") +
                                          " --ratios 1,0.25,0.05 --obj-prefix " + quoted(prefix) + " --json",
                                      dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  const auto& levels = report["levels"];
  ASSERT_EQ(levels.size(), 3u);
  for (std::size_t k = 0; k < levels.size(); ++k) {
    SCOPED_TRACE("level " + std::to_string(k));
    const std::string obj = prefix + "_" + std::to_string(k) + ".obj";
    ASSERT_TRUE(fs::is_regular_file(obj)) << obj;
    EXPECT_EQ(obj_faces(obj), levels[k]["faces"].get<std::size_t>());
    // its material names a texture written beside it
    const std::string mtl = bytes_of(prefix + "_" + std::to_string(k) + ".mtl");
    const std::size_t map = mtl.find("map_Kd ");
    ASSERT_NE(map, std::string::npos) << mtl;
    const std::string texture = mtl.substr(map + 7, mtl.find('\n', map) - map - 7);
    EXPECT_EQ(bytes_of((fs::path(dir) / texture).string()).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8))
        << texture;
  }
  EXPECT_FALSE(fs::exists(prefix + "_3.obj"));
}

// The report counts a level's vertices as the GLB stores them: an input with vertices in no face
// (scans often have some) reports only those in a face, at the input level as at the others.
TEST(cmgeom_cli, LodReportsTheVerticesItsLevelsStore) {
  const std::string dir = cmgeom_test::scratch_dir();
  std::vector<std::array<double, 3>> p;
  std::vector<std::array<std::size_t, 3>> f;
  cmgeom_test::icosphere(3, p, f);
  const std::size_t sphere_vertices = p.size();
  p.push_back({5, 5, 5});  // two vertices in no face
  p.push_back({-5, 5, 5});
  const std::string in = cmgeom_test::write_text(dir, "loose.off", off_text(p, f));
  const std::string glb = dir + "/loose.glb";
  const auto r =
      cmgeom_test::run_cli("--quiet lod " + quoted(in) + " -o " + quoted(glb) + " --ratios 1,0.5 --json", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  const nlohmann::json g = glb_json(glb);
  ASSERT_FALSE(g.is_null());
  ASSERT_EQ(report["levels"].size(), 2u);
  EXPECT_EQ(report["levels"][0]["vertices"].get<std::size_t>(), sphere_vertices);
  for (std::size_t k = 0; k < 2; ++k) {
    SCOPED_TRACE("level " + std::to_string(k));
    std::size_t stored = 0;
    for (const auto& prim : g["meshes"][g["nodes"][k]["mesh"].get<std::size_t>()]["primitives"])
      stored += g["accessors"][prim["attributes"]["POSITION"].get<std::size_t>()]["count"].get<std::size_t>();
    EXPECT_EQ(report["levels"][k]["vertices"].get<std::size_t>(), stored);
  }
}

// A level of the chain is the mesh `cmgeom simplify` gives for its face count, final fit included
// (taken during the one run, fitted on its own); with --fit-rounds 0 on both, the collapses' mesh;
// with --memory-points 1000 on both (of the sphere's 10,242 vertices), the mesh of that memory.
TEST(cmgeom_cli, LodLevelsAreWhatSimplifyGivesForTheirFaceCounts) {
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string in = (fs::path(dir) / "sphere.off").string();
  {
    std::ofstream f(in);
    f << icosphere_off(5);  // 20480 faces
  }
  // the vertices of an OBJ, as sorted lines (the two files number them differently)
  const auto vertex_lines = [](const std::string& path) {
    std::istringstream s(bytes_of(path));
    std::vector<std::string> v;
    for (std::string line; std::getline(s, line);)
      if (line.rfind("v ", 0) == 0) v.push_back(line);
    std::sort(v.begin(), v.end());
    return v;
  };
  std::vector<std::string> fitted_level;
  for (const auto& [rounds, points] : {std::pair<int, int>{3, 0}, {0, 0}, {3, 1000}}) {
    SCOPED_TRACE("fit rounds " + std::to_string(rounds) + ", memory points " + std::to_string(points));
    const std::string options = " --fit-rounds " + std::to_string(rounds) +
                                (points > 0 ? " --memory-points " + std::to_string(points) : std::string());
    const std::string prefix =
        (fs::path(dir) / ("lod" + std::to_string(rounds) + "_" + std::to_string(points))).string();
    const auto r = cmgeom_test::run_cli("--quiet lod " + quoted(in) + " -o " + quoted(prefix + ".glb") +
                                            " --faces 20480,2000,300 --no-error --json" + options + " --obj-prefix " +
                                            quoted(prefix),
                                        dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["fit_rounds"], rounds);
    EXPECT_EQ(report["memory_points"], points);
    for (std::size_t k = 1; k < 3; ++k) {
      SCOPED_TRACE("level " + std::to_string(k));
      const std::size_t faces = report["levels"][k]["faces"].get<std::size_t>();
      const std::string alone = prefix + "_alone_" + std::to_string(k) + ".obj";
      const auto s = cmgeom_test::run_cli(
          "--quiet simplify " + quoted(in) + " -o " + quoted(alone) + " --faces " + std::to_string(faces) + options,
          dir);
      ASSERT_EQ(s.exit_code, 0) << s.err;
      const std::vector<std::string> level = vertex_lines(prefix + "_" + std::to_string(k) + ".obj");
      ASSERT_FALSE(level.empty());
      EXPECT_EQ(level, vertex_lines(alone));
      if (k == 2 && rounds == 3 && points == 0) fitted_level = level;
      // the fit moved the vertices (it is not a no-op on this sphere), and fewer points change the mesh
      if (k == 2 && (rounds == 0 || points > 0)) EXPECT_NE(level, fitted_level);
    }
  }
}

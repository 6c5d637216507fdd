// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// End-to-end tests of `cmgeom cm build` writing the compact CM file (format version 3) and of its
// rate-distortion options (--max-error, --bytes), on the bundled Spot; the --texture option of an
// input that names no texture (cm build, simplify, lod, pipeline).
#include "cmgeom_test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace fs = std::filesystem;

const std::string& spot() {
  static const std::string s = "'" + std::string(CMGEOM_SOURCE_DIR) + "/data/spot/spot.obj'";
  return s;
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::uint32_t version_of(const std::string& bytes) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= std::uint32_t(static_cast<unsigned char>(bytes.at(8 + std::size_t(i)))) << (8 * i);
  return v;
}

}  // namespace

TEST(cmgeom_cli, CmBuildCompactWritesASmallerVersion3FileThatReconstructsAlike) {
  const std::string dir = cmgeom_test::scratch_dir();
  for (const char* texture : {"", " --no-texture"}) {
    SCOPED_TRACE(texture);
    const auto v2 =
        cmgeom_test::run_cli("cm build " + spot() + " -o '" + dir + "/v2.cm' --ratio 0.1 --json" + texture, dir);
    ASSERT_EQ(v2.exit_code, 0) << v2.err;
    const auto v3 = cmgeom_test::run_cli(
        "cm build " + spot() + " -o '" + dir + "/v3.cm' --ratio 0.1 --compact --json" + texture, dir);
    ASSERT_EQ(v3.exit_code, 0) << v3.err;
    const auto j = nlohmann::json::parse(v3.out);
    const std::string bytes = file_bytes(dir + "/v3.cm");
    EXPECT_EQ(version_of(bytes), 3u);
    EXPECT_EQ(version_of(file_bytes(dir + "/v2.cm")), 2u);
    EXPECT_EQ(j["bytes"].get<std::size_t>(), bytes.size());
    std::size_t sum = 0;
    for (const auto& part : j["bytes_per_part"].items()) sum += part.value().get<std::size_t>();
    EXPECT_EQ(sum, bytes.size());
    EXPECT_LT(3 * bytes.size(), nlohmann::json::parse(v2.out)["bytes"].get<std::size_t>());
    // Both reconstruct to the same connectivity, and the geometry differs by far less than the CM's error.
    for (const char* v : {"v2", "v3"}) {
      const auto r = cmgeom_test::run_cli(
          "cm reconstruct '" + dir + "/" + v + ".cm' -o '" + dir + "/" + v + ".obj' --level 2 --json", dir);
      ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    const auto e = cmgeom_test::run_cli("error '" + dir + "/v2.obj' '" + dir + "/v3.obj' --json", dir);
    ASSERT_EQ(e.exit_code, 0) << e.err;
    EXPECT_LT(nlohmann::json::parse(e.out)["rms"].get<double>(), 2e-4);  // default tolerance 1e-4 of the diagonal
  }
}

TEST(cmgeom_cli, CmBuildMeetsAnErrorBoundOrAByteBound) {
  const std::string dir = cmgeom_test::scratch_dir();
  const auto a =
      cmgeom_test::run_cli("cm build " + spot() + " -o '" + dir + "/e.cm' --no-texture --max-error 0.01 --json", dir);
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const auto ja = nlohmann::json::parse(a.out);
  EXPECT_LE(ja["rate"]["hausdorff"].get<double>(), 0.01);
  EXPECT_EQ(ja["bytes"].get<std::size_t>(), fs::file_size(dir + "/e.cm"));
  // Measured again by `cmgeom error` (more samples) at the chosen level, which the file stores and
  // `cm reconstruct` takes when no level is asked for: within the bound.
  const int level = ja["rate"]["level"].get<int>();
  const auto rec = cmgeom_test::run_cli("cm reconstruct '" + dir + "/e.cm' -o '" + dir + "/e.obj' --json", dir);
  ASSERT_EQ(rec.exit_code, 0) << rec.err;
  EXPECT_EQ(nlohmann::json::parse(rec.out)["level"].get<int>(), level);
  const auto err = cmgeom_test::run_cli("error " + spot() + " '" + dir + "/e.obj' --json", dir);
  ASSERT_EQ(err.exit_code, 0) << err.err;
  EXPECT_LE(nlohmann::json::parse(err.out)["hausdorff"].get<double>(), 0.01);
  // --level still overrides it; a file with no stored level reconstructs at 2
  const int other = level == 3 ? 1 : 3;
  const auto over = cmgeom_test::run_cli(
      "cm reconstruct '" + dir + "/e.cm' -o '" + dir + "/o.obj' --level " + std::to_string(other) + " --json", dir);
  ASSERT_EQ(over.exit_code, 0) << over.err;
  EXPECT_EQ(nlohmann::json::parse(over.out)["level"].get<int>(), other);
  const auto deformed = cmgeom_test::run_cli(
      "cm deform '" + dir + "/e.cm' --affine 1,0,0,0,0,1,0,0,0,0,1,0 -o '" + dir + "/d.obj' --json", dir);
  ASSERT_EQ(deformed.exit_code, 0) << deformed.err;
  EXPECT_EQ(nlohmann::json::parse(deformed.out)["level"].get<int>(), level);
  ASSERT_EQ(
      cmgeom_test::run_cli("cm build " + spot() + " -o '" + dir + "/f.cm' --no-texture --faces 200", dir).exit_code, 0);
  const auto plain = cmgeom_test::run_cli("cm reconstruct '" + dir + "/f.cm' -o '" + dir + "/f.obj' --json", dir);
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(nlohmann::json::parse(plain.out)["level"].get<int>(), 2);

  const auto b =
      cmgeom_test::run_cli("cm build " + spot() + " -o '" + dir + "/b.cm' --no-texture --bytes 4000 --json", dir);
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_LE(fs::file_size(dir + "/b.cm"), 4000u);
  EXPECT_EQ(nlohmann::json::parse(b.out)["format_version"].get<int>(), 3);
}

TEST(cmgeom_cli, CmBuildRefusesInconsistentRateOptionsAndWritesNothing) {
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string out = " -o '" + dir + "/x.cm'";
  const struct {
    std::string args, message;
  } cases[] = {
      {"--ratio 0.1 --tolerance 1e-3", "--compact"},
      {"--faces 100 --max-error 0.01", "excludes"},
      {"--max-error 0.01", "--no-texture"},
      {"--no-texture --bytes 10", "at least 64"},
      {"--no-texture --max-error 2", "(0, 1)"},
      {"--no-texture --max-error 0.01 --tolerance 1e-3 --compact", "--tolerance is chosen"},
      {"--ratio 0.1 --compact --normal-bits 30", "--normal-bits"},
      {"--no-texture --max-error 1e-7", "no model meets the target"},
      {"--no-texture --ratio 0.1 --fit auto --cubic", "--fit thesis or joint"},
      {"--no-texture --ratio 0.1 --fit thesis --joint-fit", "contradicts --fit thesis"},
      {"--no-texture --ratio 0.1 --fit joint --select-level 3", "--select-level applies"},
      {"--no-texture --ratio 0.1 --select-level 9", "--select-level must"},
      {"--no-texture --max-error 0.01 --fit auto", "does not combine"},
      {"--no-texture --ratio 0.1 --fit best", "--fit"},
      {"--no-texture --max-error 0.01 --optimal-placement", "--optimal-placement applies"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const auto r = cmgeom_test::run_cli("cm build " + spot() + out + " " + c.args, dir);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_EQ(cmgeom_test::count_files(dir), 0u);
  }
}

// An OBJ with texture coordinates that names no texture, its image beside it (as the shared
// spot.obj): `cm build`, `simplify` and `lod` never guess the texture. Each refuses, naming the
// image and the options, and writes nothing; with --texture each makes a textured output (cm build:
// its JSON says textured, and the base's new atlas is written beside the CM file).
TEST(cmgeom_cli, AnInputThatNamesNoTextureIsRefusedUntilTextureOrNoTextureIsGiven) {
  const std::string dir = cmgeom_test::scratch_dir();
  const fs::path data = fs::path(CMGEOM_SOURCE_DIR) / "data" / "spot";
  {
    std::ifstream in(data / "spot.obj");
    std::ofstream out(fs::path(dir) / "cow.obj");
    std::string line;
    while (std::getline(in, line))
      if (line.rfind("mtllib", 0) != 0 && line.rfind("usemtl", 0) != 0) out << line << '\n';
  }
  fs::copy_file(data / "spot_texture.png", fs::path(dir) / "cow_colours.png");
  fs::create_directories(fs::path(dir) / "out");
  const std::string in = "'" + dir + "/cow.obj'";
  const std::string texture = " --texture '" + dir + "/cow_colours.png'";
  const std::vector<std::pair<std::string, std::string>> commands = {{"cm build " + in + " --faces 300 -o ", "out.cm"},
                                                                     {"simplify " + in + " --ratio 0.1 -o ", "out.obj"},
                                                                     {"lod " + in + " --ratios 1,0.25 -o ", "out.glb"}};
  for (const auto& [command, output] : commands) {
    SCOPED_TRACE(command);
    const std::string out = dir + "/out/" + output;  // (not beside the input: outputs are images too)
    const auto refused = cmgeom_test::run_cli("--quiet " + command + "'" + out + "'", dir);
    EXPECT_EQ(refused.exit_code, 1);
    EXPECT_NE(refused.err.find("names no texture (its folder holds cow_colours.png)"), std::string::npos)
        << refused.err;
    EXPECT_NE(refused.err.find("--texture FILE"), std::string::npos) << refused.err;
    EXPECT_FALSE(fs::exists(out));
    const auto given = cmgeom_test::run_cli("--quiet " + command + "'" + out + "'" + texture + " --json", dir);
    ASSERT_EQ(given.exit_code, 0) << given.err;
    EXPECT_TRUE(fs::exists(out));
    const auto j = nlohmann::json::parse(given.out);
    if (j.contains("textured")) EXPECT_EQ(j["textured"], true);
    if (output == "out.cm") EXPECT_TRUE(fs::exists(fs::path(dir) / "out" / "out.png"));  // the base's atlas
    const auto plain = cmgeom_test::run_cli("--quiet " + command + "'" + out + "'" + " --no-texture", dir);
    EXPECT_EQ(plain.exit_code, 0) << plain.err;
  }
  // the pipeline refuses it before it writes anything (its --texture passes the image to its stages)
  const std::string report = dir + "/report";
  const auto pipeline = cmgeom_test::run_cli("--quiet pipeline --model " + in + " -o '" + report + "'", dir);
  EXPECT_EQ(pipeline.exit_code, 1);
  EXPECT_NE(pipeline.err.find("names no texture (its folder holds cow_colours.png); pass --texture FILE"),
            std::string::npos)
      << pipeline.err;
  EXPECT_FALSE(fs::exists(report));
}

// Texture coordinates without any texture (none named, no image beside the file) make a
// geometry-only CM, as `simplify` makes a geometry-only mesh of such an input, with a note; a
// textured base that the charts stop above its face target says so on stderr and in the JSON.
TEST(cmgeom_cli, CmBuildOfUVsWithoutTextureIsGeometryOnlyAndATexturedBaseAboveItsTargetSaysWhy) {
  const std::string dir = cmgeom_test::scratch_dir();
  {
    std::ifstream in(fs::path(CMGEOM_SOURCE_DIR) / "data" / "spot" / "spot.obj");
    std::ofstream out(fs::path(dir) / "bare.obj");
    std::string line;
    while (std::getline(in, line))
      if (line.rfind("mtllib", 0) != 0 && line.rfind("usemtl", 0) != 0) out << line << '\n';
  }
  const auto bare =
      cmgeom_test::run_cli("--quiet cm build '" + dir + "/bare.obj' --faces 300 --json -o '" + dir + "/bare.cm'", dir);
  ASSERT_EQ(bare.exit_code, 0) << bare.err;
  EXPECT_NE(bare.err.find("names no texture: texture coordinates are dropped (geometry-only model)"), std::string::npos)
      << bare.err;
  const auto jb = nlohmann::json::parse(bare.out);
  EXPECT_EQ(jb["textured"], false);
  EXPECT_LE(jb["base_faces"].get<int>(), 300);
  EXPECT_FALSE(jb.contains("base_stopped_by"));
  // Spot's 13 charts keep its textured base above 20 faces
  const auto above =
      cmgeom_test::run_cli("--quiet cm build " + spot() + " --faces 20 --json -o '" + dir + "/spot.cm'", dir);
  ASSERT_EQ(above.exit_code, 0) << above.err;
  const auto ja = nlohmann::json::parse(above.out);
  EXPECT_EQ(ja["textured"], true);
  EXPECT_GT(ja["base_faces"].get<int>(), 20);
  EXPECT_EQ(ja["base_target_faces"], 20);
  EXPECT_EQ(ja["base_stopped_by"], "chart_limit");
  EXPECT_NE(above.err.find("the base stopped at " + std::to_string(ja["base_faces"].get<int>()) +
                           " faces for a target of 20 (chart limit"),
            std::string::npos)
      << above.err;
}

// `cm build` without --fit measures its candidate builds and keeps the lowest Hausdorff error
// (select_compact_model.h); the JSON lists them. --fit thesis builds the thesis' model alone, whose
// error is the thesis candidate's.
TEST(cmgeom_cli, CmBuildChoosesItsFitsByMeasurement) {
  const std::string dir = cmgeom_test::scratch_dir();
  const auto a =
      cmgeom_test::run_cli("cm build " + spot() + " -o '" + dir + "/a.cm' --no-texture --ratio 0.05 --json", dir);
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const auto ja = nlohmann::json::parse(a.out);
  ASSERT_TRUE(ja.contains("selection"));
  EXPECT_EQ(ja["selection"]["level"], 3);
  const auto& cs = ja["selection"]["candidates"];
  ASSERT_EQ(cs.size(), 3u);
  EXPECT_EQ(cs[0]["fit"], "thesis");
  double lowest = 1e300;
  std::string lowest_fit;
  for (const auto& c : cs)
    if (c["hausdorff"].get<double>() < lowest) {
      lowest = c["hausdorff"].get<double>();
      lowest_fit = c["fit"].get<std::string>();
    }
  EXPECT_EQ(ja["fit"], lowest_fit);
  EXPECT_TRUE(fs::exists(dir + "/a.cm"));

  const auto t = cmgeom_test::run_cli(
      "cm build " + spot() + " -o '" + dir + "/t.cm' --no-texture --ratio 0.05 --fit thesis --json", dir);
  ASSERT_EQ(t.exit_code, 0) << t.err;
  const auto jt = nlohmann::json::parse(t.out);
  EXPECT_EQ(jt["fit"], "thesis");
  EXPECT_FALSE(jt.contains("selection"));
  EXPECT_FALSE(jt["joint_fit"].get<bool>());
  // its level-3 reconstruction measured on the selection's samples (100,000 per direction for
  // Spot's 5,856 faces, the same seed) has the thesis candidate's error, up to the output's floats
  const auto r = cmgeom_test::run_cli("cm reconstruct '" + dir + "/t.cm' -o '" + dir + "/t3.ply' --level 3", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto e = cmgeom_test::run_cli("error " + spot() + " '" + dir + "/t3.ply' --samples 100000 --json", dir);
  ASSERT_EQ(e.exit_code, 0) << e.err;
  const auto je = nlohmann::json::parse(e.out);
  EXPECT_NEAR(je["hausdorff"].get<double>(), cs[0]["hausdorff"].get<double>(), 1e-4 * cs[0]["hausdorff"].get<double>());
  EXPECT_NEAR(je["rms"].get<double>(), cs[0]["rms"].get<double>(), 1e-4 * cs[0]["rms"].get<double>());
  if (ja["fit"] == "thesis") EXPECT_EQ(file_bytes(dir + "/a.cm"), file_bytes(dir + "/t.cm"));
}

// `cm build --level-errors` stores the table (its bytes reported as a part of the compact file);
// `cm reconstruct --vertices` at the vertex count of regular level 2 places them by it, within
// the budget, and `cmgeom error` measures an RMS and a Hausdorff distance against the input no
// larger than the regular level's (the Hausdorff up to the measure's sampling, 2 %). Without a
// table the budget is placed by the chord error. A depth out of range writes nothing.
TEST(cmgeom_cli, CmReconstructToAVertexBudgetFromTheLevelErrorTable) {
  const std::string dir = cmgeom_test::scratch_dir();
  const auto b = cmgeom_test::run_cli(
      "cm build " + spot() + " -o '" + dir + "/t.cm' --no-texture --ratio 0.1 --level-errors 3 --compact --json", dir);
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const auto jb = nlohmann::json::parse(b.out);
  EXPECT_EQ(jb["level_errors"]["depth"].get<int>(), 3);
  EXPECT_GT(jb["bytes_per_part"]["level_errors"].get<std::size_t>(), 0u);
  const auto reg =
      cmgeom_test::run_cli("cm reconstruct '" + dir + "/t.cm' -o '" + dir + "/reg.obj' --level 2 --json", dir);
  ASSERT_EQ(reg.exit_code, 0) << reg.err;
  const std::size_t budget = nlohmann::json::parse(reg.out)["vertices"].get<std::size_t>();
  const auto ad = cmgeom_test::run_cli(
      "cm reconstruct '" + dir + "/t.cm' -o '" + dir + "/ad.obj' --vertices " + std::to_string(budget) + " --json",
      dir);
  ASSERT_EQ(ad.exit_code, 0) << ad.err;
  const auto ja = nlohmann::json::parse(ad.out);
  EXPECT_EQ(ja["placed_by"].get<std::string>(), "level errors");
  EXPECT_EQ(ja["mode"].get<std::string>(), "vertex-budget");
  EXPECT_LE(ja["vertices"].get<std::size_t>(), budget);
  EXPECT_LE(ja["estimated_rms"].get<double>(), ja["regular_estimated_rms"].get<double>());
  const auto er = cmgeom_test::run_cli("error " + spot() + " '" + dir + "/reg.obj' --json", dir);
  const auto ea = cmgeom_test::run_cli("error " + spot() + " '" + dir + "/ad.obj' --json", dir);
  ASSERT_EQ(er.exit_code, 0) << er.err;
  ASSERT_EQ(ea.exit_code, 0) << ea.err;
  const auto jr = nlohmann::json::parse(er.out), je = nlohmann::json::parse(ea.out);
  EXPECT_LE(je["rms"].get<double>(), jr["rms"].get<double>());
  EXPECT_LE(je["hausdorff"].get<double>(), 1.02 * jr["hausdorff"].get<double>());

  ASSERT_EQ(
      cmgeom_test::run_cli("cm build " + spot() + " -o '" + dir + "/p.cm' --no-texture --ratio 0.1", dir).exit_code, 0);
  const auto chord = cmgeom_test::run_cli(
      "cm reconstruct '" + dir + "/p.cm' -o '" + dir + "/c.obj' --vertices " + std::to_string(budget) + " --json", dir);
  ASSERT_EQ(chord.exit_code, 0) << chord.err;
  EXPECT_EQ(nlohmann::json::parse(chord.out)["placed_by"].get<std::string>(), "chord error");
  EXPECT_LE(nlohmann::json::parse(chord.out)["vertices"].get<std::size_t>(), budget);

  const auto bad = cmgeom_test::run_cli(
      "cm build " + spot() + " -o '" + dir + "/bad.cm' --no-texture --ratio 0.1 --level-errors 9", dir);
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("--level-errors"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir + "/bad.cm"));
}

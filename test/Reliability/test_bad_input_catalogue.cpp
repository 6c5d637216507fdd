// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Bad-input catalogue of the cmgeom tool (doc/Reliability.md): every entry point that reads user
// files (simplify, error, render, compare, cm build, cm reconstruct, cm deform, deform) is fed
// malformed or unreasonable input written by the test itself. Each case checks:
//   * a non-zero exit code;
//   * stderr carries exactly one error line, "cmgeom <command>: error: ...", that names the
//     offending file or option (warnings, notes and the progress lines of stages that finished
//     before it may precede it, nothing else);
//   * the output directory is still empty (no output file, no temporary left behind).
// Cases with a documented handling instead of an error (a target larger than the input, a mesh
// outside a mean value cage, tiling UVs) check that handling.
// The mesh-reader catalogue (empty, garbage, truncated, out-of-range indices, NaN/Inf, degenerate
// and non-manifold input through the library and `cmgeom convert`) is in test/Mesh_IO.
#include "cmgeom_test_meshes.h"
#include "cmgeom_test_support.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

std::string q(const std::string& path) { return "'" + path + "'"; }

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

std::vector<std::string> lines_of(const std::string& s) {
  std::vector<std::string> r;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) r.push_back(l);
  return r;
}

// A closed box cage [-s, s]^3 (quads, outward), optionally without its last face, with vertex 7
// moved by `shift` in x (the "deformed" pose), then every vertex mapped by x -> scale x + offset.
std::string box_cage(double s, bool open = false, double shift = 0, double scale = 1,
                     const std::array<double, 3>& offset = {0, 0, 0}) {
  std::ostringstream o;
  o.precision(17);
  const double v[8][3] = {{-s, -s, -s}, {s, -s, -s}, {s, s, -s}, {-s, s, -s},
                          {-s, -s, s},  {s, -s, s},  {s, s, s},  {-s, s, s}};
  for (int i = 0; i < 8; ++i)
    o << "v " << scale * (v[i][0] + (i == 6 ? shift : 0)) + offset[0] << " " << scale * v[i][1] + offset[1] << " "
      << scale * v[i][2] + offset[2] << "\n";
  o << "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\n";
  if (!open) o << "f 4 1 5 8\n";
  return o.str();
}

std::uint64_t fnv1a64(const std::string& b, std::size_t n) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::size_t i = 0; i < n; ++i) {
    h ^= static_cast<unsigned char>(b[i]);
    h *= 1099511628211ull;
  }
  return h;
}

void put_u64(std::string& b, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) b[at + std::size_t(i)] = char((v >> (8 * i)) & 0xffu);
}

void put_u32(std::string& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + std::size_t(i)] = char((v >> (8 * i)) & 0xffu);
}

std::uint64_t get_u64(const std::string& b, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= std::uint64_t(static_cast<unsigned char>(b[at + std::size_t(i)])) << (8 * i);
  return v;
}

// CM files (include/CMGeom/Compact_model/cm_io.h): the trailing 8 bytes are an FNV-1a hash of
// the rest; recomputing it lets a corruption reach the validation behind the checksum.
void fix_checksum(std::string& b) { put_u64(b, b.size() - 8, fnv1a64(b, b.size() - 8)); }

class Bad_input : public ::testing::Test {
protected:
  void SetUp() override {
    base = cmgeom_test::scratch_dir();
    in = (fs::path(base) / "in").string();
    out = (fs::path(base) / "out").string();
    fs::create_directories(in);
    fs::create_directories(out);
  }

  std::string input(const std::string& name, const std::string& content) {
    const std::string p = (fs::path(in) / name).string();
    write_bytes(p, content);
    return p;
  }
  std::string output(const std::string& name) const { return (fs::path(out) / name).string(); }

  // Runs `args`; checks the catalogue's three rules; `names` must occur in the error line.
  void expect_rejected(const std::string& args, const std::vector<std::string>& names) {
    const cmgeom_test::Cli_result r = cmgeom_test::run_cli(args, base);
    SCOPED_TRACE("cmgeom " + args);
    EXPECT_NE(r.exit_code, 0) << "stdout: " << r.out;
    const std::vector<std::string> lines = lines_of(r.err);
    std::size_t errors = 0;
    std::string error_line;
    for (const std::string& l : lines) {
      if (l.find(": warning: ") != std::string::npos || l.find(": note: ") != std::string::npos) continue;
      // a stage that finished before the error, on a slow machine (doc/CLI.md, "Progress")
      if (l.rfind("cmgeom: ", 0) == 0 && l.find(": done in ") != std::string::npos) continue;
      ++errors;
      error_line = l;
    }
    EXPECT_EQ(errors, 1u) << "expected one error line, stderr was:\n" << r.err;
    std::cout << "    rejected (exit " << r.exit_code << "): " << error_line << "\n";
    if (r.exit_code == 1)  // usage errors (exit code 2) are CLI11's own format
      EXPECT_EQ(error_line.rfind("cmgeom ", 0), 0u) << error_line;
    for (const std::string& n : names)
      EXPECT_NE(error_line.find(n), std::string::npos) << "'" << n << "' not in: " << error_line;
    std::vector<std::string> left;
    for (const auto& e : fs::recursive_directory_iterator(out)) left.push_back(e.path().string());
    EXPECT_TRUE(left.empty()) << "left behind: " << (left.empty() ? "" : left.front());
  }

  cmgeom_test::Cli_result run(const std::string& args) { return cmgeom_test::run_cli(args, base); }

  // A valid CM file of a level-2 icosphere (320 faces) with a 40-face base, made by the tool.
  std::string good_cm() {
    const std::string mesh = input("sphere.obj", cmgeom_test::icosphere_obj(2));
    const std::string cm = (fs::path(in) / "good.cm").string();
    const auto r = run("cm build " + q(mesh) + " -o " + q(cm) + " --faces 40");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return cm;
  }

  std::string base, in, out;
};

// ------------------------------------------------------------------ simplify
TEST_F(Bad_input, SimplifyEmptyFile) {
  const std::string m = input("empty.obj", "");
  expect_rejected("simplify " + q(m) + " -o " + q(output("s.obj")) + " --faces 10", {"empty.obj"});
}

TEST_F(Bad_input, SimplifyBinaryGarbage) {
  std::string g(4096, '\0');
  for (std::size_t i = 0; i < g.size(); ++i) g[i] = char((i * 2654435761u) >> 13);
  const std::string m = input("garbage.obj", g);
  expect_rejected("simplify " + q(m) + " -o " + q(output("s.obj")) + " --faces 10", {"garbage.obj"});
}

TEST_F(Bad_input, SimplifyNaNCoordinate) {
  const std::string m = input("nan.obj", cmgeom_test::icosphere_obj(1, 1.0, "v nan 0 0"));
  expect_rejected("simplify " + q(m) + " -o " + q(output("s.obj")) + " --faces 10", {"nan.obj"});
}

TEST_F(Bad_input, SimplifyInfCoordinate) {
  const std::string m = input("inf.obj", cmgeom_test::icosphere_obj(1, 1.0, "v 0 inf 0"));
  expect_rejected("simplify " + q(m) + " -o " + q(output("s.obj")) + " --faces 10", {"inf.obj"});
}

TEST_F(Bad_input, SimplifyIndexOutOfRange) {
  const std::string m = input("range.obj", cmgeom_test::icosphere_obj(1) + "f 1 2 999\n");
  expect_rejected("simplify " + q(m) + " -o " + q(output("s.obj")) + " --faces 10", {"range.obj"});
}

TEST_F(Bad_input, SimplifyZeroTargetFaces) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("simplify " + q(m) + " -o " + q(output("s.obj")) + " --faces 0", {"--faces"});
}

TEST_F(Bad_input, SimplifyZeroRatio) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("simplify " + q(m) + " -o " + q(output("s.obj")) + " --ratio 0", {"--ratio"});
}

TEST_F(Bad_input, SimplifyRatioAboveOne) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("simplify " + q(m) + " -o " + q(output("s.obj")) + " --ratio 1.5", {"--ratio"});
}

TEST_F(Bad_input, SimplifyNaNRatio) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("simplify " + q(m) + " -o " + q(output("s.obj")) + " --ratio nan", {"--ratio"});
}

// Documented handling (doc/Reliability.md): a target at or above the input's face count leaves
// the mesh as it is; the output is written and has every input face.
TEST_F(Bad_input, SimplifyTargetLargerThanInputKeepsTheMesh) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));  // 80 faces
  const std::string o = output("s.off");
  const auto r = run("simplify " + q(m) + " -o " + q(o) + " --faces 100000");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream off(o);
  std::string magic;
  std::size_t nv = 0, nf = 0;
  off >> magic >> nv >> nf;
  EXPECT_EQ(magic, "OFF");
  EXPECT_EQ(nv, 42u);
  EXPECT_EQ(nf, 80u);
}

TEST_F(Bad_input, SimplifyUnsupportedOutputFormat) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("simplify " + q(m) + " -o " + q(output("s.xyz")) + " --faces 10", {"s.xyz"});
}

TEST_F(Bad_input, SimplifyOutputDirectoryMissing) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("simplify " + q(m) + " -o " + q(output("missing/s.obj")) + " --faces 10", {"s.obj"});
}

TEST_F(Bad_input, SimplifyMissingInput) {
  expect_rejected("simplify " + q(in + "/nothere.obj") + " -o " + q(output("s.obj")) + " --faces 10", {"nothere.obj"});
}

// A planar 16 x 16 grid (512 triangles) whose UVs span [-1, 2]^2: the texture tiles 3 x 3.
std::string tiled_grid_obj(const std::string& mtllib) {
  std::ostringstream o;
  if (!mtllib.empty()) o << "mtllib " << mtllib << "\n";
  const int n = 16;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      o << "v " << double(i) / n << " " << double(j) / n << " " << 0.05 * ((i * j) % 3) << "\n";
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) o << "vt " << 3.0 * i / n - 1 << " " << 3.0 * j / n - 1 << "\n";
  if (!mtllib.empty()) o << "usemtl tiles\n";
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i + 1, b = a + 1, c = a + n + 2, d = a + n + 1;
      o << "f " << a << "/" << a << " " << b << "/" << b << " " << c << "/" << c << "\n";
      o << "f " << a << "/" << a << " " << c << "/" << c << " " << d << "/" << d << "\n";
    }
  return o.str();
}

// Documented handling (doc/Textured_simplification, "Domain of the textures"): UVs outside [0, 1]
// repeat the texture; the simplified mesh gets its own texture and UVs renormalised into [0, 1].
TEST_F(Bad_input, SimplifyTilingUVsAreRenormalised) {
  input("t.ppm", "P3\n2 2\n255\n255 0 0 0 255 0 0 0 255 255 255 255\n");
  const std::string m = input("tiled.obj", tiled_grid_obj(""));
  const std::string o = output("s.obj");
  const auto r = run("simplify " + q(m) + " -o " + q(o) + " --ratio 0.25 --texture " + q(in + "/t.ppm"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream obj(o);
  std::size_t uvs = 0;
  for (std::string line; std::getline(obj, line);) {
    if (line.rfind("vt ", 0) != 0) continue;
    std::istringstream ls(line.substr(3));
    double u = -1, v = -1;
    ls >> u >> v;
    EXPECT_TRUE(u >= 0 && u <= 1 && v >= 0 && v <= 1) << line;
    ++uvs;
  }
  EXPECT_GT(uvs, 0u);
}

TEST_F(Bad_input, SimplifyMissingTexture) {
  input("m.mtl", "newmtl tiles\nmap_Kd nothere.png\n");
  const std::string m = input("tiled.obj", tiled_grid_obj("m.mtl"));
  expect_rejected("simplify " + q(m) + " -o " + q(output("s.obj")) + " --ratio 0.5", {"nothere.png"});
}

// ------------------------------------------------------------------ error, render, compare
TEST_F(Bad_input, ErrorTruncatedApproximation) {
  const std::string ref = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  const std::string full = cmgeom_test::icosphere_obj(1);
  const std::string app = input("cut.obj", full.substr(0, full.size() * 2 / 3) + "f 1 2 300\n");
  expect_rejected("error " + q(ref) + " " + q(app) + " --field " + q(output("f.txt")), {"cut.obj"});
}

TEST_F(Bad_input, ErrorNaNReference) {
  const std::string ref = input("nan.obj", cmgeom_test::icosphere_obj(1, 1.0, "v 0 0 nan"));
  const std::string app = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("error " + q(ref) + " " + q(app) + " --field " + q(output("f.txt")), {"nan.obj"});
}

TEST_F(Bad_input, ErrorUnsupportedFieldFormat) {
  const std::string ref = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("error " + q(ref) + " " + q(ref) + " --field " + q(output("f.csv")), {"f.csv"});
}

TEST_F(Bad_input, RenderNaNMesh) {
  const std::string m = input("nan.obj", cmgeom_test::icosphere_obj(1, 1.0, "v nan nan nan"));
  expect_rejected("render " + q(m) + " -o " + q(output("r.png")) + " --size 64x64", {"nan.obj"});
}

TEST_F(Bad_input, RenderBadSize) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("render " + q(m) + " -o " + q(output("r.png")) + " --size 0x64", {"--size"});
}

TEST_F(Bad_input, RenderFieldWithWrongCount) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));  // 42 vertices
  const std::string f = input("field.txt", "1\n2\n3\n");
  expect_rejected("render " + q(m) + " -o " + q(output("r.png")) + " --size 64x64 --field " + q(f), {"field.txt"});
}

// Regression test of a finding: a NaN value in a --field file was accepted and a PNG written
// whose colour for that vertex was undefined (the field reader checked the count only). The
// reader now rejects non-finite values with the file and line.
TEST_F(Bad_input, RenderFieldWithNaN) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  std::string values;
  for (int i = 0; i < 42; ++i) values += i == 5 ? "nan\n" : "1\n";
  const std::string f = input("field.txt", values);
  expect_rejected("render " + q(m) + " -o " + q(output("r.png")) + " --size 64x64 --field " + q(f), {"field.txt"});
}

// A material whose texture file is missing: the reader reports it (file and line of the MTL).
TEST_F(Bad_input, RenderMissingTexture) {
  input("m.mtl", "newmtl skin\nmap_Kd nothere.png\n");
  const std::string m = input("tex.obj",
                              "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                              "usemtl skin\nf 1/1 2/2 3/3\n");
  expect_rejected("render " + q(m) + " -o " + q(output("r.png")) + " --size 64x64", {"nothere.png"});
}

// Documented handling (doc/Reliability.md): texture coordinates outside [0, 1] tile the texture
// (OpenGL's GL_REPEAT); such a mesh renders.
TEST_F(Bad_input, RenderTilingUVsRepeatTheTexture) {
  const std::string png = input("t.ppm", "P3\n2 2\n255\n255 0 0 0 255 0 0 0 255 255 255 255\n");
  (void)png;
  const std::string m = input("tiled.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt -2 -3\nvt 4 0\nvt 0 7.5\nf 1/1 2/2 3/3\n");
  const auto r = run("render " + q(m) + " -o " + q(output("r.png")) + " --size 64x64 --texture " + q(in + "/t.ppm"));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(output("r.png")));
}

TEST_F(Bad_input, CompareMissingApproximation) {
  const std::string ref = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("compare " + q(ref) + " " + q(in + "/nothere.obj") + " -o " + q(output("c.png")) + " --size 32",
                  {"nothere.obj"});
}

TEST_F(Bad_input, CompareEmptyReference) {
  const std::string ref = input("empty.off", "");
  const std::string app = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("compare " + q(ref) + " " + q(app) + " -o " + q(output("c.png")) + " --size 32", {"empty.off"});
}

// ------------------------------------------------------------------ cm build
TEST_F(Bad_input, CmBuildEmptyMesh) {
  const std::string m = input("empty.ply", "");
  expect_rejected("cm build " + q(m) + " -o " + q(output("m.cm")) + " --faces 10", {"empty.ply"});
}

TEST_F(Bad_input, CmBuildZeroTargetFaces) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("cm build " + q(m) + " -o " + q(output("m.cm")) + " --faces 0", {"--faces"});
}

TEST_F(Bad_input, CmBuildZeroRatio) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("cm build " + q(m) + " -o " + q(output("m.cm")) + " --ratio 0", {"--ratio"});
}

TEST_F(Bad_input, CmBuildNaNCoordinate) {
  const std::string m = input("nan.obj", cmgeom_test::icosphere_obj(1, 1.0, "v 1 nan 0"));
  expect_rejected("cm build " + q(m) + " -o " + q(output("m.cm")) + " --faces 10", {"nan.obj"});
}

TEST_F(Bad_input, CmBuildBadSharpAngle) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  expect_rejected("cm build " + q(m) + " -o " + q(output("m.cm")) + " --faces 10 --sharp-angle 200", {"--sharp-angle"});
}

TEST_F(Bad_input, CmBuildBadErrorControl) {
  const std::string m = input("sphere.obj", cmgeom_test::icosphere_obj(1));
  const std::string head = "cm build " + q(m) + " -o " + q(output("m.cm")) + " --faces 10 --error-bound 0.01";
  expect_rejected(head + " --error-rounds -1", {"--error-rounds"});
  expect_rejected(head + " --error-level 9", {"--error-level"});
  expect_rejected("cm build " + q(m) + " -o " + q(output("m.cm")) + " --faces 10 --error-bound -1", {"--error-bound"});
}

// ------------------------------------------------------------------ cm reconstruct
TEST_F(Bad_input, CmReconstructEmptyFile) {
  const std::string cm = input("empty.cm", "");
  expect_rejected("cm reconstruct " + q(cm) + " -o " + q(output("r.ply")), {"empty.cm"});
}

TEST_F(Bad_input, CmReconstructNotACmFile) {
  const std::string cm = input("mesh.cm", cmgeom_test::icosphere_obj(1));
  expect_rejected("cm reconstruct " + q(cm) + " -o " + q(output("r.ply")), {"mesh.cm"});
}

TEST_F(Bad_input, CmReconstructTruncatedFile) {
  const std::string bytes = read_bytes(good_cm());
  ASSERT_GT(bytes.size(), 200u);
  const std::string cm = input("cut.cm", bytes.substr(0, bytes.size() / 2));
  expect_rejected("cm reconstruct " + q(cm) + " -o " + q(output("r.ply")), {"cut.cm"});
}

TEST_F(Bad_input, CmReconstructCorruptByte) {
  std::string bytes = read_bytes(good_cm());
  bytes[bytes.size() / 2] = char(bytes[bytes.size() / 2] ^ 0x10);  // the checksum catches it
  const std::string cm = input("flip.cm", bytes);
  expect_rejected("cm reconstruct " + q(cm) + " -o " + q(output("r.ply")), {"flip.cm"});
}

// A declared vertex count of 2^60 with a valid checksum: rejected before any allocation.
TEST_F(Bad_input, CmReconstructHugeDeclaredCount) {
  std::string bytes = read_bytes(good_cm());
  put_u64(bytes, 16, std::uint64_t(1) << 60);
  fix_checksum(bytes);
  const std::string cm = input("huge.cm", bytes);
  expect_rejected("cm reconstruct " + q(cm) + " -o " + q(output("r.ply")), {"huge.cm"});
}

// A face corner naming a vertex past the end, with a valid checksum.
TEST_F(Bad_input, CmReconstructIndexOutOfRange) {
  std::string bytes = read_bytes(good_cm());
  const std::uint64_t nv = get_u64(bytes, 16), nn = get_u64(bytes, 24), ns = get_u64(bytes, 32),
                      nc = get_u64(bytes, 40), nf = get_u64(bytes, 48);
  ASSERT_GT(nf, 0u);
  // Walk version 2's sections (doc/Compact_model/README.md) to the faces' vertex indices.
  ASSERT_EQ(std::uint8_t(bytes[8]), 2u);
  std::size_t at = 56 + 12 * std::size_t(nv + nn);
  for (std::uint64_t i = 0; i < ns; ++i) {
    const int model_id = std::uint8_t(bytes[at]);
    ASSERT_LE(model_id, 2);
    at += 1 + 4 * std::size_t(model_id == 0 ? 5 : model_id == 1 ? 6 : 9);
  }
  at += 4 * std::size_t(nc);
  std::size_t sectors = 0;
  for (std::uint64_t v = 0; v < nv; ++v) sectors += std::uint8_t(bytes[at + v]);
  at += std::size_t(nv);
  if (!(std::uint8_t(bytes[12]) & 2u)) at += 8 * sectors;  // explicit sector table
  put_u32(bytes, at, std::uint32_t(nv + nn + 5));          // first corner's vertex index
  fix_checksum(bytes);
  const std::string cm = input("index.cm", bytes);
  expect_rejected("cm reconstruct " + q(cm) + " -o " + q(output("r.ply")), {"index.cm"});
}

// A NaN vertex coordinate with a valid checksum.
TEST_F(Bad_input, CmReconstructNaNVertex) {
  std::string bytes = read_bytes(good_cm());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::uint32_t u;
  std::memcpy(&u, &nan, 4);
  put_u32(bytes, 56, u);  // x of the first vertex
  fix_checksum(bytes);
  const std::string cm = input("nan.cm", bytes);
  expect_rejected("cm reconstruct " + q(cm) + " -o " + q(output("r.ply")), {"nan.cm"});
}

TEST_F(Bad_input, CmReconstructLevelOutOfRange) {
  const std::string cm = good_cm();
  expect_rejected("cm reconstruct " + q(cm) + " -o " + q(output("r.ply")) + " --level 13", {"--level"});
}

// ------------------------------------------------------------------ deform, cm deform
class Bad_cages : public Bad_input {
protected:
  // A cage system of one cage: rest and deformed OBJ files, coordinates `coords`.
  std::string system(const std::string& rest, const std::string& deformed, const std::string& coords = "mean_value",
                     const std::string& extra = "") {
    input("rest.obj", rest);
    input("deformed.obj", deformed);
    return input("system.json",
                 "{\"cages\": [{\"rest\": \"rest.obj\", \"deformed\": \"deformed.obj\", "
                 "\"coordinates\": \"" +
                     coords + "\"" + extra + "}]}");
  }
  std::string mesh() { return input("sphere.obj", cmgeom_test::icosphere_obj(1)); }
  // The deformed mesh `off` (an OFF file, vertices in mesh()'s order) is mesh() mapped by
  // x -> scale x + shift, to 1e-6.
  void expect_mesh_mapped(const std::string& off, double scale, const std::array<double, 3>& shift) {
    std::vector<std::array<double, 3>> p;
    std::vector<std::array<std::size_t, 3>> f;
    cmgeom_test::icosphere(1, p, f);
    std::ifstream in(off);
    std::string magic;
    std::size_t nv = 0, nf = 0, ne = 0;
    in >> magic >> nv >> nf >> ne;
    ASSERT_EQ(nv, p.size());
    for (std::size_t i = 0; i < nv; ++i)
      for (std::size_t k = 0; k < 3; ++k) {
        double x = 0;
        in >> x;
        EXPECT_NEAR(x, scale * p[i][k] + shift[k], 1e-6) << "vertex " << i;
      }
  }
};

TEST_F(Bad_cages, DeformOpenCage) {
  const std::string s = system(box_cage(2, true), box_cage(2, true, 1));
  expect_rejected("deform " + q(mesh()) + " --cages " + q(s) + " -o " + q(output("d.ply")), {"rest.obj"});
}

TEST_F(Bad_cages, DeformMismatchedRestAndDeformedCages) {
  const std::string s = system(box_cage(2), box_cage(2) + "v 9 9 9\n");
  expect_rejected("deform " + q(mesh()) + " --cages " + q(s) + " -o " + q(output("d.ply")),
                  {"system.json", "/cages/0/deformed"});
}

TEST_F(Bad_cages, DeformFlatCage) {
  const std::string flat = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 4 3 2 1\n";
  const std::string s = system(flat, flat);
  expect_rejected("deform " + q(mesh()) + " --cages " + q(s) + " -o " + q(output("d.ply")), {"rest.obj"});
}

TEST_F(Bad_cages, DeformNaNCageVertex) {
  const std::string s = system(box_cage(2), "v nan 0 0\n" + box_cage(2).substr(box_cage(2).find('\n') + 1));
  expect_rejected("deform " + q(mesh()) + " --cages " + q(s) + " -o " + q(output("d.ply")), {"deformed.obj"});
}

TEST_F(Bad_cages, DeformInvalidJson) {
  const std::string s = input("system.json", "{\"cages\": [ {\"rest\": ");
  expect_rejected("deform " + q(mesh()) + " --cages " + q(s) + " -o " + q(output("d.ply")), {"system.json"});
}

TEST_F(Bad_cages, DeformUnknownCoordinates) {
  const std::string s = system(box_cage(2), box_cage(2, false, 1), "barycentric");
  expect_rejected("deform " + q(mesh()) + " --cages " + q(s) + " -o " + q(output("d.ply")), {"system.json"});
}

TEST_F(Bad_cages, DeformMissingCageFile) {
  const std::string s =
      input("system.json", "{\"cages\": [{\"rest\": \"nothere.obj\", \"deformed\": \"nothere.obj\"}]}");
  expect_rejected("deform " + q(mesh()) + " --cages " + q(s) + " -o " + q(output("d.ply")), {"nothere.obj"});
}

// Harmonic coordinates are undefined outside the cage: a mesh that sticks out is an error, whose
// message names the coordinates defined there.
TEST_F(Bad_cages, DeformHarmonicCageNotEnclosingTheMesh) {
  const std::string s =
      system(box_cage(0.5), box_cage(0.5, false, 0.2), "harmonic", ", \"harmonic\": {\"resolution\": 16}");
  expect_rejected("deform " + q(mesh()) + " --cages " + q(s) + " -o " + q(output("d.ply")),
                  {"outside", "\"harmonic\": {\"outside\": \"mean_value\"}", "\"green\""});
}

// The remedy the refusal names first: "harmonic": {"outside": "mean_value"}. Inside the cage the
// harmonic coordinates, outside it the mean value ones; both reproduce affine maps, so a cage
// mapped by x -> 2x + (0.1, 0.2, 0.3) maps every vertex of the mesh, inside or out, the same way.
TEST_F(Bad_cages, DeformHarmonicCageWithMeanValueOutsideMapsEveryVertex) {
  const std::string s = system(box_cage(0.9), box_cage(0.9, false, 0, 2, {0.1, 0.2, 0.3}), "harmonic",
                               ", \"harmonic\": {\"resolution\": 16, \"outside\": \"mean_value\"}");
  const std::string o = output("d.off");
  const auto r = run("deform " + q(mesh()) + " --cages " + q(s) + " -o " + q(o) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // (both kinds of vertices: the unit sphere's points near the axes lie outside the box, those
  // near its diagonals inside)
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["vertex_status"]["extended"].get<int>(), 0) << r.out;
  EXPECT_GT(j["vertex_status"]["regular"].get<int>() + j["vertex_status"]["approximate"].get<int>(), 0) << r.out;
  EXPECT_EQ(j["vertex_status"]["undefined"].get<int>(), 0) << r.out;
  expect_mesh_mapped(o, 2, {0.1, 0.2, 0.3});
}

// Documented handling (doc/Cage_deformation, doc/Reliability.md): mean value coordinates extend
// outside the cage; a rest pose equal to the deformed pose reproduces every vertex, inside or out.
TEST_F(Bad_cages, DeformMeanValueCageNotEnclosingTheMeshExtends) {
  const std::string s = system(box_cage(0.5), box_cage(0.5));
  const std::string o = output("d.off");
  const auto r = run("deform " + q(mesh()) + " --cages " + q(s) + " -o " + q(o));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_mesh_mapped(o, 1, {0, 0, 0});
}

TEST_F(Bad_cages, CmDeformMismatchedCages) {
  const std::string cm = good_cm();
  const std::string s = system(box_cage(2), box_cage(2) + "v 9 9 9\n");
  expect_rejected("cm deform " + q(cm) + " --cages " + q(s) + " -o " + q(output("d.ply")),
                  {"system.json", "/cages/0/deformed"});
}

// A singular affine map would flatten the model (every face degenerate): refused, naming the option.
TEST_F(Bad_cages, CmDeformSingularAffineMap) {
  expect_rejected("cm deform " + q(good_cm()) + " --affine 1,0,0,0,0,1,0,0,0,0,0,0 -o " + q(output("d.ply")),
                  {"--affine 1,0,0,0,0,1,0,0,0,0,0,0", "singular"});
}

TEST_F(Bad_cages, CmDeformCorruptCm) {
  std::string bytes = read_bytes(good_cm());
  bytes.resize(bytes.size() - 3);
  const std::string cm = input("cut.cm", bytes);
  const std::string s = system(box_cage(2), box_cage(2, false, 1));
  expect_rejected("cm deform " + q(cm) + " --cages " + q(s) + " -o " + q(output("d.ply")), {"cut.cm"});
}

}  // namespace

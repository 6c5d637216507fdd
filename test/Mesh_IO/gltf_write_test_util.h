// Helpers of the tests of the glTF 2.0 / GLB writer: images, textured meshes built here, face
// records and their comparison after a round trip, the buffers of written files, and the Khronos
// glTF validator (skipped when Node.js or the validator's npm package is missing). Included by
// the test_gltf_write_*.cpp files and test_gltf_validator.cpp.
#ifndef CMGEOM_TEST_GLTF_WRITE_UTIL_H
#define CMGEOM_TEST_GLTF_WRITE_UTIL_H

#include <CMGeom/Mesh_IO.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>

#include "cmgeom_test_support.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

using namespace CMGeom;
using cmgeom_test::count_files;
using cmgeom_test::scratch_dir;
using cmgeom_test::shared_data;
namespace fs = std::filesystem;

namespace {

using Vertex_index = Surface_mesh::Vertex_index;
using Face_index = Surface_mesh::Face_index;

inline std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline bool is_png(const std::string& bytes) { return bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0; }

inline nlohmann::json read_json(const std::string& path) { return nlohmann::json::parse(file_bytes(path)); }

// The PNG chunk types of a file, in order (none when it is not a PNG).
inline std::vector<std::string> png_chunks(const std::string& png) {
  std::vector<std::string> types;
  if (!is_png(png)) return types;
  for (std::size_t i = 8; i + 12 <= png.size();) {
    const auto byte = [&](std::size_t k) { return std::uint32_t(std::uint8_t(png[i + k])); };
    types.push_back(png.substr(i + 4, 4));
    i += 12 + (byte(0) << 24 | byte(1) << 16 | byte(2) << 8 | byte(3));
  }
  return types;
}

// What the writer embeds for a texture file: JPEG as it is, PNG without the colour-space chunks
// that glTF viewers ignore (iCCP, sRGB, gAMA, cHRM), every other chunk byte for byte.
inline std::string expected_embedded_texture(const std::string& source) {
  if (!is_png(source)) return source;
  std::string out = source.substr(0, 8);
  for (std::size_t i = 8; i + 12 <= source.size();) {
    const auto byte = [&](std::size_t k) { return std::uint32_t(std::uint8_t(source[i + k])); };
    const std::size_t length = 12 + (byte(0) << 24 | byte(1) << 16 | byte(2) << 8 | byte(3));
    const std::string type = source.substr(i + 4, 4);
    if (type != "iCCP" && type != "sRGB" && type != "gAMA" && type != "cHRM") out += source.substr(i, length);
    i += length;
  }
  return out;
}

// Decodes encoded image bytes in memory (IO::read_image_from_memory, as the readers of embedded
// textures do), checking that the same bytes written as a file decode to the same pixels.
inline Image decode_image(const std::string& bytes, const std::string& dir) {
  const Image in_memory =
      IO::read_image_from_memory(std::vector<unsigned char>(bytes.begin(), bytes.end()), "embedded");
  const std::string path = (fs::path(dir) / (is_png(bytes) ? "decoded.png" : "decoded.jpg")).string();
  std::ofstream(path, std::ios::binary) << bytes;
  const Image from_file = IO::read_image(path);
  fs::remove(path);
  EXPECT_TRUE(in_memory == from_file) << "embedded image decodes differently in memory and from a file";
  return in_memory;
}

// A small RGB image whose pixels differ from those of another seed (so that two textures are
// two images in the file).
inline Image pattern_image(int width, int height, int seed) {
  Image img(width, height, 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c)
        img.bytes()[img.index(x, y, c)] = std::uint8_t((x * 29 + y * 53 + c * 71 + seed * 101) % 256);
  return img;
}

inline std::string write_png(const std::string& dir, const std::string& name, int seed) {
  const std::string path = (fs::path(dir) / name).string();
  IO::write_image(path, pattern_image(8, 4, seed));
  return path;
}

inline Material textured_material(const std::string& name, const std::array<double, 3>& colour,
                                  const std::string& texture) {
  Material m;
  m.name = name;
  m.diffuse_color = colour;
  m.diffuse_texture = texture;
  return m;
}

// Adds triangle (a, b, c) with the texture coordinates of its corners and its material.
inline void add_triangle(Textured_mesh& tm, Vertex_index a, Vertex_index b, Vertex_index c,
                         const std::array<Point_2, 3>& uv, int material) {
  Surface_mesh& m = tm.mesh();
  const Face_index f = m.add_face(a, b, c);
  ASSERT_TRUE(f != Surface_mesh::null_face());
  const std::array<Vertex_index, 3> v = {a, b, c};
  for (auto h : m.halfedges_around_face(m.halfedge(f)))
    for (int k = 0; k < 3; ++k)
      if (m.target(h) == v[std::size_t(k)]) tm.set_uv(h, uv[std::size_t(k)]);
  tm.material_map()[f] = material;
}

// A cube of side 2 centred at (10, -3, 5) (away from the origin, so that float rounding of the
// coordinates is tested against a box smaller than them): 8 vertices, 12 triangles. Every side
// has a tile of its own in a 3 x 2 atlas, so every edge of the cube is a UV seam and the writer
// has to split every vertex into 3 glTF vertices. Sides 0-2 use material 0, sides 3-5 material
// `last_material`.
inline Textured_mesh textured_cube(std::vector<Material> materials, int last_material) {
  Textured_mesh tm;
  std::vector<Vertex_index> v;
  for (int i = 0; i < 8; ++i)
    v.push_back(tm.mesh().add_vertex(Point_3(9 + 2 * (i & 1), -4 + (i & 2), 4 + (i & 4) / 2)));
  // vertex i at (x, y, z) = bits of i; each side counter-clockwise seen from outside
  const int sides[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (int s = 0; s < 6; ++s) {
    const double u0 = (s % 3) / 3.0 + 0.01, v0 = (s / 3) / 2.0 + 0.01, du = 1 / 3.0 - 0.02, dv = 0.5 - 0.02;
    const Point_2 t[4] = {{u0, v0}, {u0 + du, v0}, {u0 + du, v0 + dv}, {u0, v0 + dv}};
    const auto& q = sides[s];
    const int mat = s < 3 ? 0 : last_material;
    add_triangle(tm, v[std::size_t(q[0])], v[std::size_t(q[1])], v[std::size_t(q[2])], {t[0], t[1], t[2]}, mat);
    add_triangle(tm, v[std::size_t(q[0])], v[std::size_t(q[2])], v[std::size_t(q[3])], {t[0], t[2], t[3]}, mat);
  }
  tm.set_has_uvs(true);
  tm.materials() = std::move(materials);
  return tm;
}

// An n x n grid of quads (2 n^2 triangles) over [0, 4]^2 with a wavy height (flat when `wave` is
// 0), texture coordinates (x, y) / 4: the same surface at several resolutions, for levels of detail.
inline Textured_mesh textured_grid(int n, const Material& material, double wave = 0.3) {
  Textured_mesh tm;
  std::vector<Vertex_index> v;
  std::vector<Point_2> uv;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = 4.0 * i / n, y = 4.0 * j / n;
      v.push_back(tm.mesh().add_vertex(Point_3(x, y, wave * std::sin(x) * std::cos(y))));
      uv.emplace_back(x / 4, y / 4);
    }
  auto id = [n](int i, int j) { return std::size_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::size_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      add_triangle(tm, v[a], v[b], v[c], {uv[a], uv[b], uv[c]}, 0);
      add_triangle(tm, v[a], v[c], v[d], {uv[a], uv[c], uv[d]}, 0);
    }
  tm.set_has_uvs(true);
  tm.materials() = {material};
  return tm;
}

// The corners of one face: positions, texture coordinates, material.
struct Face_record {
  std::array<Point_3, 3> p;
  std::array<Point_2, 3> uv;
  int material;
};

inline std::vector<Face_record> face_records(const Textured_mesh& tm) {
  const Surface_mesh& m = tm.mesh();
  std::vector<Face_record> r;
  for (Face_index f : m.faces()) {
    Face_record rec;
    int k = 0;
    for (auto h : m.halfedges_around_face(m.halfedge(f))) {
      rec.p[std::size_t(k)] = m.point(m.target(h));
      rec.uv[std::size_t(k)] = tm.has_uvs() ? tm.uv(h) : Point_2(0, 0);
      ++k;
    }
    rec.material = tm.material(f);
    r.push_back(rec);
  }
  return r;
}

inline double bbox_diagonal(const Textured_mesh& tm) {
  const auto b = CGAL::bbox_3(tm.mesh().points().begin(), tm.mesh().points().end());
  return std::sqrt(CGAL::square(b.xmax() - b.xmin()) + CGAL::square(b.ymax() - b.ymin()) +
                   CGAL::square(b.zmax() - b.zmin()));
}

// How far the read-back values may be from the written ones.
struct Tolerance {
  double position;  // per coordinate
  double uv = -1;   // per coordinate; < 0: float rounding of the value
  double uv_bound(double x) const { return uv >= 0 ? uv : FLT_EPSILON * (2 + std::abs(x)); }
};

// Checks that `back` (read from what was written from `original`) has the faces of `original`,
// in the order the writer emits them (grouped by material index, in face order within a
// material), each with the same corner positions and texture coordinates up to `tol` (the
// first corner may differ: a face is a cycle) and a material of the same name and colour.
inline void expect_same_faces(const Textured_mesh& original, const Textured_mesh& back, const Tolerance& tol) {
  std::vector<Face_record> a = face_records(original);
  std::stable_sort(a.begin(), a.end(),
                   [](const Face_record& x, const Face_record& y) { return x.material < y.material; });
  const std::vector<Face_record> b = face_records(back);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(back.has_uvs(), original.has_uvs());
  ASSERT_EQ(back.materials().empty(), original.materials().empty());
  for (std::size_t i = 0; i < a.size(); ++i) {
    // the rotation of b's corners that puts a's first corner first
    std::size_t r = 0;
    double best = std::numeric_limits<double>::max();
    for (std::size_t k = 0; k < 3; ++k) {
      const double d = CGAL::squared_distance(a[i].p[0], b[i].p[k]);
      if (d < best) best = d, r = k;
    }
    for (std::size_t k = 0; k < 3; ++k) {
      const Point_3 &p = a[i].p[k], &q = b[i].p[(k + r) % 3];
      for (int c = 0; c < 3; ++c)
        ASSERT_LE(std::abs(p[c] - q[c]), tol.position)
            << "face " << i << " corner " << k << ": " << p << " read back as " << q;
      if (original.has_uvs()) {
        const Point_2 &s = a[i].uv[k], &t = b[i].uv[(k + r) % 3];
        ASSERT_LE(std::abs(s.x() - t.x()), tol.uv_bound(s.x()))
            << "face " << i << " corner " << k << ": " << s << " vs " << t;
        ASSERT_LE(std::abs(s.y() - t.y()), tol.uv_bound(s.y()))
            << "face " << i << " corner " << k << ": " << s << " vs " << t;
      }
    }
    if (!original.materials().empty()) {
      const Material& ma = original.materials()[std::size_t(a[i].material)];
      ASSERT_GE(b[i].material, 0);
      ASSERT_LT(std::size_t(b[i].material), back.materials().size());
      const Material& mb = back.materials()[std::size_t(b[i].material)];
      ASSERT_EQ(ma.name, mb.name) << "face " << i;
      for (std::size_t c = 0; c < 3; ++c) ASSERT_NEAR(ma.diffuse_color[c], mb.diffuse_color[c], 1e-12) << ma.name;
    }
  }
}

// Checks that every texture file of `original` (PNG or JPEG) reached `back` byte for byte (PNG
// colour-space chunks aside): as a file beside the .gltf, or embedded in the .glb.
inline void expect_same_texture_bytes(const Textured_mesh& original, const Textured_mesh& back,
                                      const std::string& written) {
  const bool glb = IO::extension(written) == ".glb";
  for (const Material& ma : original.materials()) {
    SCOPED_TRACE(ma.name);
    if (ma.diffuse_texture.empty()) continue;
    const auto mb = std::find_if(back.materials().begin(), back.materials().end(),
                                 [&](const Material& m) { return m.name == ma.name; });
    ASSERT_NE(mb, back.materials().end());
    const std::string source = expected_embedded_texture(file_bytes(ma.diffuse_texture));
    ASSERT_FALSE(source.empty());
    if (glb) {
      EXPECT_TRUE(mb->diffuse_texture.empty()) << "a .glb embeds its textures";
      EXPECT_TRUE(std::string(mb->diffuse_texture_blob.begin(), mb->diffuse_texture_blob.end()) == source)
          << "embedded image differs from " << ma.diffuse_texture;
    } else {
      ASSERT_FALSE(mb->diffuse_texture.empty());
      EXPECT_EQ(fs::path(mb->diffuse_texture).parent_path(), fs::absolute(written).parent_path().lexically_normal());
      EXPECT_TRUE(file_bytes(mb->diffuse_texture) == source)
          << mb->diffuse_texture << " differs from " << ma.diffuse_texture;
    }
    if (!ma.normal_texture.empty() && !glb) {  // the reader keeps normal maps of .gltf files only
      ASSERT_FALSE(mb->normal_texture.empty());
      EXPECT_TRUE(file_bytes(mb->normal_texture) == expected_embedded_texture(file_bytes(ma.normal_texture)));
    }
  }
}

inline std::string out_path(const std::string& dir, const std::string& name) { return (fs::path(dir) / name).string(); }

// The values of a float accessor of a written .gltf (read from the .bin beside it).
inline std::vector<float> float_accessor(const nlohmann::json& j, const std::string& gltf, int index) {
  const auto& a = j["accessors"][index];
  EXPECT_EQ(a["componentType"], 5126);
  const auto& view = j["bufferViews"][a["bufferView"].get<int>()];
  const std::string bin = file_bytes(out_path(fs::path(gltf).parent_path().string(), j["buffers"][0]["uri"]));
  const std::size_t components = a["type"] == "VEC4" ? 4 : a["type"] == "VEC3" ? 3 : a["type"] == "VEC2" ? 2 : 1;
  const std::size_t stride = view.value("byteStride", 4 * components);
  const std::size_t start = view.value("byteOffset", 0) + a.value("byteOffset", 0);
  std::vector<float> values;
  for (std::size_t i = 0; i < a["count"].get<std::size_t>(); ++i)
    for (std::size_t c = 0; c < components; ++c) {
      float x;
      std::memcpy(&x, bin.data() + start + i * stride + 4 * c, 4);
      values.push_back(x);
    }
  return values;
}

// ------------------------------------------------------------------ the Khronos validator

// Why the validator cannot run here ("" when it can).
inline std::string gltf_validator_missing() {
  const fs::path dir = CMGEOM_GLTF_VALIDATOR_DIR;
  if (std::system("command -v node > /dev/null 2>&1") != 0)
    return "node is not on PATH: install Node.js and npm (scripts/install-deps.sh does), then run "
           "'npm install' in " +
           dir.string();
  std::error_code ec;
  if (!fs::is_directory(dir / "node_modules" / "gltf-validator", ec))
    return "the glTF validator is not installed: run 'npm install' in " + dir.string() + " (scripts/test.sh does)";
  return std::string();
}

#define CMGEOM_REQUIRE_GLTF_VALIDATOR()                       \
  do {                                                        \
    const std::string why_missing = gltf_validator_missing(); \
    if (!why_missing.empty()) GTEST_SKIP() << why_missing;    \
  } while (0)

struct Validation {
  int errors = -1, warnings = -1, infos = -1, hints = -1;
  std::string report;  // the validator's output: the counts, then one line per issue
};

// Runs validate.js on `file`; a file the validator could not read is a test failure.
inline Validation validate_gltf(const std::string& file) {
  const std::string report_file = file + ".validation.txt";
  const std::string cmd = "node '" + (fs::path(CMGEOM_GLTF_VALIDATOR_DIR) / "validate.js").string() + "' '" + file +
                          "' > '" + report_file + "' 2>&1";
  const int status = std::system(cmd.c_str());
  Validation v;
  v.report = file_bytes(report_file);
  fs::remove(report_file);
  if (status != 0 || std::sscanf(v.report.c_str(), "errors=%d warnings=%d infos=%d hints=%d", &v.errors, &v.warnings,
                                 &v.infos, &v.hints) != 4)
    ADD_FAILURE() << "the validator could not validate " << file << ":\n" << v.report;
  return v;
}

// Validates `file`: no error and no warning; the infos are printed.
inline void expect_valid_gltf(const std::string& file) {
  SCOPED_TRACE(file);
  const Validation v = validate_gltf(file);
  EXPECT_EQ(v.errors, 0) << v.report;
  EXPECT_EQ(v.warnings, 0) << v.report;
  std::istringstream lines(v.report);
  std::string line;
  std::cout << fs::path(file).filename().string() << ": ";
  while (std::getline(lines, line))
    if (line.compare(0, 7, "errors=") == 0 || line.compare(0, 5, "info ") == 0) std::cout << line << "\n";
}

// The textured cube with one material (diffuse and normal texture, PNG files) in `dir`/in.
inline Textured_mesh single_material_cube(const std::string& dir) {
  const std::string in = (fs::path(dir) / "in").string();
  fs::create_directories(in);
  Material m = textured_material("painted", {0.9, 0.5, 0.25}, write_png(in, "paint.png", 1));
  m.normal_texture = write_png(in, "bumps.png", 2);
  return textured_cube({m}, 0);
}

// The textured cube with two materials, two textures (PNG and JPEG files) in `dir`/in.
inline Textured_mesh two_material_cube(const std::string& dir) {
  const std::string in = (fs::path(dir) / "in").string();
  fs::create_directories(in);
  const std::string jpeg = (fs::path(in) / "wood.jpg").string();
  IO::write_image(jpeg, pattern_image(8, 8, 3));
  return textured_cube({textured_material("stone", {0.5, 0.5, 0.5}, write_png(in, "stone.png", 4)),
                        textured_material("wood", {1.0, 0.75, 0.125}, jpeg)},
                       1);
}

// Three levels of the same grid (512, 128 and 32 faces) sharing one texture file; the first
// without an error, the others with error and ratio.
inline std::vector<Textured_mesh> lod_meshes(const std::string& dir) {
  const std::string in = (fs::path(dir) / "in").string();
  fs::create_directories(in);
  const Material m = textured_material("ground", {0.75, 0.75, 0.5}, write_png(in, "ground.png", 5));
  return {textured_grid(16, m), textured_grid(8, m), textured_grid(4, m)};
}

inline std::vector<IO::Gltf_level> lod_levels(const std::vector<Textured_mesh>& meshes) {
  return {IO::Gltf_level{&meshes[0], "fine", -1, -1}, IO::Gltf_level{&meshes[1], "medium", 0.01, 0.25},
          IO::Gltf_level{&meshes[2], "coarse", 0.05, 0.0625}};
}

}  // namespace

#endif  // CMGEOM_TEST_GLTF_WRITE_UTIL_H

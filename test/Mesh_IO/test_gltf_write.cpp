// Tests of the glTF 2.0 / GLB writer (write_mesh, write_textured_mesh, write_gltf,
// write_textured_gltf): round trips through the reader on meshes built here and on the shared
// textured models, several materials, KHR_mesh_quantization, the MSFT_lod node structure, the
// refusals that must leave nothing behind, and the Khronos glTF validator on every kind of file
// written (skipped when Node.js or the validator's npm package is missing).
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

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool is_png(const std::string& bytes) { return bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0; }

nlohmann::json read_json(const std::string& path) { return nlohmann::json::parse(file_bytes(path)); }

// The PNG chunk types of a file, in order (none when it is not a PNG).
std::vector<std::string> png_chunks(const std::string& png) {
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
std::string expected_embedded_texture(const std::string& source) {
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
Image decode_image(const std::string& bytes, const std::string& dir) {
  const Image in_memory = IO::read_image_from_memory(std::vector<unsigned char>(bytes.begin(), bytes.end()), "embedded");
  const std::string path = (fs::path(dir) / (is_png(bytes) ? "decoded.png" : "decoded.jpg")).string();
  std::ofstream(path, std::ios::binary) << bytes;
  const Image from_file = IO::read_image(path);
  fs::remove(path);
  EXPECT_TRUE(in_memory == from_file) << "embedded image decodes differently in memory and from a file";
  return in_memory;
}

// A small RGB image whose pixels differ from those of another seed (so that two textures are
// two images in the file).
Image pattern_image(int width, int height, int seed) {
  Image img(width, height, 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c)
        img.bytes()[img.index(x, y, c)] = std::uint8_t((x * 29 + y * 53 + c * 71 + seed * 101) % 256);
  return img;
}

std::string write_png(const std::string& dir, const std::string& name, int seed) {
  const std::string path = (fs::path(dir) / name).string();
  IO::write_image(path, pattern_image(8, 4, seed));
  return path;
}

Material textured_material(const std::string& name, const std::array<double, 3>& colour,
                           const std::string& texture) {
  Material m;
  m.name = name;
  m.diffuse_color = colour;
  m.diffuse_texture = texture;
  return m;
}

// Adds triangle (a, b, c) with the texture coordinates of its corners and its material.
void add_triangle(Textured_mesh& tm, Vertex_index a, Vertex_index b, Vertex_index c,
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
Textured_mesh textured_cube(std::vector<Material> materials, int last_material) {
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
Textured_mesh textured_grid(int n, const Material& material, double wave = 0.3) {
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

std::vector<Face_record> face_records(const Textured_mesh& tm) {
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

double bbox_diagonal(const Textured_mesh& tm) {
  const auto b = CGAL::bbox_3(tm.mesh().points().begin(), tm.mesh().points().end());
  return std::sqrt(CGAL::square(b.xmax() - b.xmin()) + CGAL::square(b.ymax() - b.ymin()) +
                   CGAL::square(b.zmax() - b.zmin()));
}

// How far the read-back values may be from the written ones.
struct Tolerance {
  double position;                          // per coordinate
  double uv = -1;                           // per coordinate; < 0: float rounding of the value
  double uv_bound(double x) const { return uv >= 0 ? uv : FLT_EPSILON * (2 + std::abs(x)); }
};

// Checks that `back` (read from what was written from `original`) has the faces of `original`,
// in the order the writer emits them (grouped by material index, in face order within a
// material), each with the same corner positions and texture coordinates up to `tol` (the
// first corner may differ: a face is a cycle) and a material of the same name and colour.
void expect_same_faces(const Textured_mesh& original, const Textured_mesh& back, const Tolerance& tol) {
  std::vector<Face_record> a = face_records(original);
  std::stable_sort(a.begin(), a.end(), [](const Face_record& x, const Face_record& y) { return x.material < y.material; });
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
        ASSERT_LE(std::abs(p[c] - q[c]), tol.position) << "face " << i << " corner " << k << ": " << p << " read back as " << q;
      if (original.has_uvs()) {
        const Point_2 &s = a[i].uv[k], &t = b[i].uv[(k + r) % 3];
        ASSERT_LE(std::abs(s.x() - t.x()), tol.uv_bound(s.x())) << "face " << i << " corner " << k << ": " << s << " vs " << t;
        ASSERT_LE(std::abs(s.y() - t.y()), tol.uv_bound(s.y())) << "face " << i << " corner " << k << ": " << s << " vs " << t;
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
void expect_same_texture_bytes(const Textured_mesh& original, const Textured_mesh& back, const std::string& written) {
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
      EXPECT_TRUE(file_bytes(mb->diffuse_texture) == source) << mb->diffuse_texture << " differs from " << ma.diffuse_texture;
    }
    if (!ma.normal_texture.empty() && !glb) {  // the reader keeps normal maps of .gltf files only
      ASSERT_FALSE(mb->normal_texture.empty());
      EXPECT_TRUE(file_bytes(mb->normal_texture) == expected_embedded_texture(file_bytes(ma.normal_texture)));
    }
  }
}

std::string out_path(const std::string& dir, const std::string& name) { return (fs::path(dir) / name).string(); }

// The values of a float accessor of a written .gltf (read from the .bin beside it).
std::vector<float> float_accessor(const nlohmann::json& j, const std::string& gltf, int index) {
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
std::string gltf_validator_missing() {
  const fs::path dir = CMGEOM_GLTF_VALIDATOR_DIR;
  if (std::system("command -v node > /dev/null 2>&1") != 0)
    return "node is not on PATH: install Node.js and npm (scripts/install-deps.sh does), then run "
           "'npm install' in " + dir.string();
  std::error_code ec;
  if (!fs::is_directory(dir / "node_modules" / "gltf-validator", ec))
    return "the glTF validator is not installed: run 'npm install' in " + dir.string() +
           " (scripts/test.sh does)";
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
Validation validate_gltf(const std::string& file) {
  const std::string report_file = file + ".validation.txt";
  const std::string cmd = "node '" + (fs::path(CMGEOM_GLTF_VALIDATOR_DIR) / "validate.js").string() + "' '" + file +
                          "' > '" + report_file + "' 2>&1";
  const int status = std::system(cmd.c_str());
  Validation v;
  v.report = file_bytes(report_file);
  fs::remove(report_file);
  if (status != 0 ||
      std::sscanf(v.report.c_str(), "errors=%d warnings=%d infos=%d hints=%d", &v.errors, &v.warnings, &v.infos,
                  &v.hints) != 4)
    ADD_FAILURE() << "the validator could not validate " << file << ":\n" << v.report;
  return v;
}

// Validates `file`: no error and no warning; the infos are printed.
void expect_valid_gltf(const std::string& file) {
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

}  // namespace

// ------------------------------------------------------------------ round trips

namespace {

// The textured cube with one material (diffuse and normal texture, PNG files) in `dir`/in.
Textured_mesh single_material_cube(const std::string& dir) {
  const std::string in = (fs::path(dir) / "in").string();
  fs::create_directories(in);
  Material m = textured_material("painted", {0.9, 0.5, 0.25}, write_png(in, "paint.png", 1));
  m.normal_texture = write_png(in, "bumps.png", 2);
  return textured_cube({m}, 0);
}

// The textured cube with two materials, two textures (PNG and JPEG files) in `dir`/in.
Textured_mesh two_material_cube(const std::string& dir) {
  const std::string in = (fs::path(dir) / "in").string();
  fs::create_directories(in);
  const std::string jpeg = (fs::path(in) / "wood.jpg").string();
  IO::write_image(jpeg, pattern_image(8, 8, 3));
  return textured_cube({textured_material("stone", {0.5, 0.5, 0.5}, write_png(in, "stone.png", 4)),
                        textured_material("wood", {1.0, 0.75, 0.125}, jpeg)},
                       1);
}

}  // namespace

TEST(Mesh_IO_gltf_write, CubeWithSeamsRoundTripsThroughGlbAndGltf) {
  const std::string dir = scratch_dir();
  const Textured_mesh cube = single_material_cube(dir);
  for (const char* name : {"cube.glb", "cube.gltf"}) {
    SCOPED_TRACE(name);
    const std::string path = out_path(dir, name);
    IO::write_mesh(path, cube);
    Textured_mesh back;
    IO::read_mesh(path, back);
    EXPECT_EQ(back.mesh().number_of_vertices(), 8u);  // split at the seams on write, welded on read
    expect_same_faces(cube, back, {1e-6 * bbox_diagonal(cube)});
    expect_same_texture_bytes(cube, back, path);
    // every cube corner is on three tiles of the atlas: 3 x 8 glTF vertices
    if (IO::extension(path) == ".gltf") {
      const nlohmann::json j = read_json(path);
      const int position = j["meshes"][0]["primitives"][0]["attributes"]["POSITION"];
      EXPECT_EQ(j["accessors"][position]["count"], 24);
      EXPECT_EQ(j["asset"]["version"], "2.0");
      // the .bin and the two images beside the .gltf, named after it
      EXPECT_TRUE(fs::exists(out_path(dir, "cube.bin")));
      EXPECT_EQ(j["images"].size(), 2u);
    }
  }
  // .gltf output: the .gltf, its .bin and two images; .glb: one file
  EXPECT_EQ(count_files(dir), 5u);
}

// A file name with spaces: the writer percent-encodes the image and buffer URIs, the reader
// decodes them; and the textures of a .glb (embedded bytes) decode in memory to the source's pixels.
TEST(Mesh_IO_gltf_write, NamesWithSpacesAndEmbeddedTexturesReadBack) {
  const std::string dir = scratch_dir();
  Textured_mesh cube = single_material_cube(dir);
  IO::load_textures(cube);
  for (const char* name : {"my cube.gltf", "my cube.glb"}) {
    SCOPED_TRACE(name);
    const std::string path = out_path(dir, name);
    IO::write_textured_mesh(path, cube);
    Textured_mesh back;
    IO::read_textured_mesh(path, back);
    expect_same_faces(cube, back, {1e-6 * bbox_diagonal(cube)});
    ASSERT_EQ(back.materials().size(), cube.materials().size());
    for (std::size_t i = 0; i < cube.materials().size(); ++i)
      EXPECT_TRUE(back.materials()[i].diffuse_image == cube.materials()[i].diffuse_image)
          << "material " << i << ": the texture read back differs from the one written";
  }
}

TEST(Mesh_IO_gltf_write, TwoMaterialsGiveTwoPrimitivesAndKeepFaceMaterials) {
  const std::string dir = scratch_dir();
  const Textured_mesh cube = two_material_cube(dir);
  for (const char* name : {"two.gltf", "two.glb"}) {
    SCOPED_TRACE(name);
    const std::string path = out_path(dir, name);
    IO::write_mesh(path, cube);
    Textured_mesh back;
    IO::read_mesh(path, back);
    ASSERT_EQ(back.materials().size(), 2u);
    expect_same_faces(cube, back, {1e-6 * bbox_diagonal(cube)});
    expect_same_texture_bytes(cube, back, path);
    // faces of each material: 6 of 12
    std::size_t stone = 0;
    for (Face_index f : back.mesh().faces()) stone += back.materials()[std::size_t(back.material(f))].name == "stone";
    EXPECT_EQ(stone, 6u);
  }
  const nlohmann::json j = read_json(out_path(dir, "two.gltf"));
  ASSERT_EQ(j["meshes"].size(), 1u);
  const auto& prims = j["meshes"][0]["primitives"];
  ASSERT_EQ(prims.size(), 2u);
  EXPECT_NE(prims[0]["material"], prims[1]["material"]);
  ASSERT_EQ(j["materials"].size(), 2u);
  EXPECT_EQ(j["images"].size(), 2u);
  std::vector<std::string> mime;
  for (const auto& img : j["images"]) mime.push_back(fs::path(img["uri"].get<std::string>()).extension().string());
  std::sort(mime.begin(), mime.end());
  EXPECT_EQ(mime, (std::vector<std::string>{".jpg", ".png"}));  // each image keeps its format
  for (const auto& prim : prims) {
    const auto& mat = j["materials"][prim["material"].get<int>()];
    EXPECT_EQ(j["accessors"][prim["indices"].get<int>()]["count"], 18);  // 6 triangles each
    EXPECT_EQ(mat["pbrMetallicRoughness"]["metallicFactor"], 0.0);
    EXPECT_TRUE(mat["pbrMetallicRoughness"].contains("baseColorTexture"));
  }
}

TEST(Mesh_IO_gltf_write, TexturedModelsRoundTripThroughGlbAndGltf) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  // spot has no MTL: its texture is assigned here; DamagedHelmet needs repair (non-manifold),
  // and its duplicated vertices are welded again on read, so it is read back with repair too
  for (const char* model : {"textured/Duck/Duck.obj", "textured/spot/spot.obj",
                            "textured/DamagedHelmet/DamagedHelmet.obj", "textured/fuze/fuze.obj"}) {
    SCOPED_TRACE(model);
    IO::Read_options options;
    options.repair = std::string(model).find("DamagedHelmet") != std::string::npos;
    Textured_mesh tm;
    IO::read_mesh(shared_data(model), tm, options);
    if (tm.materials().empty())
      tm.materials().push_back(textured_material("spot", {1, 1, 1}, shared_data("textured/spot/spot_texture.png")));
    ASSERT_TRUE(tm.has_uvs());
    const std::string stem = fs::path(model).stem().string();
    for (const char* ext : {".glb", ".gltf"}) {
      SCOPED_TRACE(ext);
      const std::string path = out_path(dir, stem + ext);
      IO::write_mesh(path, tm);
      Textured_mesh back;
      IO::read_mesh(path, back, options);
      EXPECT_EQ(back.mesh().number_of_faces(), tm.mesh().number_of_faces());
      expect_same_faces(tm, back, {1e-6 * bbox_diagonal(tm)});
      expect_same_texture_bytes(tm, back, path);
    }
  }
}

TEST(Mesh_IO_gltf_write, QuantizedPositionsAndUvsStayWithinTheGridStep) {
  const std::string dir = scratch_dir();
  IO::Gltf_options quantize;
  quantize.quantize = true;
  const Textured_mesh cube = single_material_cube(dir);
  const Textured_mesh grid = textured_grid(12, cube.materials()[0]);
  for (const auto& [mesh, stem] : {std::make_pair(&cube, "cube"), std::make_pair(&grid, "grid")}) {
    const auto b = CGAL::bbox_3(mesh->mesh().points().begin(), mesh->mesh().points().end());
    const double extent = std::max({b.xmax() - b.xmin(), b.ymax() - b.ymin(), b.zmax() - b.zmin()});
    for (const char* ext : {".glb", ".gltf"}) {
      const std::string path = out_path(dir, std::string(stem) + "_q" + ext);
      SCOPED_TRACE(path);
      IO::write_textured_mesh(path, *mesh, quantize);
      Textured_mesh back;
      IO::read_mesh(path, back);
      // rounding to the nearest of 65536 grid values: half a step at most (mesh_io.h), read back
      // through the node's scale and translation in double precision
      Tolerance tol{extent / 131070 * (1 + 1e-9)};
      tol.uv = 0.5 / 65535 + 1e-12;
      expect_same_faces(*mesh, back, tol);
    }
    const nlohmann::json j = read_json(out_path(dir, std::string(stem) + "_q.gltf"));
    auto contains = [](const nlohmann::json& list, const char* s) {
      return std::find(list.begin(), list.end(), s) != list.end();
    };
    EXPECT_TRUE(contains(j["extensionsUsed"], "KHR_mesh_quantization"));
    EXPECT_TRUE(contains(j["extensionsRequired"], "KHR_mesh_quantization"));
    const auto& attributes = j["meshes"][0]["primitives"][0]["attributes"];
    EXPECT_EQ(j["accessors"][attributes["POSITION"].get<int>()]["componentType"], 5123);  // unsigned short
    EXPECT_EQ(j["accessors"][attributes["NORMAL"].get<int>()]["componentType"], 5120);    // byte
    const auto& uv = j["accessors"][attributes["TEXCOORD_0"].get<int>()];
    EXPECT_EQ(uv["componentType"], 5123);
    EXPECT_EQ(uv["normalized"], true);
  }
}

TEST(Mesh_IO_gltf_write, NormalMapsGetUnitTangentsAlongUWithHandedness) {
  // A flat grid (normal +z) with u along +x and v along +y: tangent +x, and cross(normal,
  // tangent) = +y is the direction of increasing v (w = 1). Mirrored (u along -x): tangent -x,
  // w = -1. Without a normal map no tangent is written.
  const std::string dir = scratch_dir();
  Material m = textured_material("bumpy", {1, 1, 1}, write_png(dir, "base.png", 1));
  m.normal_texture = write_png(dir, "normal.png", 2);
  Textured_mesh plain = textured_grid(4, m, 0), mirrored = plain;
  for (auto h : mirrored.mesh().halfedges())
    if (!mirrored.mesh().is_border(h)) mirrored.set_uv(h, Point_2(1 - mirrored.uv(h).x(), mirrored.uv(h).y()));
  Textured_mesh no_normal_map = plain;
  no_normal_map.materials()[0].normal_texture.clear();
  for (const auto& [mesh, stem, x_sign] : {std::make_tuple(&plain, "plain", 1.0), std::make_tuple(&mirrored, "mirrored", -1.0),
                                           std::make_tuple(&no_normal_map, "no_normal_map", 0.0)}) {
    SCOPED_TRACE(stem);
    const std::string path = out_path(dir, std::string(stem) + ".gltf");
    IO::write_mesh(path, *mesh);
    const nlohmann::json j = read_json(path);
    const auto& attributes = j["meshes"][0]["primitives"][0]["attributes"];
    if (x_sign == 0) {
      EXPECT_FALSE(attributes.contains("TANGENT"));
      continue;
    }
    ASSERT_TRUE(attributes.contains("TANGENT"));
    EXPECT_EQ(j["accessors"][attributes["TANGENT"].get<int>()]["type"], "VEC4");
    const std::vector<float> t = float_accessor(j, path, attributes["TANGENT"]);
    ASSERT_EQ(t.size(), 4 * 25u);
    for (std::size_t i = 0; i < t.size(); i += 4) {
      EXPECT_EQ(t[i], x_sign) << "vertex " << i / 4;
      EXPECT_EQ(t[i + 1], 0.f);
      EXPECT_EQ(t[i + 2], 0.f);
      EXPECT_EQ(t[i + 3], x_sign) << "vertex " << i / 4;
    }
  }
}

TEST(Mesh_IO_gltf_write, PngColourSpaceChunksAreDroppedAndPixelsKept) {
  // spot's texture has iCCP and cHRM chunks (glTF viewers must ignore them; the validator warns)
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  const std::string source = shared_data("textured/spot/spot_texture.png");
  const std::vector<std::string> source_chunks = png_chunks(file_bytes(source));
  ASSERT_NE(std::find(source_chunks.begin(), source_chunks.end(), "iCCP"), source_chunks.end());
  const Textured_mesh cube = textured_cube({textured_material("spot", {1, 1, 1}, source)}, 0);
  const std::string path = out_path(dir, "cube.glb");
  IO::write_mesh(path, cube);
  Textured_mesh back;
  IO::read_mesh(path, back);
  ASSERT_EQ(back.materials().size(), 1u);
  const std::string blob(back.materials()[0].diffuse_texture_blob.begin(), back.materials()[0].diffuse_texture_blob.end());
  std::vector<std::string> kept;
  for (const std::string& c : source_chunks)
    if (c != "iCCP" && c != "sRGB" && c != "gAMA" && c != "cHRM") kept.push_back(c);
  EXPECT_EQ(png_chunks(blob), kept);
  EXPECT_TRUE(decode_image(blob, dir) == IO::read_image(source));
}

// ------------------------------------------------------------------ levels of detail

namespace {

// Three levels of the same grid (512, 128 and 32 faces) sharing one texture file; the first
// without an error, the others with error and ratio.
std::vector<Textured_mesh> lod_meshes(const std::string& dir) {
  const std::string in = (fs::path(dir) / "in").string();
  fs::create_directories(in);
  const Material m = textured_material("ground", {0.75, 0.75, 0.5}, write_png(in, "ground.png", 5));
  return {textured_grid(16, m), textured_grid(8, m), textured_grid(4, m)};
}

std::vector<IO::Gltf_level> lod_levels(const std::vector<Textured_mesh>& meshes) {
  return {IO::Gltf_level{&meshes[0], "fine", -1, -1}, IO::Gltf_level{&meshes[1], "medium", 0.01, 0.25},
          IO::Gltf_level{&meshes[2], "coarse", 0.05, 0.0625}};
}

}  // namespace

TEST(Mesh_IO_gltf_write, LevelsOfDetailAreMsftLodNodesOfOneScene) {
  const std::string dir = scratch_dir();
  const std::vector<Textured_mesh> meshes = lod_meshes(dir);
  const std::vector<IO::Gltf_level> levels = lod_levels(meshes);
  for (const char* name : {"lod.gltf", "lod.glb"}) IO::write_gltf(out_path(dir, name), levels);
  const nlohmann::json j = read_json(out_path(dir, "lod.gltf"));
  ASSERT_EQ(j["scenes"].size(), 1u);
  EXPECT_EQ(j["scene"], 0);
  EXPECT_EQ(j["scenes"][0]["nodes"], nlohmann::json::array({0}));
  ASSERT_EQ(j["nodes"].size(), 3u);
  EXPECT_EQ(j["nodes"][0]["extensions"]["MSFT_lod"]["ids"], nlohmann::json::array({1, 2}));
  EXPECT_NE(std::find(j["extensionsUsed"].begin(), j["extensionsUsed"].end(), "MSFT_lod"), j["extensionsUsed"].end());
  EXPECT_FALSE(j.contains("extensionsRequired"));  // viewers without MSFT_lod show level 0
  for (std::size_t i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    const auto& node = j["nodes"][i];
    EXPECT_EQ(node["name"], levels[i].name);
    EXPECT_FALSE(node.contains("children"));
    const auto& extras = node["extras"];
    EXPECT_EQ(extras["level"], i);
    EXPECT_EQ(extras["faces"], meshes[i].mesh().number_of_faces());
    if (levels[i].error >= 0) {
      EXPECT_DOUBLE_EQ(extras["error"].get<double>(), levels[i].error);
      EXPECT_DOUBLE_EQ(extras["ratio"].get<double>(), levels[i].ratio);
    } else {
      EXPECT_FALSE(extras.contains("error"));
      EXPECT_FALSE(extras.contains("ratio"));
    }
    // the node's mesh has the level's triangles
    const auto& prims = j["meshes"][node["mesh"].get<int>()]["primitives"];
    ASSERT_EQ(prims.size(), 1u);
    EXPECT_EQ(j["accessors"][prims[0]["indices"].get<int>()]["count"], 3 * meshes[i].mesh().number_of_faces());
  }
  // one texture file for all levels: one image, one material
  EXPECT_EQ(j["images"].size(), 1u);
  EXPECT_EQ(j["materials"].size(), 1u);
  EXPECT_EQ(count_files(dir), 4u);  // lod.gltf, lod.bin, lod_0.png, lod.glb
  // a reader without MSFT_lod sees the first level only, in either container
  for (const char* name : {"lod.gltf", "lod.glb"}) {
    Textured_mesh back;
    IO::read_mesh(out_path(dir, name), back);
    expect_same_faces(meshes[0], back, {1e-6 * bbox_diagonal(meshes[0])});
  }
}

TEST(Mesh_IO_gltf_write, LevelsWithEqualDecodedTexturesShareOneImage) {
  // textures that exist only as decoded images (a baked atlas): encoded once when the pixels
  // are equal, even in two separate Image objects; a different image is a second one
  const std::string dir = scratch_dir();
  Material m;
  m.name = "baked";
  m.diffuse_image = pattern_image(16, 16, 7);
  const Textured_mesh a = textured_grid(8, m), b = textured_grid(4, m);
  Material other = m;
  other.diffuse_image = pattern_image(16, 16, 8);
  const Textured_mesh c = textured_grid(2, other);
  const std::string path = out_path(dir, "baked.gltf");
  IO::write_textured_gltf(path, {IO::Gltf_level{&a, "a", -1, -1}, IO::Gltf_level{&b, "b", -1, -1}});
  nlohmann::json j = read_json(path);
  ASSERT_EQ(j["images"].size(), 1u);
  EXPECT_TRUE(IO::read_image(out_path(dir, j["images"][0]["uri"].get<std::string>())) == m.diffuse_image);
  IO::write_textured_gltf(path, {IO::Gltf_level{&a, "a", -1, -1}, IO::Gltf_level{&c, "c", -1, -1}});
  j = read_json(path);
  EXPECT_EQ(j["images"].size(), 2u);
  EXPECT_EQ(j["materials"].size(), 2u);
}

// ------------------------------------------------------------------ refusals

TEST(Mesh_IO_gltf_write, EmptyMeshIsRefusedAndNothingIsWritten) {
  const std::string dir = scratch_dir();
  const Textured_mesh empty;
  const Textured_mesh grid = textured_grid(2, textured_material("m", {1, 1, 1}, write_png(dir, "m.png", 1)));
  const std::string out = (fs::path(dir) / "out").string();
  fs::create_directories(out);
  for (const char* name : {"empty.glb", "empty.gltf"}) {
    SCOPED_TRACE(name);
    const std::string path = out_path(out, name);
    EXPECT_THROW(IO::write_mesh(path, empty), IO_error);
    EXPECT_THROW(IO::write_textured_mesh(path, empty), IO_error);
    EXPECT_THROW(IO::write_gltf(path, {}), IO_error);
    EXPECT_THROW(IO::write_gltf(path, {IO::Gltf_level{nullptr, "none", -1, -1}}), IO_error);
    // an empty level after a good one: the good one is not written either
    EXPECT_THROW(IO::write_gltf(path, {IO::Gltf_level{&grid, "a", -1, -1}, IO::Gltf_level{&empty, "b", -1, -1}}),
                 IO_error);
    EXPECT_EQ(count_files(out), 0u) << "a refused write left files behind";
  }
}

TEST(Mesh_IO_gltf_write, TextureNeitherPngNorJpegIsRefusedByWriteMesh) {
  const std::string dir = scratch_dir();
  const std::string in = (fs::path(dir) / "in").string(), out = (fs::path(dir) / "out").string();
  fs::create_directories(in);
  fs::create_directories(out);
  const std::string tga = (fs::path(in) / "paint.tga").string();
  IO::write_image(tga, pattern_image(8, 4, 1));
  ASSERT_FALSE(is_png(file_bytes(tga)));
  // the second material's texture is the TGA: the first one's image and the buffers are not kept
  const Textured_mesh cube = textured_cube(
      {textured_material("fine", {1, 1, 1}, write_png(in, "fine.png", 2)), textured_material("tga", {1, 1, 1}, tga)}, 1);
  for (const char* name : {"cube.gltf", "cube.glb"}) {
    SCOPED_TRACE(name);
    try {
      IO::write_mesh(out_path(out, name), cube);
      ADD_FAILURE() << "a TGA texture was written into a glTF file";
    } catch (const IO_error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("neither PNG nor JPEG"), std::string::npos) << msg;
      EXPECT_NE(msg.find("'tga'"), std::string::npos) << "the message names the material: " << msg;
    }
    EXPECT_EQ(count_files(out), 0u) << "a refused write left files behind";
  }
}

TEST(Mesh_IO_gltf_write, WriteTexturedMeshEncodesOtherImageTypesAsPng) {
  const std::string dir = scratch_dir();
  const std::string in = (fs::path(dir) / "in").string();
  fs::create_directories(in);
  const std::string tga = (fs::path(in) / "paint.tga").string();
  IO::write_image(tga, pattern_image(8, 4, 1));
  const Image pixels = IO::read_image(tga);
  const Textured_mesh cube = textured_cube({textured_material("tga", {1, 1, 1}, tga)}, 0);
  for (const char* name : {"cube.gltf", "cube.glb"}) {
    SCOPED_TRACE(name);
    const std::string path = out_path(dir, name);
    IO::write_textured_mesh(path, cube);
    Textured_mesh back;
    IO::read_mesh(path, back);
    expect_same_faces(cube, back, {1e-6 * bbox_diagonal(cube)});
    ASSERT_EQ(back.materials().size(), 1u);
    const Material& m = back.materials()[0];
    const std::string bytes = m.diffuse_texture.empty()
                                  ? std::string(m.diffuse_texture_blob.begin(), m.diffuse_texture_blob.end())
                                  : file_bytes(m.diffuse_texture);
    EXPECT_TRUE(is_png(bytes));
    if (!m.diffuse_texture.empty()) {
      EXPECT_EQ(fs::path(m.diffuse_texture).extension().string(), ".png");
    }
    EXPECT_TRUE(decode_image(bytes, dir) == pixels) << "the PNG does not hold the TGA's pixels";
  }
}

// ------------------------------------------------------------------ the Khronos validator

TEST(Mesh_IO_gltf_validator, EveryKindOfWrittenFileIsValid) {
  CMGEOM_REQUIRE_GLTF_VALIDATOR();
  const std::string dir = scratch_dir();
  std::vector<std::string> files;
  IO::Gltf_options quantize;
  quantize.quantize = true;
  const Textured_mesh cube = single_material_cube(dir), two = two_material_cube(dir);
  const std::vector<Textured_mesh> lod = lod_meshes(dir);
  const Textured_mesh tga_cube = [&] {
    const std::string tga = (fs::path(dir) / "in" / "paint.tga").string();
    IO::write_image(tga, pattern_image(8, 4, 1));
    return textured_cube({textured_material("tga", {1, 1, 1}, tga)}, 0);
  }();
  Material baked;
  baked.name = "baked";
  baked.diffuse_image = pattern_image(16, 16, 7);
  const Textured_mesh baked_grid = textured_grid(8, baked);
  for (const char* ext : {".glb", ".gltf"}) {
    auto path = [&](const std::string& stem) {
      files.push_back(out_path(dir, stem + ext));
      return files.back();
    };
    IO::write_mesh(path("cube"), cube);
    IO::write_mesh(path("two"), two);
    IO::write_textured_mesh(path("cube_q"), cube, quantize);
    IO::write_textured_mesh(path("grid_q"), lod[0], quantize);
    IO::write_gltf(path("lod"), lod_levels(lod));
    IO::write_gltf(path("lod_q"), lod_levels(lod), quantize);
    IO::write_textured_mesh(path("tga"), tga_cube);
    IO::write_textured_mesh(path("baked"), baked_grid);
  }
  for (const std::string& f : files) expect_valid_gltf(f);
}

TEST(Mesh_IO_gltf_validator, TexturedModelsConvertToValidGlb) {
  CMGEOM_REQUIRE_SHARED_DATA();
  CMGEOM_REQUIRE_GLTF_VALIDATOR();
  const std::string dir = scratch_dir();
  std::size_t models = 0;
  for (const auto& entry : fs::directory_iterator(shared_data("textured"))) {
    if (!entry.is_directory()) continue;
    for (const auto& file : fs::directory_iterator(entry.path())) {
      if (IO::extension(file.path().string()) != ".obj") continue;
      SCOPED_TRACE(file.path().string());
      IO::Read_options options;
      options.repair = true;  // DamagedHelmet is not manifold; the others read as they are
      Textured_mesh tm;
      IO::read_mesh(file.path().string(), tm, options);
      if (tm.materials().empty() && fs::exists(entry.path() / "spot_texture.png"))
        tm.materials().push_back(textured_material("spot", {1, 1, 1}, (entry.path() / "spot_texture.png").string()));
      const std::string glb = out_path(dir, file.path().stem().string() + ".glb");
      IO::write_mesh(glb, tm);
      expect_valid_gltf(glb);
      // quantized too: its 8-bit normals must still pass the validator's unit-length check
      const std::string quantized = out_path(dir, file.path().stem().string() + "_q.glb");
      IO::Gltf_options quantize;
      quantize.quantize = true;
      IO::write_textured_mesh(quantized, tm, quantize);
      expect_valid_gltf(quantized);
      ++models;
    }
  }
  EXPECT_GE(models, 8u);
}

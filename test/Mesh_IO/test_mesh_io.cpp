// Tests of the Mesh_IO package: reference values of the shared models (SOURCES.md), round trips,
// an independent cross-check of the OBJ parser with tinyobjloader, the textured-mesh model and
// chart queries, and the malformed-input catalogue (library errors and CLI behaviour).
#include <CMGeom/Mesh_IO.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>

#include "cmgeom_test_support.h"
#include "io_internal.h"  // src/Mesh_IO: the reader's own soup check

#include <nlohmann/json.hpp>

#define TINYOBJLOADER_IMPLEMENTATION
#define TINYOBJLOADER_USE_DOUBLE
#include <tiny_obj_loader.h>

#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>

using namespace CMGeom;
using cmgeom_test::scratch_dir;
using cmgeom_test::shared_data;
using cmgeom_test::write_text;
namespace fs = std::filesystem;

namespace {

struct Textured_case {
  const char* path;
  std::size_t vertices, faces, charts;
  bool manifold;
};

// Values from ../shared/data/SOURCES.md (computed there by other means).
const Textured_case textured_models[] = {
    {"textured/spot/spot.obj", 2930, 5856, 13, true},
    {"textured/bob/bob_tri.obj", 5344, 10688, 3, true},
    {"textured/fuze/fuze.obj", 502, 1000, 8, true},
    {"textured/DamagedHelmet/DamagedHelmet.obj", 8661, 15452, 478, false},
    {"textured/WaterBottle/WaterBottle.obj", 2385, 4510, 5, true},
    {"textured/Duck/Duck.obj", 2108, 4212, 10, true},
    {"textured/bunny10k_textured/bunny10k_textured.obj", 5051, 9999, 190, true},
    {"textured/texturedknot/texturedknot.obj", 1440, 2880, 1, true},
};

struct Classic_case {
  const char* path;
  bool closed, manifold;
  int genus;  // -1: not given
  std::size_t components;
};

const Classic_case classic_models[] = {
    {"classic/bunny.off", true, true, 0, 1},          {"classic/fandisk.obj", true, true, 0, 1},
    {"classic/rocker-arm.obj", true, true, 1, 1},     {"classic/igea.ply.gz", true, true, 0, 1},
    {"classic/nefertiti.obj.gz", true, true, 0, 1},   {"classic/ogre.obj.gz", false, false, -1, 44},
    {"classic/homer.obj", true, true, 0, 1},          {"classic/cheburashka.obj", true, true, 0, 1},
    {"classic/cow.obj", true, false, -1, 1},          {"classic/horse.ply", true, true, 0, 1},
    {"classic/camel.off", true, true, 0, 1},          {"classic/decimated-max.obj", true, true, 0, 1},
    {"classic/armadillo.obj.gz", true, true, 0, 1},   {"classic/knot_orig.ply", true, true, 1, 1},
    {"classic/trim-star.off", true, true, 1, 1},      {"classic/sharp_sphere.off", true, true, 0, 1},
    {"classic/block.off", true, true, 3, 1},          {"classic/anchor.off", true, true, 4, 1},
    {"classic/pinion.off", true, true, 1, 1},         {"classic/joint.off", true, true, 2, 1},
    {"classic/mech-holes-shark.off", false, true, -1, 1}, {"classic/teapot.obj", false, false, -1, 4},
    {"classic/beetle.obj", false, false, -1, 2},      {"classic/suzanne.obj", false, true, -1, 3},
    {"classic/beast.obj.gz", true, true, 0, 1},       {"classic/stanford-bunny.obj.gz", false, true, -1, 1},
};

void expect_same_geometry_and_uvs(const Textured_mesh& a, const Textured_mesh& b) {
  const Surface_mesh &ma = a.mesh(), &mb = b.mesh();
  ASSERT_EQ(ma.number_of_vertices(), mb.number_of_vertices());
  ASSERT_EQ(ma.number_of_faces(), mb.number_of_faces());
  ASSERT_EQ(a.has_uvs(), b.has_uvs());
  for (auto v : ma.vertices()) {
    const Point_3 &p = ma.point(v), &q = mb.point(v);
    ASSERT_EQ(std::memcmp(&p, &q, sizeof(Point_3)), 0) << "vertex " << std::size_t(v) << " moved";
  }
  // Faces are written in order; compare corners by their vertex (UVs bit for bit).
  auto fb = mb.faces().begin();
  for (auto f : ma.faces()) {
    const auto g = *fb++;
    ASSERT_EQ(a.material(f), b.material(g));
    for (auto h : ma.halfedges_around_face(ma.halfedge(f))) {
      bool found = false;
      for (auto k : mb.halfedges_around_face(mb.halfedge(g)))
        if (std::size_t(mb.target(k)) == std::size_t(ma.target(h))) {
          found = true;
          if (a.has_uvs()) {
            const Point_2 u = a.uv(h), w = b.uv(k);
            ASSERT_EQ(std::memcmp(&u, &w, sizeof(Point_2)), 0) << "UV changed at face " << std::size_t(f);
          }
        }
      ASSERT_TRUE(found) << "face " << std::size_t(f) << " has different vertices";
    }
  }
}

std::size_t mesh_charts(const Textured_mesh& tm) {
  auto ids = get(CGAL::dynamic_face_property_t<int>(), tm.mesh());  // scratch map on a const mesh
  return compute_chart_ids(tm.mesh(), tm.uv_map(), ids);
}

}  // namespace

// ------------------------------------------------------------------ shared models

TEST(Mesh_IO_models, TexturedModelsMatchSourcesAndRoundTripBitExact) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  for (const auto& c : textured_models) {
    SCOPED_TRACE(c.path);
    const Polygon_soup soup = IO::read_polygon_soup(shared_data(c.path));
    const Mesh_statistics st = analyze_soup(soup);
    EXPECT_EQ(soup.positions.size(), c.vertices);
    EXPECT_EQ(st.faces, c.faces);
    EXPECT_EQ(st.charts, c.charts);
    EXPECT_EQ(st.manifold, c.manifold);

    IO::Read_options opt;
    opt.repair = !c.manifold;  // DamagedHelmet: non-manifold edges and vertices
    Textured_mesh tm;
    IO::read_textured_mesh(shared_data(c.path), tm, opt);
    ASSERT_TRUE(tm.has_uvs());
    ASSERT_TRUE(CGAL::is_valid_polygon_mesh(tm.mesh()));
    if (c.manifold) {
      EXPECT_EQ(tm.mesh().number_of_vertices(), c.vertices);
      EXPECT_EQ(mesh_charts(tm), c.charts);  // halfedge-based charts agree with the soup's
    }
    const std::string out = (fs::path(dir) / (fs::path(c.path).stem().string() + "_rt.obj")).string();
    IO::write_textured_mesh(out, tm);
    Textured_mesh back;
    IO::read_textured_mesh(out, back);
    expect_same_geometry_and_uvs(tm, back);
    EXPECT_EQ(mesh_charts(back), mesh_charts(tm));
    ASSERT_EQ(back.materials().size(), tm.materials().size());
    for (std::size_t i = 0; i < tm.materials().size(); ++i) {
      const Image &x = tm.materials()[i].diffuse_image, &y = back.materials()[i].diffuse_image;
      EXPECT_EQ(x.empty(), y.empty());
      if (!x.empty()) EXPECT_TRUE(x == y) << "texture pixels changed in the PNG round trip";
    }
  }
}

TEST(Mesh_IO_models, ClassicModelsTopologyMatchesSources) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  for (const auto& c : classic_models) {
    SCOPED_TRACE(c.path);
    const std::string path = cmgeom_test::shared_mesh(c.path, dir);
    ASSERT_FALSE(path.empty());
    const Mesh_statistics st = analyze_soup(IO::read_polygon_soup(path));
    EXPECT_EQ(st.closed, c.closed);
    EXPECT_EQ(st.manifold, c.manifold);
    EXPECT_EQ(st.components, c.components);
    if (c.genus >= 0) EXPECT_EQ(st.genus, c.genus);
  }
}

TEST(Mesh_IO_models, ObjParserAgreesWithTinyobjloader) {
  CMGEOM_REQUIRE_SHARED_DATA();
  for (const auto& c : textured_models) {
    SCOPED_TRACE(c.path);
    const std::string path = shared_data(c.path);
    tinyobj::ObjReaderConfig cfg;
    cfg.triangulate = false;
    cfg.mtl_search_path = fs::path(path).parent_path().string();
    tinyobj::ObjReader reader;
    ASSERT_TRUE(reader.ParseFromFile(path, cfg)) << reader.Error();
    const auto& attrib = reader.GetAttrib();
    const Polygon_soup soup = IO::read_polygon_soup(path);
    ASSERT_EQ(attrib.vertices.size(), 3 * soup.positions.size());
    ASSERT_EQ(attrib.texcoords.size(), 2 * soup.uvs.size());
    // tinyobjloader's own number parser is not correctly rounded (it may differ in the last
    // bit); ours uses std::from_chars, which is. Hence a relative tolerance of a few ulps.
    auto close = [](double a, double b) { return std::abs(a - b) <= 1e-15 * std::max(1.0, std::abs(a)); };
    for (std::size_t i = 0; i < soup.positions.size(); ++i)
      for (int k = 0; k < 3; ++k) ASSERT_TRUE(close(attrib.vertices[3 * i + k], soup.positions[i][k])) << i;
    for (std::size_t i = 0; i < soup.uvs.size(); ++i)
      for (int k = 0; k < 2; ++k) ASSERT_TRUE(close(attrib.texcoords[2 * i + k], soup.uvs[i][k])) << i;
    std::size_t faces = 0, corner = 0;
    for (const auto& shape : reader.GetShapes()) {
      std::size_t offset = 0;
      for (unsigned char n : shape.mesh.num_face_vertices) {
        ASSERT_LT(faces, soup.number_of_faces());
        ASSERT_EQ(n, soup.face_size(faces));
        for (unsigned k = 0; k < n; ++k, ++corner) {
          const auto& idx = shape.mesh.indices[offset + k];
          ASSERT_EQ(std::uint32_t(idx.vertex_index), soup.corner_vertex[soup.face_start[faces] + k]);
          ASSERT_EQ(std::uint32_t(idx.texcoord_index), soup.corner_uv[soup.face_start[faces] + k]);
        }
        offset += n;
        ++faces;
      }
    }
    EXPECT_EQ(faces, soup.number_of_faces());
  }
}

TEST(Mesh_IO_models, GeometryRoundTripKeepsVertexOrderIncludingUnreferenced) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  const std::string path = cmgeom_test::shared_mesh("classic/stanford-bunny.obj.gz", dir);
  Textured_mesh tm;
  IO::read_mesh(path, tm);
  EXPECT_EQ(tm.mesh().number_of_vertices(), 35947u);  // 1113 unreferenced vertices kept
  for (const char* ext : {".obj", ".off", ".ply"}) {
    SCOPED_TRACE(ext);
    const std::string out = (fs::path(dir) / (std::string("bunny") + ext)).string();
    IO::write_mesh(out, tm);
    Textured_mesh back;
    IO::read_mesh(out, back);
    expect_same_geometry_and_uvs(tm, back);
  }
}

// ------------------------------------------------------------------ small hand-made files

// The triangles of a mesh as (smallest vertex first, orientation kept) triples, sorted.
std::vector<std::array<std::size_t, 3>> oriented_triangles(const Textured_mesh& tm) {
  std::vector<std::array<std::size_t, 3>> r;
  for (auto f : tm.mesh().faces()) {
    std::vector<std::size_t> vs;
    for (auto v : tm.mesh().vertices_around_face(tm.mesh().halfedge(f))) vs.push_back(std::size_t(v));
    std::rotate(vs.begin(), std::min_element(vs.begin(), vs.end()), vs.end());
    r.push_back({vs[0], vs[1], vs[2]});
  }
  std::sort(r.begin(), r.end());
  return r;
}

// A 3 x 3 grid of vertices (rows y = 0, 1, 2) as triangle strips: one per row of quads, the
// second after a -1 restart; then as one strip stitched through repeated vertices; then in binary.
// The same 8 triangles, counter-clockwise, as a face element for reference.
TEST(Mesh_IO_ply, TriangleStripsReadAsTheTrianglesTheyEncode) {
  const std::string dir = scratch_dir();
  const std::string verts = "0 0 0\n1 0 0\n2 0 0\n0 1 0\n1 1 0\n2 1 0\n0 2 0\n1 2 0\n2 2 0\n";
  const std::string head = "ply\nformat ascii 1.0\ncomment strips as MeshLab writes them\nelement vertex 9\n"
                           "property float x\nproperty float y\nproperty float z\n";
  const std::string strips = write_text(dir, "strips.ply",
                                        head + "element tristrips 1\nproperty list int int vertex_indices\nend_header\n" +
                                            verts + "13 3 0 4 1 5 2 -1 6 3 7 4 8 5\n");
  const std::string joined = write_text(dir, "joined.ply",
                                        head + "element tristrips 1\nproperty list int int vertex_indices\nend_header\n" +
                                            verts + "14 3 0 4 1 5 2 2 6 6 3 7 4 8 5\n");
  const std::string faces = write_text(dir, "faces.ply",
                                       head + "element face 8\nproperty list uchar int vertex_indices\nend_header\n" + verts +
                                           "3 3 0 4\n3 4 0 1\n3 4 1 5\n3 5 1 2\n3 6 3 7\n3 7 3 4\n3 7 4 8\n3 8 4 5\n");
  Textured_mesh a, b, c;
  IO::read_mesh(strips, a);
  IO::read_mesh(faces, c);
  ASSERT_EQ(a.mesh().number_of_faces(), 8u);
  EXPECT_EQ(oriented_triangles(a), oriented_triangles(c));
  // every triangle counter-clockwise seen from +z (the strips' alternation done right)
  for (auto f : a.mesh().faces()) {
    std::vector<CMGeom::Point_3> p;
    for (auto v : a.mesh().vertices_around_face(a.mesh().halfedge(f))) p.push_back(a.mesh().point(v));
    EXPECT_GT(CGAL::cross_product(p[1] - p[0], p[2] - p[0]).z(), 0.);
  }
  // one stitched strip: the four triangles of the join "2 2 6 6" repeat a vertex and are dropped,
  // and the strip's parity runs on through them
  IO::read_mesh(joined, b);
  EXPECT_EQ(oriented_triangles(b), oriented_triangles(c));
  // binary little endian: the same strip
  std::string bin = "ply\nformat binary_little_endian 1.0\nelement vertex 9\nproperty float x\nproperty float y\n"
                    "property float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n";
  const float xyz[9][3] = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}, {0, 2, 0}, {1, 2, 0}, {2, 2, 0}};
  bin.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  const std::int32_t list[] = {13, 3, 0, 4, 1, 5, 2, -1, 6, 3, 7, 4, 8, 5};
  bin.append(reinterpret_cast<const char*>(list), sizeof list);
  const std::string binary = write_text(dir, "strips_bin.ply", bin);
  Textured_mesh d;
  IO::read_mesh(binary, d);
  EXPECT_EQ(oriented_triangles(d), oriented_triangles(c));
}

TEST(Mesh_IO_obj, PolygonsAreFanSplitInFileOrderAndNegativeIndicesWork) {
  const std::string dir = scratch_dir();
  const std::string path = write_text(dir, "quad.obj",
                                      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\n"
                                      "f -5 -4 -3 -2\nf 4 3 5\n");
  Textured_mesh tm;
  IO::read_mesh(path, tm);
  ASSERT_EQ(tm.mesh().number_of_faces(), 3u);
  std::vector<std::vector<std::size_t>> faces;
  for (auto f : tm.mesh().faces()) {
    std::vector<std::size_t> vs;
    for (auto v : tm.mesh().vertices_around_face(tm.mesh().halfedge(f))) vs.push_back(std::size_t(v));
    std::rotate(vs.begin(), std::min_element(vs.begin(), vs.end()), vs.end());
    faces.push_back(vs);
  }
  EXPECT_EQ(faces[0], (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_EQ(faces[1], (std::vector<std::size_t>{0, 2, 3}));
  EXPECT_EQ(faces[2], (std::vector<std::size_t>{2, 4, 3}));
}

TEST(Mesh_IO_obj, UnknownStatementsAreSkippedWithAWarning) {
  // Some exporters write a stray "V F 0" line (QMVC's Beast.obj does): read the mesh, warn once.
  const std::string dir = scratch_dir();
  const std::string path = write_text(dir, "stray.obj", "# x\n3 1 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const Polygon_soup soup = IO::read_polygon_soup(path);
  EXPECT_EQ(soup.number_of_faces(), 1u);
  ASSERT_EQ(soup.warnings.size(), 1u);
  EXPECT_NE(soup.warnings[0].find("stray.obj:2: unknown OBJ statement '3'"), std::string::npos) << soup.warnings[0];
}

TEST(Mesh_IO_model, SeamsAreChartBoundariesWithoutSplitVertices) {
  // Two triangles sharing edge (1,2); the right one uses other UVs at vertex 2: a seam.
  const std::string dir = scratch_dir();
  const std::string path = write_text(dir, "seam.obj",
                                      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                                      "vt 0 0\nvt 1 0\nvt 0 1\nvt 0.5 0.5\nvt 1 1\n"
                                      "f 1/1 2/2 3/3\nf 2/2 4/5 3/4\n");
  Textured_mesh tm;
  IO::read_mesh(path, tm);
  EXPECT_EQ(tm.mesh().number_of_vertices(), 4u);  // no vertex split at the seam
  std::size_t seams = 0, border = 0;
  for (auto e : tm.mesh().edges()) {
    seams += is_seam_edge(e, tm.mesh(), tm.uv_map());
    border += tm.mesh().is_border(e);
  }
  EXPECT_EQ(seams, 1u);
  EXPECT_EQ(border, 4u);
  EXPECT_EQ(mesh_charts(tm), 2u);
  auto ids = tm.mesh().add_property_map<Surface_mesh::Face_index, int>("f:c", -1).first;
  compute_chart_ids(tm.mesh(), tm.uv_map(), ids);
  EXPECT_EQ(number_of_charts_around_vertex(Surface_mesh::Vertex_index(1), tm.mesh(), ids), 2u);
  EXPECT_EQ(number_of_charts_around_vertex(Surface_mesh::Vertex_index(0), tm.mesh(), ids), 1u);
  EXPECT_EQ(number_of_chart_boundary_edges(Surface_mesh::Vertex_index(1), tm.mesh(), tm.uv_map()), 3u);
  // Same UVs on both sides: one chart.
  const std::string path2 = write_text(dir, "noseam.obj",
                                       "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                                       "vt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n"
                                       "f 1/1 2/2 3/3\nf 2/2 4/4 3/3\n");
  Textured_mesh tm2;
  IO::read_mesh(path2, tm2);
  EXPECT_EQ(mesh_charts(tm2), 1u);
}

TEST(Mesh_IO_model, CopiesRebindPropertyMaps) {
  const std::string dir = scratch_dir();
  const std::string path = write_text(dir, "t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.25 0.5\nf 1/1 2/1 3/1\n");
  Textured_mesh a;
  IO::read_mesh(path, a);
  Textured_mesh b = a;
  const auto h = b.mesh().halfedge(*b.mesh().faces().begin());
  b.set_uv(h, Point_2(9, 9));
  EXPECT_EQ(a.uv(h), Point_2(0.25, 0.5));  // the copy does not write into the original
  EXPECT_EQ(b.uv(h), Point_2(9, 9));
  Textured_mesh c = std::move(b);
  EXPECT_EQ(c.uv(h), Point_2(9, 9));
}

TEST(Mesh_IO_gltf, EmbeddedBufferWeldedFlippedAndTextured) {
  // A unit quad of two triangles, 4 unique positions given as 6 glTF vertices (as exporters
  // do at UV seams), base-colour texture as an external PNG.
  const std::string dir = scratch_dir();
  Image tex(2, 2, 3);
  tex.set_value(0, 0, 0, 1.f);
  IO::write_image((fs::path(dir) / "tex.png").string(), tex);
  std::vector<float> pos = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0};
  std::vector<float> uv = {0, 1, 1, 1, 1, 0, 0, 1, 1, 0, 0, 0};
  std::string bin(reinterpret_cast<const char*>(pos.data()), pos.size() * 4);
  bin.append(reinterpret_cast<const char*>(uv.data()), uv.size() * 4);
  std::ofstream(fs::path(dir) / "quad.bin", std::ios::binary) << bin;
  nlohmann::json j = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}, {"translation", {0, 0, 2}}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}}}, {"material", 0}}}}}}},
      {"materials", {{{"name", "m"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}}},
      {"textures", {{{"source", 0}}}},
      {"images", {{{"uri", "tex.png"}}}},
      {"buffers", {{{"uri", "quad.bin"}, {"byteLength", bin.size()}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 72}},
                       {{"buffer", 0}, {"byteOffset", 72}, {"byteLength", 48}}}},
      {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 6}, {"type", "VEC3"},
                      {"min", {0, 0, 0}}, {"max", {1, 1, 0}}},
                     {{"bufferView", 1}, {"componentType", 5126}, {"count", 6}, {"type", "VEC2"}}}}};
  const std::string path = write_text(dir, "quad.gltf", j.dump());
  Textured_mesh tm;
  IO::read_textured_mesh(path, tm);
  EXPECT_EQ(tm.mesh().number_of_vertices(), 4u);  // welded
  EXPECT_EQ(tm.mesh().number_of_faces(), 2u);
  ASSERT_TRUE(tm.has_uvs());
  for (auto v : tm.mesh().vertices()) EXPECT_EQ(tm.mesh().point(v).z(), 2.0);  // node translation
  for (auto h : tm.mesh().halfedges()) {
    if (tm.mesh().is_border(h)) continue;
    const Point_3 p = tm.mesh().point(tm.mesh().target(h));
    EXPECT_EQ(tm.uv(h), Point_2(p.x(), p.y()));  // v flipped: glTF v = 1 - y
  }
  ASSERT_EQ(tm.materials().size(), 1u);
  EXPECT_TRUE(tm.materials()[0].diffuse_image == tex);
  EXPECT_EQ(mesh_charts(tm), 1u);
}

TEST(Mesh_IO_image, RgbaPngRoundTripIsLossless) {
  const std::string dir = scratch_dir();
  Image img(7, 5, 4);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x)
      for (int c = 0; c < 4; ++c) img.bytes()[img.index(x, y, c)] = std::uint8_t((x * 37 + y * 11 + c * 71) % 256);
  const std::string path = (fs::path(dir) / "rgba.png").string();
  IO::write_image(path, img);
  EXPECT_TRUE(IO::read_image(path) == img);
  EXPECT_EQ(IO::image_size(path), std::make_pair(7, 5));
}

// OpenImageIO (about 260 shared libraries) is loaded by the first image read or written, not at
// program start: whether it was mapped is recorded while this program initialises, before main().
namespace {
bool oiio_mapped() {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line))
    if (line.find("libOpenImageIO") != std::string::npos) return true;
  return false;
}
const bool oiio_mapped_at_start = oiio_mapped();
}  // namespace

TEST(Mesh_IO_image, OpenImageIOIsLoadedOnFirstUseOnly) {
  EXPECT_FALSE(oiio_mapped_at_start) << "OpenImageIO was loaded at program start";
  const std::string path = (fs::path(scratch_dir()) / "lazy.png").string();
  Image img(3, 2, 3);
  img.bytes()[img.index(2, 1, 0)] = 200;
  IO::write_image(path, img);
  EXPECT_TRUE(oiio_mapped()) << "writing an image did not go through OpenImageIO";
  EXPECT_TRUE(IO::read_image(path) == img);
}

// ------------------------------------------------------------------ malformed input catalogue

namespace {

struct Bad_case {
  const char* name;     // file name the test writes
  std::string content;
  const char* expect;   // part of the message
  std::size_t line;     // expected line (0: none)
  IO::Read_options options = IO::Read_options();
};

std::vector<Bad_case> bad_cases() {
  std::vector<Bad_case> v;
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  v.push_back({"empty.obj", "", "empty file", 0});
  v.push_back({"garbage.obj", std::string("\x7f" "ELF\x02\x01\x01\0\0\0binary", 16), "", 0});
  v.push_back({"unknown.obj", "v 0 0 0\nhello world\n", "no faces", 0});  // unknown lines only warn
  v.push_back({"short_vertex.obj", "v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "three numbers", 1});
  v.push_back({"nan.obj", "v 0 nan 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "not finite", 1});
  v.push_back({"inf.obj", "v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n", "not finite", 2});
  v.push_back({"range.obj", tri + "f 1 2 4\n", "out of range", 4});
  v.push_back({"zero_index.obj", tri + "f 0 1 2\n", "out of range", 4});
  v.push_back({"uv_range.obj", tri + "vt 0 0\nf 1/1 2/2 3/1\n", "texture coordinate index 2 out of range", 5});
  v.push_back({"two_corners.obj", tri + "f 1 2\n", "at least 3", 4});
  v.push_back({"no_faces.obj", tri, "no faces", 0});
  v.push_back({"partial_uv_face.obj", tri + "vt 0 0\nf 1/1 2 3/1\n", "some corners only", 5});
  v.push_back({"faces_without_uv.obj", tri + "v 1 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 2 4 3\n", "no texture coordinates", 7});
  v.push_back({"repeated.obj", tri + "f 1 2 2\n", "repeats a vertex", 4});
  v.push_back({"zero_area.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 4 2\n", "zero-area", 5});
  // Three triangles on edge (1,2): non-manifold edge.
  v.push_back({"nm_edge.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
               "non-manifold edge", 0});
  // Two tetrahedra touching at one vertex: non-manifold vertex.
  v.push_back({"nm_vertex.obj",
               "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv -1 0 0\nv 0 -1 0\nv 0 0 -1\n"
               "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 1 5 6\nf 1 6 7\nf 1 7 5\nf 5 7 6\n",
               "non-manifold vertex", 0});
  v.push_back({"orientation.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 3 4\n", "inconsistently oriented", 0});
  v.push_back({"missing_texture.obj", "mtllib missing_texture.mtl\n" + tri + "vt 0 0\nusemtl m\nf 1/1 2/1 3/1\n",
               "not found", 2});
  v.push_back({"empty.off", "", "empty file", 0});
  v.push_back({"truncated.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n", "truncated", 0});
  v.push_back({"huge.off", "OFF\n2000000000 2000000000 0\n0 0 0\n", "more than the file can hold", 2});
  v.push_back({"range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", "out of range", 6});
  v.push_back({"nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", "not finite", 4});
  v.push_back({"notply.ply", "this is not a ply file\n", "not a PLY file", 1});
  // an ASCII PLY of three vertices, then its face or strip element
  const std::string ply3 = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string ply3_face = ply3 + "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string ply3_strip = ply3 + "element tristrips 1\nproperty list int int vertex_indices\nend_header\n";
  v.push_back({"truncated.ply", ply3_face + "0 0 0\n1 0 0\n", "", 0});
  v.push_back({"range.ply", ply3_face + "0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", "out of range", 0});
  // Regression (fuzzing): CGAL's PLY reader crashed on a property declared before any element.
  v.push_back({"prop_first.ply", "ply\nformat ascii 1.0\nproperty float x\nelement vertex 1\nend_header\n0\n",
               "property before any element", 3});
  v.push_back({"huge.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
                           "property float y\nproperty float z\nelement face 1\n"
                           "property list uchar int vertex_indices\nend_header\n", "more than the file can hold", 0});
  v.push_back({"no_end.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", "no end_header", 0});
  v.push_back({"strip_negative.ply", ply3_strip + "0 0 0\n1 0 0\n0 1 0\n4 0 1 -2 2\n", "negative vertex index", 0});
  v.push_back({"strip_range.ply", ply3_strip + "0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n", "out of range", 0});
  v.push_back({"garbage.gltf", "{ this is not json", "", 0});
  v.push_back({"empty.glb", "", "empty file", 0});
  v.push_back({"mesh.stl", "solid x\nendsolid x\n", "unsupported file type", 0});
  return v;
}

}  // namespace

TEST(Mesh_IO_bad_input, EveryCaseGivesOneLineErrorWithFileAndLine) {
  const std::string dir = scratch_dir();
  write_text(dir, "missing_texture.mtl", "newmtl m\nmap_Kd does_not_exist.png\n");
  const auto cases = bad_cases();
  EXPECT_GE(cases.size(), 25u);
  for (const Bad_case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = write_text(dir, c.name, c.content);
    try {
      Textured_mesh tm;
      IO::read_mesh(path, tm, c.options);
      ADD_FAILURE() << "no error for " << c.name;
    } catch (const IO_error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      const std::string stem = fs::path(c.name).stem().string();
      EXPECT_NE(msg.find(stem), std::string::npos) << "message does not name the file: " << msg;
      EXPECT_NE(msg.find(c.expect), std::string::npos) << msg;
      if (c.line) EXPECT_NE(msg.find(":" + std::to_string(c.line) + ":"), std::string::npos) << msg;
    }
  }
  EXPECT_THROW({ Textured_mesh tm; IO::read_mesh((fs::path(dir) / "absent.obj").string(), tm); }, IO_error);
  EXPECT_THROW({ Textured_mesh tm; IO::read_mesh(dir, tm); }, IO_error);  // a directory
}

TEST(Mesh_IO_bad_input, CliFailsWithOneLineAndWritesNothing) {
  const std::string dir = scratch_dir();
  write_text(dir, "missing_texture.mtl", "newmtl m\nmap_Kd does_not_exist.png\n");
  for (const Bad_case& c : bad_cases()) {
    SCOPED_TRACE(c.name);
    const std::string in_dir = (fs::path(dir) / "in").string();
    fs::create_directories(in_dir);
    const std::string path = write_text(in_dir, c.name, c.content);
    if (std::string(c.name) == "missing_texture.obj")
      write_text(in_dir, "missing_texture.mtl", "newmtl m\nmap_Kd does_not_exist.png\n");
    const std::string out_dir = (fs::path(dir) / "out").string();
    fs::remove_all(out_dir);
    fs::create_directories(out_dir);
    const auto r = cmgeom_test::run_cli("convert '" + path + "' -o '" + out_dir + "/result.obj'", dir);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("error"), std::string::npos) << r.err;
    EXPECT_EQ(cmgeom_test::count_files(out_dir), 0u) << "a failed command left files behind";
  }
  // Usage errors: exit code 2, one line.
  const auto r = cmgeom_test::run_cli("convert", dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST(Mesh_IO_bad_input, RepairDuplicatesNonManifoldVertexAndKeepsUVs) {
  const std::string dir = scratch_dir();
  std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv -1 0 0\nv 0 -1 0\nv 0 0 -1\n";
  for (int i = 0; i < 24; ++i) obj += "vt " + std::to_string(i / 24.0) + " 0.5\n";
  const int f[8][3] = {{1, 3, 2}, {1, 2, 4}, {1, 4, 3}, {2, 3, 4}, {1, 5, 6}, {1, 6, 7}, {1, 7, 5}, {5, 7, 6}};
  int t = 1;
  for (const auto& face : f) {
    obj += "f";
    for (int k = 0; k < 3; ++k) obj += " " + std::to_string(face[k]) + "/" + std::to_string(t++);
    obj += "\n";
  }
  const std::string path = write_text(dir, "bowtie.obj", obj);
  IO::Read_options opt;
  opt.repair = true;
  Textured_mesh tm;
  IO::read_mesh(path, tm, opt);
  EXPECT_TRUE(CGAL::is_valid_polygon_mesh(tm.mesh()));
  EXPECT_EQ(tm.mesh().number_of_vertices(), 8u);  // the shared apex is duplicated
  EXPECT_EQ(tm.mesh().number_of_faces(), 8u);
  // Every corner kept its own UV: all 24 values appear once.
  std::vector<double> us;
  for (auto h : tm.mesh().halfedges())
    if (!tm.mesh().is_border(h)) us.push_back(tm.uv(h).x());
  std::sort(us.begin(), us.end());
  ASSERT_EQ(us.size(), 24u);
  for (int i = 0; i < 24; ++i) EXPECT_NEAR(us[std::size_t(i)], i / 24.0, 1e-6);
}

TEST(Mesh_IO_bad_input, RepairMakesNonManifoldClassicModelsValid) {
  // Regression (fuzzing): repairing beetle (47 non-manifold edges) once produced an invalid
  // halfedge structure; suzanne's quads become non-manifold only after the fan split.
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  for (const char* name : {"classic/beetle.obj", "classic/teapot.obj", "classic/suzanne.obj", "classic/cow.obj",
                           "classic/ogre.obj.gz", "textured/DamagedHelmet/DamagedHelmet.obj"}) {
    SCOPED_TRACE(name);
    IO::Read_options opt;
    opt.repair = true;
    opt.allow_degenerate_faces = true;  // ogre has four zero-area faces
    Textured_mesh tm;
    IO::read_mesh(cmgeom_test::shared_mesh(name, dir), tm, opt);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(tm.mesh()));
    EXPECT_TRUE(CGAL::is_triangle_mesh(tm.mesh()));
    // Without repair the same files are refused with a clear error.
    Textured_mesh plain;
    EXPECT_THROW(IO::read_mesh(cmgeom_test::shared_mesh(name, dir), plain), IO_error);
  }
}

TEST(Mesh_IO_bad_input, OrientedManifoldCheckAgreesWithCgal) {
  // the reader's repair decides with io_internal.h's sort-based check; CGAL's
  // is_polygon_soup_a_polygon_mesh is the reference, and the expected answer is stated too
  using Tris = std::vector<std::vector<std::size_t>>;
  const Tris tetra = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  Tris flipped = tetra, doubled = tetra, bowtie = tetra;
  std::swap(flipped[0][1], flipped[0][2]);
  doubled.push_back({0, 2, 1});  // an edge with three faces
  for (const auto& t : tetra) {  // a second tetrahedron sharing vertex 0 only: two fans there
    std::vector<std::size_t> u;
    for (std::size_t v : t) u.push_back(v == 0 ? 0 : v + 3);
    bowtie.push_back(u);
  }
  const Tris repeated = {{0, 1, 1}}, open = {{0, 1, 2}, {0, 2, 3}}, same_direction = {{0, 1, 2}, {0, 1, 3}};
  const std::vector<std::pair<const Tris*, bool>> cases = {{&tetra, true},   {&flipped, false},  {&doubled, false},
                                                           {&bowtie, false}, {&repeated, false}, {&open, true},
                                                           {&same_direction, false}};
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const auto& [soup, expected] = cases[c];
    Polygon_soup ps;
    std::size_t vertices = 0;
    for (const auto& t : *soup) {
      for (std::size_t v : t) {
        ps.corner_vertex.push_back(std::uint32_t(v));
        vertices = std::max(vertices, v + 1);
      }
      ps.face_start.push_back(std::uint32_t(ps.corner_vertex.size()));
    }
    const bool ours = IO::internal::is_oriented_manifold_soup(ps, vertices);
    EXPECT_EQ(ours, expected) << "case " << c;
    if (std::none_of(soup->begin(), soup->end(), [](const auto& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }))
      EXPECT_EQ(ours, CGAL::Polygon_mesh_processing::is_polygon_soup_a_polygon_mesh(*soup)) << "case " << c;
  }
}

TEST(Mesh_IO_atomic, FailedWritesLeaveNothingAndKeepOldFiles) {
  const std::string dir = scratch_dir();
  const std::string path = write_text(dir, "t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  Textured_mesh tm;
  IO::read_mesh(path, tm);
  EXPECT_THROW(IO::write_mesh((fs::path(dir) / "no_such_dir" / "x.obj").string(), tm), IO_error);
  EXPECT_THROW(IO::write_mesh((fs::path(dir) / "x.stl").string(), tm), IO_error);
  // A texture that vanished makes the whole OBJ write fail: neither .obj nor .mtl appears,
  // and an existing output keeps its old content.
  const std::string existing = write_text(dir, "out.obj", "old content\n");
  tm.materials().push_back(Material());
  tm.materials()[0].name = "m";
  tm.materials()[0].diffuse_texture = (fs::path(dir) / "vanished.png").string();
  EXPECT_THROW(IO::write_mesh(existing, tm), IO_error);
  std::ifstream in(existing);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "old content");
  EXPECT_FALSE(fs::exists(fs::path(dir) / "out.mtl"));
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << "temporary left: " << e.path();
}

TEST(Mesh_IO_cli, InfoJsonReportsSourcesValues) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  const auto r = cmgeom_test::run_cli("info --json '" + shared_data("textured/fuze/fuze.obj") + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["vertices"], 502);
  EXPECT_EQ(j["faces"], 1000);
  EXPECT_EQ(j["charts"], 8);
  EXPECT_EQ(j["closed"], true);
  EXPECT_EQ(j["manifold"], true);
  EXPECT_EQ(j["genus"], 0);
  EXPECT_EQ(j["components"], 1);
  EXPECT_EQ(j["materials"][0]["diffuse_texture"]["width"], 1024);  // "fuze uv.jpg": a space in the name
}

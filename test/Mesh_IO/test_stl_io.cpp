// Tests of the STL reader and writer: ASCII and binary files written by hand (corners merged into
// vertices, orientation from the corner order, binary files whose header begins with "solid"),
// bad files refused with their place, a binary round trip of a generated closed mesh and of the
// Stanford bunny, .stl.gz, and the tool converting to and simplifying from STL.
#include "mesh_io_test_util.h"

#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/boost/graph/helpers.h>

#include <cstdio>
#include <sstream>

namespace {

// The tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1) with outward faces, as ASCII STL: keywords in
// mixed case, a solid name with spaces, numbers with '+', exponents and a "-0" for a 0 of another facet, and
// a NaN normal as old Windows writers print it.
const char* const ascii_tetra =
    "solid my part, 2 mm\n"
    "facet normal 0 0 -1\n  outer loop\n    vertex 0 0 0\n    vertex 0 1 0\n    vertex 1 0 0\n  endloop\nendfacet\n"
    "FACET NORMAL 0 -1 0\n  OUTER LOOP\n    VERTEX 0 -0 0\n    VERTEX 1e0 0 0\n    VERTEX 0 0 +1\n  ENDLOOP\nENDFACET\n"
    "facet normal -1 0 0\n outer loop\n vertex 0 0 0\n vertex 0 0 1\n vertex 0 1.0 0\n endloop\n endfacet\n"
    "facet normal -1.#IND00 -1.#IND00 -1.#IND00\n outer loop\n vertex 1 0 0\n vertex 0 1 0\n vertex 0 0 10e-1\n"
    " endloop\n endfacet\n"
    "endsolid my part, 2 mm\n";

// Signed volume of a closed triangle mesh (positive when its faces point outwards).
double signed_volume(const Surface_mesh& m) {
  double v = 0;
  for (auto f : m.faces()) {
    std::array<Point_3, 3> p;
    int k = 0;
    for (auto x : m.vertices_around_face(m.halfedge(f))) p[std::size_t(k++)] = m.point(x);
    v += CGAL::scalar_product(p[0] - CGAL::ORIGIN, CGAL::cross_product(p[1] - CGAL::ORIGIN, p[2] - CGAL::ORIGIN)) / 6;
  }
  return v;
}

// A binary STL: `header` (80 bytes, padded with spaces) and the triangles' corners (normals zero).
std::string binary_stl(const std::string& header, const std::vector<std::array<float, 9>>& triangles,
                       std::uint32_t declared) {
  std::string s = header.substr(0, 80);
  s.resize(80, ' ');
  s.append(reinterpret_cast<const char*>(&declared), 4);
  for (const auto& t : triangles) {
    const float normal[3] = {0, 0, 0};
    s.append(reinterpret_cast<const char*>(normal), sizeof normal);
    s.append(reinterpret_cast<const char*>(t.data()), 9 * sizeof(float));
    s.append(2, '\0');
  }
  return s;
}

// A closed genus-0 mesh of (rings - 1) x segments quads and two polar fans, as OFF text, its
// coordinates not representable in float (so that the round trip through float shows).
std::string sphere_off(int rings, int segments) {
  std::ostringstream s;
  s.precision(17);
  const int nv = 2 + (rings - 1) * segments, nf = 2 * segments + 2 * (rings - 2) * segments;
  s << "OFF\n" << nv << " " << nf << " 0\n";
  s << "0 0 1.1\n0 0 -1.1\n";
  for (int r = 1; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      const double th = CGAL_PI * r / rings, ph = 2 * CGAL_PI * k / segments;
      s << 1.1 * std::sin(th) * std::cos(ph) << " " << 1.1 * std::sin(th) * std::sin(ph) << " " << 1.1 * std::cos(th)
        << "\n";
    }
  auto ring_vertex = [&](int r, int k) { return 2 + (r - 1) * segments + (k % segments); };
  for (int k = 0; k < segments; ++k) s << "3 0 " << ring_vertex(1, k) << " " << ring_vertex(1, k + 1) << "\n";
  for (int r = 1; r + 1 < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      s << "3 " << ring_vertex(r, k) << " " << ring_vertex(r + 1, k) << " " << ring_vertex(r + 1, k + 1) << "\n";
      s << "3 " << ring_vertex(r, k) << " " << ring_vertex(r + 1, k + 1) << " " << ring_vertex(r, k + 1) << "\n";
    }
  for (int k = 0; k < segments; ++k)
    s << "3 1 " << ring_vertex(rings - 1, k + 1) << " " << ring_vertex(rings - 1, k) << "\n";
  return s.str();
}

// The file's bytes.
std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Writes `tm` to STL and reads it back: same faces, in order, each corner the float of the input's
// corner, the vertices merged back to the input's count; the file 84 + 50 F bytes, its header not
// "solid" (which would make readers guess ASCII).
void expect_stl_round_trip(const Textured_mesh& tm, const std::string& dir) {
  const std::string out = (fs::path(dir) / "round.stl").string();
  IO::write_mesh(out, tm);
  const std::string bytes = file_bytes(out);
  ASSERT_EQ(bytes.size(), 84 + 50 * tm.mesh().number_of_faces());
  EXPECT_NE(bytes.compare(0, 5, "solid"), 0);
  Textured_mesh back;
  IO::read_mesh(out, back);
  const Surface_mesh &a = tm.mesh(), &b = back.mesh();
  ASSERT_EQ(b.number_of_faces(), a.number_of_faces());
  EXPECT_EQ(b.number_of_vertices(), a.number_of_vertices());
  EXPECT_FALSE(back.has_uvs());
  auto fa = a.faces().begin();
  for (auto fb : b.faces()) {
    std::vector<Point_3> pa, pb;
    for (auto v : a.vertices_around_face(a.halfedge(*fa))) pa.push_back(a.point(v));
    for (auto v : b.vertices_around_face(b.halfedge(fb))) pb.push_back(b.point(v));
    ASSERT_EQ(pb.size(), 3u);
    for (std::size_t k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) ASSERT_EQ(pb[k][d], double(float(pa[k][d])));
    ++fa;
  }
  EXPECT_NEAR(CGAL::Polygon_mesh_processing::area(b), CGAL::Polygon_mesh_processing::area(a),
              1e-5 * CGAL::Polygon_mesh_processing::area(a));
}

}  // namespace

TEST(Mesh_IO_stl, AsciiFacetsShareTheirCornersAsVertices) {
  const std::string dir = scratch_dir();
  const std::string path = write_text(dir, "tetra.stl", ascii_tetra);
  const Polygon_soup soup = IO::read_polygon_soup(path);
  EXPECT_TRUE(soup.warnings.empty());
  ASSERT_EQ(soup.positions.size(), 4u);  // 12 corners, 4 places (the "-0" and the "10e-1" among them)
  ASSERT_EQ(soup.number_of_faces(), 4u);
  EXPECT_EQ(soup.positions[0], (std::array<double, 3>{{0, 0, 0}}));
  EXPECT_EQ(soup.positions[1], (std::array<double, 3>{{0, 1, 0}}));
  EXPECT_EQ(soup.positions[2], (std::array<double, 3>{{1, 0, 0}}));
  EXPECT_EQ(soup.positions[3], (std::array<double, 3>{{0, 0, 1}}));
  EXPECT_EQ(soup.face_location(1), path + ":9");  // the line of its "facet"
  const Mesh_statistics st = analyze_soup(soup);
  EXPECT_TRUE(st.closed);
  EXPECT_TRUE(st.manifold);
  EXPECT_TRUE(st.oriented);
  EXPECT_EQ(st.genus, 0);
  Textured_mesh tm;
  IO::read_mesh(path, tm);
  EXPECT_NEAR(signed_volume(tm.mesh()), 1.0 / 6, 1e-15);  // outwards: the corner order, not the normals

  // a facet of four corners is a polygon, split as any reader splits one; no "endsolid": a warning
  const std::string quad = write_text(dir, "quad.stl",
                                      "solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                      "vertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\n");
  const Polygon_soup q = IO::read_polygon_soup(quad);
  ASSERT_EQ(q.number_of_faces(), 1u);
  EXPECT_EQ(q.face_size(0), 4u);
  ASSERT_EQ(q.warnings.size(), 1u);
  EXPECT_NE(q.warnings[0].find("no 'endsolid'"), std::string::npos) << q.warnings[0];
  Textured_mesh qm;
  IO::read_mesh(quad, qm);
  EXPECT_EQ(qm.mesh().number_of_faces(), 2u);

  // several solids in one file
  const std::string two = std::string(ascii_tetra) +
                          "solid again\nfacet normal 0 0 1\nouter loop\nvertex 5 0 0\n"
                          "vertex 6 0 0\nvertex 5 1 0\nendloop\nendfacet\nendsolid\n";
  const Polygon_soup t = IO::read_polygon_soup(write_text(dir, "two.stl", two));
  EXPECT_EQ(t.number_of_faces(), 5u);
  EXPECT_EQ(t.positions.size(), 7u);
}

TEST(Mesh_IO_stl, BinaryFilesAreToldFromAsciiByTheirSize) {
  const std::string dir = scratch_dir();
  // the tetrahedron's four faces, in a binary file whose header begins with "solid" as many exporters write it
  const std::vector<std::array<float, 9>> tris = {{{0, 0, 0, 0, 1, 0, 1, 0, 0}},
                                                  {{0, 0, 0, 1, 0, 0, 0, 0, 1}},
                                                  {{0, 0, 0, 0, 0, 1, 0, 1, 0}},
                                                  {{1, 0, 0, 0, 1, 0, 0, 0, 1}}};
  for (const char* header : {"solid exported by a CAD tool", "binary"}) {
    const std::string path = write_text(dir, "b.stl", binary_stl(header, tris, 4));
    const Polygon_soup soup = IO::read_polygon_soup(path);
    EXPECT_EQ(soup.positions.size(), 4u) << header;
    EXPECT_EQ(soup.number_of_faces(), 4u) << header;
    EXPECT_EQ(soup.face_location(2), path + " (face 2)");
    Textured_mesh tm;
    IO::read_mesh(path, tm);
    EXPECT_NEAR(signed_volume(tm.mesh()), 1.0 / 6, 1e-7) << header;
  }
  // bytes after the declared triangles (padding some exporters add): read, with a warning
  const std::string padded = write_text(dir, "padded.stl", binary_stl("x", tris, 4) + std::string(7, '\0'));
  const Polygon_soup p = IO::read_polygon_soup(padded);
  EXPECT_EQ(p.number_of_faces(), 4u);
  ASSERT_EQ(p.warnings.size(), 1u);
  EXPECT_NE(p.warnings[0].find("7 bytes after the 4 triangles"), std::string::npos) << p.warnings[0];
  // gzipped
  const std::string plain = write_text(dir, "t.stl", binary_stl("x", tris, 4));
  ASSERT_EQ(std::system(("gzip -c '" + plain + "' > '" + dir + "/t.stl.gz'").c_str()), 0);
  EXPECT_EQ(IO::read_polygon_soup(dir + "/t.stl.gz").number_of_faces(), 4u);
}

TEST(Mesh_IO_stl, BadFilesAreRefusedWithTheirPlace) {
  const std::string dir = scratch_dir();
  const std::string head = "solid s\nfacet normal 0 0 1\nouter loop\n";
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<std::array<float, 9>> one = {{{0, 0, 0, 1, 0, 0, 0, 1, 0}}};
  struct Case {
    std::string content, expected;
  };
  const std::vector<Case> cases = {
      {"", "empty file"},
      {"hello", "neither an ASCII STL file (text beginning with 'solid') nor a binary one (5 bytes"},
      {"solid s\nendsolid s\n", "no faces in file"},
      {head + "vertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid\n", ":2: facet with 2 vertices"},
      {head + "vertex 0 0 0\nvertex 1 abc 0\nvertex 0 1 0\nendloop\nendfacet\n", ":5: bad vertex coordinate 'abc'"},
      {head + "vertex 0 0 0\nvertex 1 nan 0\nvertex 0 1 0\nendloop\nendfacet\n", ":5: vertex coordinate is not finite"},
      {head + "vertex 0 0 0\nvertex 1 0 0\n", "bad.stl: truncated: facet without 'endloop'"},
      {"solid s\nfacet normal 0 0 1\nouter loops\n", ":3: expected 'loop' after 'outer', found 'loops'"},
      {"solid s\nfacet 0 0 1\n", ":2: expected 'normal' after 'facet', found '0'"},
      {"solid s\nfacet normal 0 0\n", "bad.stl: truncated: expected the facet normal's components"},
      {"solid s\nvertex 0 0 0\n", ":2: expected 'facet' or 'endsolid', found 'vertex'"},
      {head + "vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\ngarbage\n",
       ":10: expected 'solid' or the end of the file, found 'garbage'"},
      {std::string("solid s\nfacet normal 0 0 1\n") + '\0' + "\n", ":3: binary data (NUL byte)"},
      // binary: a triangle short of the count its header declares (the header begins with "solid")
      {binary_stl("solid x", one, 2), "its header declares 2 triangles, 184 bytes; the file has 134"},
      {binary_stl("x", {{{0, 0, 0, 1, nan, 0, 0, 1, 0}}}, 1), "triangle 0: vertex coordinate is not finite"},
  };
  for (const Case& c : cases) {
    const std::string path = write_text(dir, "bad.stl", c.content);
    try {
      IO::read_polygon_soup(path);
      ADD_FAILURE() << "accepted: " << c.expected;
    } catch (const IO_error& e) {
      EXPECT_EQ(e.file(), path);
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << e.what() << "\nexpected: " << c.expected;
    }
  }
  // a crack (two corners a float step apart) stays open: the mesh reader says where
  const std::vector<std::array<float, 9>> cracked = {{{0, 0, 0, 1, 0, 0, 0, 1, 0}},
                                                     {{1, 0, 0, 1, 1, 0, 0, std::nextafter(1.f, 2.f), 0}}};
  const Polygon_soup soup = IO::read_polygon_soup(write_text(dir, "crack.stl", binary_stl("c", cracked, 2)));
  EXPECT_EQ(soup.positions.size(), 5u);
  EXPECT_EQ(analyze_soup(soup).boundary_edges, 6u);
}

TEST(Mesh_IO_stl, BinaryRoundTripKeepsEveryTriangle) {
  const std::string dir = scratch_dir();
  Textured_mesh sphere;
  IO::read_mesh(write_text(dir, "sphere.off", sphere_off(12, 20)), sphere);
  expect_stl_round_trip(sphere, dir);
  // a face of more than three corners cannot be stored
  Textured_mesh quad;
  {
    Surface_mesh& m = quad.mesh();
    const auto a = m.add_vertex(Point_3(0, 0, 0)), b = m.add_vertex(Point_3(1, 0, 0)),
               c = m.add_vertex(Point_3(1, 1, 0)), d = m.add_vertex(Point_3(0, 1, 0));
    m.add_face(a, b, c, d);
  }
  try {
    IO::write_mesh(dir + "/quad.stl", quad);
    ADD_FAILURE() << "a quad was written to STL";
  } catch (const IO_error& e) {
    EXPECT_NE(std::string(e.what()).find("STL stores triangles only"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir + "/quad.stl"));
}

TEST(Mesh_IO_stl, BunnyRoundTrip) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  Textured_mesh bunny;
  IO::read_mesh(shared_data("classic/bunny.off"), bunny);
  expect_stl_round_trip(bunny, dir);
}

TEST(Mesh_IO_stl, ToolConvertsToStlAndSimplifiesFromIt) {
  const std::string dir = scratch_dir();
  const std::string off = write_text(dir, "sphere.off", sphere_off(16, 24));
  const auto conv = cmgeom_test::run_cli("convert '" + off + "' -o '" + dir + "/sphere.stl'", dir);
  ASSERT_EQ(conv.exit_code, 0) << conv.err;
  const auto info = cmgeom_test::run_cli("info '" + dir + "/sphere.stl' --json", dir);
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const auto j = nlohmann::json::parse(info.out);
  EXPECT_EQ(j.at("faces").get<int>(), 2 * 24 + 2 * 14 * 24);
  EXPECT_EQ(j.at("vertices").get<int>(), 2 + 15 * 24);
  EXPECT_EQ(j.at("genus").get<int>(), 0);
  const auto simp =
      cmgeom_test::run_cli("simplify '" + dir + "/sphere.stl' -o '" + dir + "/small.stl' --faces 100", dir);
  ASSERT_EQ(simp.exit_code, 0) << simp.err;
  // (a simplified sphere: at most 100 faces, still closed)
  auto expect_small_and_closed = [](const std::string& path) {
    Textured_mesh small;
    IO::read_mesh(path, small);
    EXPECT_LE(small.mesh().number_of_faces(), 100u) << path;
    EXPECT_TRUE(CGAL::is_closed(small.mesh())) << path;
  };
  expect_small_and_closed(dir + "/small.stl");
  // a sliver whose corners merge into two (as CAD exports hold): refused, naming the option that drops it
  std::string sliver = file_bytes(dir + "/sphere.stl");
  const std::uint32_t faces = 2 * 24 + 2 * 14 * 24 + 1;
  std::memcpy(&sliver[80], &faces, 4);
  const std::string record = sliver.substr(84, 50);  // the first triangle, its second corner made its first
  sliver += record.substr(0, 24) + record.substr(12, 12) + record.substr(36, 14);
  const std::string sliver_path = write_text(dir, "sliver.stl", sliver);
  const auto refused = cmgeom_test::run_cli("simplify '" + sliver_path + "' -o '" + dir + "/s.stl' --faces 100", dir);
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.err.find(sliver_path + " (face 720): face repeats a vertex"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("--drop-repeated"), std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(dir + "/s.stl"));
  const auto dropped =
      cmgeom_test::run_cli("simplify '" + sliver_path + "' -o '" + dir + "/s.stl' --faces 100 --drop-repeated", dir);
  ASSERT_EQ(dropped.exit_code, 0) << dropped.err;
  expect_small_and_closed(dir + "/s.stl");

  // a textured input loses its texture in STL: the tool says so
  const std::string textured =
      write_text(dir, "textured.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n");
  const auto tex = cmgeom_test::run_cli("convert '" + textured + "' -o '" + dir + "/textured.stl'", dir);
  ASSERT_EQ(tex.exit_code, 0) << tex.err;
  EXPECT_NE(tex.err.find("textured.stl: stl output stores the geometry only"), std::string::npos) << tex.err;
  EXPECT_EQ(conv.err.find("geometry only"), std::string::npos) << conv.err;
  // a file that is not STL: one line naming it, nothing written
  const std::string bad = write_text(dir, "bad.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 x\n");
  const std::size_t files = cmgeom_test::count_files(dir);
  const auto fail = cmgeom_test::run_cli("simplify '" + bad + "' -o '" + dir + "/out.stl' --faces 10", dir);
  EXPECT_EQ(fail.exit_code, 1);
  EXPECT_NE(fail.err.find(bad + ":4: bad vertex coordinate 'x'"), std::string::npos) << fail.err;
  EXPECT_EQ(cmgeom_test::count_files(dir), files);
}

// The malformed-input catalogue of Mesh_IO: library errors and CLI behaviour, repair of
// non-manifold input, the oriented-manifold check against CGAL.
#include "mesh_io_test_util.h"

#include <algorithm>
#include <array>
#include <set>

// ------------------------------------------------------------------ malformed input catalogue

namespace {

struct Bad_case {
  const char* name;  // file name the test writes
  std::string content;
  const char* expect;  // part of the message
  std::size_t line;    // expected line (0: none)
  IO::Read_options options = IO::Read_options();
};

std::vector<Bad_case> bad_cases() {
  std::vector<Bad_case> v;
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  v.push_back({"empty.obj", "", "empty file", 0});
  v.push_back({"garbage.obj",
               std::string("\x7f"
                           "ELF\x02\x01\x01\0\0\0binary",
                           16),
               "", 0});
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
  v.push_back(
      {"orientation.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 3 4\n", "inconsistently oriented", 0});
  v.push_back({"missing_texture.obj", "mtllib missing_texture.mtl\n" + tri + "vt 0 0\nusemtl m\nf 1/1 2/1 3/1\n",
               "not found", 2});
  v.push_back({"empty.off", "", "empty file", 0});
  v.push_back({"truncated.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n", "truncated", 0});
  v.push_back({"huge.off", "OFF\n2000000000 2000000000 0\n0 0 0\n", "more than the file can hold", 2});
  v.push_back({"range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", "out of range", 6});
  v.push_back({"nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", "not finite", 4});
  v.push_back({"notply.ply", "this is not a ply file\n", "not a PLY file", 1});
  // an ASCII PLY of three vertices, then its face or strip element
  const std::string ply3 =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  // (its face element with an index list of the given length and item types)
  const auto ply3_list = [&](const char* types) {
    return ply3 + "element face 1\nproperty list " + types + " vertex_indices\nend_header\n";
  };
  const std::string ply3_face = ply3_list("uchar int");
  const std::string verts3 = "0 0 0\n1 0 0\n0 1 0\n";  // (the three vertices in ASCII)
  const std::string ply3_strip = ply3 + "element tristrips 1\nproperty list int int vertex_indices\nend_header\n";
  v.push_back({"truncated.ply", ply3_face + "0 0 0\n1 0 0\n", "", 0});
  v.push_back({"range.ply", ply3_face + verts3 + "3 0 1 9\n", "out of range", 0});
  // Regression (fuzzing): CGAL's PLY reader crashed on a property declared before any element.
  v.push_back({"prop_first.ply", "ply\nformat ascii 1.0\nproperty float x\nelement vertex 1\nend_header\n0\n",
               "property before any element", 3});
  v.push_back({"huge.ply",
               "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
               "property float y\nproperty float z\nelement face 1\n"
               "property list uchar int vertex_indices\nend_header\n",
               "more than the file can hold", 0});
  v.push_back({"no_end.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", "no end_header", 0});
  v.push_back({"strip_negative.ply", ply3_strip + verts3 + "4 0 1 -2 2\n", "negative vertex index", 0});
  v.push_back({"strip_range.ply", ply3_strip + verts3 + "3 0 1 5\n", "out of range", 0});
  // the body's numbers: a token that is not a number of its type, with its line; an index list of
  // negative length; an ASCII face's own line in the messages checked once all is read
  v.push_back({"word.ply", ply3_face + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n", "bad PLY value 'zero'", 11});
  v.push_back({"float_index.ply", ply3_face + verts3 + "3 0 1.5 2\n", "bad PLY value '1.5'", 13});
  v.push_back({"negative_length.ply", ply3_list("int int") + verts3 + "-3 0 1 2\n", "negative list length", 13});
  v.push_back({"two_corner_face.ply", ply3_face + verts3 + "2 0 1\n", "fewer than 3 corners", 13});
  v.push_back({"range_line.ply", ply3_face + verts3 + "3 0 1 9\n", "vertex index 9 out of range", 13});
  v.push_back(
      {"float_count.ply", ply3_list("float int") + verts3 + "3 0 1 2\n", "length type must be an integer type", 8});
  v.push_back(
      {"float_list.ply", ply3_list("uchar float") + verts3 + "3 0 1 2\n", "without an integer vertex_indices list", 0});
  {
    // binary: the face list ends inside its last index
    std::string bin =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    bin.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
    const unsigned char count = 3;
    const std::int32_t idx[3] = {0, 1, 2};
    bin.append(reinterpret_cast<const char*>(&count), 1);
    bin.append(reinterpret_cast<const char*>(idx), sizeof idx - 2);
    v.push_back({"cut_binary.ply", bin, "truncated PLY: element 'face' item 0 of 1", 0});
    // an element whose huge count the header's size check does not see (only `vertex` and the
    // face elements are counted there): read until the file ends, nothing allocated for it
    std::string plural =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement vertices 4000000000\nproperty float x\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n";
    plural.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
    plural.append(reinterpret_cast<const char*>(&count), 1);
    plural.append(reinterpret_cast<const char*>(idx), sizeof idx);
    v.push_back({"huge_plural.ply", plural, "truncated PLY: element 'vertices' item 3 of 4000000000", 0});
  }
  v.push_back({"garbage.gltf", "{ this is not json", "", 0});
  v.push_back({"empty.glb", "", "empty file", 0});
  v.push_back({"mesh.3mf", "PK\x03\x04", "unsupported file type", 0});
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
      // the geometry-only reader checks the same, texture coordinates included, word for word
      try {
        Surface_mesh m;
        IO::read_mesh(path, m, c.options);
        ADD_FAILURE() << "no error from the geometry-only reader for " << c.name;
      } catch (const IO_error& g) {
        EXPECT_EQ(std::string(g.what()), msg);
      }
    }
  }
  EXPECT_THROW(
      {
        Textured_mesh tm;
        IO::read_mesh((fs::path(dir) / "absent.obj").string(), tm);
      },
      IO_error);
  EXPECT_THROW(
      {
        Textured_mesh tm;
        IO::read_mesh(dir, tm);
      },
      IO_error);  // a directory
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
  // halfedge structure. suzanne's quads became non-manifold after first-corner fan splits (two
  // quads share three corners); its fans now avoid that, and it reads as it is.
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  {
    Textured_mesh suzanne;
    ASSERT_NO_THROW(IO::read_mesh(cmgeom_test::shared_mesh("classic/suzanne.obj", dir), suzanne));
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(suzanne.mesh()));
    EXPECT_EQ(suzanne.mesh().number_of_faces(), 968u);
    std::set<std::array<std::size_t, 3>> corners;  // no two triangles on the same three vertices
    for (auto f : suzanne.mesh().faces()) {
      std::array<std::size_t, 3> c;
      std::size_t k = 0;
      for (auto v : suzanne.mesh().vertices_around_face(suzanne.mesh().halfedge(f))) c[k++] = std::size_t(v);
      std::sort(c.begin(), c.end());
      EXPECT_TRUE(corners.insert(c).second) << c[0] << " " << c[1] << " " << c[2];
    }
  }
  for (const char* name : {"classic/beetle.obj", "classic/teapot.obj", "classic/cow.obj", "classic/ogre.obj.gz",
                           "textured/DamagedHelmet/DamagedHelmet.obj"}) {
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
  const std::vector<std::pair<const Tris*, bool>> cases = {
      {&tetra, true},     {&flipped, false}, {&doubled, false},       {&bowtie, false},
      {&repeated, false}, {&open, true},     {&same_direction, false}};
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
    if (std::none_of(soup->begin(), soup->end(),
                     [](const auto& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }))
      EXPECT_EQ(ours, CGAL::Polygon_mesh_processing::is_polygon_soup_a_polygon_mesh(*soup)) << "case " << c;
  }
}

// Tests of the OBJ and PLY readers on small hand-made files: triangle strips, polygons split in
// file order, negative indices, unknown statements.
#include "mesh_io_test_util.h"

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
  const std::string head =
      "ply\nformat ascii 1.0\ncomment strips as MeshLab writes them\nelement vertex 9\n"
      "property float x\nproperty float y\nproperty float z\n";
  const std::string strips =
      write_text(dir, "strips.ply",
                 head + "element tristrips 1\nproperty list int int vertex_indices\nend_header\n" + verts +
                     "13 3 0 4 1 5 2 -1 6 3 7 4 8 5\n");
  const std::string joined =
      write_text(dir, "joined.ply",
                 head + "element tristrips 1\nproperty list int int vertex_indices\nend_header\n" + verts +
                     "14 3 0 4 1 5 2 2 6 6 3 7 4 8 5\n");
  const std::string faces =
      write_text(dir, "faces.ply",
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
  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 9\nproperty float x\nproperty float y\n"
      "property float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n";
  const float xyz[9][3] = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0},
                           {2, 1, 0}, {0, 2, 0}, {1, 2, 0}, {2, 2, 0}};
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

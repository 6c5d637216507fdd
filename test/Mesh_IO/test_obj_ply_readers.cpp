// Tests of the OBJ and PLY readers on hand-made files: triangle strips, polygons split in file
// order (from another corner where that fan would repeat an edge), negative indices, unknown statements; large
// generated OBJ files (read in chunks).
#include "mesh_io_test_util.h"

#include <CMGeom/Metrics/soup_metrics.h>

#include "../Reliability/fuzz_mutate.h"

#include <charconv>
#include <cstdlib>
#include <iterator>
#include <random>
#include <sstream>
#include <cstring>

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

// PLY as writers lay it out: extra vertex properties (normals, colours, a list), an element the
// reader does not use, a face property before the index list, faces before vertices, any integer
// type for the list's length and indices, coordinates as float or double, ASCII and both binary
// byte orders. Every file reads as the same two triangles on the same four points.
namespace {

template <class T>
void put(std::string& out, T value, bool big_endian) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (big_endian) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}

}  // namespace

TEST(Mesh_IO_ply, EveryLayoutAndByteOrderReadsTheSameMesh) {
  const std::string dir = scratch_dir();
  const double xyz[4][3] = {{0, 0, 0}, {1.5, 0, 0}, {1.5, 2.25, 0}, {0, 2.25, -0.125}};
  const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
  // ASCII: vertices after the faces, with normals, a colour and a list of their own; an edge
  // element between them; the faces with a flags property first and uint8 / uint32 lists
  std::string ascii =
      "ply\nformat ascii 1.0\ncomment layout test\nobj_info none\nelement face 2\nproperty uchar flags\n"
      "property list uint8 uint32 vertex_indices\nelement edge 1\nproperty int vertex1\nproperty int vertex2\n"
      "element vertex 4\nproperty float nx\nproperty double x\nproperty float y\nproperty list uchar float "
      "texcoord\nproperty float z\nproperty uchar red\nend_header\n";
  for (const auto& t : tri)
    ascii += "7 3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  ascii += "0 1\n";
  for (const auto& p : xyz) {
    std::ostringstream line;
    line << "0 " << p[0] << " " << p[1] << " 2 0.25 0.75 " << p[2] << " 255\r\n";
    ascii += line.str();
  }
  const std::string ascii_path = write_text(dir, "layout_ascii.ply", ascii);
  // binary: the vertices first with double x, y, z between a float and a list; ushort lengths and
  // int16 indices; a trailing element of lists the reader skips
  std::vector<std::string> paths{ascii_path};
  for (const bool big : {false, true}) {
    std::string bin = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
                      " 1.0\nelement vertex 4\nproperty float nx\nproperty float64 x\nproperty float64 y\n"
                      "property list uchar int texcoord\nproperty float64 z\nelement face 2\n"
                      "property list ushort int16 vertex_indices\nelement extra 1\nproperty list int double values\n"
                      "end_header\n";
    for (const auto& p : xyz) {
      put(bin, 0.5f, big);
      put(bin, p[0], big);
      put(bin, p[1], big);
      put(bin, std::uint8_t(2), big);
      put(bin, std::int32_t(7), big);
      put(bin, std::int32_t(-8), big);
      put(bin, p[2], big);
    }
    for (const auto& t : tri) {
      put(bin, std::uint16_t(3), big);
      for (int k : t) put(bin, std::int16_t(k), big);
    }
    put(bin, std::int32_t(2), big);
    put(bin, 1.0, big);
    put(bin, 2.0, big);
    paths.push_back(write_text(dir, big ? "layout_big.ply" : "layout_little.ply", bin));
  }
  for (const std::string& path : paths) {
    SCOPED_TRACE(path);
    Textured_mesh tm;
    IO::read_mesh(path, tm);
    const Surface_mesh& m = tm.mesh();
    ASSERT_EQ(m.number_of_vertices(), 4u);
    ASSERT_EQ(m.number_of_faces(), 2u);
    for (auto v : m.vertices())
      for (int k = 0; k < 3; ++k) EXPECT_EQ(m.point(v)[k], xyz[std::size_t(v)][k]);
    EXPECT_EQ(oriented_triangles(tm), (std::vector<std::array<std::size_t, 3>>{{0, 1, 2}, {0, 2, 3}}));
  }
}

// OFF as writers lay it out: the counts on the header line or the next, no header at all,
// comments, blank lines and CRLF line ends, COFF's colours after the coordinates and after a
// face's indices. Every file reads as the same quad split in two; STOFF's texture coordinates
// become the corners' own, and each face keeps its line.
TEST(Mesh_IO_off, HeaderFormsCommentsAndColoursReadTheSameMesh) {
  const std::string dir = scratch_dir();
  const std::string verts = "0 0 0\n1.5 0 0\n1.5 2.25 0\n0 2.25 -0.125\n";
  const std::vector<std::string> texts = {
      "OFF\n4 2 0\n" + verts + "3 0 1 2\n3 0 2 3\n", "OFF 4 2 0\n" + verts + "3 0 1 2\n3 0 2 3\n",
      "4 2 0\n" + verts + "3 0 1 2\n3 0 2 3\n",
      "# a comment\n\nOFF # header\r\n\n4 2 0\r\n# vertices\r\n0 0 0\r\n1.5 0 0 # second\r\n1.5 2.25 0\r\n"
      "0 2.25 -0.125\r\n\r\n3 0 1 2\r\n3 0 2 3 # last\r\n",
      "COFF\n4 2 0\n0 0 0 255 0 0 255\n1.5 0 0 0 255 0 255\n1.5 2.25 0 0 0 255 255\n0 2.25 -0.125 9 9 9 255\n"
      "3 0 1 2 0.5 0.5 0.5\n3 0 2 3 1 1 1\n"};
  for (std::size_t i = 0; i < texts.size(); ++i) {
    SCOPED_TRACE(texts[i]);
    const Polygon_soup soup = IO::read_polygon_soup(write_text(dir, "quad" + std::to_string(i) + ".off", texts[i]));
    ASSERT_EQ(soup.positions.size(), 4u);
    EXPECT_EQ(soup.positions[2], (std::array<double, 3>{{1.5, 2.25, 0}}));
    EXPECT_EQ(soup.positions[3], (std::array<double, 3>{{0, 2.25, -0.125}}));
    EXPECT_EQ(soup.corner_vertex, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
    EXPECT_EQ(soup.face_start, (std::vector<std::uint32_t>{0, 3, 6}));
    EXPECT_EQ(soup.corner_uv, std::vector<std::uint32_t>(6, Polygon_soup::no_index));
  }
  // the lines of the faces: the fourth file's are 12 and 13
  const Polygon_soup commented = IO::read_polygon_soup((fs::path(dir) / "quad3.off").string());
  EXPECT_EQ(commented.face_line, (std::vector<std::size_t>{12, 13}));
  const Polygon_soup st = IO::read_polygon_soup(write_text(
      dir, "quad.off", "STOFF\n4 2 0\n0 0 0 0 0\n1.5 0 0 1 0\n1.5 2.25 0 1 1\n0 2.25 -0.125 0 1\n3 0 1 2\n3 0 2 3\n"));
  EXPECT_EQ(st.uvs.size(), 4u);
  EXPECT_EQ(st.uvs[2], (std::array<double, 2>{{1, 1}}));
  EXPECT_EQ(st.corner_uv, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
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

// Two quads that share three corners (as Blender's Suzanne has, shared suzanne.obj line 1170): both
// first-corner fans take the diagonal 1-3, which would give that edge four triangles, two of them on
// the same three vertices. The second quad's fan starts at its next corner instead (diagonal 4-5):
// the mesh reads without repair, manifold, with each corner's texture coordinate kept.
TEST(Mesh_IO_obj, AFanWhoseDiagonalIsAlreadyAnEdgeStartsAtAnotherCorner) {
  const std::string dir = scratch_dir();
  const std::string path = write_text(dir, "shared_corners.obj",
                                      "v 0 0 0\nv 1 -1 0\nv 2 0 0\nv 1 0.5 0.3\nv 1 2 0\n"
                                      "vt 0 0\nvt 0.5 0\nvt 1 0\nvt 0.5 0.25\nvt 0.5 1\n"
                                      "f 1/1 2/2 3/3 4/4\nf 1/1 4/4 3/3 5/5\n");
  Textured_mesh tm;
  ASSERT_NO_THROW(IO::read_mesh(path, tm));  // (no repair asked)
  const Surface_mesh& m = tm.mesh();
  ASSERT_EQ(m.number_of_faces(), 4u);
  EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
  EXPECT_EQ((oriented_triangles(tm)),
            (std::vector<std::array<std::size_t, 3>>{{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {2, 4, 3}}));
  for (auto h : m.halfedges())
    if (!m.is_border(h)) {  // vertex i (0-based) has texture coordinate i in the file
      const auto uv = tm.uv(h);
      const double expected[5][2] = {{0, 0}, {0.5, 0}, {1, 0}, {0.5, 0.25}, {0.5, 1}};
      EXPECT_EQ(uv.x(), expected[std::size_t(m.target(h))][0]);
      EXPECT_EQ(uv.y(), expected[std::size_t(m.target(h))][1]);
    }
  // the fans of files that read before are unchanged (the test above); the soup metrics and the
  // renderer split the polygons the same way (polygon_fan_starts): the file measured as a soup
  // lies on the mesh read from it (vertex 4 is off the plane, so another split would not)
  const std::string off = (fs::path(dir) / "read.off").string();
  IO::write_mesh(off, tm);
  const auto e = CMGeom::Metrics::approximation_error(IO::read_polygon_soup(path), IO::read_polygon_soup(off));
  EXPECT_LT(e.hausdorff, 1e-12);
  EXPECT_EQ(CMGeom::polygon_fan_starts(IO::read_polygon_soup(path)), (std::vector<std::uint32_t>{0, 1}));
  Polygon_soup first_corner = IO::read_polygon_soup(path);  // the same quads, the second's fan moved by hand
  std::rotate(first_corner.corner_vertex.begin() + 4, first_corner.corner_vertex.begin() + 5,
              first_corner.corner_vertex.end());
  EXPECT_EQ(CMGeom::polygon_fan_starts(first_corner), (std::vector<std::uint32_t>{0, 0}));
  EXPECT_LT(CMGeom::Metrics::approximation_error(first_corner, IO::read_polygon_soup(off)).hausdorff, 1e-12);
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

// Whether the faces carry texture coordinates is decided by the faces, not by `vt` lines: the
// soup says so as the reader decides (a textured mesh when a face has one at every corner).
TEST(Mesh_IO_obj, FacesCarryTextureCoordinatesWhenOneHasThemAtEveryCorner) {
  const std::string dir = scratch_dir();
  const std::string head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n";
  const Polygon_soup unused = IO::read_polygon_soup(write_text(dir, "vt_unused.obj", head + "f 1 2 3\nf 2 4 3\n"));
  EXPECT_TRUE(unused.has_uvs());
  EXPECT_FALSE(unused.face_has_uvs(0));
  EXPECT_FALSE(unused.faces_have_uvs());
  Textured_mesh plain;
  IO::build_textured_mesh(unused, plain);
  EXPECT_FALSE(plain.has_uvs());

  const Polygon_soup used = IO::read_polygon_soup(write_text(dir, "vt_used.obj", head + "f 1 2 3\nf 2/2 4/1 3/3\n"));
  EXPECT_FALSE(used.face_has_uvs(0));
  EXPECT_TRUE(used.face_has_uvs(1));
  EXPECT_TRUE(used.faces_have_uvs());
  // then every face must have them: the reader refuses the first one without
  try {
    Textured_mesh refused;
    IO::build_textured_mesh(used, refused);
    ADD_FAILURE() << "expected an IO_error";
  } catch (const IO_error& e) {
    EXPECT_NE(std::string(e.what()).find("vt_used.obj:8: face has no texture coordinates"), std::string::npos)
        << e.what();
  }

  // (the OBJ reader refuses such a face itself; other formats' soups are built the same way)
  Polygon_soup partial;
  partial.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  partial.uvs = {{0, 0}, {0, 1}};
  partial.face_start = {0, 3};
  partial.corner_vertex = {0, 1, 2};
  partial.corner_uv = {0, Polygon_soup::no_index, 1};
  EXPECT_FALSE(partial.face_has_uvs(0));
  EXPECT_FALSE(partial.faces_have_uvs());
  partial.corner_uv[1] = 1;
  EXPECT_TRUE(partial.faces_have_uvs());
}

// ------------------------------------------------------------------ gzipped files

namespace {

// `gzip -c` of a file (the system's gzip: an independent compressor), to `path` + ".gz".
std::string gzipped(const std::string& path) {
  const std::string out = path + ".gz";
  EXPECT_EQ(std::system(("gzip -c '" + path + "' > '" + out + "'").c_str()), 0);
  return out;
}

void expect_same_soup(const Polygon_soup& a, const Polygon_soup& b) {
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.uvs, b.uvs);
  EXPECT_EQ(a.face_start, b.face_start);
  EXPECT_EQ(a.corner_vertex, b.corner_vertex);
  EXPECT_EQ(a.corner_uv, b.corner_uv);
  EXPECT_EQ(a.face_material, b.face_material);
  EXPECT_EQ(a.face_line, b.face_line);
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (std::size_t i = 0; i < a.materials.size(); ++i) {
    EXPECT_EQ(a.materials[i].name, b.materials[i].name);
    EXPECT_EQ(a.materials[i].diffuse_texture, b.materials[i].diffuse_texture);
  }
}

}  // namespace

// OBJ (with a material library and a texture beside it), OFF and PLY (ASCII and binary) read the
// same gzipped as plain: same soup, materials resolved beside the .gz file; errors name the .gz
// file (and their line for text formats); concatenated gzip members are one file; data that is not
// gzip, a truncated file and a compressed glTF are refused with a clear error.
TEST(Mesh_IO_gzip, GzippedFilesReadAsTheirContent) {
  const std::string dir = scratch_dir();
  write_text(dir, "m.mtl", "newmtl paint\nmap_Kd paint.png\n");
  write_text(dir, "paint.png", "not read here");
  const std::string cube_v = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";
  const std::string obj = write_text(dir, "cube.obj",
                                     "mtllib m.mtl\n" + cube_v +
                                         "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl paint\n"
                                         "f 1/1 4/4 3/3 2/2\nf 5/1 6/2 7/3 8/4\nf 1/1 2/2 6/3 5/4\n"
                                         "f 2/1 3/2 7/3 6/4\nf 3/1 4/2 8/3 7/4\nf 4/1 1/2 5/3 8/4\n");
  const std::string off =
      write_text(dir, "tet.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  const std::string ply = write_text(dir, "tet.ply",
                                     "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                     "property float z\nelement face 4\nproperty list uchar int vertex_indices\n"
                                     "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  Textured_mesh tet;
  IO::read_mesh(off, tet);
  const std::string bin = (fs::path(dir) / "tet_bin.ply").string();
  IO::write_mesh(bin, tet);  // binary little-endian PLY
  for (const std::string& path : {obj, off, ply, bin}) {
    SCOPED_TRACE(path);
    const std::string gz = gzipped(path);
    const Polygon_soup plain = IO::read_polygon_soup(path), packed = IO::read_polygon_soup(gz);
    expect_same_soup(plain, packed);
    EXPECT_EQ(packed.source, gz);
    Textured_mesh a, b;
    IO::read_mesh(path, a);
    IO::read_mesh(gz, b);
    EXPECT_EQ(a.mesh().number_of_faces(), b.mesh().number_of_faces());
  }
  EXPECT_EQ(IO::read_polygon_soup(obj + ".gz").materials.at(0).diffuse_texture,
            fs::absolute(fs::path(dir) / "paint.png").string());
  // an error inside names the .gz file and the line
  const std::string bad = write_text(dir, "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
  try {
    IO::read_polygon_soup(gzipped(bad));
    ADD_FAILURE() << "no error";
  } catch (const IO_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.obj.gz:4"), std::string::npos) << e.what();
  }
  // two gzip members, one after the other, are the file they make together
  const std::string head = write_text(dir, "head.txt", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n");
  const std::string tail = write_text(dir, "tail.txt", "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  const std::string joined = (fs::path(dir) / "joined.off.gz").string();
  ASSERT_EQ(std::system(("cat '" + gzipped(head) + "' '" + gzipped(tail) + "' > '" + joined + "'").c_str()), 0);
  expect_same_soup(IO::read_polygon_soup(joined), IO::read_polygon_soup(off));
  // refused: not gzip data, a truncated file, an empty one, a compressed glTF
  auto refused = [&](const std::string& path, const std::string& what) {
    try {
      IO::read_polygon_soup(path);
      ADD_FAILURE() << path << ": no error";
    } catch (const IO_error& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused(write_text(dir, "plain.off.gz", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), "not gzip data");
  {
    std::ifstream in(obj + ".gz", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    write_text(dir, "cut.obj.gz", bytes.substr(0, bytes.size() / 2));
  }
  refused((fs::path(dir) / "cut.obj.gz").string(), "corrupt or truncated gzip data");
  refused(write_text(dir, "empty.ply.gz", ""), "not gzip data");
  refused(write_text(dir, "x.glb.gz", "?"), "unsupported compressed file type '.glb.gz'");
  refused((fs::path(dir) / "missing.obj.gz").string(), "file not found");
}

// ------------------------------------------------------------ large files (read in chunks)

namespace {

// A large OBJ written with known content: an n x n grid of vertices with texture coordinates,
// its cells as quads or as two triangles (some with relative indices), materials switched by
// usemtl (one library found, one not), comments and grouping statements between them.
struct Written_obj {
  std::string text;
  std::vector<std::array<double, 3>> positions;
  std::vector<std::array<double, 2>> uvs;
  std::vector<std::vector<std::uint32_t>> faces;  // 0-based corners (vertex = uv index)
  std::vector<std::string> face_material_name;    // "" before the first usemtl
  std::vector<std::size_t> face_line;
  std::size_t missing_library_line = 0;
};

Written_obj write_large_obj(std::size_t n) {
  Written_obj w;
  std::size_t line = 0;
  auto emit = [&](const std::string& s) {
    w.text += s;
    w.text += '\n';
    ++line;
  };
  auto num = [](double x) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, r.ptr);
  };
  emit("# generated grid");
  emit("mtllib grid.mtl");
  emit("mtllib absent.mtl");
  w.missing_library_line = line;
  std::uint64_t state = 12345;
  auto next = [&] {  // a fixed linear congruential sequence: coordinates that need all digits
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) / double(1ull << 53);
  };
  for (std::size_t i = 0; i < n * n; ++i) {
    const std::array<double, 3> p{double(i % n) + 0.25 * next(), double(i / n) + 0.25 * next(), next() - 0.5};
    w.positions.push_back(p);
    emit((i % 7 == 0 ? "v  " : "v ") + num(p[0]) + " " + num(p[1]) + "\t" + num(p[2]) + (i % 11 == 0 ? " 1.0" : ""));
    const std::array<double, 2> t{next(), next()};
    w.uvs.push_back(t);
    emit("vt " + num(t[0]) + " " + num(t[1]));
  }
  const char* names[] = {"green", "red", "blue"};
  std::string current;
  std::size_t cell = 0;
  for (std::size_t y = 0; y + 1 < n; ++y) {
    if (y % 5 == 0) emit("g row" + std::to_string(y));
    for (std::size_t x = 0; x + 1 < n; ++x, ++cell) {
      if (cell % 997 == 500) {
        current = names[(cell / 997) % 3];
        emit("usemtl " + current);
      }
      if (cell % 503 == 0) emit("# cell " + std::to_string(cell));
      const std::uint32_t a = std::uint32_t(y * n + x), b = a + 1, c = a + std::uint32_t(n) + 1,
                          d = a + std::uint32_t(n);
      auto corner = [&](std::uint32_t v, bool relative) {
        const long long i = relative ? (long long)v - (long long)w.positions.size() : (long long)v + 1;
        return std::to_string(i) + "/" + std::to_string(i);
      };
      const bool relative = cell % 3 == 1;
      if (cell % 4 == 0) {
        emit("f " + corner(a, relative) + " " + corner(b, relative) + " " + corner(c, relative) + " " +
             corner(d, relative));
        w.faces.push_back({a, b, c, d});
        w.face_material_name.push_back(current);
        w.face_line.push_back(line);
      } else {
        for (const auto& t : {std::array<std::uint32_t, 3>{a, b, c}, std::array<std::uint32_t, 3>{a, c, d}}) {
          emit("f " + corner(t[0], relative) + " " + corner(t[1], relative) + " " + corner(t[2], relative));
          w.faces.push_back({t[0], t[1], t[2]});
          w.face_material_name.push_back(current);
          w.face_line.push_back(line);
        }
      }
    }
  }
  return w;
}

}  // namespace

// Files of a megabyte or more are parsed on all cores in chunks; the soup must be the file's,
// element for element: positions and texture coordinates bit-exact, polygons whole, relative
// indices resolved, each face's material and line, the missing library's warning.
TEST(Mesh_IO_obj, LargeFilesGiveTheSoupAsWritten) {
  const std::string dir = scratch_dir();
  const Written_obj w = write_large_obj(260);
  ASSERT_GT(w.text.size(), std::size_t(4) << 20);  // several chunks
  write_text(dir, "grid.mtl", "newmtl red\nKd 1 0 0\nnewmtl green\nKd 0 1 0\n");
  const std::string path = write_text(dir, "grid.obj", w.text);
  const Polygon_soup soup = IO::read_polygon_soup(path);
  ASSERT_EQ(soup.positions.size(), w.positions.size());
  for (std::size_t i = 0; i < w.positions.size(); ++i) ASSERT_EQ(soup.positions[i], w.positions[i]) << i;
  ASSERT_EQ(soup.uvs.size(), w.uvs.size());
  for (std::size_t i = 0; i < w.uvs.size(); ++i) ASSERT_EQ(soup.uvs[i], w.uvs[i]) << i;
  ASSERT_EQ(soup.number_of_faces(), w.faces.size());
  // materials: the library's two in its order, then blue at its first use, then "default" for
  // the faces before the first usemtl
  ASSERT_EQ(soup.materials.size(), 4u);
  EXPECT_EQ(soup.materials[0].name, "red");
  EXPECT_EQ(soup.materials[1].name, "green");
  EXPECT_EQ(soup.materials[2].name, "blue");
  EXPECT_EQ(soup.materials[3].name, "default");
  EXPECT_EQ(soup.materials[0].diffuse_color[0], 1.);
  for (std::size_t f = 0; f < w.faces.size(); ++f) {
    ASSERT_EQ(soup.face_size(f), w.faces[f].size()) << f;
    for (std::size_t k = 0; k < w.faces[f].size(); ++k) {
      ASSERT_EQ(soup.corner_vertex[soup.face_start[f] + k], w.faces[f][k]) << f;
      ASSERT_EQ(soup.corner_uv[soup.face_start[f] + k], w.faces[f][k]) << f;
    }
    const std::string& name = w.face_material_name[f];
    ASSERT_EQ(soup.materials[std::size_t(soup.face_material[f])].name, name.empty() ? "default" : name) << f;
    ASSERT_EQ(soup.face_line[f], w.face_line[f]) << f;
  }
  ASSERT_EQ(soup.warnings.size(), 1u);
  EXPECT_NE(soup.warnings[0].find("grid.obj:" + std::to_string(w.missing_library_line) +
                                  ": material library 'absent.mtl' not found"),
            std::string::npos)
      << soup.warnings[0];
  // the mesh built from it: quads split into two triangles each, texture coordinates on corners
  Textured_mesh tm;
  IO::read_mesh(path, tm);
  EXPECT_EQ(tm.mesh().number_of_faces(), 2 * 259u * 259u);
  EXPECT_TRUE(tm.has_uvs());
}

// An error or an unknown statement late in a large file is reported at its own line, as in a
// small file; a file cut in the middle of a line still reads.
TEST(Mesh_IO_obj, LargeFilesReportErrorsAndWarningsAtTheirLine) {
  const std::string dir = scratch_dir();
  const Written_obj w = write_large_obj(200);
  const std::size_t cut = w.text.rfind("\nf ", w.text.size() - 1000);  // a late face line
  ASSERT_NE(cut, std::string::npos);
  const std::size_t line = std::size_t(std::count(w.text.begin(), w.text.begin() + std::ptrdiff_t(cut), '\n')) + 2;
  {
    const std::string bad = w.text.substr(0, cut + 1) + "f 1 2 99999999\n" + w.text.substr(cut + 1);
    const std::string path = write_text(dir, "bad.obj", bad);
    try {
      IO::read_polygon_soup(path);
      FAIL() << "no error";
    } catch (const IO_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("bad.obj:" + std::to_string(line) + ":"), std::string::npos) << what;
      EXPECT_NE(what.find("vertex index 99999999 out of range"), std::string::npos) << what;
    }
  }
  {
    const std::string odd = w.text.substr(0, cut + 1) + "weird 1 2\n" + w.text.substr(cut + 1);
    const Polygon_soup soup = IO::read_polygon_soup(write_text(dir, "odd.obj", odd));
    EXPECT_EQ(soup.number_of_faces(), w.faces.size());
    ASSERT_EQ(soup.warnings.size(), 3u);  // both libraries are missing here, then the statement
    EXPECT_NE(soup.warnings[2].find("odd.obj:" + std::to_string(line) + ": unknown OBJ statement 'weird'"),
              std::string::npos)
        << soup.warnings[2];
  }
  {
    // no newline at the end: the last face still counts
    std::string open_end = w.text;
    open_end.pop_back();
    const Polygon_soup soup = IO::read_polygon_soup(write_text(dir, "open.obj", open_end));
    EXPECT_EQ(soup.number_of_faces(), w.faces.size());
  }
}

// The chunked reader against the line-by-line one, on mutated OBJ files cut into chunks of a few
// dozen bytes (every statement meets a chunk boundary somewhere): the same soup, element for
// element, with the same materials and warnings, or the same error.
TEST(Mesh_IO_obj, ChunksReadMutatedFilesAsLinesDo) {
  const std::string dir = scratch_dir();
  write_text(dir, "grid.mtl", "newmtl red\nKd 1 0 0\nnewmtl green\nKd 0 1 0\n");
  write_text(dir, "seed.mtl", "newmtl a\nKd 0.5 0.5 0.5\n");
  std::vector<cmgeom_fuzz::Bytes> seeds;
  auto add_seed = [&](const std::string& text) {
    cmgeom_fuzz::Bytes b{0};  // the mutator's format byte, dropped below
    b.insert(b.end(), text.begin(), text.end());
    seeds.push_back(b);
  };
  add_seed(write_large_obj(12).text);
  add_seed(
      "mtllib seed.mtl\n# seed\nv 0 0 0\nv 1 0 0\r\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nvt 0 0\nvt 1 0\nvt 1 1\n"
      "vt 0 1\nvt 0.5 0.5\nvn 0 0 1\nusemtl a\nf 1/1/1 4/4/1 3/3/1 2/2/1\nf 1/1 2/2 5/5\n\tf 2/2 3/3 5/5\n"
      "o part\nusemtl b\nf 3/3 4/4 5/5\nf -1/-1 -5/-5 -2/-2");
  std::mt19937_64 rng(7);
  auto read = [](const std::string& path, std::size_t chunk_bytes, Polygon_soup& soup) {
    try {
      IO::internal::read_obj(path, soup, chunk_bytes);
      return std::string();
    } catch (const IO_error& e) {
      return std::string(e.what());
    }
  };
  std::size_t read_ok = 0;
  for (int iteration = 0; iteration < 2000; ++iteration) {
    const cmgeom_fuzz::Bytes& seed = seeds[std::size_t(iteration) % seeds.size()];
    const cmgeom_fuzz::Bytes b = iteration < 2 ? seed : cmgeom_fuzz::mutate(seed, rng, seeds);
    if (b.size() < 2) continue;
    const std::string path = write_text(dir, "m.obj", std::string(b.begin() + 1, b.end()));
    Polygon_soup lines, chunks;
    const std::string e_lines = read(path, 0, lines);
    const std::size_t chunk_bytes = 1 + std::size_t(rng() % 64);
    const std::string e_chunks = read(path, chunk_bytes, chunks);
    SCOPED_TRACE("iteration " + std::to_string(iteration) + ", chunks of " + std::to_string(chunk_bytes));
    ASSERT_EQ(e_chunks, e_lines);
    if (!e_lines.empty()) continue;
    ++read_ok;
    ASSERT_EQ(chunks.positions, lines.positions);
    ASSERT_EQ(chunks.uvs, lines.uvs);
    ASSERT_EQ(chunks.face_start, lines.face_start);
    ASSERT_EQ(chunks.corner_vertex, lines.corner_vertex);
    ASSERT_EQ(chunks.corner_uv, lines.corner_uv);
    ASSERT_EQ(chunks.face_material, lines.face_material);
    ASSERT_EQ(chunks.face_line, lines.face_line);
    ASSERT_EQ(chunks.warnings, lines.warnings);
    ASSERT_EQ(chunks.materials.size(), lines.materials.size());
    for (std::size_t m = 0; m < lines.materials.size(); ++m) {
      EXPECT_EQ(chunks.materials[m].name, lines.materials[m].name);
      EXPECT_EQ(chunks.materials[m].diffuse_color, lines.materials[m].diffuse_color);
      EXPECT_EQ(chunks.materials[m].diffuse_texture, lines.materials[m].diffuse_texture);
    }
  }
  EXPECT_GT(read_ok, 250u);  // enough of the mutants still read for the comparison to mean something
}

// Tests of the glTF reader on Draco-compressed primitives (KHR_draco_mesh_compression): a textured
// grid written by CMGeom's glTF writer and compressed by Draco's own draco_transcoder (Debian's
// `draco` package; the tests skip when it is missing) reads back as the same surface, as GLB and as
// .gltf + .bin; a broken compressed buffer and a file that requires meshopt compression are refused
// with their reason.
#include "mesh_io_test_util.h"

#include <cstdlib>
#include <sstream>

namespace {

bool have_transcoder() { return std::system("command -v draco_transcoder > /dev/null 2>&1") == 0; }

#define CMGEOM_REQUIRE_DRACO_TRANSCODER()                                                                   \
  do {                                                                                                      \
    if (!have_transcoder())                                                                                 \
      GTEST_SKIP() << "draco_transcoder not found (Debian package 'draco', installed by "                   \
                      "scripts/install-deps.sh): the Draco-compressed files of this test are made with it"; \
  } while (0)

// A textured n x n grid over a bumpy height field (UVs follow x and y), as OBJ text.
std::string grid_obj(int n) {
  std::ostringstream s;
  s.precision(17);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = double(i) / n, y = double(j) / n;
      s << "v " << x << " " << y << " " << 0.1 * std::sin(7 * x) * std::cos(5 * y) << "\n";
      s << "vt " << 0.05 + 0.9 * x << " " << 0.05 + 0.9 * y << "\n";
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i + 1, b = a + 1, c = a + n + 1, d = c + 1;
      s << "f " << a << "/" << a << " " << b << "/" << b << " " << d << "/" << d << "\n";
      s << "f " << a << "/" << a << " " << d << "/" << d << " " << c << "/" << c << "\n";
    }
  return s.str();
}

int run(const std::string& command) { return std::system((command + " > /dev/null 2>&1").c_str()); }

// The corners of every face (positions and UVs, in the face's order, starting at its smallest
// position), to compare two readings of one surface whose faces and vertices come in other orders.
struct Face_corners {
  std::array<std::array<double, 5>, 3> c;
};
std::vector<Face_corners> face_corners(const Textured_mesh& tm) {
  const Surface_mesh& m = tm.mesh();
  std::vector<Face_corners> out;
  for (auto f : m.faces()) {
    Face_corners fc;
    int k = 0;
    for (auto h : CGAL::halfedges_around_face(m.halfedge(f), m)) {
      const Point_3& p = m.point(m.target(h));
      const Point_2 t = tm.uv(h);
      fc.c[std::size_t(k++)] = {{p.x(), p.y(), p.z(), t.x(), t.y()}};
    }
    std::rotate(fc.c.begin(), std::min_element(fc.c.begin(), fc.c.end()), fc.c.end());
    out.push_back(fc);
  }
  return out;
}

// Every face of `b` has a face of `a` with the same corners in the same order (orientation kept),
// positions within `dp` and UVs within `dt`; and as many faces.
void expect_same_faces(const Textured_mesh& a, const Textured_mesh& b, double dp, double dt) {
  const auto fa = face_corners(a), fb = face_corners(b);
  ASSERT_EQ(fa.size(), fb.size());
  std::size_t unmatched = 0;
  for (const auto& g : fb) {
    bool found = false;
    for (const auto& f : fa) {
      bool same = true;
      for (std::size_t k = 0; k < 3 && same; ++k)
        for (std::size_t d = 0; d < 5 && same; ++d) same = std::abs(f.c[k][d] - g.c[k][d]) <= (d < 3 ? dp : dt);
      if (same) {
        found = true;
        break;
      }
    }
    unmatched += found ? 0 : 1;
  }
  EXPECT_EQ(unmatched, 0u);
}

}  // namespace

TEST(Mesh_IO_draco, CompressedPrimitivesReadAsTheSurface) {
  CMGEOM_REQUIRE_DRACO_TRANSCODER();
  const std::string dir = scratch_dir();
  Textured_mesh grid;
  IO::read_mesh(write_text(dir, "grid.obj", grid_obj(20)), grid);
  IO::write_mesh(dir + "/grid.glb", grid);
  Textured_mesh plain;
  IO::read_mesh(dir + "/grid.glb", plain);  // (the reference: float positions, glTF's v flip)
  // 16-bit positions (the grid spans 1 unit: steps of 1.5e-5) and 14-bit texture coordinates
  for (const char* out : {"draco.glb", "draco.gltf"}) {
    SCOPED_TRACE(out);
    ASSERT_EQ(run("draco_transcoder -i '" + dir + "/grid.glb' -o '" + dir + "/" + out + "' -qp 16 -qt 14"), 0);
    std::ifstream in(dir + "/" + out, std::ios::binary);
    std::stringstream bytes;
    bytes << in.rdbuf();
    ASSERT_NE(bytes.str().find("KHR_draco_mesh_compression"), std::string::npos);  // (compressed indeed)
    Textured_mesh back;
    IO::read_mesh(dir + "/" + out, back);
    ASSERT_TRUE(back.has_uvs());
    EXPECT_EQ(back.mesh().number_of_vertices(), plain.mesh().number_of_vertices());
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(back.mesh()));
    expect_same_faces(plain, back, 2e-5, 1e-4);
  }
  // the tool simplifies it
  const auto r = cmgeom_test::run_cli("simplify '" + dir + "/draco.glb' -o '" + dir + "/small.obj' --faces 200", dir);
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST(Mesh_IO_draco, BrokenOrUnreadableCompressionIsRefusedWithItsReason) {
  CMGEOM_REQUIRE_DRACO_TRANSCODER();
  const std::string dir = scratch_dir();
  Textured_mesh grid;
  IO::read_mesh(write_text(dir, "grid.obj", grid_obj(6)), grid);
  IO::write_mesh(dir + "/grid.glb", grid);
  ASSERT_EQ(run("draco_transcoder -i '" + dir + "/grid.glb' -o '" + dir + "/draco.glb'"), 0);
  std::string bytes;
  {
    std::ifstream in(dir + "/draco.glb", std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    bytes = s.str();
  }
  const std::size_t magic = bytes.find("DRACO");
  ASSERT_NE(magic, std::string::npos);
  bytes[magic] = 'X';  // the compressed buffer no longer says what it is
  const std::string broken = write_text(dir, "broken.glb", bytes);
  try {
    IO::read_polygon_soup(broken);
    ADD_FAILURE() << "a broken Draco buffer was read";
  } catch (const IO_error& e) {
    EXPECT_EQ(e.file(), broken);
    EXPECT_NE(std::string(e.what()).find("KHR_draco_mesh_compression: "), std::string::npos) << e.what();
  }
}

TEST(Mesh_IO_draco, FilesRequiringMeshoptCompressionAreRefusedByName) {
  const std::string dir = scratch_dir();
  // a valid one-triangle glTF (data URI buffer) that says it needs EXT_meshopt_compression
  const std::string gltf = R"({"asset":{"version":"2.0"},"extensionsUsed":["EXT_meshopt_compression"],)"
                           R"("extensionsRequired":["EXT_meshopt_compression"],"scene":0,"scenes":[{"nodes":[0]}],)"
                           R"("nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
                           R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",)"
                           R"("min":[0,0,0],"max":[1,1,0]}],"bufferViews":[{"buffer":0,"byteLength":36}],)"
                           R"("buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,)"
                           R"(AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]})";
  const std::string path = write_text(dir, "meshopt.gltf", gltf);
  try {
    IO::read_polygon_soup(path);
    ADD_FAILURE() << "a file requiring EXT_meshopt_compression was read";
  } catch (const IO_error& e) {
    EXPECT_NE(std::string(e.what()).find("requires the glTF extension EXT_meshopt_compression"), std::string::npos)
        << e.what();
  }
  // the same file without the requirement reads: the refusal is the extension's, not the file's
  std::string plain = gltf;
  plain.replace(plain.find(R"("extensionsUsed")"),
                std::string(R"("extensionsUsed":["EXT_meshopt_compression"],)"
                            R"("extensionsRequired":["EXT_meshopt_compression"],)")
                    .size(),
                "");
  EXPECT_EQ(IO::read_polygon_soup(write_text(dir, "plain.gltf", plain)).number_of_faces(), 1u);
}

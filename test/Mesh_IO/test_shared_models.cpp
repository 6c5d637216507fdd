// Tests of the Mesh_IO readers on the shared models: reference values (SOURCES.md), round trips,
// an independent cross-check of the OBJ parser with tinyobjloader.
#include "mesh_io_test_util.h"

#define TINYOBJLOADER_IMPLEMENTATION
#define TINYOBJLOADER_USE_DOUBLE
#include <tiny_obj_loader.h>
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
    {"classic/bunny.off", true, true, 0, 1},
    {"classic/fandisk.obj", true, true, 0, 1},
    {"classic/rocker-arm.obj", true, true, 1, 1},
    {"classic/igea.ply.gz", true, true, 0, 1},
    {"classic/nefertiti.obj.gz", true, true, 0, 1},
    {"classic/ogre.obj.gz", false, false, -1, 44},
    {"classic/homer.obj", true, true, 0, 1},
    {"classic/cheburashka.obj", true, true, 0, 1},
    {"classic/cow.obj", true, false, -1, 1},
    {"classic/horse.ply", true, true, 0, 1},
    {"classic/camel.off", true, true, 0, 1},
    {"classic/decimated-max.obj", true, true, 0, 1},
    {"classic/armadillo.obj.gz", true, true, 0, 1},
    {"classic/knot_orig.ply", true, true, 1, 1},
    {"classic/trim-star.off", true, true, 1, 1},
    {"classic/sharp_sphere.off", true, true, 0, 1},
    {"classic/block.off", true, true, 3, 1},
    {"classic/anchor.off", true, true, 4, 1},
    {"classic/pinion.off", true, true, 1, 1},
    {"classic/joint.off", true, true, 2, 1},
    {"classic/mech-holes-shark.off", false, true, -1, 1},
    {"classic/teapot.obj", false, false, -1, 4},
    {"classic/beetle.obj", false, false, -1, 2},
    {"classic/suzanne.obj", false, true, -1, 3},
    {"classic/beast.obj.gz", true, true, 0, 1},
    {"classic/stanford-bunny.obj.gz", false, true, -1, 1},
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

// The textured OBJ models and the large classic ones (a megabyte or more: read in chunks).
TEST(Mesh_IO_models, ObjParserAgreesWithTinyobjloader) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  std::vector<std::string> paths;
  for (const auto& c : textured_models) paths.push_back(shared_data(c.path));
  for (const char* c : {"classic/armadillo.obj.gz", "classic/nefertiti.obj.gz", "classic/stanford-bunny.obj.gz",
                        "classic/beast.obj.gz", "classic/ogre.obj.gz"})
    paths.push_back(cmgeom_test::shared_mesh(c, dir));
  std::size_t large = 0;
  for (const std::string& path : paths) {
    SCOPED_TRACE(path);
    ASSERT_FALSE(path.empty());
    large += fs::file_size(path) >= (std::size_t(1) << 20);
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
  EXPECT_GE(large, 5u);
}

// The reader links the triangles of a manifold soup in one pass (link_oriented_manifold); the
// mesh must be the one CGAL::Euler::add_face builds from the same triangles, connectivity and
// numbering alike (halfedges' targets, next, prev and faces, vertices' and faces' halfedges).
TEST(Mesh_IO_models, LinkedMeshesEqualTheOnesAddFaceBuilds) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  std::size_t compared = 0;
  for (const auto& c : classic_models) {
    SCOPED_TRACE(c.path);
    Textured_mesh tm;
    IO::Read_options ro;
    ro.repair = true;  // cow and the open non-manifold models: their repaired soups are linked too
    try {
      IO::read_mesh(cmgeom_test::shared_mesh(c.path, dir), tm, ro);
    } catch (const IO_error&) {
      continue;  // ogre: zero-area faces, refused without allow_degenerate_faces
    }
    const Surface_mesh& m = tm.mesh();
    Surface_mesh r;
    for (auto v : m.vertices()) r.add_vertex(m.point(v));
    for (auto f : m.faces()) {
      const auto h = m.halfedge(f);  // into the triangle's first corner
      const std::array<Surface_mesh::Vertex_index, 3> t{m.target(h), m.target(m.next(h)), m.target(m.next(m.next(h)))};
      ASSERT_NE(CGAL::Euler::add_face(t, r), Surface_mesh::null_face());
    }
    ASSERT_EQ(r.number_of_halfedges(), m.number_of_halfedges());
    for (auto h : m.halfedges()) {
      ASSERT_EQ(m.target(h), r.target(h)) << h;
      ASSERT_EQ(m.next(h), r.next(h)) << h;
      ASSERT_EQ(m.prev(h), r.prev(h)) << h;
      ASSERT_EQ(m.face(h), r.face(h)) << h;
    }
    for (auto v : m.vertices()) ASSERT_EQ(m.halfedge(v), r.halfedge(v)) << v;
    for (auto f : m.faces()) ASSERT_EQ(m.halfedge(f), r.halfedge(f)) << f;
    ++compared;
  }
  EXPECT_GE(compared, 20u);
}

TEST(Mesh_IO_models, GeometryOnlyReadingGivesTheTexturedMeshWithoutItsMaps) {
  // read_mesh() into a Surface_mesh: the mesh of the Textured_mesh reading, element for element
  // and bit for bit, without the "h:uv" and "f:material" maps; the same refusals
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  std::vector<std::string> paths;
  for (const auto& c : classic_models) paths.push_back(c.path);
  paths.push_back("textured/bob/bob_tri.obj");
  paths.push_back("textured/spot/spot.obj");
  std::size_t compared = 0, refused = 0;
  for (const std::string& path : paths) {
    SCOPED_TRACE(path);
    const std::string file = cmgeom_test::shared_mesh(path, dir);
    ASSERT_FALSE(file.empty());
    for (bool repair : {false, true}) {
      IO::Read_options ro;
      ro.repair = repair;
      Textured_mesh tm;
      Surface_mesh g;
      std::string textured_error, geometry_error;
      try {
        IO::read_mesh(file, tm, ro);
      } catch (const IO_error& e) {
        textured_error = e.what();
      }
      try {
        IO::read_mesh(file, g, ro);
      } catch (const IO_error& e) {
        geometry_error = e.what();
      }
      ASSERT_EQ(geometry_error, textured_error);
      if (!textured_error.empty()) {
        ++refused;
        continue;
      }
      const Surface_mesh& m = tm.mesh();
      EXPECT_FALSE((g.property_map<Surface_mesh::Halfedge_index, Point_2>("h:uv").second));
      EXPECT_FALSE((g.property_map<Surface_mesh::Face_index, int>("f:material").second));
      ASSERT_EQ(g.num_vertices(), m.num_vertices());
      ASSERT_EQ(g.num_halfedges(), m.num_halfedges());
      ASSERT_EQ(g.num_faces(), m.num_faces());
      for (auto v : m.vertices()) {
        ASSERT_EQ(std::memcmp(&g.point(v), &m.point(v), sizeof(Point_3)), 0) << v;
        ASSERT_EQ(g.halfedge(v), m.halfedge(v)) << v;
      }
      for (auto h : m.halfedges()) {
        ASSERT_EQ(g.target(h), m.target(h)) << h;
        ASSERT_EQ(g.next(h), m.next(h)) << h;
        ASSERT_EQ(g.face(h), m.face(h)) << h;
      }
      for (auto f : m.faces()) ASSERT_EQ(g.halfedge(f), m.halfedge(f)) << f;
      ++compared;
    }
  }
  EXPECT_GE(compared, 40u);
  EXPECT_GE(refused, 1u);  // ogre's zero-area faces, and the non-manifold models without repair
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

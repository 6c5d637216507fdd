// Tests of the textured-mesh model: seams as chart boundaries, copies rebinding property maps,
// the UV map of an untextured mesh made only when asked for.
#include "mesh_io_test_util.h"

#include <CGAL/boost/graph/helpers.h>

#include <thread>

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

// A file without texture coordinates is read without the "h:uv" map (16 bytes a halfedge of
// zeros); the map comes, filled with (0, 0), when first asked for, and copies keep either state.
TEST(Mesh_IO_model, UntexturedReadDefersTheUvMap) {
  const std::string dir = scratch_dir();
  const auto uv_property = [](const Textured_mesh& t) {
    return t.mesh().property_map<Surface_mesh::Halfedge_index, Point_2>("h:uv").second;
  };
  Textured_mesh plain;
  IO::read_mesh(write_text(dir, "quad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n"), plain);
  EXPECT_FALSE(plain.has_uvs());
  EXPECT_FALSE(plain.has_uv_map());
  EXPECT_FALSE(uv_property(plain));
  EXPECT_EQ(plain.material(*plain.mesh().faces().begin()), 0);  // the material map is there

  Textured_mesh deferred_copy = plain;  // a copy keeps the map deferred
  EXPECT_FALSE(deferred_copy.has_uv_map());
  EXPECT_FALSE(uv_property(deferred_copy));

  // several threads asking a const mesh at once get one map, the same for all, of (0, 0)
  const Textured_mesh& c = plain;
  std::vector<Textured_mesh::UV_map> got(4);
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < got.size(); ++i) threads.emplace_back([&c, &got, i] { got[i] = c.uv_map(); });
  for (auto& t : threads) t.join();
  EXPECT_TRUE(plain.has_uv_map());
  EXPECT_TRUE(uv_property(plain));
  std::size_t uv_maps = 0;
  for (const auto& name : plain.mesh().properties<Surface_mesh::Halfedge_index>()) uv_maps += name == "h:uv";
  EXPECT_EQ(uv_maps, 1u);
  for (const auto& m : got) EXPECT_EQ(m, got.front());
  for (auto h : plain.mesh().halfedges()) EXPECT_EQ(plain.uv(h), Point_2(0, 0));
  EXPECT_FALSE(deferred_copy.has_uv_map());  // the copy made before is not concerned

  const auto h = *plain.mesh().halfedges().begin();
  plain.set_uv(h, Point_2(0.5, 0.25));
  Textured_mesh bound_copy = plain;  // a copy of a mesh with the map has it, with its values
  EXPECT_TRUE(bound_copy.has_uv_map());
  EXPECT_EQ(bound_copy.uv(h), Point_2(0.5, 0.25));
  bound_copy.set_uv(h, Point_2(1, 1));
  EXPECT_EQ(plain.uv(h), Point_2(0.5, 0.25));

  // set_uv() and set_has_uvs(true) on a deferred map make it
  Textured_mesh moved = std::move(deferred_copy);
  EXPECT_FALSE(moved.has_uv_map());
  moved.set_uv(h, Point_2(0.75, 0.5));
  EXPECT_EQ(moved.uv(h), Point_2(0.75, 0.5));
  Textured_mesh other(Surface_mesh(plain.mesh()), Textured_mesh::without_uv_map);  // (it has "h:uv")
  EXPECT_TRUE(other.has_uv_map());
  EXPECT_EQ(other.uv(h), Point_2(0.5, 0.25));
  Surface_mesh bare;
  CGAL::make_triangle(Point_3(0, 0, 0), Point_3(1, 0, 0), Point_3(0, 1, 0), bare);
  Textured_mesh later(bare, Textured_mesh::without_uv_map);
  EXPECT_FALSE(later.has_uv_map());
  later.set_has_uvs(true);
  EXPECT_TRUE(later.has_uv_map());
  EXPECT_TRUE(later.has_uvs());
  EXPECT_TRUE(Textured_mesh(bare).has_uv_map());  // without the tag the map is made at once

  // a textured file has the map from the start
  Textured_mesh textured;
  IO::read_mesh(write_text(dir, "t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.25 0.5\nf 1/1 2/1 3/1\n"), textured);
  EXPECT_TRUE(textured.has_uvs());
  EXPECT_TRUE(textured.has_uv_map());
}

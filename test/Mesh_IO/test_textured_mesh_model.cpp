// Tests of the textured-mesh model: seams as chart boundaries, copies rebinding property maps.
#include "mesh_io_test_util.h"

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

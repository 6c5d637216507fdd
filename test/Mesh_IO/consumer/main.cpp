// Builds a tetrahedron with per-corner UVs, writes it as OBJ through the installed CMGeom,
// reads it back and checks that nothing changed. Exit code 0 on success.
#include <CMGeom/Mesh_IO.h>

#include <cstdio>
#include <filesystem>

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : ".";
  CMGeom::Textured_mesh tm;
  auto& m = tm.mesh();
  const auto a = m.add_vertex(CMGeom::Point_3(0, 0, 0));
  const auto b = m.add_vertex(CMGeom::Point_3(1, 0, 0));
  const auto c = m.add_vertex(CMGeom::Point_3(0, 1, 0));
  const auto d = m.add_vertex(CMGeom::Point_3(0, 0, 1));
  m.add_face(a, c, b);
  m.add_face(a, b, d);
  m.add_face(a, d, c);
  m.add_face(b, c, d);
  int k = 0;
  for (auto h : m.halfedges())
    if (!m.is_border(h)) {
      tm.set_uv(h, CMGeom::Point_2(0.125 * (k % 8), 0.1 * (k / 8)));
      ++k;
    }
  tm.set_has_uvs(true);
  const std::string path = (std::filesystem::path(dir) / "tetra.obj").string();
  CMGeom::IO::write_mesh(path, tm);
  CMGeom::Textured_mesh back;
  CMGeom::IO::read_mesh(path, back);
  auto ids = back.mesh().add_property_map<CMGeom::Surface_mesh::Face_index, int>("f:chart", -1).first;
  const std::size_t charts = CMGeom::compute_chart_ids(back.mesh(), back.uv_map(), ids);
  const bool ok = back.mesh().number_of_vertices() == 4 && back.mesh().number_of_faces() == 4 && back.has_uvs() &&
                  charts == 4;  // every face has its own UVs: 4 charts
  std::printf("consumer: %zu vertices, %zu faces, %zu charts: %s\n", std::size_t(back.mesh().number_of_vertices()),
              std::size_t(back.mesh().number_of_faces()), charts, ok ? "ok" : "MISMATCH");
  return ok ? 0 : 1;
}

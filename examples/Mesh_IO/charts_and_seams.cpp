// Reads a textured mesh, labels its texture charts and counts seam edges.
//
//   mesh_io_charts [mesh.obj]      (default: the bundled Spot model)
//
// Seams are not cuts: the mesh keeps one vertex per position and each face corner carries its
// own UV ("h:uv" halfedge property), so an edge is a seam when its two faces disagree.
#include <CMGeom/Mesh_IO.h>

#include <iostream>

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : "data/spot/spot.obj";
  CMGeom::Textured_mesh tm;
  try {
    CMGeom::IO::read_mesh(path, tm);  // validated; textures stay as file paths
  } catch (const CMGeom::Error& e) {
    std::cerr << e.what() << "\n";
    return 1;
  }
  const CMGeom::Surface_mesh& mesh = tm.mesh();

  // Chart ids in a face property map; any writable face map works.
  auto chart = tm.mesh().add_property_map<CMGeom::Surface_mesh::Face_index, int>("f:chart", -1).first;
  const std::size_t charts = CMGeom::compute_chart_ids(mesh, tm.uv_map(), chart);

  std::size_t seams = 0, corners_on_seams = 0;
  for (auto e : mesh.edges()) seams += CMGeom::is_seam_edge(e, mesh, tm.uv_map());
  for (auto v : mesh.vertices()) corners_on_seams += CMGeom::number_of_charts_around_vertex(v, mesh, chart) > 1;

  std::cout << path << ": " << mesh.number_of_vertices() << " vertices, " << mesh.number_of_faces() << " faces, "
            << charts << " charts, " << seams << " seam edges, " << corners_on_seams
            << " vertices shared by several charts\n";
  for (const auto& m : tm.materials())
    std::cout << "material '" << m.name << "': texture " << (m.diffuse_texture.empty() ? "(none)" : m.diffuse_texture)
              << "\n";
  return charts > 0 ? 0 : 1;
}

// An error map: a coarse sphere coloured by the distance of its vertices to a fine one, with a
// legend and a caption, next to a wireframe view of it, in one PNG grid.
//
//   rendering_error_map [out.png]
#include <CMGeom/Metrics/approximation_error.h>
#include <CMGeom/Mesh_IO/image_io.h>
#include <CMGeom/Rendering.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/subdivision_method_3.h>

#include <cmath>
#include <iostream>

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<K::Point_3>;
namespace R = CMGeom::Rendering;

Mesh sphere(int level, double bump) {
  Mesh m;
  CGAL::make_tetrahedron(K::Point_3(1, 1, 1), K::Point_3(1, -1, -1), K::Point_3(-1, 1, -1), K::Point_3(-1, -1, 1), m);
  CGAL::Subdivision_method_3::Loop_subdivision(m, CGAL::parameters::number_of_iterations(level));
  for (auto v : m.vertices()) {
    const K::Vector_3 d = m.point(v) - CGAL::ORIGIN;
    const K::Vector_3 u = d / std::sqrt(d.squared_length());
    m.point(v) = CGAL::ORIGIN + u * (1. + bump * std::sin(5 * u.x()) * std::sin(4 * u.y()));
  }
  return m;
}

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "error_map.png";
  const Mesh fine = sphere(5, 0.1), coarse = sphere(2, 0.1);
  const auto e = CMGeom::Metrics::approximation_error(fine, coarse);

  R::Renderer renderer;  // one context for both pictures
  const R::Render_mesh field_mesh = R::make_render_mesh(coarse, &e.approximation_vertex_error);
  R::Render_options o;
  o.width = o.height = 400;
  o.shading = R::Shading::Field;
  o.legend_label = "distance";
  o.caption = "coarse vs fine";
  const CMGeom::Image left = R::render_picture(renderer, field_mesh, o);
  R::Render_options w;
  w.width = w.height = 400;
  w.wireframe = true;
  const CMGeom::Image right = R::render_picture(renderer, R::make_render_mesh(coarse), w);
  CMGeom::IO::write_image(out, R::make_grid({left, right}, {"error map", "wireframe"}, 2));
  std::cout << "wrote " << out << " (Hausdorff " << 100 * e.hausdorff << " % of the diagonal, "
            << renderer.description() << ")\n";
  return 0;
}

// Metro-style error between a mesh and a coarser version of it, with the per-vertex field; then
// several coarser versions against the reference prepared once (Error_reference), and a cheap
// lower bound of the Hausdorff distance for searches (Error_reference::hausdorff_lower_bound()).
//
//   metrics_approximation_error [reference] [approximation]
//
// Without arguments: a tetrahedron-subdivided sphere against a coarser one, built in memory.
#include <CMGeom/Metrics/approximation_error.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>
#include <CGAL/subdivision_method_3.h>

#include <algorithm>
#include <cmath>
#include <iostream>

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<K::Point_3>;

// A sphere of `level` Loop subdivisions of a tetrahedron, projected on the unit sphere.
Mesh sphere(int level) {
  Mesh m;
  CGAL::make_tetrahedron(K::Point_3(1, 1, 1), K::Point_3(1, -1, -1), K::Point_3(-1, 1, -1), K::Point_3(-1, -1, 1), m);
  CGAL::Subdivision_method_3::Loop_subdivision(m, CGAL::parameters::number_of_iterations(level));
  for (auto v : m.vertices()) {
    const K::Vector_3 d = m.point(v) - CGAL::ORIGIN;
    m.point(v) = CGAL::ORIGIN + d / std::sqrt(d.squared_length());
  }
  return m;
}

int main(int argc, char** argv) {
  Mesh reference, approximation;
  if (argc > 2) {
    if (!CGAL::IO::read_polygon_mesh(argv[1], reference) || !CGAL::IO::read_polygon_mesh(argv[2], approximation)) {
      std::cerr << "cannot read the meshes\n";
      return 1;
    }
  } else {
    reference = sphere(5);
    approximation = sphere(2);
  }
  CMGeom::Metrics::Error_options options;  // Metro defaults: 10 x max(F) samples per direction
  const auto e = CMGeom::Metrics::approximation_error(reference, approximation, options);
  std::cout << "samples   " << e.samples << "\n"
            << "diagonal  " << e.diagonal << "\n"
            << "hausdorff " << 100 * e.hausdorff << " % of the diagonal\n"
            << "mean      " << 100 * e.mean << " %\n"
            << "rms       " << 100 * e.rms << " %\n";
  // The vertex field: where does the approximation deviate most?
  const auto worst = std::max_element(e.approximation_vertex_error.begin(), e.approximation_vertex_error.end());
  std::cout << "worst approximation vertex: #" << (worst - e.approximation_vertex_error.begin()) << " at " << *worst
            << "\n";
  // Several approximations of one reference (a level-of-detail chain): the reference's tree and
  // samples are built once; each call gives what approximation_error() gives for that pair.
  const CMGeom::Metrics::Error_reference prepared(reference, options);
  const auto again = prepared.error(approximation);
  std::cout << "again     " << 100 * again.hausdorff << " % (the reference prepared once)\n";
  if (argc <= 2)
    for (int level = 1; level <= 4; ++level)
      std::cout << "level " << level << "   " << 100 * prepared.error(sphere(level)).hausdorff << " %\n";
  // A search among many candidates: a lower bound on one sample in 16 first, the full measure only
  // where the bound leaves the answer open (it is never above the full Hausdorff distance).
  const double lower = prepared.hausdorff_lower_bound(approximation, 16);
  std::cout << "lower bound " << 100 * lower << " % (one sample in 16)\n";
  return e.hausdorff > 0. && e.rms <= e.hausdorff && again.hausdorff == e.hausdorff && again.rms == e.rms &&
                 lower <= e.hausdorff * (1 + 1e-12)
             ? 0
             : 1;
}

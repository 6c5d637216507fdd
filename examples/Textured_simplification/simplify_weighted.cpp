// Simplifies a mesh with the weighted quadrics of thesis §3.4 on CMGeom's engine, then with the
// same policy under CGAL's edge_collapse, with the plain (unweighted) policy for comparison, with
// a policy of CGAL's own (Lindstrom-Turk) swapped into CMGeom's engine, and with the memoryful
// cost followed by the final fit of the vertices to the input's points (what simplify_mesh() and
// `cmgeom simplify` do by default), put together by hand; the fit is first foretold without moving
// anything (Surface_memory::fitted_positions()). Last, the mesh with 40 small spheres beside it,
// simplified far with and without removing whole parts (parameters::prune_components).
//   simplify_weighted [mesh.off|obj|ply] [target faces]
// Without arguments a lat-long sphere is used.
#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Textured_simplification.h>
// once per program: its blocks of 8 MB or more on transparent huge pages (see the header)
#include <CMGeom/huge_page_new.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/LindstromTurk_cost.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/LindstromTurk_placement.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/boost/graph/copy_face_graph.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <vector>

namespace TS = CMGeom::Textured_simplification;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<K::Point_3>;

// Counts collapses; the visitor is copied by the engines, so it points to its counter.
struct Counting_visitor : TS::Edge_collapse_visitor_base {
  std::size_t* collapses;
  explicit Counting_visitor(std::size_t* c) : collapses(c) {}
  template <class Profile, class V>
  void OnCollapsed(const Profile&, const V&) const {
    ++*collapses;
  }
};

// Counts the whole parts the engine removes (parameters::prune_components).
struct Pruned_parts_visitor : TS::Edge_collapse_visitor_base {
  std::size_t* parts;
  explicit Pruned_parts_visitor(std::size_t* p) : parts(p) {}
  template <class TM, class FaceRange>
  void OnFacesRemoved(const TM&, const FaceRange&) const {
    ++*parts;
  }
};

static Mesh sphere(int n) {
  Mesh m;
  std::vector<Mesh::Vertex_index> v;
  const auto north = m.add_vertex(K::Point_3(0, 0, 1)), south = m.add_vertex(K::Point_3(0, 0, -1));
  for (int i = 1; i < n; ++i)
    for (int j = 0; j < 2 * n; ++j) {
      const double t = M_PI * i / n, p = M_PI * j / n;
      v.push_back(m.add_vertex(K::Point_3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t))));
    }
  auto at = [&](int i, int j) { return v[(i - 1) * 2 * n + (j % (2 * n))]; };
  for (int j = 0; j < 2 * n; ++j) {
    m.add_face(north, at(1, j), at(1, j + 1));
    m.add_face(at(n - 1, j), south, at(n - 1, j + 1));
    for (int i = 1; i + 1 < n; ++i) {
      m.add_face(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      m.add_face(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  }
  return m;
}

int main(int argc, char** argv) {
  Mesh input;
  if (argc > 1) {
    try {  // the geometry alone: no texture coordinate or material maps, the reader's checks
      CMGeom::IO::read_mesh(argv[1], input);
    } catch (const CMGeom::IO_error& e) {
      std::cerr << e.what() << "\n";  // file:line: what is wrong
      return EXIT_FAILURE;
    }
  } else {
    input = sphere(40);
  }
  const std::size_t target = argc > 2 ? std::strtoul(argv[2], nullptr, 10) : input.number_of_faces() / 10;

  // 1. CMGeom's engine, weighted policy (the default policy of TS::edge_collapse)
  Mesh a = input;
  std::size_t collapses = 0;
  TS::edge_collapse(a, TS::Face_count_stop_predicate<Mesh>(a, target),
                    CGAL::parameters::visitor(Counting_visitor(&collapses)));
  std::cout << "cmgeom engine, weighted: " << a.number_of_faces() << " faces after " << collapses << " collapses\n";

  // 2. The same policy object under CGAL's engine (add the fold-over filter CMGeom's engine has built in)
  Mesh b = input;
  TS::Area_weighted_quadric_policies<Mesh> policy(b);
  CGAL::Surface_mesh_simplification::edge_collapse(
      b, TS::Face_count_stop_predicate<Mesh>(b, target),
      CGAL::parameters::get_cost(policy).get_placement(policy).filter(TS::No_normal_flip_filter<>()));
  std::cout << "cgal engine, weighted:   " << b.number_of_faces() << " faces\n";

  // 3. Swap the policy: plain Garland-Heckbert quadrics, with edge flips (§3.5.1)
  Mesh c = input;
  TS::Quadric_options plain;
  plain.weighted = false;
  TS::Area_weighted_quadric_policies<Mesh> plain_policy(c, plain);
  TS::edge_collapse(
      c, TS::Face_count_stop_predicate<Mesh>(c, target),
      CMGeom::parameters::edge_flips(true, CGAL::parameters::get_cost(plain_policy).get_placement(plain_policy)));
  std::cout << "cmgeom engine, plain + flips: " << c.number_of_faces() << " faces\n";

  // 4. Swap in a policy CMGeom did not write: CGAL's Lindstrom-Turk cost and placement run on
  //    CMGeom's engine unchanged (both engines take the same GetCost / GetPlacement concepts).
  Mesh d = input;
  namespace SMS = CGAL::Surface_mesh_simplification;
  TS::edge_collapse(
      d, TS::Face_count_stop_predicate<Mesh>(d, target),
      CGAL::parameters::get_cost(SMS::LindstromTurk_cost<Mesh>()).get_placement(SMS::LindstromTurk_placement<Mesh>()));
  std::cout << "cmgeom engine, CGAL's Lindstrom-Turk: " << d.number_of_faces() << " faces\n";

  // 5. Plain quadrics, the memoryful cost (the input's vertices kept on the faces), then the fit
  //    of the vertices to those points, with each vertex's quadric as its regulariser
  Mesh e = input;
  using Memory = TS::Surface_memory<Mesh, Mesh::Property_map<Mesh::Vertex_index, K::Point_3>>;
  Memory memory(e, e.points());
  TS::Area_weighted_quadric_policies<Mesh> memory_policy(e, plain);
  TS::edge_collapse(e, TS::Face_count_stop_predicate<Mesh>(e, target),
                    CMGeom::parameters::surface_memory(
                        &memory, CGAL::parameters::get_cost(memory_policy).get_placement(memory_policy)));
  // the fit is made only with points enough: by default 3 rounds, and at least 3 of the input's
  // points per face of the result (min_points_per_face; fewer, and it would move the vertices off
  // the points they were made from)
  const TS::Surface_fit_options fit;
  std::cout << "points per face " << double(memory.number_of_points()) / double(e.number_of_faces()) << ": the fit is "
            << (memory.fit_applies(e, fit) ? "made" : "not made (too few points)") << "\n";
  // where the fit will move the vertices, asked first without moving them (what a level-of-detail
  // chain does for each level while its collapses go on)
  const auto quadric_of = [&](Mesh::Vertex_index v) { return memory_policy.quadric(v); };
  const std::vector<K::Point_3> foretold = memory.fitted_positions(e, fit, quadric_of);
  const std::size_t moves = memory.fit_vertices(e, fit, quadric_of);
  for (Mesh::Vertex_index v : e.vertices())
    if (e.point(v) != foretold[std::size_t(v)]) {
      std::cerr << "fitted_positions() did not foretell the fit\n";
      return EXIT_FAILURE;
    }
  e.collect_garbage();  // (after the fit: the memory's points are attached to face indices)
  std::cout << "cmgeom engine, plain + memoryful cost + fit: " << e.number_of_faces() << " faces, " << moves
            << " vertex moves\n";

  // 6. Many parts: the mesh and 40 small spheres (48 faces each) in a row beside it. Collapses
  //    never remove a part, so a closed sphere keeps a few faces and together they hold a floor of
  //    faces above a low target; prune_components(target) lets the engine remove whole parts,
  //    cheapest first, when that costs less than the next collapse, never below the target.
  Mesh many = input;
  double x_max = -1e300, size = 0;
  for (Mesh::Vertex_index v : input.vertices()) x_max = (std::max)(x_max, input.point(v).x());
  for (Mesh::Vertex_index v : input.vertices()) size = (std::max)(size, std::abs(input.point(v).x() - x_max));
  const Mesh small = sphere(4);
  for (int k = 0; k < 40; ++k) {
    Mesh part = small;
    for (Mesh::Vertex_index v : part.vertices()) {
      const K::Point_3& q = part.point(v);
      part.point(v) =
          K::Point_3(x_max + 0.02 * size * (2 + 3 * k) + 0.01 * size * q.x(), 0.01 * size * q.y(), 0.01 * size * q.z());
    }
    CGAL::copy_face_graph(part, many);
  }
  const std::size_t low = target / 4;
  Mesh kept = many, pruned = many;
  TS::Area_weighted_quadric_policies<Mesh> kept_policy(kept, plain), pruned_policy(pruned, plain);
  TS::edge_collapse(kept, TS::Face_count_stop_predicate<Mesh>(kept, low),
                    CGAL::parameters::get_cost(kept_policy).get_placement(kept_policy));
  std::size_t parts_removed = 0;
  TS::edge_collapse(pruned, TS::Face_count_stop_predicate<Mesh>(pruned, low),
                    CMGeom::parameters::prune_components(low, CGAL::parameters::get_cost(pruned_policy)
                                                                  .get_placement(pruned_policy)
                                                                  .visitor(Pruned_parts_visitor(&parts_removed))));
  std::cout << "41 parts to " << low << " faces: " << kept.number_of_faces() << " faces without pruning, "
            << pruned.number_of_faces() << " with it (" << parts_removed << " parts removed)\n";

  bool ok = moves > 0 && kept.number_of_faces() > low && pruned.number_of_faces() <= low && parts_removed > 0 &&
            CGAL::is_valid_polygon_mesh(kept) && CGAL::is_valid_polygon_mesh(pruned);
  for (const Mesh* m : {&a, &b, &c, &d, &e})
    ok = ok && m->number_of_faces() <= target && CGAL::is_valid_polygon_mesh(*m);
  return ok ? EXIT_SUCCESS : EXIT_FAILURE;
}

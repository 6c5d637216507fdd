// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Where a Compact Model's error comes from (a diagnostic, never run by CTest): for every base face
// and each of its corners, the largest distance to the input of that corner's own local surface
// (closest-point projection of points of the flat base face) over the part of the face where the
// corner weighs most in the blend of §4.5 (barycentric coordinate >= 1/3), next to the largest
// distance of the flat base face itself. A corner surface much worse than its flat face is a
// surface that does not represent the input there (a fit spanning two different parts of the
// surface, an extrapolation); the blend W_i = a_i^3 / sum a^3 passes a share of that error on.
// Prints the worst corners and counts, as Markdown.
//
//   cm_surface_deviation [model file] [base faces] [rows]   (default: shared data fandisk, 250, 12)
#include <CMGeom/Compact_model.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include "cmgeom_bench_support.h"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace CM = CMGeom::CM;

int main(int argc, char** argv) {
  std::string path = argc > 1 ? argv[1] : std::string(CMGEOM_BENCH_DATA_DIR) + "/classic/fandisk.obj";
  const std::size_t base_faces = argc > 2 ? std::size_t(std::atol(argv[2])) : 250;
  const std::size_t rows = argc > 3 ? std::size_t(std::atol(argv[3])) : 12;
  if (!std::filesystem::exists(path)) {
    std::fprintf(stderr, "cm_surface_deviation: %s not found\n", path.c_str());
    return 1;
  }
  path = cmgeom_bench::readable_model(path, std::filesystem::temp_directory_path().string(), "cmgeom_bench_");
  CMGeom::Textured_mesh tm;
  CMGeom::IO::read_mesh(path, tm);
  const CMGeom::Surface_mesh& input = tm.mesh();
  using Primitive = CGAL::AABB_face_graph_triangle_primitive<CMGeom::Surface_mesh>;
  CGAL::AABB_tree<CGAL::AABB_traits<CMGeom::Kernel, Primitive>> tree(faces(input).first, faces(input).second, input);
  tree.accelerate_distance_queries();
  auto distance = [&](const CM::Vec3& p) { return std::sqrt(tree.squared_distance(CMGeom::Point_3(p.x, p.y, p.z))); };
  const double diagonal = cmgeom_bench::diagonal(CGAL::Polygon_mesh_processing::bbox(input));

  const CM::Compact_model m = CM::build_compact_model(input, base_faces);
  struct Corner_row {
    double surface, flat;
    std::size_t face;
    int corner;
  };
  std::vector<Corner_row> out;
  const int N = 12;  // samples per face side
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const auto& F = m.faces[f];
    double flat = 0, worst[3] = {0, 0, 0};
    for (int i = 0; i <= N; ++i)
      for (int j = 0; i + j <= N; ++j) {
        const double a[3] = {double(i) / N, double(j) / N, double(N - i - j) / N};
        const CM::Vec3 p =
            a[0] * m.vertices[F[0].vertex] + a[1] * m.vertices[F[1].vertex] + a[2] * m.vertices[F[2].vertex];
        flat = std::max(flat, distance(p));
        for (int c = 0; c < 3; ++c)
          if (3 * a[c] >= 1.0)
            worst[c] = std::max(worst[c], distance(CM::closest_point(m.frame(F[c]), m.surfaces[F[c].surface], p)));
      }
    for (int c = 0; c < 3; ++c) out.push_back({worst[c], flat, f, c});
  }
  std::sort(out.begin(), out.end(), [](const Corner_row& a, const Corner_row& b) { return a.surface > b.surface; });
  std::size_t worse = 0, much_worse = 0;
  for (const auto& r : out) {
    worse += r.surface > r.flat;
    much_worse += r.surface > 2 * r.flat + 1e-3 * diagonal;
  }
  std::printf("%s, %zu base vertices, %zu faces, %zu surfaces; distances in %% of the diagonal (%.4g)\n\n",
              path.c_str(), m.vertices.size(), m.faces.size(), m.surfaces.size(), diagonal);
  std::printf(
      "corner surfaces farther from the input than their flat face: %zu of %zu; more than twice as far "
      "(+0.1 %%): %zu\n\n",
      worse, out.size(), much_worse);
  std::printf(
      "| face | corner | base vertex | surface | model | surface max %% | flat face max %% "
      "|\n|---|---|---|---|---|---|---|\n");
  for (std::size_t k = 0; k < std::min(rows, out.size()); ++k) {
    const auto& r = out[k];
    const CM::Corner& c = m.faces[r.face][r.corner];
    std::printf("| %zu | %d | %u | %u | %d | %.3f | %.3f |\n", r.face, r.corner, unsigned(c.vertex),
                unsigned(c.surface), int(m.surfaces[c.surface].model), 100 * r.surface / diagonal,
                100 * r.flat / diagonal);
  }
  return 0;
}

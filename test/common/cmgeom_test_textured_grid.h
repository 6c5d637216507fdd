// A textured model built from scratch for the tests of several packages (no shared data needed).
#ifndef CMGEOM_TEST_TEXTURED_GRID_H
#define CMGEOM_TEST_TEXTURED_GRID_H

#include <CMGeom/Mesh_IO/Textured_mesh.h>

#include <cmath>
#include <cstddef>
#include <vector>

namespace cmgeom_test {

/// A bumpy N x N grid over the unit square with two charts: the left half maps to the left half
/// of the atlas, the right half, mirrored, to the right half, both stretched quadratically (a
/// non-uniform map, so that interpolating uvs over large triangles moves texels unless the
/// texture is resampled); v = 0.02 + 0.96 y². Its material has a `texels`² procedural texture:
/// smooth ramps (a texel's colour says where it is) plus a checker of 32-texel squares.
inline CMGeom::Textured_mesh two_chart_grid(int N, int texels) {
  CMGeom::Textured_mesh tm;
  auto& m = tm.mesh();
  std::vector<CMGeom::Surface_mesh::Vertex_index> v;
  for (int j = 0; j <= N; ++j)
    for (int i = 0; i <= N; ++i) {
      const double x = double(i) / N, y = double(j) / N;
      v.push_back(m.add_vertex(CMGeom::Point_3(x, y, 0.1 * std::sin(6 * x) * std::cos(4 * y))));
    }
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i) {
      const auto a = v[std::size_t(j * (N + 1) + i)], b = v[std::size_t(j * (N + 1) + i + 1)],
                 c = v[std::size_t((j + 1) * (N + 1) + i + 1)], d = v[std::size_t((j + 1) * (N + 1) + i)];
      const bool right = 2 * i >= N;
      for (auto f : {m.add_face(a, b, c), m.add_face(a, c, d)})
        for (auto h : CGAL::halfedges_around_face(m.halfedge(f), m)) {
          const CMGeom::Point_3 p = m.point(m.target(h));
          const double s = right ? 2 * (p.x() - 0.5) : 2 * p.x();
          const double u = right ? 0.98 - 0.45 * s * s : 0.02 + 0.45 * s * s;
          tm.set_uv(h, CMGeom::Point_2(u, 0.02 + 0.96 * p.y() * p.y()));
        }
    }
  tm.set_has_uvs(true);
  CMGeom::Image img(texels, texels, 3);
  for (int y = 0; y < texels; ++y)
    for (int x = 0; x < texels; ++x) {
      const float checker = ((x / 32 + y / 32) & 1) ? 0.2f : 0.f;
      img.set_value(x, y, 0, 0.7f * float(x) / float(texels) + checker);
      img.set_value(x, y, 1, 0.7f * float(y) / float(texels) + checker);
      img.set_value(x, y, 2, 0.5f);
    }
  tm.materials().resize(1);
  tm.materials()[0].name = "grid";
  tm.materials()[0].diffuse_image = img;
  return tm;
}

}  // namespace cmgeom_test

#endif

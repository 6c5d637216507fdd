// Surface_mesh test surfaces shared by several test files: a rippled torus and a height field.
#ifndef CMGEOM_TEST_SURFACE_MESHES_H
#define CMGEOM_TEST_SURFACE_MESHES_H

#include <CMGeom/Mesh_IO/Textured_mesh.h>

#include <cmath>
#include <cstddef>
#include <vector>

namespace cmgeom_test {

/// A torus of n x m quads, each split in two: closed, genus 1, every vertex of degree 6. Its tube
/// radius is `tube + ripple * sin(fa * a) * cos(fb * b)` at angles a (around the axis), b (around the tube).
inline CMGeom::Surface_mesh rippled_torus(int n, int m, double tube, double ripple, int fa, int fb) {
  using Mesh = CMGeom::Surface_mesh;
  Mesh t;
  std::vector<Mesh::Vertex_index> v(std::size_t(n * m));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double a = 2 * M_PI * i / n, b = 2 * M_PI * j / m;
      const double r = tube + ripple * std::sin(fa * a) * std::cos(fb * b);
      v[std::size_t(i * m + j)] = t.add_vertex(
          CMGeom::Point_3((1 + r * std::cos(b)) * std::cos(a), (1 + r * std::cos(b)) * std::sin(a), r * std::sin(b)));
    }
  auto at = [&](int i, int j) { return v[std::size_t(((i + n) % n) * m + (j + m) % m)]; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      t.add_face(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      t.add_face(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  return t;
}

/// The height field z = height(x, y) over the unit square on an n x n grid, each quad split in
/// two: an open sheet with one border loop.
template <class Height>
CMGeom::Surface_mesh height_field(int n, const Height& height) {
  using Mesh = CMGeom::Surface_mesh;
  Mesh t;
  std::vector<Mesh::Vertex_index> v;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double x = double(i) / n, y = double(j) / n;
      v.push_back(t.add_vertex(CMGeom::Point_3(x, y, height(x, y))));
    }
  auto at = [&](int i, int j) { return v[std::size_t(i * (n + 1) + j)]; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      t.add_face(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      t.add_face(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  return t;
}

}  // namespace cmgeom_test

#endif  // CMGEOM_TEST_SURFACE_MESHES_H
